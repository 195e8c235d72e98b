"""Energy minimization by Newton's method with a line search.

Contact and elasticity are written as one energy ``Pi(u)`` (NGSolve
``Variation`` terms), so the residual ``r(u) = Pi'(u)`` and the tangent
``K(u) = Pi''(u)`` come from NGSolve's linearization. One step solves
``K(u) du = r(u)`` and sets ``u <- u - alpha du`` with the step length of
:mod:`ngcontact.solvers.line_search`: the largest ``alpha = 1, 1/2, 1/4,
...`` that passes Armijo's test on the energy (a step the energy cannot
resolve, by its round-off, judged by the residual instead), or with
``line_search="exact"`` the minimizer of the energy along the direction,
guarded by the same test.  NaN or Inf never enter the iterate.

The iteration stops when the residual (free dofs) has fallen below
``rtol`` times the first residual, or below ``atol``, or below its
round-off floor after real progress (:mod:`ngcontact.solvers.roundoff`).
A step that lowers neither the energy nor the residual at any length is
converged when the iterate is at round-off by the same module's rule, and
fails otherwise.

A quadratic energy is minimized by a linear solve, refined with the same
factorization while the residual is above the tolerance (at most
``REFINE_STEPS`` times); a residual still above ``max(rtol |r_0|, atol)`` and
above its round-off floor is a singular or ill-posed system (e.g. a
rigid-body mode the supports leave free) and raises, never "converged".
Solved by CG, the linear solve stops on the residual this test measures,
at ``LINEAR_MARGIN`` times its target
(:class:`~ngcontact.solvers.residual_cg.ResidualCG`): the test then passes
with that margin, so that one process and N MPI ranks make the same number
of solves, where a stop in CG's preconditioned norm lands at the target and
leaves the refinement to round-off.

On failure a :class:`~ngcontact.errors.ConvergenceError` carries the history:
residual norms, energies, step lengths.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import ngsolve as ng

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.line_search import ARMIJO, MIN_STEP, armijo, exact_step
from ngcontact.solvers.linear_solver import LinearSolver, fixed_mask, forcing_term
from ngcontact.solvers.roundoff import at_floor, at_roundoff, free_norm, roundoff_floors, within_roundoff

log = logging.getLogger(__name__)

REFINE_STEPS = 2
#: a linear solve by CG stops at this fraction of the residual's target (module docstring)
LINEAR_MARGIN = 0.5


@dataclass
class NewtonHistory:
    """What happened during a solve (JSON-ready lists of floats)."""

    residuals: list[float] = field(default_factory=list)
    energies: list[float] = field(default_factory=list)
    steps: list[float] = field(default_factory=list)
    converged: bool = False
    linear: bool = False
    active_set_sizes: list[int] = field(default_factory=list)

    @property
    def iterations(self) -> int:
        return len(self.steps)

    def as_dict(self) -> dict:
        return {"iterations": self.iterations, "converged": self.converged,
                "linear_solve_only": self.linear,
                "residuals": list(self.residuals), "energies": list(self.energies),
                "step_lengths": list(self.steps), "active_set_sizes": list(self.active_set_sizes)}


class ActiveSetCycle:
    """Detects an active set that flips back and forth while the residual stagnates.

    Feed it the signature of the active set (any hashable, e.g. the sign
    pattern of the penetration at the contact quadrature points) and the
    residual after every Newton step.  A signature that recurs after other
    ones, for the ``repeats``-th time, while the residual has not fallen
    below ``progress`` times its value at the signature's previous
    occurrence, is a cycle: Newton would only go round it until its
    iteration limit.
    """

    def __init__(self, repeats: int = 2, progress: float = 0.5):
        self.repeats, self.progress = repeats, progress
        self.seen: dict = {}      # signature -> (last step, residual there, recurrences)
        self.previous = None

    def step(self, it: int, signature, residual: float) -> str | None:
        """Record step ``it``; return a description of the cycle, or ``None``."""
        message = None
        if signature in self.seen and signature != self.previous:
            last, r_last, count = self.seen[signature]
            stagnant = residual > self.progress * r_last
            count = count + 1 if stagnant else 0
            if count >= self.repeats:
                message = (f"the active set of step {last} recurred at step {it} (period {it - last}, "
                           f"{count} recurrences) while the residual stagnated ({r_last:.3e} -> {residual:.3e})")
            self.seen[signature] = (it, residual, count)
        else:
            self.seen[signature] = (it, residual, 0)
        self.previous = signature
        return message


def minimize(form: ng.BilinearForm, gfu: ng.GridFunction, *, freedofs=None,
             rtol: float = 1e-10, atol: float = 0.0, max_iter: int = 50,
             inverse: str = "sparsecholesky", quadratic: bool = False,
             callback=None, line_search: str = "armijo", max_step: float = 8.0,
             active_set=None, linear: LinearSolver | None = None) -> NewtonHistory:
    """Minimize the energy of ``form`` starting from ``gfu`` (updated in place).

    Parameters
    ----------
    form
        BilinearForm made of ``Variation`` energy terms.
    gfu
        Start value; Dirichlet values must already be set in it.
    freedofs
        BitArray of the unknowns (default: the space's free dofs).
    rtol, atol
        Stop when ``|r| <= max(rtol * |r_0|, atol)``.
    max_iter
        Largest number of Newton steps.
    inverse
        Sparse direct solver for the tangent (when no ``linear`` is given).
    quadratic
        The energy is quadratic: one linear solve, no iteration.
    callback
        Called as ``callback(iteration, gfu)`` after each accepted step.
    line_search
        ``"armijo"`` (backtracking from ``alpha = 1``) or ``"exact"`` (root of
        the slope along the direction, for convex energies; see the module
        docstring).
    max_step
        Largest step length tried by the exact line search.
    active_set
        Optional ``active_set(gfu) -> hashable`` signature of the contact
        state; an active set that cycles while the residual stagnates raises
        :class:`~ngcontact.errors.ConvergenceError` at once
        (:class:`ActiveSetCycle`) instead of iterating to ``max_iter``.
    linear
        The tangent solves (:class:`~ngcontact.solvers.linear_solver.LinearSolver`:
        direct, BDDC-preconditioned CG, or by size), which also records
        them; default: direct with ``inverse``.
    """
    if line_search not in ("armijo", "exact"):
        raise ValueError(f"line_search = {line_search!r}: must be 'armijo' or 'exact'")
    if not max_step >= 1.0:
        raise ValueError(f"max_step = {max_step!r}: must be >= 1")
    if freedofs is None:
        freedofs = gfu.space.FreeDofs()
    if linear is None:
        linear = LinearSolver("direct", inverse=inverse)
    linear.register(form, freedofs)
    newton = _Iteration(form, gfu, freedofs, linear, NewtonHistory(linear=quadratic), line_search, max_step,
                        target=lambda r0: max(rtol * r0, atol))
    hist = newton.hist
    if newton.rnorm <= atol or newton.rnorm == 0.0:
        hist.converged = True
        return hist
    if quadratic:
        return _linear_solve(form, gfu, freedofs, linear, newton.residual, newton.res, newton.du, hist, newton.r0,
                             rtol, atol, newton.fixed)
    cycle = ActiveSetCycle() if active_set is not None else None
    for it in range(1, max_iter + 1):
        if newton.step(it):
            return hist
        if callback is not None:
            callback(it, gfu)
        if cycle is not None:
            sig = active_set(gfu)
            hist.active_set_sizes.append(_size(sig))
            found = cycle.step(it, sig, newton.rnorm)
            if found is not None and not newton.tolerance_met():
                raise ConvergenceError(f"Newton step {it}: {found}", hist.as_dict())
        if newton.tolerance_met():
            hist.converged = True
            return hist
    raise ConvergenceError(
        f"Newton did not converge in {max_iter} steps: residual {newton.rnorm:.3e} "
        f"> {newton.target(newton.r0):.3e} (rtol {rtol:g} x first residual {newton.r0:.3e})",
        hist.as_dict())


class _Iteration:
    """The state of one Newton minimization and its step; the stopping rules are its named tests.

    Stopping rules, each a method: :meth:`tolerance_met` (``|r| <= max(rtol |r_0|, atol)``), the residual
    at its round-off floor after real progress (:func:`~ngcontact.solvers.roundoff.at_floor`, in
    :meth:`step`), a step along which no decrease is measurable at round-off
    (:func:`~ngcontact.solvers.roundoff.at_roundoff`, in :meth:`step_length`); a cycling active set is
    :class:`ActiveSetCycle`'s, in :func:`minimize`.
    """

    def __init__(self, form, gfu, freedofs, linear: LinearSolver, hist: NewtonHistory, line_search: str,
                 max_step: float, target):
        self.form, self.gfu, self.freedofs, self.linear, self.hist = form, gfu, freedofs, linear, hist
        self.line_search, self.max_step, self.target = line_search, max_step, target
        self.fixed = fixed_mask(freedofs)
        self.res, self.du, self.trial = (gfu.vec.CreateVector() for _ in range(3))
        self.energy = form.Energy(gfu.vec)
        self.rnorm = self.residual(gfu.vec)
        hist.energies.append(self.energy)
        hist.residuals.append(self.rnorm)
        if not (math.isfinite(self.energy) and math.isfinite(self.rnorm)):
            raise ConvergenceError("the start value gives a non-finite energy or residual", hist.as_dict())
        self.r0 = self.rnorm
        self.floor0: float | None = None
        self.previous: float | None = None
        self.eta: float | None = None

    def residual(self, vec) -> float:
        """``|r(vec)|`` on the free dofs, over the MPI ranks (:func:`~ngcontact.solvers.roundoff.free_norm`);
        leaves ``r(vec)`` in ``self.res``."""
        self.form.Apply(vec, self.res)
        return free_norm(self.res, self.fixed)

    def tolerance_met(self) -> bool:
        """The residual is within the requested tolerance."""
        return self.rnorm <= self.target(self.r0)

    def direction(self, it: int) -> float:
        """Solve ``K du = r`` into ``self.du`` (inexactly where the linear solver iterates); the slope
        ``du . r``, checked to be a descent direction."""
        self.eta = forcing_term(self.rnorm, self.previous, self.eta, self.target(self.r0))
        self.previous = self.rnorm
        self.linear.prepare(self.form, self.freedofs, forcing=self.eta).apply(self.res, self.du)
        slope = ng.InnerProduct(self.du, self.res)
        if not math.isfinite(slope):
            raise ConvergenceError(f"Newton step {it}: the tangent solve gave non-finite values",
                                   self.hist.as_dict())
        if slope <= 0.0:
            raise ConvergenceError(
                f"Newton step {it}: the tangent gives no descent direction (du . r = {slope:.3e}); "
                "the tangent is singular or indefinite, e.g. a load the interface cannot carry",
                self.hist.as_dict())
        return slope

    def step_length(self, it: int, slope: float, floor: float, efloor: float) -> tuple[float, float, float] | None:
        """The accepted step length along ``-du`` with the trial's energy and residual (the trial left in
        ``self.trial``), or ``None`` where no decrease is measurable and the iterate is at round-off."""
        alpha = 1.0
        if self.line_search == "exact":
            alpha = exact_step(self.form, self.gfu.vec, self.du, slope, self.fixed, self.trial, self.res,
                               self.max_step)
        while True:
            self.trial.data = self.gfu.vec - alpha * self.du
            e_new = self.form.Energy(self.trial)
            decreased = armijo(self.energy, e_new, alpha * slope)
            if decreased or within_roundoff(self.energy, e_new, efloor):
                r_new = self.residual(self.trial)        # a finite energy can still have a non-finite gradient
                if math.isfinite(r_new) and (decreased or r_new <= (1.0 - ARMIJO * alpha) * self.rnorm):
                    return alpha, e_new, r_new
                if not math.isfinite(r_new):
                    log.debug("newton %d: non-finite residual at alpha = %g, backtracking", it, alpha)
            alpha *= 0.5
            if alpha < MIN_STEP:
                if at_roundoff(slope, efloor, self.rnorm, floor, self.r0):
                    log.info("newton %d: residual %.3e, no decrease measurable along the step; at round-off, "
                             "converged", it, self.rnorm)
                    return None
                self.hist.steps.append(0.0)
                raise ConvergenceError(
                    f"Newton step {it}: line search found no decrease of the energy "
                    f"(residual {self.rnorm:.3e}); the tangent may be wrong or the problem unbounded",
                    self.hist.as_dict())

    def step(self, it: int) -> bool:
        """One Newton step; ``True`` where a round-off rule ends the iteration as converged."""
        self.form.AssembleLinearization(self.gfu.vec)
        floor, efloor = roundoff_floors(self.form.mat, self.gfu.vec, self.fixed, self.energy)
        self.floor0 = floor if self.floor0 is None else self.floor0
        if at_floor(self.rnorm, floor, self.r0, self.floor0):
            log.info("newton %d: residual %.3e at its round-off floor; converged", it, self.rnorm)
            self.hist.converged = True
            return True
        accepted = self.step_length(it, self.direction(it), floor, efloor)
        if accepted is None:
            self.hist.converged = True
            return True
        alpha, self.energy, self.rnorm = accepted
        self.gfu.vec.data = self.trial
        self.hist.steps.append(alpha)
        self.hist.energies.append(self.energy)
        self.hist.residuals.append(self.rnorm)
        log.debug("newton %d: |r| = %.3e, energy = %.6e, alpha = %g", it, self.rnorm, self.energy, alpha)
        return False


def _linear_solve(form, gfu, freedofs, linear, residual, res, du, hist, r0, rtol, atol, fixed) -> NewtonHistory:
    """A quadratic energy: ``u <- u - K^{-1} r(u)``, refined with the same factorization, and checked.

    ``res`` holds ``r(u)`` on entry.  Raises when the residual stays above
    ``max(rtol r_0, atol)`` and above its round-off floor.
    """
    form.AssembleLinearization(gfu.vec)
    inv = linear.prepare(form, freedofs)
    target = max(rtol * r0, atol)
    floor0 = roundoff_floors(form.mat, gfu.vec, fixed)[0]
    rnorm = r0
    for _ in range(1 + REFINE_STEPS):
        inv.apply(res, du, reach=LINEAR_MARGIN * target)
        gfu.vec.data -= du
        rnorm = residual(gfu.vec)          # leaves r(u) in res for the next refinement
        energy = form.Energy(gfu.vec)
        hist.steps.append(1.0)
        hist.residuals.append(rnorm)
        hist.energies.append(energy)
        if not (math.isfinite(rnorm) and math.isfinite(energy)):
            raise ConvergenceError("the linear solve gave non-finite values: the system is singular "
                                   "(e.g. a rigid-body mode that no support removes)", hist.as_dict())
        if rnorm <= target:
            break
    if rnorm <= target or at_floor(rnorm, roundoff_floors(form.mat, gfu.vec, fixed)[0], r0, floor0):
        hist.converged = True
        return hist
    raise ConvergenceError(
        f"the linear solve left the residual at {rnorm:.3e} > {target:.3e} (first residual {r0:.3e}) after "
        f"{REFINE_STEPS} refinements: the system is singular or ill-posed, e.g. a rigid-body mode that no "
        "support removes, or a stiffness far beyond the others", hist.as_dict())


def _size(signature) -> int:
    """Number of active entries: set bits of a ``bytes`` signature, true entries of a sequence, or -1."""
    if isinstance(signature, (bytes, bytearray)):
        return sum(bin(b).count("1") for b in signature)
    try:
        return int(sum(bool(b) for b in signature))
    except TypeError:
        return -1
