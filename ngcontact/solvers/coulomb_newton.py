"""Coulomb friction by one Newton iteration with the threshold differentiated (consistent tangent).

Coulomb's law makes the friction threshold a function of the state,
``G(u) = mu p(u)`` with ``p = k_n [J_n - g]_+`` (paper eqs. 16-17; the
penalized contact of eq. 65), so the equations

    R(u) = Pi_T'(u; G)|_{G = mu p(u)} = 0

are the stationarity of no energy: ``Pi_T(u; G)`` is the convex Tresca
energy with a threshold field ``G`` held as data, and ``R`` its gradient
with ``G`` then set to ``mu p(u)``.  The fixed point of
:mod:`ngcontact.solvers.coulomb` solves a Tresca problem per pass and
converges linearly (the rectangular valley: 6, 17, 24 Newton steps summed
over the passes of its three loads).  Here Newton is applied to ``R``
itself: its Jacobian

    K_c(u) = Pi_T''(u; G(u)) + d/dG [Pi_T'(u; G)] . mu dp/du

adds to the symmetric Tresca tangent the coupling of the friction traction
``G J_t / max(|J_t|, w)`` with the pressure, ``mu k_n (J_t / max(|J_t|, w))
(x) n`` on the points in contact: a non-symmetric matrix, solved by a
sparse LU factorization (UMFPACK).  ``[.]_+`` and the Huber branches are
differentiated on their active side (a semismooth Newton, as for the
penalty), which NGSolve's linearization of the residual form does.

Choice (against substepping the load with a predictor, option (b) of issue
12): the passes of the fixed point are slow because the *map* is a
contraction with factor 0.2-0.3 even where every set has settled, not
because the start is far; smaller load steps shrink each pass's work but
not their number per step, while the consistent tangent converges
quadratically once the contact, stick and slip sets have settled.  The
solution is the same: a zero of ``R`` is exactly a fixed point
``u = argmin Pi_T(.; mu p(u))``.

Globalization.  ``R`` has no potential, so no energy decides the step.
A step ``du = K_c^{-1} R(u)`` is taken in full when it lowers ``|R|``;
otherwise the step length minimizes, along ``du``, the Tresca energy with
the threshold frozen at the current iterate, ``Pi_T(.; mu p(u))`` (whose
gradient at ``u`` is ``R(u)``: the frozen energy is a local model of the
problem and its exact line search, :func:`ngcontact.solvers.newton.exact_step`,
is the one the frictionless and Tresca cells use), guarded by Armijo's
test on it.  Where ``du`` is no descent direction of that energy (a
strong coupling) the symmetric Tresca direction ``Pi_T''^{-1} R`` is taken
instead.  Measured on ``geometries/cells/rectangular_coulomb.toml``: 5, 6,
11 steps for the three loads (the shear loads' rigid continuation
counted); a pure full-step iteration cycles between two contact sets on
the first load; a residual-norm backtracking search took 16 and 12 steps
on the first and last loads; the symmetric Tresca steps until the sets
settle, then coupled steps, 5, 6, 12.

Stopping rule: that of :func:`ngcontact.solvers.newton.minimize` on
``|R|`` (``rtol`` times the first residual, ``atol``, or the round-off
floor after real progress), stricter than the fixed point's pressure
change.  An active set that cycles while the residual stagnates
(:class:`~ngcontact.solvers.newton.ActiveSetCycle`) or ``max_iter`` steps
raise :class:`~ngcontact.errors.ConvergenceError` with the history; the
caller may then fall back to the fixed point.  The history is a
:class:`~ngcontact.solvers.newton.NewtonHistory` whose energies are the
frozen Tresca energies of the iterates, plus the largest pressure change
of each step (``coulomb_changes``).
"""
from __future__ import annotations

import logging
import math
from typing import Callable

import ngsolve as ng
import numpy as np

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.linear_solver import LinearSolver, TangentSolve
from ngcontact.solvers.newton import (ARMIJO, MIN_STEP, ActiveSetCycle, NewtonHistory, at_floor, exact_step,
                                      fixed_mask, mask_fixed, roundoff_floor)

log = logging.getLogger(__name__)


def coupled_newton(residual_form: ng.BilinearForm, energy_form: ng.BilinearForm, gfu: ng.GridFunction, *,
                   freeze: Callable[[], None], pressure: Callable[[], np.ndarray], freedofs,
                   rtol: float = 1e-10, atol: float = 0.0, max_iter: int = 40, inverse: str = "umfpack",
                   symmetric_inverse: str = "sparsecholesky", max_step: float = 8.0,
                   active_set=None, record: LinearSolver | None = None) -> dict:
    """Solve ``R(u) = 0`` from ``gfu`` (updated in place) by the coupled Newton of the module docstring.

    Parameters
    ----------
    residual_form
        Non-symmetric form whose ``Apply`` is ``R`` (the threshold a
        function of the trial function) and whose linearization is ``K_c``.
    energy_form
        The Tresca energy ``Pi_T(.; G)`` with ``G`` read from a frozen copy
        of the state, which ``freeze()`` sets to the current ``gfu``.
    pressure
        The contact pressure of the current state at the contact points.
    freedofs
        BitArray of the unknowns.
    rtol, atol, max_iter
        Stopping rule and step limit (:func:`ngcontact.solvers.newton.minimize`).
    inverse, symmetric_inverse
        Sparse direct solvers of ``K_c`` (LU) and of the Tresca tangent.
    max_step
        Largest step of the exact line search.
    active_set
        Optional ``active_set(gfu) -> hashable`` signature (cycle detection).
    record
        A :class:`~ngcontact.solvers.linear_solver.LinearSolver` whose
        record of solves the LU solves join (the report's count).

    Returns
    -------
    dict
        The history (:meth:`NewtonHistory.as_dict`) with ``"stage":
        "coulomb_newton"`` and ``coulomb_changes``.
    """
    hist = NewtonHistory()
    changes: list[float] = []
    cycle = ActiveSetCycle() if active_set is not None else None
    fixed = fixed_mask(freedofs)
    res, du, trial, work, r_trial = (gfu.vec.CreateVector() for _ in range(5))

    def failed(message: str) -> ConvergenceError:
        out = hist.as_dict()
        out.update(stage="coulomb_newton", coulomb_changes=changes)
        return ConvergenceError(message, out)

    def residual(vec, out=res) -> float:
        residual_form.Apply(vec, out)
        mask_fixed(out, fixed)
        return math.sqrt(max(ng.InnerProduct(out, out), 0.0))

    freeze()
    rnorm = residual(gfu.vec)
    energy = energy_form.Energy(gfu.vec)
    hist.residuals.append(rnorm)
    hist.energies.append(energy)
    if not (math.isfinite(rnorm) and math.isfinite(energy)):
        raise failed("the start value gives a non-finite energy or residual")
    r0, floor0, p_old = rnorm, None, pressure()
    for it in range(1, max_iter + 1):
        if rnorm <= max(rtol * r0, atol) or rnorm == 0.0:
            hist.converged = True
            break
        residual_form.AssembleLinearization(gfu.vec)
        floor = roundoff_floor(residual_form.mat, gfu.vec, fixed)
        floor0 = floor if floor0 is None else floor0
        if at_floor(rnorm, floor, r0, floor0):
            log.info("coulomb newton %d: residual %.3e at its round-off floor; converged", it, rnorm)
            hist.converged = True
            break
        lu = residual_form.mat.Inverse(freedofs, inverse=inverse)
        if record is None:
            du.data = lu * res
        else:
            TangentSolve(record, lu, counted=False).apply(res, du)
        trial.data = gfu.vec - du
        r_full = residual(trial, r_trial)
        if math.isfinite(r_full) and r_full < rnorm:
            alpha = 1.0
            gfu.vec.data = trial
        else:
            alpha = _frozen_energy_step(energy_form, gfu, du, freedofs, fixed, trial, work, res,
                                        symmetric_inverse, max_step, record)
            if alpha == 0.0:
                hist.steps.append(0.0)
                raise failed(f"Coulomb Newton step {it}: no decrease of the frozen Tresca energy "
                             f"(residual {rnorm:.3e})")
        freeze()
        rnorm = residual(gfu.vec)
        energy = energy_form.Energy(gfu.vec)
        p_new = pressure()
        changes.append(float(np.max(np.abs(p_new - p_old))) if p_new.size else 0.0)
        p_old = p_new
        hist.steps.append(alpha)
        hist.residuals.append(rnorm)
        hist.energies.append(energy)
        log.debug("coulomb newton %d: |R| = %.3e, alpha = %g", it, rnorm, alpha)
        if not (math.isfinite(rnorm) and math.isfinite(energy)):
            raise failed(f"Coulomb Newton step {it}: non-finite residual or energy")
        if cycle is not None:
            sig = active_set(gfu)
            hist.active_set_sizes.append(int(sum(bin(b).count("1") for b in sig))
                                         if isinstance(sig, (bytes, bytearray)) else -1)
            found = cycle.step(it, sig, rnorm)
            if found is not None and not rnorm <= max(rtol * r0, atol):
                raise failed(f"Coulomb Newton step {it}: {found}")
    else:
        if not rnorm <= max(rtol * r0, atol):
            raise failed(f"Coulomb Newton did not converge in {max_iter} steps: residual {rnorm:.3e} > "
                         f"{max(rtol * r0, atol):.3e} (rtol {rtol:g} x first residual {r0:.3e})")
        hist.converged = True
    out = hist.as_dict()
    out.update(stage="coulomb_newton", coulomb_changes=changes)
    return out


def _frozen_energy_step(energy_form, gfu, du, freedofs, fixed, trial, work, res, symmetric_inverse,
                        max_step, record) -> float:
    """Step along ``du`` (or the Tresca direction) minimizing the frozen Tresca energy; updates ``gfu``.

    ``res`` holds ``R(u)`` = the frozen energy's gradient at ``u`` on entry
    and may be overwritten.  Returns the step length, 0 when Armijo's test
    fails down to ``MIN_STEP``.
    """
    slope = ng.InnerProduct(du, res)
    if not slope > 0.0:          # no descent of the frozen energy: the symmetric Tresca direction
        energy_form.AssembleLinearization(gfu.vec)
        inv = energy_form.mat.Inverse(freedofs, inverse=symmetric_inverse)
        if record is None:
            du.data = inv * res
        else:
            TangentSolve(record, inv, counted=False).apply(res, du)
        slope = ng.InnerProduct(du, res)
        if not slope > 0.0:
            return 0.0
    energy = energy_form.Energy(gfu.vec)
    alpha = exact_step(energy_form, gfu.vec, du, slope, fixed, trial, work, max_step)
    while alpha >= MIN_STEP:
        trial.data = gfu.vec - alpha * du
        e_new = energy_form.Energy(trial)
        if math.isfinite(e_new) and e_new <= energy - ARMIJO * alpha * slope + 1e-14 * abs(energy):
            gfu.vec.data = trial
            return alpha
        alpha *= 0.5
    return 0.0
