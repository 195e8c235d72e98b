"""Coulomb friction by Newton's method on the coupled equations (threshold differentiated, consistent tangent).

Coulomb's law makes the friction threshold a function of the state,
``G(u) = mu [p(u)]_+ + G0`` (paper eqs. 16-17; the penalized contact of
eq. 65 on the cell, the homogenized law of eqs. 42-43 on the macro
problem), so the equilibrium

    R(u) = Pi_T'(u; G)|_{G = G(u)} = Pi_0'(u) + int_S tau_t(J(u); G(u)) . J_t(v) ds = 0

is the stationarity of no energy: ``Pi_T(u; G)`` is the convex Tresca
energy with a threshold field ``G`` held as data (``Pi_0`` everything but
friction, ``tau_t`` the Huber-regularized friction traction of
:func:`ngcontact.laws.interface_energy.friction_traction`), and ``R`` its
gradient with ``G`` then set to ``G(u)``.  The fixed point of
:mod:`ngcontact.solvers.coulomb` solves a Tresca problem per pass and
converges linearly, each pass a whole Newton solve.  Here Newton is applied to
``R`` itself, with its generalized Jacobian

    K_c(u) = Pi_T''(u; G(u)) + d/dG [Pi_T'(u; G)] . dG/du

(NGSolve's linearization of the residual form): the symmetric Tresca
tangent plus the coupling of the friction traction ``G J_t / max(|J_t|,
w)`` with the pressure, ``mu k_n (J_t / max(|J_t|, w)) (x) n`` on the
points in contact, a non-symmetric matrix.  ``[.]_+`` and the Huber
branches are differentiated on their active side: a semismooth Newton
(Qi and Sun, Math. Program. 58, 1993), locally superlinear once the
contact, stick and slip sets have settled.  A zero of ``R`` is exactly a
fixed point ``u = argmin Pi_T(.; G(u))``: the solution is the fixed
point's.

Tangent solves go through a
:class:`~ngcontact.solvers.linear_solver.LinearSolver` with
``symmetric=False``: UMFPACK (or the policy's LU) directly, GMRES with
BDDC iteratively; the symmetric Tresca direction below is solved by the
policy's symmetric solve (Cholesky or CG with BDDC).

Globalization (``R`` has no potential, so no energy decides the step).
The Newton step ``du = K_c^{-1} R(u)`` is taken in full when it lowers
``|R|``.  Otherwise, one of two:

* ``frozen`` given (:class:`FrozenTresca`: the Tresca energy with the
  threshold read from a frozen copy of the state): the step length
  minimizes, along ``du``, ``Pi_T(.; G(u))`` with ``G`` frozen at the
  current iterate (whose gradient at ``u`` is ``R(u)``: a local model of
  the problem; its exact line search,
  :func:`ngcontact.solvers.line_search.exact_step`, is the frictionless and
  Tresca cells'), guarded by Armijo's test on it; where ``du`` is no
  descent direction of that energy (strong coupling) the symmetric Tresca
  direction ``Pi_T''^{-1} R`` is taken instead.
* no ``frozen``: backtracking on the merit ``|R|``, the largest ``alpha =
  1/2, 1/4, ...`` (down to ``2^-MAX_HALVINGS``) with ``|R(u - alpha du)|
  <= (1 - c alpha) |R(u)|``, ``c = 1e-4``, else the step with the smallest
  residual among those tried when it decreases ``|R|`` at all.

Both callers pass ``frozen``: on the cell
``geometries/cells/rectangular_coulomb.toml`` and on the femur / hip-stem
scene and its variants (``scripts/femur_coulomb_variants.py``) the
frozen-energy search takes fewer Newton steps than residual backtracking
and never needs the macro problem's width continuation, which
backtracking needs on some variants (``scripts/coulomb_newton_globalization.py``:
docs/benchmarks.md, section coulomb_newton_globalization); a pure full
step cycles between two contact sets on the cell.

Stopping rule: that of :func:`ngcontact.solvers.newton.minimize` on
``|R|`` (``rtol`` times the first residual, ``atol``, or the round-off
floor after real progress).  An active set that cycles while the residual
stagnates (:class:`~ngcontact.solvers.newton.ActiveSetCycle`), no
decrease along the step, or ``max_iter`` steps raise
:class:`~ngcontact.errors.ConvergenceError` with the history; the caller
may then fall back (the cell to the fixed point, the macro problem to
continuation in the Huber width).
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Callable

import ngsolve as ng
import numpy as np

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.linear_solver import LinearSolver, fixed_mask
from ngcontact.solvers.line_search import ARMIJO, MIN_STEP, armijo, exact_step
from ngcontact.solvers.newton import ActiveSetCycle, NewtonHistory
from ngcontact.solvers.roundoff import at_floor, free_norm, roundoff_floors

log = logging.getLogger(__name__)

#: largest number of step halvings of the residual line search
MAX_HALVINGS = 12
#: largest step of the exact line search on the frozen Tresca energy
MAX_STEP = 8.0


@dataclass
class FrozenTresca:
    """The Tresca energy ``Pi_T(.; G)`` whose threshold ``G`` is read from a frozen copy of the state.

    ``form``: symmetric ``BilinearForm`` of ``Variation`` terms;
    ``freeze()``: copy the current state into the frozen one.
    """

    form: ng.BilinearForm
    freeze: Callable[[], None]


def coupled_newton(residual_form: ng.BilinearForm, gfu: ng.GridFunction, *, freedofs=None,
                   linear: LinearSolver | None = None, frozen: FrozenTresca | None = None,
                   pressure: Callable[[], np.ndarray] | None = None, rtol: float = 1e-10, atol: float = 0.0,
                   max_iter: int = 40, max_step: float = MAX_STEP, active_set=None) -> dict:
    """Solve ``R(u) = 0`` (``R = residual_form.Apply``) from ``gfu`` (updated in place); module docstring.

    Parameters
    ----------
    residual_form
        Non-symmetric form whose ``Apply`` is ``R`` and whose linearization is ``K_c``.
    gfu
        Start value with the Dirichlet values set.
    freedofs
        The unknowns (default: the space's free dofs).
    linear
        Tangent solves (default: direct, UMFPACK); its record counts them.
    frozen
        The frozen Tresca energy: its exact line search globalizes; without
        it, backtracking on ``|R|``.
    pressure
        Optional: the contact pressure of the current state at the contact
        points; its largest change per step goes to ``coulomb_changes``.
    rtol, atol, max_iter
        Stopping rule and step limit (:func:`ngcontact.solvers.newton.minimize`).
    max_step
        Largest step of the exact line search.
    active_set
        Optional ``active_set(gfu) -> hashable`` signature (cycle detection).

    Returns
    -------
    dict
        The history (:meth:`NewtonHistory.as_dict`: residual norms; the
        frozen Tresca energies of the iterates when ``frozen`` is given)
        with ``"stage": "coulomb_newton"`` and ``coulomb_changes``.

    Raises
    ------
    ConvergenceError
        No decrease along the step, a cycling active set, or ``max_iter`` steps.
    """
    if freedofs is None:
        freedofs = gfu.space.FreeDofs()
    linear = linear if linear is not None else LinearSolver("direct", inverse="umfpack")
    linear.register(residual_form, freedofs)
    if frozen is not None:
        linear.register(frozen.form, freedofs)
    rec = _Record(residual_form, gfu, fixed_mask(freedofs), frozen, pressure)
    hist, fixed = rec.hist, rec.fixed
    cycle = ActiveSetCycle() if active_set is not None else None
    du, trial, work, r_trial = (gfu.vec.CreateVector() for _ in range(4))
    rnorm = rec.state()
    r0, floor0 = rnorm, None
    target = max(rtol * r0, atol)
    for it in range(1, max_iter + 1):
        if rnorm <= target or rnorm == 0.0:
            hist.converged = True
            break
        residual_form.AssembleLinearization(gfu.vec)
        floor = roundoff_floors(residual_form.mat, gfu.vec, fixed)[0]
        floor0 = floor if floor0 is None else floor0
        if at_floor(rnorm, floor, r0, floor0):
            log.info("coulomb newton %d: residual %.3e at its round-off floor; converged", it, rnorm)
            hist.converged = True
            break
        linear.prepare(residual_form, freedofs, symmetric=False).apply(rec.res, du)
        trial.data = gfu.vec - du
        r_full = rec.residual(trial, r_trial)
        if math.isfinite(r_full) and r_full < rnorm:
            alpha = 1.0
            gfu.vec.data = trial
        elif frozen is not None:
            alpha = _frozen_energy_step(frozen.form, gfu, du, freedofs, fixed, trial, work, rec.res, linear,
                                        max_step)
        else:
            alpha = _residual_step(gfu.vec, du, rnorm, trial, lambda v: rec.residual(v, r_trial))
        if alpha == 0.0:
            hist.steps.append(0.0)
            what = "the frozen Tresca energy" if frozen is not None else "the residual"
            raise rec.failed(f"Coulomb Newton step {it}: no decrease of {what} along the step (residual {rnorm:.3e})")
        hist.steps.append(alpha)
        rnorm = rec.state()
        log.debug("coulomb newton %d: |R| = %.3e, alpha = %g", it, rnorm, alpha)
        if cycle is not None:
            found = cycle.step(it, rec.active_set(active_set), rnorm)
            if found is not None and not rnorm <= target:
                raise rec.failed(f"Coulomb Newton step {it}: {found}")
    else:
        if not rnorm <= target:
            raise rec.failed(f"Coulomb Newton did not converge in {max_iter} steps: residual {rnorm:.3e} > "
                             f"{target:.3e} (rtol {rtol:g} x first residual {r0:.3e})")
        hist.converged = True
    return rec.as_dict()


class _Record:
    """The coupled Newton's iterates as recorded: residual norms, frozen energies, pressure changes."""

    def __init__(self, residual_form, gfu, fixed, frozen: FrozenTresca | None, pressure):
        self.residual_form, self.gfu, self.fixed = residual_form, gfu, fixed
        self.frozen, self.pressure = frozen, pressure
        self.hist = NewtonHistory()
        self.changes: list[float] = []
        self.res = gfu.vec.CreateVector()
        self.p_old = None

    def as_dict(self) -> dict:
        out = self.hist.as_dict()
        out.update(stage="coulomb_newton", coulomb_changes=self.changes)
        return out

    def failed(self, message: str) -> ConvergenceError:
        return ConvergenceError(message, self.as_dict())

    def residual(self, vec, out=None) -> float:
        """``|R(vec)|`` on the free dofs, ``R(vec)`` left in ``out`` (default ``self.res``)."""
        out = self.res if out is None else out
        self.residual_form.Apply(vec, out)
        return free_norm(out, self.fixed)

    def state(self) -> float:
        """Freeze the threshold at the iterate, return ``|R|`` (into ``self.res``); the energy and the largest
        pressure change since the last iterate go to the record."""
        frozen = self.frozen
        if frozen is not None:
            frozen.freeze()
        rnorm = self.residual(self.gfu.vec)
        energy = frozen.form.Energy(self.gfu.vec) if frozen is not None else 0.0
        self.hist.residuals.append(rnorm)
        if frozen is not None:
            self.hist.energies.append(energy)
        if not (math.isfinite(rnorm) and math.isfinite(energy)):
            raise self.failed(f"Coulomb Newton step {len(self.hist.steps)}: non-finite residual or energy")
        if self.pressure is not None:
            p_new = self.pressure()
            if self.p_old is not None:
                self.changes.append(float(np.max(np.abs(p_new - self.p_old))) if p_new.size else 0.0)
            self.p_old = p_new
        return rnorm

    def active_set(self, signature_of):
        """The iterate's active-set signature, its size recorded."""
        sig = signature_of(self.gfu)
        self.hist.active_set_sizes.append(int(sum(bin(b).count("1") for b in sig))
                                          if isinstance(sig, (bytes, bytearray)) else -1)
        return sig


def _frozen_energy_step(energy_form, gfu, du, freedofs, fixed, trial, work, res, linear, max_step) -> float:
    """Step along ``du`` (or the Tresca direction) minimizing the frozen Tresca energy; updates ``gfu``.

    ``res`` holds ``R(u)`` = the frozen energy's gradient at ``u`` on entry
    and may be overwritten.  Returns the step length, 0 when Armijo's test
    fails down to ``MIN_STEP``.
    """
    slope = ng.InnerProduct(du, res)
    if not slope > 0.0:          # no descent of the frozen energy: the symmetric Tresca direction
        energy_form.AssembleLinearization(gfu.vec)
        linear.prepare(energy_form, freedofs, symmetric=True).apply(res, du)
        slope = ng.InnerProduct(du, res)
        if not slope > 0.0:
            return 0.0
    energy = energy_form.Energy(gfu.vec)
    alpha = exact_step(energy_form, gfu.vec, du, slope, fixed, trial, work, max_step)
    while alpha >= MIN_STEP:
        trial.data = gfu.vec - alpha * du
        e_new = energy_form.Energy(trial)
        if armijo(energy, e_new, alpha * slope):
            gfu.vec.data = trial
            return alpha
        alpha *= 0.5
    return 0.0


def _residual_step(u, du, rnorm: float, trial, residual) -> float:
    """Backtracking on ``|R|`` from ``alpha = 1/2`` (module docstring); updates ``u``, 0 when nothing decreases it."""
    best, r_best = 0.0, rnorm
    alpha = 0.5
    for _ in range(MAX_HALVINGS):
        trial.data = u - alpha * du
        r = residual(trial)
        if math.isfinite(r):
            if r <= (1.0 - ARMIJO * alpha) * rnorm:
                best = alpha
                break
            if r < r_best:
                best, r_best = alpha, r
        alpha *= 0.5
    if best > 0.0:
        u.data -= best * du
    return best
