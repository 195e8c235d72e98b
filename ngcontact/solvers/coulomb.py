"""Coulomb friction as a fixed point of Tresca problems, written once for every scale.

Coulomb's law ``G = mu p`` makes the friction threshold depend on the
contact pressure, so no energy of the coupled problem exists (paper Sec.
2, eqs. 16-17, and the homogenized ``G0 = mu0 [p]_+ + G0`` of eqs. 42-43).
Each pass freezes the pressure of the previous iterate, ``G_k = mu
p_{k-1}``, and minimizes the convex Tresca energy with that threshold:

    for k = 1, 2, ...:  u_k = argmin Pi_Tresca(u; G = mu p(u_{k-1}))

stopped at the first ``k`` with

    max |p_k - p_{k-1}|  <=  coulomb_rtol * max |p_k|

over the quadrature points of the contact surface (``coulomb_rtol`` of
the scene's ``[solver]``), or failing with :class:`ConvergenceError` after
``coulomb_max_iter`` passes.  The history has one format everywhere:
``{"coulomb_changes": [...], "coulomb_iterations": k}`` plus the Newton
histories of the passes.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

import numpy as np

from ngcontact.errors import ConvergenceError

log = logging.getLogger(__name__)


def coulomb_fixed_point(freeze: Callable[[], None], tresca_solve: Callable[[], dict],
                        pressure: Callable[[], np.ndarray], *, rtol: float, max_iter: int) -> dict[str, Any]:
    """Iterate Tresca solves with the threshold of the previous pressure until it stops changing.

    Parameters
    ----------
    freeze
        Copies the current state into the one the threshold ``mu p`` is
        evaluated at (the previous iterate).
    tresca_solve
        Solves the Tresca problem with the frozen threshold from the
        current state; returns its Newton history (a dict).
    pressure
        The contact pressure of the current state at the quadrature points
        of the contact surface.
    rtol, max_iter
        The stopping rule of the module docstring.

    Returns
    -------
    dict
        ``newton`` (the passes' histories), ``coulomb_changes``,
        ``coulomb_iterations``.

    Raises
    ------
    ConvergenceError
        After ``max_iter`` passes, with the history.
    """
    history: dict[str, Any] = {"newton": [], "coulomb_changes": [], "coulomb_iterations": 0}
    p_old = pressure()
    change = scale = 0.0
    for k in range(1, max_iter + 1):
        freeze()
        history["newton"].append(tresca_solve())
        p_new = pressure()
        change = float(np.max(np.abs(p_new - p_old))) if p_new.size else 0.0
        scale = float(np.max(np.abs(p_new))) if p_new.size else 0.0
        history["coulomb_changes"].append(change)
        history["coulomb_iterations"] = k
        log.info("Coulomb fixed point %d: max |dp| = %.3e (max p %.3e)", k, change, scale)
        if change <= rtol * max(scale, 1e-300):
            return history
        p_old = p_new
    raise ConvergenceError(f"Coulomb fixed point did not converge in {max_iter} passes: max pressure change "
                           f"{change:.3e} > coulomb_rtol {rtol:g} x max pressure {scale:.3e}; raise "
                           "solver.coulomb_max_iter or solver.coulomb_rtol, or widen the Huber width", history)
