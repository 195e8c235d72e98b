"""Newton's method on a system of equations that is no energy's gradient.

Coulomb friction makes the friction threshold depend on the pressure,
``G = mu [p(u)]_+ + G0`` (paper eqs. 16-17; the homogenized law, eqs.
42-43), and the coupled problem has no energy.  Its equilibrium is still a
system of equations,

    R(u) = Pi_0'(u) + int_S tau_t(J(u); G(p(u))) . J_t(v) ds = 0,

with ``Pi_0`` the energy of everything but friction (elasticity, normal
law, loads) and ``tau_t`` the regularized friction traction
(:func:`ngcontact.laws.interface_energy.friction_traction`).  ``R`` is
piecewise smooth (kinks at contact and at the stick/slip threshold), so
Newton's method with its generalized Jacobian ``K = R'(u)`` (NGSolve's
linearization of the form, which differentiates ``G(p(u))`` too: ``K`` is
not symmetric) converges locally superlinearly (semismooth Newton; Qi and
Sun, Math. Program. 58, 1993).

Globalization: with no energy to decrease, the merit function is the
residual norm ``phi(u) = |R(u)|`` (free dofs).  A step ``u <- u - alpha du``,
``K du = R``, takes the largest ``alpha = 1, 1/2, 1/4, ...`` with

    |R(u - alpha du)| <= (1 - c alpha) |R(u)|,   c = 1e-4,

(``du`` is a descent direction of ``|R|^2`` wherever ``R`` is
differentiable).  Where no ``alpha`` down to ``2^-MAX_HALVINGS`` passes,
the step with the smallest residual among those tried is taken when it
still decreases the residual at all; otherwise the solve fails with its
history.  The stopping rule and the round-off floor are those of
:func:`ngcontact.solvers.newton.minimize`.
"""
from __future__ import annotations

import logging
import math

import ngsolve as ng

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.linear_solver import LinearSolver
from ngcontact.solvers.newton import ARMIJO, NewtonHistory, at_floor, fixed_mask, mask_fixed, roundoff_floor

log = logging.getLogger(__name__)

#: largest number of step halvings of the residual line search
MAX_HALVINGS = 12


def solve_equations(form: ng.BilinearForm, gfu: ng.GridFunction, *, freedofs=None, rtol: float = 1e-10,
                    atol: float = 0.0, max_iter: int = 50, linear: LinearSolver | None = None) -> NewtonHistory:
    """Solve ``R(u) = 0`` (``R = form.Apply``) from ``gfu`` (updated in place).

    Parameters
    ----------
    form
        Non-symmetric ``BilinearForm`` whose ``Apply`` is the residual and
        whose linearization is its Jacobian.
    gfu
        Start value with the Dirichlet values set.
    freedofs
        The unknowns (default: the space's free dofs).
    rtol, atol, max_iter
        Stop when ``|R| <= max(rtol |R_0|, atol)`` or at the round-off floor.
    linear
        Tangent solves; non-symmetric: UMFPACK directly, GMRES with BDDC
        iteratively (:class:`~ngcontact.solvers.linear_solver.LinearSolver`).

    Returns
    -------
    NewtonHistory
        Residual norms in ``residuals``; ``energies`` stays empty (there is none).

    Raises
    ------
    ConvergenceError
        No step decreases the residual, or ``max_iter`` steps were not enough.
    """
    if freedofs is None:
        freedofs = gfu.space.FreeDofs()
    linear = linear if linear is not None else LinearSolver("direct", inverse="umfpack")
    linear.register(form, freedofs)
    fixed = fixed_mask(freedofs)
    hist = NewtonHistory()
    res, du, trial = (gfu.vec.CreateVector() for _ in range(3))

    def residual(vec) -> float:
        form.Apply(vec, res)
        mask_fixed(res, fixed)
        return math.sqrt(max(ng.InnerProduct(res, res), 0.0))

    rnorm = residual(gfu.vec)
    hist.residuals.append(rnorm)
    if not math.isfinite(rnorm):
        raise ConvergenceError("the start value gives a non-finite residual", hist.as_dict())
    r0 = rnorm
    if rnorm <= atol or rnorm == 0.0:
        hist.converged = True
        return hist
    floor0 = None
    for it in range(1, max_iter + 1):
        form.AssembleLinearization(gfu.vec)
        floor = roundoff_floor(form.mat, gfu.vec, fixed)
        floor0 = floor if floor0 is None else floor0
        if at_floor(rnorm, floor, r0, floor0):
            hist.converged = True
            return hist
        residual(gfu.vec)
        linear.prepare(form, freedofs, symmetric=False).apply(res, du)
        alpha, r_new = _line_search(gfu.vec, du, rnorm, trial, residual)
        if alpha == 0.0:
            hist.steps.append(0.0)
            raise ConvergenceError(f"Newton step {it} on the coupled equations: no step along the Newton "
                                   f"direction decreases the residual {rnorm:.3e}", hist.as_dict())
        gfu.vec.data -= alpha * du
        rnorm = r_new
        hist.steps.append(alpha)
        hist.residuals.append(rnorm)
        log.debug("semismooth newton %d: |R| = %.3e, alpha = %g", it, rnorm, alpha)
        if rnorm <= max(rtol * r0, atol):
            hist.converged = True
            return hist
    raise ConvergenceError(f"Newton on the coupled equations did not converge in {max_iter} steps: residual "
                           f"{rnorm:.3e} > {max(rtol * r0, atol):.3e} (rtol {rtol:g} x first residual {r0:.3e})",
                           hist.as_dict())


def _line_search(u, du, rnorm: float, trial, residual) -> tuple[float, float]:
    """The step length of the module docstring and the residual there; ``(0, rnorm)`` when none decreases it."""
    best = (0.0, rnorm)
    alpha = 1.0
    for _ in range(MAX_HALVINGS + 1):
        trial.data = u - alpha * du
        r = residual(trial)
        if math.isfinite(r):
            if r <= (1.0 - ARMIJO * alpha) * rnorm:
                return alpha, r
            if r < best[1]:
                best = (alpha, r)
        alpha *= 0.5
    return best
