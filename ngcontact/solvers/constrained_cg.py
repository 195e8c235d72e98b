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

Method (Polonsky & Keer, Wear 231 (1999) 206-219, with two changes argued
below).  Conjugate gradients on a working set, the search direction made
mean-free over it when the mean pressure is prescribed; after each step the
pressures are clipped at 0 and the mean is rescaled to ``pbar``.  Chosen
over a semismooth Newton with the FFT-applied operator because each step
costs one operator application (and one of the preconditioner) and no inner
linear solve, it needs no regularization of the complementarity, and it
converges to the exact contact set of the grid (the active set settles in a
few dozen steps, then it is plain CG on an SPD system).

* The working set is the contact set ``{p > 0}`` together with the points
  outside it whose gap is negative, ``{p = 0, gamma < 0}``.  Polonsky and
  Keer put such points back by a separate steepest-descent step of the
  unpreconditioned size ``-tau gamma``; on the working set they enter through
  the (preconditioned) direction itself, with the step of the points already
  in contact, and the next clipping removes them again where the direction
  does not press them.
* The conjugacy is kept when the working set changes (Polonsky and Keer
  restart it whenever a point is put back): the step is then a nonlinear
  conjugate gradient of Fletcher-Reeves kind on the piecewise quadratic
  ``f``, restarted only where the conjugate direction is no descent
  direction (``<gs, t> <= 0``, ``gs`` the gap on the working set).  On a
  random map a few hundred edge points enter and leave at every step for
  tens of steps; a restart at each would make all these steps
  steepest-descent steps.  Once the set has settled the step is the
  conjugate-gradient step on the fixed set, and the stopping rule below
  holds the answer to the same tolerance whichever way the set was found.

Preconditioning (``precondition``, Vollebregt, J. Comput. Phys. 257 (2014)
333-351).  The compliance of an elastic body falls like ``1 / |k|``, so on a
grid of ``N`` points per direction ``A`` has a condition number of order
``N`` on a contact set of many small patches (a random map), and plain CG needs ``O(sqrt(N))`` steps per digit:
hundreds at 1024^2.  With ``M`` an approximation of ``A^{-1}`` (the inverse
symbol ``|k|``-like, by FFTs) the search direction is ``Pi R M R^T g``
(``R`` the restriction to the working set, ``Pi`` the mean-free projection
there): the preconditioned operator on the set is spectrally equivalent to
the identity up to a ``log^2 N`` factor (the operators of order -1 and 1
restricted to a subdomain, as in domain decomposition), so the step count
hardly grows with the grid.  The answer is the same to the tolerance.

Cost of a step, in operator applications (FFT pairs for a convolution).
The step length needs ``<t, A t>``; the gap after the step needs ``A p``.
A step that clips no point moves ``A p`` along ``A t``; a step that clips
points changes ``p`` by ``-tau t`` plus the clipped values, and its ``A p``
is one application to ``p``.  Where ``A`` is given as a
:class:`DirectionOperator` (a convolution, whose forward transform ``T`` of
``t`` gives ``<t, A t>`` by Parseval's identity and ``c A t`` by one inverse
transform), a step costs one forward and one inverse transform, and one
more forward transform where it clips points, plus the preconditioner's pair;
a plain function ``A`` costs one application per step and one more where it
clips.  The preconditioner's pair cannot be shared with the operator's: the
restriction to the working set lies between them, and it is not diagonal in
Fourier space.  Every ``REFRESH`` steps, and before a converged answer is
returned, the gap is evaluated anew from ``p`` (round-off).

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
from typing import Callable, Protocol, runtime_checkable

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
    """``sum a b`` in one pass without BLAS (``einsum``'s own loop): OpenBLAS' threads, spinning against another
    busy process, made a short dot product hundreds of times slower than a plain sum.  ``out``: a buffer of the
    shape for the products, accepted for callers that hold one and not needed."""
    return float(np.einsum("i,i->", a.ravel(), b.ravel()))


def roundoff_floor(norm: float | None, p: np.ndarray, b: np.ndarray, gscale: float) -> float:
    """The gap's round-off relative to ``gscale``: ``ROUNDOFF eps (|A| max|p| + max|b|) / gscale`` (module
    docstring); 0 without the norm."""
    if norm is None:
        return 0.0
    return ROUNDOFF * float(np.finfo(float).eps) * (norm * float(np.max(np.abs(p))) + float(np.max(np.abs(b)))) \
        / gscale


@runtime_checkable
class DirectionOperator(Protocol):
    """``A`` seen along a search direction ``t`` from one transform ``T`` of it (module docstring, cost of a
    step): :class:`ngcontact.cell.spectral.convolution.Convolution` by FFTs, :class:`_Applied` by one
    application of a plain function."""

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """``A x`` (a new array)."""

    def transform(self, x: np.ndarray) -> np.ndarray:
        """The transform ``T`` of ``x`` from which :meth:`energy` and :meth:`from_transform` answer."""

    def energy(self, T: np.ndarray, x: np.ndarray) -> float:
        """``<x, A x>``."""

    def from_transform(self, T: np.ndarray, x: np.ndarray, factor: float = 1.0) -> np.ndarray:
        """``factor A x`` (a new array; ``T`` may be overwritten)."""


class _Applied:
    """A plain function ``x -> A x`` as a :class:`DirectionOperator`: the transform is ``A x`` itself."""

    def __init__(self, apply_A: Callable[[np.ndarray], np.ndarray]):
        self.apply_A = apply_A
        self.work: np.ndarray | None = None

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return self.apply_A(x)

    def transform(self, x: np.ndarray) -> np.ndarray:
        return self.apply_A(x)

    def energy(self, T: np.ndarray, x: np.ndarray) -> float:
        if self.work is None or self.work.shape != x.shape:
            self.work = np.empty(x.shape)
        return inner(T, x, self.work)

    def from_transform(self, T: np.ndarray, x: np.ndarray, factor: float = 1.0) -> np.ndarray:
        T *= factor
        return T


def direction_operator(apply_A) -> DirectionOperator:
    """``apply_A`` where it is a :class:`DirectionOperator`, else the plain function wrapped as one."""
    return apply_A if isinstance(apply_A, DirectionOperator) else _Applied(apply_A)


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
        self.work = np.empty(shape)
        self.count = 0

    def update(self, p: np.ndarray) -> None:
        np.greater(p, 0.0, out=self.mask)
        self.count = int(np.count_nonzero(self.mask))

    def widen(self, on: _ContactSet, more: np.ndarray) -> None:
        """This set becomes ``on`` with the points where ``more`` (booleans) holds."""
        np.logical_or(on.mask, more, out=self.mask, casting="unsafe")
        self.count = int(np.count_nonzero(self.mask))

    def mean(self, x: np.ndarray) -> float:
        """The mean of ``x`` over the set (0 on an empty set)."""
        return inner(x, self.mask, self.work) / self.count if self.count else 0.0

    def residual(self, g: np.ndarray, shift: float, gscale: float) -> float:
        """``max(max_on |g - shift|, max_off max(shift - g, 0)) / gscale`` (module docstring): at each point
        ``max(-gamma, 1_on gamma)``, so the maximum of ``-gamma`` and of ``gamma`` on the set."""
        gamma = np.subtract(g, shift, out=self.work)
        r_neg = -float(gamma.min())
        r_on = float(np.multiply(gamma, self.mask, out=gamma).max())
        return max(r_on, r_neg, 0.0) / gscale


def constrained_cg(apply_A: Callable[[np.ndarray], np.ndarray], b: np.ndarray, *, pbar: float | None,
                   tol: float, max_iter: int, gscale: float, p0: np.ndarray | None = None,
                   norm: float | None = None,
                   precondition: Callable[[np.ndarray], np.ndarray] | None = None) -> ConstrainedResult:
    """Minimize ``1/2 <p, A p> + <p, b>`` over ``p >= 0`` (module docstring).

    Parameters
    ----------
    apply_A
        ``p -> A p`` (same shape as ``b``, a new array), or a :class:`DirectionOperator` (a convolution:
        fewer transforms per step, module docstring).
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
    it = _Iteration(direction_operator(apply_A), b, pbar, gscale, norm, _start(apply_A, b, pbar, p0))
    started = reported = time.perf_counter()
    while it.steps < max_iter:
        # nothing pressed and nothing penetrating (approach below every summit): the open solution
        if not it.on.count and it.on.residual(it.g, 0.0, gscale) <= tol:
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
    mean, the contact set, the working set, the search direction ``t`` and the conjugacy."""

    def __init__(self, A: DirectionOperator, b: np.ndarray, pbar: float | None, gscale: float,
                 norm: float | None, p: np.ndarray):
        self.A, self.b, self.pbar, self.gscale = A, b, pbar, gscale
        self.floor_b = 0.0 if norm is None else float(np.max(np.abs(b)))
        self.norm = norm
        self.p = p
        self.Ap = A(p)
        self.g = self.Ap + b
        self.on, self.working = _ContactSet(b.shape), _ContactSet(b.shape)
        self.on.update(p)
        self.shift = self.on.mean(self.g) if pbar is not None else 0.0
        self.t, self.gs, self.work = np.zeros(b.shape), np.empty(b.shape), np.empty(b.shape)
        self.g_old, self.steps, self.stuck = 1.0, 0, False
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

    def _mean_free(self, x: np.ndarray) -> None:
        """``x`` made mean-free over the working set under a prescribed mean (in place; 0 outside it)."""
        x *= self.working.mask
        if self.pbar is not None:
            x -= self.working.mean(x)
            x *= self.working.mask

    def direction(self, precondition) -> np.ndarray:
        """The conjugate (or, at the first step and where that is no descent direction, the steepest)
        preconditioned direction on the working set (module docstring); the gap there, less its mean under a
        prescribed mean, is kept in ``gs`` for the step length."""
        ws, gs, t = self.working, self.gs, self.t
        ws.widen(self.on, self.g < self.shift)
        np.subtract(self.g, ws.mean(self.g) if self.pbar is not None else 0.0, out=gs)
        gs *= ws.mask
        if precondition is None:
            z = gs
        else:
            z = precondition(gs)
            self._mean_free(z)
        G = inner(gs, z, self.work)
        if self.steps > 1:
            t *= G / self.g_old
            t += z
            self._mean_free(t)
            if inner(gs, t, self.work) <= 0.0:
                np.copyto(t, z)
        else:
            np.copyto(t, z)
        self.g_old = G
        return t

    def step(self, precondition, tol: float) -> ConstrainedResult | None:
        """One step (module docstring); the result where it converged."""
        self.steps += 1
        on, p, shift = self.on, self.p, self.shift
        t = self.direction(precondition)
        T = self.A.transform(t)
        rt = self.A.energy(T, t)
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
        scale = self.pbar / p.mean() if self.pbar is not None else 1.0
        p *= scale
        # a step that clips nothing moves A p along A t (module docstring, cost of a step)
        linear = self.steps % REFRESH != 0 and not clipped
        if linear:
            self.Ap += self.A.from_transform(T, t, -tau)
            self.Ap *= scale
        else:
            self.Ap = self.A(p)
        res = self.gap_state()
        if res <= max(tol, self.floor()) and linear:
            self.Ap = self.A(p)    # converged on an updated gap: confirmed on the gap itself
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
