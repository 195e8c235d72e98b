"""Continuation in a regularization parameter, from a smooth problem to the one asked for.

The regularized Coulomb law of the macro interface (paper eqs. 16-17 and
42-43) replaces ``|J_t|`` by the Huber function of width ``w``: a
sticking point carries ``G J_t / w``, a sliding one ``G J_t / |J_t|``.
With ``w`` of a micrometre the stick/slip kink is sharp against the
slips a load produces (tens of micrometres), and Newton's method started
far from the solution can stall on it.  With ``w`` as large as those slips
every point sticks in the Huber sense, the equations are nearly linear and
Newton converges in a few steps; the solution then moves continuously as
``w`` shrinks.  Hence the ladder

    w_0 = w_start > w_1 > ... > w_J = w,   w_{j+1} = w_j / ratio,

each rung solved from the solution of the one before.  A rung that fails
is retried from the last solved one with the ratio replaced by its square
root (at most ``MAX_REFINEMENTS`` times in a row; a solved rung squares
it again, up to ``RATIO``); the intermediate rungs
are solved to ``INTERMEDIATE_RTOL`` only, the last one to the caller's
tolerance.
"""
from __future__ import annotations

import logging
import math
from typing import Callable

from ngcontact.errors import ConvergenceError

log = logging.getLogger(__name__)

#: ratio between consecutive widths of the ladder
RATIO = 10.0
#: halvings (in the logarithm) of the ratio a failed rung may take before the ladder gives up
MAX_REFINEMENTS = 4
#: relative residual reduction of the rungs before the last one
INTERMEDIATE_RTOL = 1e-6


def ladder(solve_at: Callable[[float, bool], dict], save: Callable[[], object], restore: Callable[[object], None],
           *, start: float, target: float) -> list[dict]:
    """Solve at widths from ``start`` down to ``target`` (module docstring).

    Parameters
    ----------
    solve_at
        ``solve_at(w, last)`` solves at width ``w`` from the current state
        (to the caller's tolerance when ``last``, else to
        ``INTERMEDIATE_RTOL``) and returns its history; raises
        :class:`ConvergenceError` on failure.
    save, restore
        Copy of the current state, and its restoration.
    start, target
        The first and the last width, ``start >= target > 0``.

    Returns
    -------
    list of dict
        One record per rung solved: ``{"width", "history"}``.

    Raises
    ------
    ConvergenceError
        A rung failed after ``MAX_REFINEMENTS`` refinements of the ratio;
        the message names the widths reached.
    """
    records: list[dict] = []
    w, ratio, refinements = max(start, target), RATIO, 0
    state = save()
    while True:
        last = w <= target * (1 + 1e-12)
        try:
            records.append({"width": w, "history": solve_at(w, last)})
        except ConvergenceError as err:
            restore(state)
            if not records or refinements >= MAX_REFINEMENTS:
                solved = f"solved down to width {records[-1]['width']:.3g}" if records else "no width solved"
                raise ConvergenceError(f"continuation in the Huber width from {start:.3g} to {target:.3g}: "
                                       f"{solved}; at {w:.3g}: {err}", {"continuation": records}) from err
            ratio, refinements = math.sqrt(ratio), refinements + 1
            w = max(records[-1]["width"] / ratio, target)
            log.info("continuation: width %.3g failed, retrying with ratio %.3g", w, ratio)
            continue
        if last:
            return records
        state, refinements = save(), 0
        ratio = min(RATIO, ratio * ratio)
        w = max(w / ratio, target)
