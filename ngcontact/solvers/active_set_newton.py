"""A primal-dual active-set (semismooth Newton) method for contact with friction in tractions.

The problem is the one of :mod:`ngcontact.solvers.projected_gradient`:

    min_t  1/2 <t, K t> + <t, b> + sum_i h_i(t_i),   mean(t_c) = m_c  (prescribed components),

``t = (q, p)``, ``K`` the layers' compliance (symmetric positive
semidefinite, applied by FFTs), ``h_i`` the separable contact and friction
terms.  Its solution is the fixed point ``t = prox(t - (K t + b) / L)`` of the
proximal-gradient map.  Accelerated proximal gradients reach it in
``O(sqrt(kappa))`` steps per digit, ``kappa`` the condition number of ``K``
on the contact set: for a compliance that falls like ``1 / |k|`` that is the
number of grid points per direction, thousands of steps at 512^2.

Method (Hintermueller, Ito & Kunisch, SIAM J. Optim. 13 (2003) 865-888, the
primal-dual active-set strategy as a semismooth Newton method; for contact
with friction Hueeber, Stadler & Wohlmuth, SIAM J. Sci. Comput. 30 (2008)
572-596).  Each outer step evaluates the proximal map once, which splits
the unknowns into *free* ones (the pressure where ``p > 0``, the shear at a
sticking point, ``|q| < G``) and *fixed* ones (``p = 0`` on the open set, the
shear ``q = G n`` on the rim at a slipping point), and then minimizes the
quadratic energy over the free unknowns with the fixed ones held, under
the mean constraints: a symmetric positive definite problem.  In 3D a
slipping point keeps one free direction, the tangent ``n_perp`` of the
friction disc, with the rim's curvature ``L (|z| / G - 1)`` as its diagonal
(the derivative of ``q = G z / |z|`` across ``z``); for a given threshold
this is the semismooth Newton step.  Every slipping point turns, also one
far outside the disc, whose large curvature the split preconditioner below
takes (held instead, such a point would converge only as fast as the
proximal-gradient map turns it, by ``G / |z|`` per step).  The free
minimum's projection onto the constraints is the next iterate, or the free
minimum itself where only that lowers the residual.  Where the step raises
the root mean square of the fixed-point residual (the Euclidean merit
function of damped semismooth Newton methods), it is shortened: the
projection of ``t_hat + alpha (t_free - t_hat)`` for ``alpha = 1/2, 1/4,
1/8``, the first that lowers it by Armijo's share ``1 - 1e-4 alpha`` (else
the smallest met).  The maximum norm, the stopping rule's, as the merit
took up to 1.9 times the operator applications on the random maps tried
at 512^2.  The semismooth Newton
step converges only locally (Qi and Sun, Math. Program. 58 (1993) 353-367;
Hintermueller, Ito and Kunisch prove global convergence for M-matrices,
which a compliance, positive off the diagonal, is not): undamped, the Coulomb
steps on the half-space of ``scripts/spectral_friction_speed.py`` at 256^2
swapped points between the stick and slip sets with the residual rising for
six steps, and the solve fell back to the slow fixed point below.

The free problem is solved by projected conjugate gradients
preconditioned by ``R K_full^{-1} R^T`` (``R`` the restriction to the free
set, ``K_full^{-1}`` the inverse of the full 3 x 3 (2D: 2 x 2) compliance per
wave vector, applied by FFTs; Vollebregt, J. Comput. Phys. 257 (2014)
333-351): the compliance is a pseudo-differential operator of order -1 and
its inverse one of order 1, so the preconditioned operator on a subset of
the grid is spectrally equivalent to the identity up to the restriction's
``log^2 N`` factor (as for the interface operators of domain
decomposition), where ``K`` alone has a condition number of order ``N``.
That equivalence fails where the curvature ``D`` dominates a point's own
compliance ``k_self`` (``K``'s diagonal in real space): a slipping point's
rim curvature is of the order of ``L``, the compliance of the longest wave,
which exceeds ``k_self`` by a factor of the order of the grid's points per
direction, and ``K^{-1}`` (of order 1) multiplies such an entry where the
operator divides it.  The preconditioner is therefore split
(:meth:`Preconditioner.for_curvature`): ``1 / (k_self + D)`` on the entries
``D`` dominates, ``R K_full^{-1} R^T`` on the others, a block-Jacobi
preconditioner that is still symmetric positive definite.  The inner
tolerance is a share of the outer residual.  The free directions live on the
pressed, sticking and slipping points, a few percent of the grid where the
contact is sparse: the Krylov vectors are held in the coordinates of that
support (:mod:`ngcontact.solvers.free_directions`), and only the applications
of ``K`` and ``K_full^{-1}`` by FFTs see the whole grid.

Coulomb friction (a threshold ``G = mu p`` of the unknown pressure) has
no potential.  Its semismooth Newton step keeps what the threshold's
dependence adds to the derivative of the proximal map: at a slipping point
``q = G(p) z / |z|`` moves with the pressure by ``(dG/dp) n dp``, so a free
pressure there carries the shear along (``lift``, with the mean shear
restored over the free shear), while the equations kept are those of the
free directions (the normal gap, the stick and the turning shear), not the
gap along the slip.  The step's linear problem is then not symmetric, and
:func:`coupled_step` solves it by GMRES with the same split preconditioner
(from the right).  Without that term (the threshold frozen within a step)
the 3D active sets cycle from a residual of a few percent on a random map
between dissimilar layers, and the method needed a fixed point of Tresca
problems first; with it the Newton steps converge from the frictionless
start.  This is the choice among the frictional solvers of spectral codes:
an alternation of normal and frozen-threshold tangential problems (the
Panagiotopoulos process of Kalker's codes; a tangential problem of given
pressure solved by a Polonsky-Keer-type constrained CG on the stick set, as
in Tamaas' ``PolonskyKeerTan``) converges linearly in the Coulomb coupling,
slowly where dissimilar layers couple pressure and shear strongly;
projected or primal-dual first-order iterations (Tamaas' ``Kato`` and
``Condat``) need ``O(sqrt(kappa))`` or more steps per digit; the Newton
step of the coupled law needs a few Krylov steps per active-set step and
converges superlinearly once the sets settle.  :func:`coulomb_active_set`
keeps the former method as its fallback: where the coupled Newton steps
stall, the fixed point ``G = mu p(G)`` of Tresca problems (each pass a
frozen-threshold problem, warm-started, to a hundredth of the current
residual), with the threshold of each pass the Anderson combination of the
previous ones (:mod:`ngcontact.solvers.anderson`), then the coupled Newton
steps again.  Neither loop is guaranteed to converge globally: a Coulomb
fixed point without progress in ``STALL_PASSES`` passes goes on with the
coupled Newton steps, and an active-set solve that makes no new best
residual in ``STALL`` steps goes on with accelerated proximal gradients
(:func:`~ngcontact.solvers.projected_gradient.fista`) from its last
iterate, so the answer is always the one of that method.

Stopping rule: the fixed-point residual of :mod:`ngcontact.solvers.projected_gradient`,
``|t - prox(t - grad / L)| L <= tol scale``, so both methods stop at the
same accuracy.  ``iterations`` counts operator applications (residual
evaluations plus inner steps), the unit of
:func:`~ngcontact.solvers.projected_gradient.fista`'s steps.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import partial
from typing import Callable, Protocol

import numpy as np

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.anderson import Anderson
from ngcontact.solvers.constrained_cg import inner
from ngcontact.solvers.free_directions import FreeDirections, FreeOperator, Lift, SplitPreconditioner
from ngcontact.solvers.projected_gradient import ProximalResult, fista

#: outer steps without a new smallest residual after which the solve goes on with accelerated proximal gradients
STALL = 6
#: tolerance of each frozen-threshold problem of a Coulomb solve: this share of the law's residual
FIXED_POINT_SHARE = 0.01
#: a pass of a Coulomb solve makes progress when it brings the residual below this share of the best so far
DECREASE = 0.7
#: passes of a Coulomb solve without progress after which it goes on with accelerated proximal gradients
STALL_PASSES = 2
#: differences kept by the Anderson acceleration of the threshold's fixed point
ANDERSON_DEPTH = 5
#: inner tolerance: this share of the outer residual
INNER_SHARE = 0.05
#: Krylov vectors of a cycle of the coupled Newton step's GMRES (:func:`coupled_step`)
GMRES_RESTART = 20
#: a projection that moves no entry by more than this share of the largest is the point itself (round-off)
SAME_POINT = 1e-13
#: halvings of a step that raises the residual (:func:`_damped`)
DAMPINGS = 3
#: Armijo's share of the residual's decrease a damped step must make
ARMIJO = 1e-4


def traction_projector(pressed: np.ndarray, stick: np.ndarray, rim: np.ndarray, t_hat: np.ndarray,
                       constrained: tuple[bool, ...]) -> FreeDirections:
    """The projector onto the free directions of ``t_hat``
    (:class:`~ngcontact.solvers.free_directions.FreeDirections`)."""
    return FreeDirections(pressed, stick, rim, t_hat, constrained)


def free_minimum(step: FreeOperator, b: np.ndarray, t: np.ndarray, atol: float,
                 max_steps: int) -> tuple[np.ndarray, int]:
    """Minimize ``1/2 <t, (A + D) t> + <t, b>`` over the free entries of ``t`` (the rest and the means held).

    Projected preconditioned conjugate gradients from ``t`` (which meets the
    mean constraints) until the projected gradient is below ``atol`` in the
    maximum norm, in the coordinates of the free directions' support (:class:`FreeOperator`).  Returns
    ``(t, steps)``, ``steps`` the operator applications (the start's gradient included).
    """
    r = step.residual(t, b)
    z = step.precondition(r)
    rz = inner(r, z)
    d = z
    u = np.zeros_like(r)
    for k in range(1, max_steps + 1):
        if float(np.max(np.abs(r))) <= atol or rz <= 0:
            return step.add(t, u), k
        Ad = step.operator(d)
        dAd = inner(d, Ad)
        if dAd <= 0:
            return step.add(t, u), k
        alpha = rz / dAd
        u -= alpha * d
        r -= alpha * Ad
        z = step.precondition(r)
        rz, rz_old = inner(r, z), rz
        d = z + (rz / rz_old) * d
    return step.add(t, u), max_steps + 1


def coupled_step(step: FreeOperator, b: np.ndarray, t: np.ndarray, atol: float, max_steps: int, *,
                 lift: Lift) -> tuple[np.ndarray, int]:
    """The Newton step of a threshold that follows the pressure: ``proj(A (t + lift(u)) + b) = 0`` for ``u`` in
    the free directions.

    ``lift`` moves the shear of a slipping point with its pressure (``dG/dp`` times the slip direction), so the
    operator is not symmetric: restarted GMRES (Saad & Schultz, SIAM J. Sci. Stat. Comput. 7 (1986)
    856-869) in the coordinates of the free directions' support (:class:`FreeOperator`), preconditioned from
    the right by ``proj M``, until the projected gradient is below ``atol`` in
    the maximum norm (its Euclidean norm, which GMRES minimizes, below the same share of its start inside a
    cycle; the gradient after a cycle is the Krylov basis times ``H y``, not a new application).  Returns
    ``(t + lift(u), steps)``, ``steps`` the operator applications (the start's gradient included).
    """
    r = step.residual(t, b)
    u = np.zeros_like(r)
    steps = 1
    basis = np.empty((GMRES_RESTART + 1, r.size))
    preconditioned = np.empty((GMRES_RESTART, r.size))       # proj M basis_j, kept for the update
    while steps < max_steps and float(np.max(np.abs(r))) > atol:
        beta = float(np.sqrt(inner(r, r)))
        target = beta * atol / float(np.max(np.abs(r)))
        H = np.zeros((GMRES_RESTART + 1, GMRES_RESTART))
        np.multiply(r, -1.0 / beta, out=basis[0])
        for j in range(min(GMRES_RESTART, max_steps - steps)):
            preconditioned[j] = step.precondition(basis[j])
            w = step.operator(lift.reduced(preconditioned[j]))
            steps += 1
            for i in range(j + 1):          # modified Gram-Schmidt
                H[i, j] = inner(w, basis[i])
                w -= H[i, j] * basis[i]
            H[j + 1, j] = float(np.sqrt(inner(w, w)))
            np.multiply(w, 1.0 / max(H[j + 1, j], 1e-300), out=basis[j + 1])
            e1 = np.zeros(j + 2)
            e1[0] = beta
            y, *_ = np.linalg.lstsq(H[:j + 2, :j + 1], e1, rcond=None)
            if float(np.linalg.norm(H[:j + 2, :j + 1] @ y - e1)) <= target or H[j + 1, j] <= 1e-300:
                break
        u += _combine(y, preconditioned)
        # the new gradient without an application: A M V_j y = V_(j+1) H y, and basis[0] = -r / beta
        r = r + _combine(H[:j + 2, :j + 1] @ y, basis)
    return step.add(t, lift.reduced(u)), steps


def _combine(c: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """``sum_i c_i basis_i`` over the first ``len(c)`` rows (``einsum``'s own loop, no BLAS threads)."""
    return np.einsum("i,ij->j", c, basis[:len(c)])


class Preconditioner(Protocol):
    """An approximate inverse of ``K`` (``r -> M r``) that splits off the entries a pointwise curvature ``D``
    dominates (e.g. :class:`~ngcontact.cell.spectral.frictional_contact.TractionPreconditioner`)."""

    def __call__(self, r: np.ndarray) -> np.ndarray: ...

    def for_curvature(self, D: np.ndarray) -> SplitPreconditioner: ...


class Constraints(Protocol):
    """The pointwise terms ``h_i`` (e.g. :class:`~ngcontact.cell.spectral.traction_constraints.TractionConstraints`)."""

    @property
    def threshold(self) -> Callable[[np.ndarray], np.ndarray]: ...

    def prox(self, v: np.ndarray, shifts: tuple) -> tuple[np.ndarray, tuple]: ...

    def project(self, v: np.ndarray, shifts: tuple) -> np.ndarray: ...

    def linearize(self, t_hat: np.ndarray, v: np.ndarray, shifts: tuple) -> tuple: ...

    def frozen(self, G: np.ndarray) -> Constraints: ...


@dataclass
class _Point:
    """An iterate ``t``, its proximal point ``t_hat = prox(v)``, ``v = t - grad(t) / L``, and its residual in
    the maximum norm (``res``, the stopping rule's) and in the root mean square (``rms``)."""

    t: np.ndarray
    v: np.ndarray
    t_hat: np.ndarray
    shifts: tuple
    res: float
    rms: float


def active_set_newton(grad: Callable[[np.ndarray], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
                      b: np.ndarray, h: Constraints, precondition: Preconditioner,
                      t0: np.ndarray, L: float, *, tol: float, scale: float, max_iter: int,
                      fallback: bool = True) -> ProximalResult:
    """The active-set method of the module docstring for the terms ``h`` with their own threshold rule.

    ``grad(t) = apply(t) + b`` is the gradient of the smooth part;
    ``precondition`` an approximate inverse of ``apply``, split for each free problem's curvature.  A solve
    that stalls goes on with accelerated proximal gradients, or without ``fallback`` returns its last iterate
    (its last residual above ``tol``).
    """
    residuals: list[float] = []
    steps = 0

    def evaluate(t, shifts):
        nonlocal steps
        steps += 1
        v = grad(t)
        np.divide(v, -L, out=v)
        v += t                                  # t - grad(t) / L, in place
        t_hat, shifts = h.prox(v, shifts)
        change = t - t_hat
        rms = float(np.sqrt(np.mean(change * change))) * L / scale
        return _Point(t, v, t_hat, shifts, float(np.max(np.abs(change, out=change))) * L / scale, rms)

    x = evaluate(t0.copy(), ())
    best, since_best = x.res, 0
    while since_best < STALL and steps < max_iter:
        residuals.append(x.res)
        if x.res <= tol:
            return ProximalResult(t=x.t_hat, shifts=x.shifts, iterations=steps, residuals=residuals)
        atol = max(INNER_SHARE * x.res, 0.2 * tol) * scale
        proj, D, lift = h.linearize(x.t_hat, x.v, x.shifts)
        operator = FreeOperator(apply, D, proj, precondition.for_curvature(D))
        newton_step = free_minimum if lift is None else partial(coupled_step, lift=lift)
        t_new, inner_steps = newton_step(operator, b, x.t_hat, atol, max(1, max_iter - steps))
        steps += inner_steps
        # the projection of the free minimum onto the constraints; where it does not lower the residual, the
        # free minimum itself if that does (not evaluated where the projection is the same point)
        projected = h.project(t_new, x.shifts)
        step = evaluate(projected, x.shifts)
        if step.res >= x.res and float(np.max(np.abs(projected - t_new))) > SAME_POINT * float(np.max(np.abs(t_new))):
            step = min(step, evaluate(t_new, x.shifts), key=lambda y: y.res)
        if step.rms >= x.rms:
            step = _damped(evaluate, h, x, t_new, step)
        x = step
        best, since_best = (x.res, 0) if x.res < best else (best, since_best + 1)
    if steps >= max_iter:
        raise ConvergenceError(f"active-set Newton: the residual ({residuals[-1]:.3g}, relative to the gap scale) "
                               f"is above {tol:g} after {steps} steps", {"residuals": residuals[-5:]})
    if not fallback:
        return ProximalResult(t=x.t, shifts=x.shifts, iterations=steps, residuals=residuals)
    rest = fista(grad, h.prox, x.t, L, tol=tol, scale=scale, max_iter=max_iter - steps)
    return ProximalResult(t=rest.t, shifts=rest.shifts, iterations=steps + rest.iterations,
                          residuals=residuals + rest.residuals)


def coulomb_active_set(grad: Callable[[np.ndarray], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
                       b: np.ndarray, h: Constraints, precondition: Preconditioner,
                       t0: np.ndarray, L: float, *, tol: float, scale: float, max_iter: int) -> ProximalResult:
    """A threshold that depends on the pressure: Newton steps of the law itself, else an accelerated fixed point
    of problems with a frozen threshold.

    First :func:`active_set_newton` on the law itself (its free problems coupled through ``dG/dp``,
    :func:`coupled_step`); where it stalls, from its last iterate, the fixed point: each pass takes the law's
    threshold ``G(p)`` at the proximal point's
    pressure, combines it with the earlier passes' (:class:`~ngcontact.solvers.anderson.Anderson`),
    and solves the problem with that threshold frozen (:func:`active_set_newton`,
    warm-started, to ``FIXED_POINT_SHARE`` of the current residual); it stops when the
    residual of the law itself (its threshold taken from the pressure of the
    proximal step) meets ``tol``, and goes on with :func:`active_set_newton` on the law
    itself when ``STALL_PASSES`` passes make no progress (module docstring).
    """
    first = active_set_newton(grad, apply, b, h, precondition, t0, L, tol=tol, scale=scale, max_iter=max_iter,
                              fallback=False)
    if first.residuals and first.residuals[-1] <= tol:
        return first
    residuals, steps = list(first.residuals), first.iterations
    t, shifts = first.t, ()
    d = t0.shape[0]
    best, since_best = np.inf, 0
    G: np.ndarray | None = None
    accelerate = Anderson(ANDERSON_DEPTH)
    while steps < max_iter and since_best < STALL_PASSES:
        t_hat, shifts = h.prox(t - grad(t) / L, shifts)
        steps += 1
        res = float(np.max(np.abs(t - t_hat))) * L / scale
        residuals.append(res)
        if res <= tol:
            return ProximalResult(t=t_hat, shifts=shifts, iterations=steps, residuals=residuals)
        best, since_best = (res, 0) if res < DECREASE * best else (min(best, res), since_best + 1)
        image = np.asarray(h.threshold(t_hat[d - 1]), float)
        G = image if G is None else accelerate.next(G, image)
        sub = active_set_newton(grad, apply, b, h.frozen(G), precondition, t_hat, L,
                                tol=max(tol, FIXED_POINT_SHARE * res), scale=scale, max_iter=max_iter - steps)
        steps += sub.iterations
        t = sub.t
    if steps < max_iter:
        rest = active_set_newton(grad, apply, b, h, precondition, t, L, tol=tol, scale=scale,
                                 max_iter=max_iter - steps)
        return ProximalResult(t=rest.t, shifts=rest.shifts, iterations=steps + rest.iterations,
                              residuals=residuals + rest.residuals)
    raise ConvergenceError(f"active-set Newton (Coulomb): the residual ({residuals[-1]:.3g}, relative to the gap "
                           f"scale) is above {tol:g} after {steps} steps", {"residuals": residuals[-5:]})


def _damped(evaluate: Callable[[np.ndarray, tuple], _Point], h: Constraints, x: _Point, t_new: np.ndarray,
            full: _Point) -> _Point:
    """A shorter step where the full one raises the residual's root mean square: the projections of ``t_hat +
    alpha (t_new - t_hat)``, ``alpha = 1/2, 1/4, ...`` (``DAMPINGS`` of them), the first that lowers it by
    Armijo's share ``1 - ARMIJO alpha``; where none does, the smallest met, the full step's included."""
    best = full
    alpha = 1.0
    for _ in range(DAMPINGS):
        alpha *= 0.5
        trial = evaluate(h.project(x.t_hat + alpha * (t_new - x.t_hat), x.shifts), x.shifts)
        if trial.rms <= (1.0 - ARMIJO * alpha) * x.rms:
            return trial
        best = min(best, trial, key=lambda y: y.rms)
    return best
