"""Uzawa's iteration for an augmented Lagrangian, written once for any constraint.

Exact non-penetration ``J_n - g <= 0`` (the rigid limit of the paper's
Winkler layer, eqs. 7, 9 and 65 with ``k_n -> infinity``) is the
saddle point of the elastic energy and the multiplier term.  With the
augmented energy of :func:`ngcontact.laws.penalty.augmented_normal_energy`
Uzawa's iteration alternates

    u_{j+1}      = argmin_u  Pi(u; lambda_j)                  (a Newton solve)
    lambda_{j+1} = [lambda_j + k (J_n(u_{j+1}) - g)]_+        (pointwise)

and stops at the first ``j`` with

    max (J_n - g)_+                       <=  rtol * L   (admissibility)
    max |lambda_{j+1} - lambda_j| / k     <=  rtol * L   (stationarity)

over the points the multiplier lives on (the second over those that carry
load, ``lambda_{j+1} > 0``, where ``|d lambda| / k = |J_n - g|`` is the gap
left open under load: complementarity), ``L`` a characteristic length of
the state (the caller's).  The change is measured in lengths, not relative
to ``lambda``: ``k`` times a penetration at the round-off of the
displacements can be a relative change of ``1e-5``.  A fixed point satisfies the complementarity
conditions ``lambda >= 0``, ``J_n - g <= 0``, ``lambda (J_n - g) = 0`` and
the equilibrium of the multiplier pressure, for every ``k > 0``: ``k`` sets
only the speed (the error in ``lambda`` contracts roughly by
``1 / (1 + k c)`` per pass, ``c`` the compliance of the mode, so ``k`` of
the order of ``E/h`` and above takes a few passes).  Each pass's Newton
solve starts from the previous one's state.

A soft augmentation converges slowly (``k`` well below ``E/h`` takes
hundreds of passes).  Since ``k`` is not in the answer, a caller
may pass ``stiffen``: whenever a pass fails to shrink the larger of the
two measures to ``SLOW`` times its value after the previous pass,
``stiffen()`` raises ``k`` (it returns ``False`` once it may not: a
ceiling that keeps the Newton systems well conditioned) and the passes
that did so are recorded.

Round-off ends the iteration too.  The measures cannot fall below the
round-off of the displacements (``eps cond(K) |u| / L``), which a graded
mesh (elements of 1e-6 of the period) lifts to about ``1e-10``: there a
multiplier update changes the equilibrium by less than the round-off floor
of the Newton residual (:func:`ngcontact.solvers.roundoff.at_floor`), the
pass's Newton solve takes no step, the state and so the measures repeat,
and the passes that follow only alternate between two states until the
pass limit (e.g. ``westergaard_graded.toml`` with exact enforcement, its
measures stalling just above ``rtol = 1e-10``).  A pass after the first
whose Newton solve took no step therefore stops the iteration, converged
at the floor (``"at_floor"`` in the history), when both measures are within
``FLOOR_GROWTH`` (Newton's own allowance for a start at round-off) times
``rtol``; otherwise the passes go on.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.roundoff import FLOOR_GROWTH

log = logging.getLogger(__name__)

#: a pass must shrink the larger of the two measures below this fraction of its previous value, or ``stiffen``
SLOW = 0.5


def uzawa(solve: Callable[[int], dict], update: Callable[[], dict[str, float]], *, rtol: float,
          max_iter: int, stiffen: Callable[[], bool] | None = None) -> dict[str, Any]:
    """Alternate ``solve`` (primal, multiplier fixed) and ``update`` (multiplier) until both tests hold.

    Parameters
    ----------
    solve
        ``solve(j)`` minimizes the augmented energy with the multiplier of
        pass ``j`` (1-based) held fixed and returns its Newton history.
    update
        Updates the multiplier from the current state and returns the two
        measures of the module docstring, ``{"penetration": max (J_n - g)_+ / L,
        "change": max |d lambda| / (k L)}`` (and optionally
        ``"relative_change"``, kept in the history).
    rtol, max_iter
        Stopping rule of the module docstring; largest number of passes.
    stiffen
        Optional: raises the augmentation when a pass is slow (module
        docstring); returns whether it did.

    Returns
    -------
    dict
        ``newton`` (the passes' histories), ``penetrations``, ``changes``,
        ``relative_changes``, ``uzawa_iterations``, ``stiffened`` (the passes
        after which the augmentation was raised), ``at_floor`` (stopped at
        the round-off floor, module docstring).

    Raises
    ------
    ConvergenceError
        After ``max_iter`` passes, with the history.
    """
    history: dict[str, Any] = {"newton": [], "penetrations": [], "changes": [], "relative_changes": [],
                               "uzawa_iterations": 0, "stiffened": [], "at_floor": False}
    pen = change = previous = float("inf")
    for j in range(1, max_iter + 1):
        history["newton"].append(solve(j))
        measures = update()
        pen, change = measures["penetration"], measures["change"]
        history["penetrations"].append(pen)
        history["changes"].append(change)
        history["relative_changes"].append(measures.get("relative_change", change))
        history["uzawa_iterations"] = j
        log.debug("uzawa %d: penetration %.3e, multiplier change %.3e (relative)", j, pen, change)
        if pen <= rtol and change <= rtol:
            return history
        worst = max(pen, change)
        if j > 1 and history["newton"][-1].get("iterations", 1) == 0 and worst <= FLOOR_GROWTH * rtol:
            history["at_floor"] = True
            log.debug("uzawa %d: the multiplier update no longer moves the state (round-off); converged", j)
            return history
        if stiffen is not None and worst > SLOW * previous and stiffen():
            history["stiffened"].append(j)
            log.debug("uzawa %d: slow pass, augmentation raised", j)
        previous = worst
    raise ConvergenceError(f"Uzawa's iteration did not converge in {max_iter} passes: relative penetration "
                           f"{pen:.3e} and multiplier change {change:.3e}, allowed {rtol:g}; raise the "
                           "augmentation k_n (towards E/h and above) or the pass limit", history)
