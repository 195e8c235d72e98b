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
this is the semismooth Newton step.  A point far outside the disc
(``|z| > 2 G``) is held entirely: its turn is small and its curvature would
spoil the conditioning.  Of the free minimum and its projection onto the
constraints, the one with the smaller residual is the next iterate.

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
tolerance is a share of the outer residual.

Coulomb friction (a threshold ``G = mu p`` of the unknown pressure) has
no potential, and with the threshold taken inside each Newton step from
the start the 3D active sets cycle (at a residual of a few percent on a
random map between dissimilar layers).  :func:`coulomb_active_set`
therefore solves the fixed point ``G = mu p(G)`` of Tresca problems (of
Panagiotopoulos and of Kalker's codes; each pass a frozen-threshold
problem, warm-started, to a hundredth of the current residual), with the
threshold of each pass the Anderson combination of the previous ones
(:mod:`ngcontact.solvers.anderson`): the plain fixed point contracts
slowly where the normal-tangential coupling of dissimilar layers is strong
(and not at all on fine grids), the few slow modes of the threshold being
what the combination removes.  Once it makes no progress, the iterate is
close enough for the semismooth Newton step of the law itself (the
threshold of each step's own proximal pressure), whose active sets then
settle.  Neither loop is guaranteed to converge globally: a Coulomb fixed
point without progress in ``STALL_PASSES`` passes goes on with the coupled
Newton steps, and an active-set solve that makes no new best residual in
``STALL`` steps goes on with accelerated proximal gradients
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
from typing import Callable, Protocol

import numpy as np

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.anderson import Anderson
from ngcontact.solvers.constrained_cg import inner
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
#: a projection that moves no entry by more than this share of the largest is the point itself (round-off)
SAME_POINT = 1e-13


def traction_projector(pressed: np.ndarray, stick: np.ndarray, rim: np.ndarray, t_hat: np.ndarray,
                       constrained: tuple[bool, ...]) -> Callable[[np.ndarray], np.ndarray]:
    """The orthogonal projector onto the free directions of a proximal point ``t_hat = (q, p)``.

    Free: the pressure where ``pressed``; the whole shear where ``stick``; at
    a slipping point (``rim``) of a 3D cell the shear along the tangent of
    the friction disc, ``n_perp`` (the slip direction's own update, the
    semismooth Newton step of ``q = G z / |z|`` without its curvature term);
    on each component group of prescribed mean, in addition, the sum zero
    (the projection ``y - Pi lambda`` with ``(sum_i Pi_i) lambda = sum_i y_i``).
    """
    d = t_hat.shape[0]
    on = np.zeros(stick.shape, bool)
    turn = np.zeros((2, 0))
    if d == 3:
        q = t_hat[:2]
        norm = np.hypot(q[0], q[1])
        on = rim & (norm > 0)
        turn = np.stack([-q[1][on], q[0][on]]) / norm[on]    # n_perp at the turning points only (few)
    stick_f, pressed_f = stick.astype(float), pressed.astype(float)

    def shear(x):
        y = x * stick_f
        if turn.shape[1]:
            y[:, on] = np.sum(x[:, on] * turn, axis=0) * turn     # stick and rim are disjoint
        return y
    n_p = int(np.count_nonzero(pressed))
    if d == 3 and constrained[0]:
        M_inv = np.linalg.pinv(np.eye(2) * float(np.count_nonzero(stick)) + turn @ turn.T)
    elif constrained[0]:
        M_inv = np.array([[1.0 / max(int(np.count_nonzero(stick)), 1)]])

    def proj(x: np.ndarray) -> np.ndarray:
        y = np.empty_like(x)
        np.multiply(x[d - 1], pressed_f, out=y[d - 1])
        if constrained[d - 1] and n_p:
            y[d - 1] -= float(y[d - 1].sum()) / n_p
            y[d - 1] *= pressed_f
        y[:d - 1] = shear(x[:d - 1])
        if constrained[0]:
            lam = M_inv @ y[:d - 1].reshape(d - 1, -1).sum(axis=1)
            y[:d - 1] -= shear(np.broadcast_to(lam.reshape((d - 1,) + (1,) * (d - 1)), y[:d - 1].shape))
        return y
    return proj


def free_minimum(apply: Callable[[np.ndarray], np.ndarray], b: np.ndarray, t: np.ndarray,
                 proj: Callable[[np.ndarray], np.ndarray], precondition: Callable[[np.ndarray], np.ndarray],
                 atol: float, max_steps: int) -> tuple[np.ndarray, int]:
    """Minimize ``1/2 <t, A t> + <t, b>`` over the free entries of ``t`` (the rest and the means held).

    Projected preconditioned conjugate gradients from ``t`` (which meets the
    mean constraints) until the projected gradient is below ``atol`` in the
    maximum norm.  Returns ``(t, steps)``.
    """
    t = t.copy()
    r = proj(apply(t) + b)
    z = proj(precondition(r))
    rz = inner(r, z)
    d = z
    for step in range(1, max_steps + 1):
        if float(np.max(np.abs(r))) <= atol or rz <= 0:
            return t, step - 1
        Ad = proj(apply(d))
        dAd = inner(d, Ad)
        if dAd <= 0:
            return t, step - 1
        alpha = rz / dAd
        t -= alpha * d
        r -= alpha * Ad
        z = proj(precondition(r))
        rz, rz_old = inner(r, z), rz
        d = z + (rz / rz_old) * d
    return t, max_steps


class Preconditioner(Protocol):
    """An approximate inverse of ``K`` (``r -> M r``) that splits off the entries a pointwise curvature ``D``
    dominates (e.g. :class:`~ngcontact.cell.spectral.frictional_contact.TractionPreconditioner`)."""

    def __call__(self, r: np.ndarray) -> np.ndarray: ...

    def for_curvature(self, D: np.ndarray) -> Callable[[np.ndarray], np.ndarray]: ...


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
    """An iterate ``t``, its proximal point ``t_hat = prox(v)``, ``v = t - grad(t) / L``, and its residual."""

    t: np.ndarray
    v: np.ndarray
    t_hat: np.ndarray
    shifts: tuple
    res: float


def active_set_newton(grad: Callable[[np.ndarray], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
                      b: np.ndarray, h: Constraints, precondition: Preconditioner,
                      t0: np.ndarray, L: float, *, tol: float, scale: float, max_iter: int) -> ProximalResult:
    """The active-set method of the module docstring for the terms ``h`` with their own threshold rule.

    ``grad(t) = apply(t) + b`` is the gradient of the smooth part;
    ``precondition`` an approximate inverse of ``apply``, split for each free problem's curvature.
    """
    residuals: list[float] = []
    steps = 0

    def evaluate(t, shifts):
        nonlocal steps
        steps += 1
        v = t - grad(t) / L
        t_hat, shifts = h.prox(v, shifts)
        return _Point(t, v, t_hat, shifts, float(np.max(np.abs(t - t_hat))) * L / scale)

    x = evaluate(t0.copy(), ())
    best, since_best = x.res, 0
    while since_best < STALL and steps < max_iter:
        residuals.append(x.res)
        if x.res <= tol:
            return ProximalResult(t=x.t_hat, shifts=x.shifts, iterations=steps, residuals=residuals)
        atol = max(INNER_SHARE * x.res, 0.2 * tol) * scale
        proj, D = h.linearize(x.t_hat, x.v, x.shifts)
        t_new, inner_steps = free_minimum(lambda y: apply(y) + D * y, b, x.t_hat, proj,
                                          precondition.for_curvature(D), atol,
                                          max(1, max_iter - steps))
        steps += inner_steps
        # the free minimum, or its projection onto the constraints, whichever has the smaller residual (one
        # evaluation where the free minimum is admissible already: the projection is the same point)
        projected = h.project(t_new, x.shifts)
        free = evaluate(t_new, x.shifts)
        if float(np.max(np.abs(projected - t_new))) > SAME_POINT * float(np.max(np.abs(t_new))):
            free = min(free, evaluate(projected, x.shifts), key=lambda y: y.res)
        x = free
        best, since_best = (x.res, 0) if x.res < best else (best, since_best + 1)
    if steps >= max_iter:
        raise ConvergenceError(f"active-set Newton: the residual ({residuals[-1]:.3g}, relative to the gap scale) "
                               f"is above {tol:g} after {steps} steps", {"residuals": residuals[-5:]})
    rest = fista(grad, h.prox, x.t, L, tol=tol, scale=scale, max_iter=max_iter - steps)
    return ProximalResult(t=rest.t, shifts=rest.shifts, iterations=steps + rest.iterations,
                          residuals=residuals + rest.residuals)


def coulomb_active_set(grad: Callable[[np.ndarray], np.ndarray], apply: Callable[[np.ndarray], np.ndarray],
                       b: np.ndarray, h: Constraints, precondition: Preconditioner,
                       t0: np.ndarray, L: float, *, tol: float, scale: float, max_iter: int) -> ProximalResult:
    """A threshold that depends on the pressure: an accelerated fixed point of problems with a frozen threshold.

    Each pass takes the law's threshold ``G(p)`` at the proximal point's
    pressure, combines it with the earlier passes' (:class:`~ngcontact.solvers.anderson.Anderson`),
    and solves the problem with that threshold frozen (:func:`active_set_newton`,
    warm-started, to ``FIXED_POINT_SHARE`` of the current residual); it stops when the
    residual of the law itself (its threshold taken from the pressure of the
    proximal step) meets ``tol``, and goes on with :func:`active_set_newton` on the law
    itself when ``STALL_PASSES`` passes make no progress (module docstring).
    """
    residuals: list[float] = []
    steps = 0
    t, shifts = t0, ()
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
