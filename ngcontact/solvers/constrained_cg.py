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


def inner(a: np.ndarray, b: np.ndarray) -> float:
    """``sum a b`` without BLAS: OpenBLAS' threads, spinning against another busy process, made a short dot
    product hundreds of times slower than this plain sum."""
    return float(np.multiply(a, b).sum())


def _residual(p, g, shift, gscale) -> float:
    gamma = g - shift
    on = p > 0
    r_on = float(np.max(np.abs(gamma[on]))) if on.any() else 0.0
    r_off = float(np.max(-gamma[~on], initial=0.0))
    return max(r_on, r_off) / gscale


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


def _gap_state(p: np.ndarray, g: np.ndarray, pbar: float | None, gscale: float) -> tuple[np.ndarray, float, float]:
    """``(g, shift, residual)``: the gap, the multiplier of the mean (the mean gap on the contact set) and the
    complementarity residual."""
    on = p > 0
    shift = float(g[on].mean()) if (pbar is not None and on.any()) else 0.0
    return g, shift, _residual(p, g, shift, gscale)


def _preconditioned(precondition, gs, on, mean_free: bool) -> np.ndarray:
    """``Pi R M R^T gs``: the preconditioner on the contact set, made mean-free there under a prescribed mean."""
    z = np.where(on, precondition(gs), 0.0)
    if mean_free:
        z = np.where(on, z - float(z[on].mean()), 0.0)
    return z


def constrained_cg(apply_A: Callable[[np.ndarray], np.ndarray], b: np.ndarray, *, pbar: float | None,
                   tol: float, max_iter: int, gscale: float, p0: np.ndarray | None = None,
                   norm: float | None = None,
                   precondition: Callable[[np.ndarray], np.ndarray] | None = None) -> ConstrainedResult:
    """Minimize ``1/2 <p, A p> + <p, b>`` over ``p >= 0`` (module docstring).

    Parameters
    ----------
    apply_A
        ``p -> A p`` (same shape as ``b``).
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
        ``r -> M r``, ``M`` symmetric positive definite and close to ``A^{-1}`` (module docstring);
        ``None``: plain CG.

    Raises
    ------
    ConvergenceError
        When the residual is still above ``tol`` after ``max_iter`` steps.
    """
    if pbar is not None and not pbar > 0:
        raise ValueError(f"pbar = {pbar!r}: a prescribed mean pressure must be > 0")
    if not gscale > 0:
        raise ValueError(f"gscale = {gscale!r}: must be > 0")
    n = b.size
    p = _start(apply_A, b, pbar, p0)
    t = np.zeros(b.shape)
    g_old = 1.0
    conjugate = False
    residuals: list[float] = []
    shift = 0.0
    Ap = apply_A(p)
    g = Ap + b
    started = reported = time.perf_counter()
    for it in range(1, max_iter + 1):
        on = p > 0
        if not on.any():       # nothing pressed (approach below every summit): the open solution
            residuals.append(_residual(p, g, 0.0, gscale))
            return ConstrainedResult(p=p, gap=g, shift=0.0, iterations=it - 1, residuals=residuals)
        shift = float(g[on].mean()) if pbar is not None else 0.0
        gs = np.where(on, g - shift, 0.0)
        z = gs if precondition is None else _preconditioned(precondition, gs, on, pbar is not None)
        G = inner(gs, z)
        t = np.where(on, z + (G / g_old) * t if conjugate else z, 0.0)
        g_old = G
        At = apply_A(t)
        r = At - At[on].mean() if pbar is not None else At
        rt = inner(np.where(on, r, 0.0), t)
        if rt <= 0:            # no descent left: converged if complementary (a uniform start on a flat gap)
            residuals.append(_residual(p, g, shift, gscale))
            if residuals[-1] <= max(tol, roundoff_floor(norm, p, b, gscale)):
                return ConstrainedResult(p=p, gap=g - shift, shift=shift, iterations=it - 1, residuals=residuals)
            break
        tau = inner(gs, t) / rt
        trial = p - tau * t
        p = np.maximum(trial, 0.0)
        back = (p == 0.0) & (g - shift < 0.0)
        conjugate = not back.any()
        # a step that clips nothing and puts nothing back moves A p along A t: no operator application needed
        linear = conjugate and it % REFRESH != 0 and not bool(np.any(trial < 0.0))
        if not conjugate:
            p[back] -= tau * (g[back] - shift)
        scale = pbar / p.mean() if pbar is not None else 1.0
        p *= scale
        Ap = scale * (Ap - tau * At) if linear else apply_A(p)
        g, shift, res = _gap_state(p, Ap + b, pbar, gscale)
        if res <= max(tol, roundoff_floor(norm, p, b, gscale)) and linear:
            Ap = apply_A(p)    # converged on an updated gap: confirmed on the gap itself
            g, shift, res = _gap_state(p, Ap + b, pbar, gscale)
        residuals.append(res)
        if res <= max(tol, roundoff_floor(norm, p, b, gscale)):
            return ConstrainedResult(p=p, gap=g - shift, shift=shift, iterations=it, residuals=residuals)
        now = time.perf_counter()
        if now - reported >= PROGRESS_SECONDS:
            reported = now
            progress.info("constrained CG: step %d of at most %d, residual %.3g (tolerance %g), grid of %d points, "
                          "%.0f s", it, max_iter, res, tol, n, now - started)
    raise ConvergenceError(
        f"constrained CG: the complementarity residual {residuals[-1]:.3g} of the gap scale is above the "
        f"tolerance {tol:g} after {len(residuals)} steps (grid of {n} points)", {"residuals": residuals[-5:]})


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

    def prec(v):
        return v if precondition is None else precondition(v) * mask
    z = prec(r)
    d = z.copy()
    rz = inner(r, z)
    stop = rtol * rtol * inner(r, r)
    for it in range(1, max_iter + 1):
        if inner(r, r) <= stop:
            return x, it - 1
        Ad = apply_A(d) * mask
        alpha = rz / inner(d, Ad)
        x += alpha * d
        r -= alpha * Ad
        z = prec(r)
        rz, rz_old = inner(r, z), rz
        d = z + (rz / rz_old) * d
    raise ConvergenceError(f"masked CG: residual {np.sqrt(inner(r, r) / inner(rhs * mask, rhs * mask)):.3g} above "
                           f"{rtol:g} after {max_iter} steps", {})
