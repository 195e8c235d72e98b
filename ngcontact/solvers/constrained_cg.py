"""Constrained conjugate gradients for a unilateral contact problem on a grid.

The problem (the discrete form of the rigid-limit cell problem, paper eq. 57
with the small-slope contact condition, or of its penalty form eq. 65):
find pressures ``p_i >= 0`` on the points of a grid minimizing

    f(p) = 1/2 <p, A p> + <p, b>        (optionally with mean(p) = pbar),

``A`` symmetric positive (semi)definite and applied as a function (an FFT
convolution for the spectral cell), ``b`` the initial gap.  Its optimality
conditions are the contact conditions: with the gap ``gamma = A p + b - c``
(``c`` the multiplier of the mean constraint, 0 without it)

    p >= 0,   gamma >= 0,   p gamma = 0.

Method (Polonsky & Keer, Wear 231 (1999) 206-219).  Conjugate gradients on
the current contact set ``{p > 0}``, the search direction made
mean-free over the set when the mean pressure is prescribed; after each
step the pressures are clipped at 0, points outside the set whose gap is
negative are put back in contact with a steepest-descent step (and the
conjugacy restarted), and the mean is rescaled to ``pbar``.  Chosen over a
semismooth Newton with the FFT-applied operator because each step costs two
operator applications and no inner linear solve, it needs no
regularization of the complementarity, and it converges to the exact
contact set of the grid (the active set settles in a few dozen steps, then
it is plain CG on an SPD system).

Preconditioning (``precondition``, Vollebregt, J. Comput. Phys. 257 (2014)
333-351).  The compliance of an elastic body falls like ``1 / |k|``, so on a
grid of ``N`` points per direction ``A`` has a condition number of order
``N`` on a contact set of many small patches (a random map), and plain CG needs ``O(sqrt(N))`` steps per digit:
hundreds at 1024^2.  With ``M`` an approximation of ``A^{-1}`` (the inverse
symbol ``|k|``-like, by FFTs) the search direction is ``Pi R M R^T g``
(``R`` the restriction to the contact set, ``Pi`` the mean-free projection
there): the preconditioned operator on the set is spectrally equivalent to
the identity up to a ``log^2 N`` factor (the operators of order -1 and 1
restricted to a subdomain, as in domain decomposition), so the step count
hardly grows with the grid.  The rest of the method (clipping, the points
put back, the restarts) is unchanged, and the answer is the same to the
tolerance.  A step that clips no point and puts none back moves ``A p``
along the search direction's ``A t``, so the gap is updated without an
operator application; every ``REFRESH`` steps, and before a converged
answer is returned, it is evaluated anew.

Stopping rule: the complementarity residual, relative to the scale ``gscale``
of the gap,

    r = max( max_{p>0} |gamma|, max_{p=0} max(-gamma, 0) ) / gscale <= tol,

or, where the operator's norm ``|A|`` is given, the residual at its round-off
``ROUNDOFF eps (|A| max|p| + max|b|) / gscale``: the gap is a sum of terms as
large as ``(A p)_i`` and ``b_i``, and cannot be evaluated more accurately
than that (a pressure far above the gap's scale, a gap of picometres under a
load of the bodies' scale).  The rule is then invariant under a scaling of
the gap or of the pressure alone.

A solve that runs longer than ``PROGRESS_SECONDS`` logs its step and
residual at INFO on the logger ``ngcontact.progress`` every
``PROGRESS_SECONDS`` (the run's progress lines, :func:`ngcontact.runner.solve`).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ngcontact.errors import ConvergenceError

#: the run's progress lines (printed as its stage lines, :func:`ngcontact.runner.solve`)
progress = logging.getLogger("ngcontact.progress")

#: factor of ``eps (|A| max|p| + max|b|)`` at which the gap's residual is round-off (module docstring)
ROUNDOFF = 10.0
#: every this many steps the gap is evaluated anew, not updated along the search direction (round-off)
REFRESH = 10
#: seconds of a solve after which, and between which, a progress line is logged
PROGRESS_SECONDS = 5.0


@dataclass
class ConstrainedResult:
    """Solution of :func:`constrained_cg`: pressure, gap, multiplier, history."""

    p: np.ndarray
    gap: np.ndarray
    shift: float
    iterations: int
    residuals: list[float]


def inner(a: np.ndarray, b: np.ndarray, out: np.ndarray | None = None) -> float:
    """``sum a b`` without BLAS: OpenBLAS' threads, spinning against another busy process, made a short dot
    product hundreds of times slower than this plain sum.  ``out``: a buffer of the shape for the products."""
    return float(np.multiply(a, b, out=out).sum())


def roundoff_floor(norm: float | None, p: np.ndarray, b: np.ndarray, gscale: float) -> float:
    """The gap's round-off relative to ``gscale``: ``ROUNDOFF eps (|A| max|p| + max|b|) / gscale`` (module
    docstring); 0 without the norm."""
    if norm is None:
        return 0.0
    return ROUNDOFF * float(np.finfo(float).eps) * (norm * float(np.max(np.abs(p))) + float(np.max(np.abs(b)))) \
        / gscale


def _start(apply_A: Callable[[np.ndarray], np.ndarray], b: np.ndarray, pbar: float | None,
           p0: np.ndarray | None) -> np.ndarray:
    """The start of :func:`constrained_cg` (its ``p0`` parameter), scaled to the mean ``pbar`` where given."""
    if p0 is not None and np.any(p0 > 0):
        p = np.maximum(p0, 0.0).astype(float)
    elif pbar is not None:
        p = np.full(b.shape, float(pbar))
    else:
        e = np.zeros(b.shape)
        e.flat[0] = 1.0
        diag = float(apply_A(e).flat[0])
        p = np.maximum(-b, 0.0) / diag
    if pbar is not None:
        p *= pbar / p.mean()
    return p


class _ContactSet:
    """The contact set ``{p > 0}`` of an iterate as a field of ones and zeros, with buffers of the grid's shape.

    Restrictions, means and maxima over the set are products with the field: a reduction that skips the
    points outside a scattered set branches at every point and costs several times a product.
    """

    def __init__(self, shape: tuple[int, ...]):
        self.mask = np.zeros(shape)
        self.rest = np.zeros(shape)
        self.work = np.empty(shape)
        self.count = 0

    def update(self, p: np.ndarray) -> None:
        np.greater(p, 0.0, out=self.mask)
        np.subtract(1.0, self.mask, out=self.rest)
        self.count = int(np.count_nonzero(self.mask))

    def mean(self, x: np.ndarray) -> float:
        """The mean of ``x`` over the set (0 on an empty set)."""
        return inner(x, self.mask, self.work) / self.count if self.count else 0.0

    def residual(self, g: np.ndarray, shift: float, gscale: float) -> float:
        """``max(max_on |g - shift|, max_off max(shift - g, 0)) / gscale`` (module docstring)."""
        gamma = np.subtract(g, shift, out=self.work)
        r_off = -float(np.multiply(gamma, self.rest, out=self.rest).min())
        np.subtract(1.0, self.mask, out=self.rest)
        r_on = float(np.abs(np.multiply(gamma, self.mask, out=gamma), out=gamma).max())
        return max(r_on, r_off, 0.0) / gscale


def _preconditioned(precondition, gs: np.ndarray, on: _ContactSet, mean_free: bool) -> np.ndarray:
    """``Pi R M R^T gs``: the preconditioner on the contact set, made mean-free there under a prescribed mean
    (``precondition`` returns a new array)."""
    z = precondition(gs)
    z *= on.mask
    if mean_free:
        z -= on.mean(z)
        z *= on.mask
    return z


def constrained_cg(apply_A: Callable[[np.ndarray], np.ndarray], b: np.ndarray, *, pbar: float | None,
                   tol: float, max_iter: int, gscale: float, p0: np.ndarray | None = None,
                   norm: float | None = None,
                   precondition: Callable[[np.ndarray], np.ndarray] | None = None) -> ConstrainedResult:
    """Minimize ``1/2 <p, A p> + <p, b>`` over ``p >= 0`` (module docstring).

    Parameters
    ----------
    apply_A
        ``p -> A p`` (same shape as ``b``, a new array).
    b
        Initial gap on the grid.
    pbar
        Prescribed mean pressure (> 0), or ``None``: no mean constraint
        (``A`` must then be positive definite, e.g. include the uniform
        mode, and ``b`` carries the prescribed approach).
    tol, max_iter
        Stopping rule (module docstring) and the largest number of steps.
    gscale
        Scale of the gap for the residual (e.g. its peak-to-valley height).
    p0
        Start (e.g. the previous load's pressure); default: uniform ``pbar``,
        or, without a mean constraint, the pressure that closes every
        penetrating point under the diagonal of ``A``.
    norm
        The largest eigenvalue of ``A`` (for a convolution: the largest value of its symbol), for the
        round-off floor of the stopping rule (module docstring); ``None``: no floor.
    precondition
        ``r -> M r`` (a new array), ``M`` symmetric positive definite and close to ``A^{-1}`` (module
        docstring); ``None``: plain CG.

    Raises
    ------
    ConvergenceError
        When the residual is still above ``tol`` after ``max_iter`` steps.
    """
    if pbar is not None and not pbar > 0:
        raise ValueError(f"pbar = {pbar!r}: a prescribed mean pressure must be > 0")
    if not gscale > 0:
        raise ValueError(f"gscale = {gscale!r}: must be > 0")
    it = _Iteration(apply_A, b, pbar, gscale, norm, _start(apply_A, b, pbar, p0))
    started = reported = time.perf_counter()
    while it.steps < max_iter:
        if not it.on.count:    # nothing pressed (approach below every summit): the open solution
            it.residuals.append(it.on.residual(it.g, 0.0, gscale))
            return it.result(0.0)
        done = it.step(precondition, tol)
        if done is not None:
            return done
        if it.stuck:
            break
        now = time.perf_counter()
        if now - reported >= PROGRESS_SECONDS:
            reported = now
            progress.info("constrained CG: step %d of at most %d, residual %.3g (tolerance %g), grid of %d points, "
                          "%.0f s", it.steps, max_iter, it.residuals[-1], tol, b.size, now - started)
    last = f"{it.residuals[-1]:.3g}" if it.residuals else "not yet measured"
    raise ConvergenceError(
        f"constrained CG: the complementarity residual {last} of the gap scale is above the "
        f"tolerance {tol:g} after {len(it.residuals)} steps (grid of {b.size} points)",
        {"residuals": it.residuals[-5:]})


class _Iteration:
    """The state of :func:`constrained_cg`: pressure ``p``, ``A p``, gap ``g = A p + b``, the multiplier of the
    mean, the contact set, the search direction ``t`` and the conjugacy."""

    def __init__(self, apply_A, b: np.ndarray, pbar: float | None, gscale: float, norm: float | None,
                 p: np.ndarray):
        self.apply_A, self.b, self.pbar, self.gscale = apply_A, b, pbar, gscale
        self.floor_b = 0.0 if norm is None else float(np.max(np.abs(b)))
        self.norm = norm
        self.p = p
        self.Ap = apply_A(p)
        self.g = self.Ap + b
        self.on = _ContactSet(b.shape)
        self.on.update(p)
        self.shift = self.on.mean(self.g) if pbar is not None else 0.0
        self.t, self.gs, self.work = np.zeros(b.shape), np.empty(b.shape), np.empty(b.shape)
        self.g_old, self.conjugate, self.steps, self.stuck = 1.0, False, 0, False
        self.residuals: list[float] = []

    def floor(self) -> float:
        """:func:`roundoff_floor` of the iterate (``max|b|`` held)."""
        if self.norm is None:
            return 0.0
        return ROUNDOFF * float(np.finfo(float).eps) * (self.norm * float(self.p.max()) + self.floor_b) / self.gscale

    def result(self, shift: float) -> ConstrainedResult:
        return ConstrainedResult(p=self.p, gap=self.g - shift, shift=shift, iterations=self.steps,
                                 residuals=self.residuals)

    def gap_state(self) -> float:
        """The gap, the multiplier and the set of the current pressure; returns the residual."""
        np.add(self.Ap, self.b, out=self.g)
        self.on.update(self.p)
        self.shift = self.on.mean(self.g) if self.pbar is not None else 0.0
        return self.on.residual(self.g, self.shift, self.gscale)

    def direction(self, precondition) -> np.ndarray:
        """The conjugate (or, after a restart, the steepest) preconditioned direction on the contact set; the
        restricted gap ``gs`` is kept for the step length."""
        on, gs, t = self.on, self.gs, self.t
        np.subtract(self.g, self.shift, out=gs)
        gs *= on.mask
        z = gs if precondition is None else _preconditioned(precondition, gs, on, self.pbar is not None)
        G = inner(gs, z, self.work)
        if self.conjugate:
            t *= G / self.g_old
            t += z
            t *= on.mask
        else:
            np.copyto(t, z)
        self.g_old = G
        return t

    def step(self, precondition, tol: float) -> ConstrainedResult | None:
        """One step (module docstring); the result where it converged."""
        self.steps += 1
        on, p, shift = self.on, self.p, self.shift
        t = self.direction(precondition)
        At = self.apply_A(t)
        rt = inner(At, t, self.work)
        if self.pbar is not None:
            rt -= on.mean(At) * float(t.sum())
        if rt <= 0:            # no descent left: converged if complementary (a uniform start on a flat gap)
            self.steps -= 1
            self.residuals.append(on.residual(self.g, shift, self.gscale))
            if self.residuals[-1] <= max(tol, self.floor()):
                return self.result(shift)
            self.stuck = True
            return None
        tau = inner(self.gs, t, self.work) / rt
        trial = np.multiply(t, -tau, out=self.work)
        trial += p
        clipped = float(trial.min()) < 0.0
        np.maximum(trial, 0.0, out=p)
        back = (p == 0.0) & (self.g < shift)
        self.conjugate = not back.any()
        # a step that clips nothing and puts nothing back moves A p along A t: no operator application needed
        linear = self.conjugate and self.steps % REFRESH != 0 and not clipped
        if not self.conjugate:
            p[back] -= tau * (self.g[back] - shift)
        scale = self.pbar / p.mean() if self.pbar is not None else 1.0
        p *= scale
        if linear:
            At *= tau
            self.Ap -= At
            self.Ap *= scale
        else:
            self.Ap = self.apply_A(p)
        res = self.gap_state()
        if res <= max(tol, self.floor()) and linear:
            self.Ap = self.apply_A(p)    # converged on an updated gap: confirmed on the gap itself
            res = self.gap_state()
        self.residuals.append(res)
        return self.result(self.shift) if res <= max(tol, self.floor()) else None


def masked_cg(apply_A: Callable[[np.ndarray], np.ndarray], active: np.ndarray, rhs: np.ndarray, *,
              rtol: float = 1e-10, max_iter: int = 10000,
              precondition: Callable[[np.ndarray], np.ndarray] | None = None) -> tuple[np.ndarray, int]:
    """Solve ``(A x)_i = rhs_i`` for ``i`` in ``active`` with ``x = 0`` outside, by conjugate gradients.

    ``A`` restricted to a set is symmetric positive definite whenever ``A`` is
    positive definite on vectors supported there (the linearization of the
    contact problem at a fixed contact set).  ``precondition``: ``r -> M r``
    with ``M`` close to ``A^{-1}``, applied as ``R M R^T`` on the set (module
    docstring).  Stops when the residual's norm is ``rtol`` times the right-hand
    side's.  Returns ``(x, iterations)``.
    """
    mask = active.astype(float)
    x = np.zeros(rhs.shape)
    r = rhs * mask
    work = np.empty(rhs.shape)

    def prec(v):
        if precondition is None:
            return v
        z = precondition(v)
        z *= mask
        return z
    z = prec(r)
    d = z.copy()
    rz = inner(r, z, work)
    stop = rtol * rtol * inner(r, r, work)
    for it in range(1, max_iter + 1):
        if inner(r, r, work) <= stop:
            return x, it - 1
        Ad = apply_A(d)
        Ad *= mask
        alpha = rz / inner(d, Ad, work)
        x += np.multiply(d, alpha, out=work)
        r -= np.multiply(Ad, alpha, out=work)
        z = prec(r)
        rz, rz_old = inner(r, z, work), rz
        d *= rz / rz_old
        d += z
    raise ConvergenceError(f"masked CG: residual {np.sqrt(inner(r, r) / inner(rhs * mask, rhs * mask)):.3g} above "
                           f"{rtol:g} after {max_iter} steps", {})
