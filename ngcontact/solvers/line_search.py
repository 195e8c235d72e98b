"""Step lengths along a Newton direction ``du``: Armijo's test and the exact line search of a convex energy.

Armijo's test (:func:`armijo`): the step ``u <- u - alpha du`` is accepted
when

    Pi(u - alpha du) <= Pi(u) - c alpha (du . r(u)),   c = ARMIJO = 1e-4,

and its energy is finite; a backtracking search halves ``alpha`` from 1
down to ``MIN_STEP``.  Where the energy cannot tell the step from no step
(:func:`ngcontact.solvers.roundoff.within_roundoff`) the caller judges it by
the residual instead (:func:`ngcontact.solvers.newton.minimize`).

The exact line search (:func:`exact_step`, ``line_search="exact"`` of
:func:`~ngcontact.solvers.newton.minimize`, for convex energies such as
penalty contact) minimizes the energy along the Newton direction:
``phi(alpha) = Pi(u - alpha du)`` is convex, so its slope
``phi'(alpha) = -du . r(u - alpha du)`` is nondecreasing, and its root is
bracketed (``alpha`` doubled up to ``max_step`` while ``phi' < 0``) and
located by the Illinois variant of regula falsi until
``|phi'(alpha)| <= 1e-3 |phi'(0)|``.  For a piecewise quadratic energy
(penalty contact) ``phi'`` is piecewise linear and a few residual
evaluations suffice.  Steps longer than 1 matter at a contact edge, where
the fixed-active-set Newton step typically covers only about half of the
distance to the solution.  The accepted step must still pass the Armijo
test above; otherwise the backtracking search decides.
"""
from __future__ import annotations

import math

import ngsolve as ng

from ngcontact.solvers.linear_solver import mask_fixed

ARMIJO = 1e-4
MIN_STEP = 2.0 ** -30


def armijo(energy: float, e_new: float, decrease: float) -> bool:
    """Armijo's test: ``Pi_new <= Pi - c decrease`` (``decrease = alpha du . r``), ``Pi_new`` finite."""
    return math.isfinite(e_new) and e_new <= energy - ARMIJO * decrease + 1e-14 * abs(energy)


def exact_step(form, u, du, slope0, fixed, trial, work, max_step) -> float:
    """Minimizer of ``phi(alpha) = Pi(u - alpha du)`` for a convex energy.

    ``slope0 = du . r(u) > 0`` is ``-phi'(0)``.  Returns 1 where the slope
    cannot be evaluated (non-finite values); the caller's Armijo test then
    guards the step.  ``work`` is overwritten.
    """
    def dphi(a):
        trial.data = u - a * du
        form.Apply(trial, work)
        mask_fixed(work, fixed)
        return -ng.InnerProduct(du, work)

    tol = 1e-3 * slope0
    lo, flo = 0.0, -slope0
    hi, fhi = 1.0, dphi(1.0)
    if not math.isfinite(fhi):
        return 1.0
    if abs(fhi) <= tol:
        return 1.0
    while fhi < 0.0 and hi < max_step:
        lo, flo = hi, fhi
        hi = min(2.0 * hi, max_step)
        fhi = dphi(hi)
        if not math.isfinite(fhi):
            return lo
        if abs(fhi) <= tol:
            return hi
    if fhi < 0.0:
        return hi
    a = illinois_root(dphi, lo, flo, hi, fhi, ftol=tol, max_iter=30)
    return a if math.isfinite(a) else 1.0


def illinois_root(f, lo: float, flo: float, hi: float, fhi: float, *, ftol: float,
                  xtol: float = 0.0, max_iter: int = 100) -> float:
    """Root of a nondecreasing ``f`` bracketed by ``f(lo) = flo < 0 < fhi = f(hi)``.

    The Illinois variant of regula falsi: secant steps within the bracket,
    halving the retained end's value when the same end is kept twice, which
    restores superlinear convergence.  Stops when ``|f| <= ftol``, the
    bracket is shorter than ``xtol`` or has collapsed numerically; returns
    ``nan`` when ``f`` is not finite at an iterate.
    """
    side, a = 0, hi
    for _ in range(max_iter):
        if not fhi > flo:          # the bracket collapsed numerically
            break
        a = (lo * fhi - hi * flo) / (fhi - flo)
        fa = f(a)
        if not math.isfinite(fa):
            return math.nan
        if abs(fa) <= ftol or hi - lo <= xtol:
            break
        if fa < 0.0:
            lo, flo = a, fa
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi = a, fa
            if side == 1:
                flo *= 0.5
            side = 1
    return a
