"""Accelerated proximal gradients for the frictional contact problem in tractions.

The frictional small-slope cell (paper eqs. 57 and 65 with Tresca friction,
eqs. 16-17, posed in the interface tractions, the dual of the displacement
form) is the convex problem

    min_t  1/2 <t, K t> + <t, b> + sum_i h_i(t_i)
    s.t.   mean(t_c) = m_c   for the components c whose mean is prescribed,

``t = (q, p)`` the tangential and normal traction at the grid points, ``K``
symmetric positive semidefinite (applied as a function), and the separable
``h_i``: for the pressure ``p_i >= 0`` (plus ``p_i^2 / (2 k_n)`` for the
penalty layer), for the friction traction ``|q_i| <= G_i`` (plus
``w |q_i|^2 / (2 G_i)``, the conjugate of the Huber-regularized friction
energy ``G huber(|J_t|, w)``).  Without ``w`` and ``1/k_n`` the contact and the
friction are exact.

Method: FISTA (Beck & Teboulle, SIAM J. Imaging Sci. 2 (2009) 183-202) with
the adaptive restart of O'Donoghue & Candes (Found. Comput. Math. 15 (2015)
715-732), step ``1/L`` with ``L`` the largest eigenvalue of ``K``.  The
proximal step of ``h`` under the mean constraints is separable up to one
shift per component, found by Newton's method on the mean
(:func:`prox_pressure`, :func:`prox_friction`).  Stopping rule: the
fixed-point residual ``|t - prox(t - grad / L)| L`` (a displacement: the
violation of the contact and friction conditions) below ``tol`` times
``scale``.  A solve longer than ``PROGRESS_SECONDS`` logs its step and
residual as a progress line, as constrained CG does
(:mod:`ngcontact.solvers.constrained_cg`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ngcontact.errors import ConvergenceError
from ngcontact.solvers import constrained_cg as _cg


def _decreasing_root(f: Callable[[float], tuple[float, float]], lo: float, hi: float, x0: float,
                     tol: float) -> float:
    """The root of a decreasing, piecewise smooth ``f`` in ``[lo, hi]`` (``f(lo) >= 0 >= f(hi)``).

    Newton's method from ``x0``, kept inside the bracket by bisection
    whenever a step leaves it; ``f`` returns its value and slope.
    """
    x = min(max(x0, lo), hi)
    for _ in range(200):
        v, slope = f(x)
        if abs(v) <= tol:
            return x
        if v > 0:
            lo = x
        else:
            hi = x
        step = x - v / slope if slope < 0 else None
        x = step if step is not None and lo < step < hi else 0.5 * (lo + hi)
        if hi - lo <= 1e-15 * max(abs(lo), abs(hi), 1e-300):
            return x
    return x


def prox_pressure(v: np.ndarray, damping: float, mean: float | None, shift0: float = 0.0) -> tuple[np.ndarray, float]:
    """``p = max(v - s, 0) / damping`` with ``s`` such that ``mean(p) = mean`` (``s = 0`` without it)."""
    if mean is None:
        return np.maximum(v / damping, 0.0), 0.0
    if not mean > 0:
        raise ConvergenceError(f"the mean pressure {mean!r} must be > 0", {})

    def f(x):
        d = v - x
        return float(np.maximum(d, 0.0).mean()) / damping - mean, -np.count_nonzero(d > 0) / (v.size * damping)
    x = _decreasing_root(f, float(v.min()) - damping * mean, float(v.max()), shift0, 1e-14 * mean)
    return np.maximum(v - x, 0.0) / damping, x


def _clipper(v: np.ndarray, radius: np.ndarray, damping: np.ndarray | float):
    """``s -> (q, z, norm, over)``: ``z = (v - s) / d``, ``q`` its clip to the discs ``|q| <= G``, ``over`` the points
    outside them (``v`` of shape ``(c, m)``, ``radius`` and ``damping`` of ``m`` points or scalars)."""
    c = v.shape[0]
    plain = not isinstance(damping, np.ndarray) and damping == 1.0

    def clip(s):
        z = v - s.reshape(c, 1)
        if not plain:
            z /= damping
        norm = np.sqrt(z[0] * z[0] + z[1] * z[1] if c == 2 else z[0] * z[0])     # 0 where z * z underflows
        over = norm > radius
        # the points outside the disc onto its rim
        q = z * np.divide(radius, norm, out=np.ones_like(norm), where=over)
        return q, z, norm, over
    return clip


def prox_friction(v: np.ndarray, radius: np.ndarray, damping: np.ndarray | float, mean: np.ndarray | None,
                  shift0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``q_i = clip_{|q| <= G_i}((v_i - s) / d_i)`` with ``s`` such that ``mean(q) = mean``.

    ``v``: shape ``(c, ...)`` with ``c`` tangential components; ``radius``
    the thresholds ``G_i``, ``damping`` the factors ``d_i``.  The shift is
    found one component at a time (each mean is decreasing in its own
    shift), sweeping until both hold.  A point of zero threshold carries no
    shear whatever the shift: the shift is found on the others alone.
    """
    c = v.shape[0]
    radius = np.broadcast_to(radius, v.shape[1:])
    s = np.zeros(c) if (mean is None or shift0 is None) else np.asarray(shift0, float).copy()
    if mean is None:
        flat = _clipper(v.reshape(c, -1), radius.reshape(-1), _flat(damping, radius))
        return flat(s)[0].reshape(v.shape), s
    capacity = float(radius.mean())
    target = np.asarray(mean, float)
    if float(np.linalg.norm(target)) >= capacity:
        raise ConvergenceError(f"a mean shear of {float(np.linalg.norm(target)):.6g} exceeds the friction the "
                               f"interface can carry, {capacity:.6g} (the mean friction threshold): the interface "
                               "cannot carry this load", {})
    loaded = np.flatnonzero(radius.reshape(-1) > 0)
    n = radius.size
    vl, rl = v.reshape(c, -1)[:, loaded], radius.reshape(-1)[loaded]
    flat_d = _flat(damping, radius)
    dl = flat_d[loaded] if isinstance(flat_d, np.ndarray) else flat_d
    s, ql = _shift(_clipper(vl, rl, dl), vl, rl, dl, s, target, n, 1e-13 * max(capacity, 1e-300))
    q = np.zeros(v.shape)
    q.reshape(c, -1)[:, loaded] = ql
    return q, s


def _flat(damping: np.ndarray | float, radius: np.ndarray) -> np.ndarray | float:
    """The damping per point of the flattened grid (a scalar stays one)."""
    if isinstance(damping, np.ndarray):
        return np.broadcast_to(damping, radius.shape).reshape(-1)
    return float(damping)


def _shift(clip, v: np.ndarray, radius: np.ndarray, damping, s: np.ndarray, target: np.ndarray, n: int,
           tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The shifts ``s`` of :func:`prox_friction` whose clip's sum over the ``n`` points of the grid is ``n target``,
    and that clip (``v``, ``radius``, ``damping``: the points of positive threshold)."""
    c = v.shape[0]
    if c > 1:                   # Newton on all shifts at once, from the warm start; one sweep at a time below if not
        joint = _joint_shift(clip, s, target, radius, damping, tol, n)
        if joint is not None:
            return joint
    reach = float(np.max(np.abs(v), initial=0.0)) + float(np.max(radius * damping, initial=0.0))
    for _ in range(100):
        for a in range(c):
            def f(x, a=a):
                s[a] = x
                q, z, norm, over = clip(s)
                # d q_a / d s_a = -(1/d) (1 inside the disc; (G/|z|)(1 - z_a^2/|z|^2) on its rim)
                rim = np.where(over, radius / np.where(over, norm, 1.0)
                               * (1.0 - z[a] ** 2 / np.where(over, norm * norm, 1.0)), 1.0)
                return float(q[a].sum()) / n - target[a], -float(np.sum(rim / damping)) / n - 1e-300
            s[a] = _decreasing_root(f, -reach, reach, float(s[a]), tol)
        q = clip(s)[0]
        if all(abs(float(q[a].sum()) / n - target[a]) <= 10 * tol for a in range(c)):
            return s, q
    raise ConvergenceError(f"the shift that makes the mean shear {target.tolist()} did not converge", {})


def _joint_shift(clip, s0: np.ndarray, target: np.ndarray, radius, damping,
                 tol: float, n: int) -> tuple[np.ndarray, np.ndarray] | None:
    """Newton's method for all the shifts of :func:`prox_friction` at once: the shifts and their clipped
    traction (``None`` if it stalls).  An accepted trial's clip is the next step's, so each step clips once
    where its full step is taken.  ``n``: the points of the grid (the means are over them)."""
    c = len(s0)
    s = s0.copy()

    def misfit(q):
        return np.array([float(q[a].sum()) / n for a in range(c)]) - target
    clipped = clip(s)
    r = misfit(clipped[0])
    for _ in range(20):
        if float(np.max(np.abs(r))) <= tol:
            return s, clipped[0]
        q, z, norm, over = clipped
        # d mean(q_a) / d s_b = -mean((1/d) (delta_ab inside; (G/|z|)(delta_ab - z_a z_b / |z|^2) on the rim)),
        # summed over the points inside the disc and over those outside it apart
        inv_d = np.broadcast_to(1.0 / np.asarray(damping, float), norm.shape)
        inside = float(np.sum(inv_d, where=~over))
        w = np.divide(radius * inv_d, norm, out=np.zeros_like(norm), where=over)
        w_uu = np.divide(w, norm * norm, out=np.zeros_like(norm), where=over)     # w / |z|^2, for u = z / |z|
        jac = -(np.eye(c) * (inside + float(w.sum())) - np.einsum("k,ak,bk->ab", w_uu, z, z)) / n
        try:
            step = np.linalg.solve(jac, r)
        except np.linalg.LinAlgError:
            return None
        t = 1.0
        while t > 1e-4:
            trial = s - t * step
            attempt = clip(trial)
            r_trial = misfit(attempt[0])
            if float(np.max(np.abs(r_trial))) < float(np.max(np.abs(r))):
                s, clipped, r = trial, attempt, r_trial
                break
            t *= 0.5
        else:
            return None
    return None


@dataclass
class ProximalResult:
    t: np.ndarray
    shifts: tuple
    iterations: int
    residuals: list[float]


def fista(grad: Callable[[np.ndarray], np.ndarray], prox: Callable[[np.ndarray, tuple], tuple], t0: np.ndarray,
          L: float, *, tol: float, scale: float, max_iter: int) -> ProximalResult:
    """FISTA with adaptive restart (module docstring).

    ``grad(t)`` is the gradient of the smooth part; ``prox(v, shifts)``
    returns ``(t, shifts)``, the proximal point of ``v`` for the step ``1/L``
    (warm-started shifts in, the new shifts out).
    """
    t = t0.copy()
    y = t.copy()
    theta = 1.0
    shifts: tuple = ()
    t_new, shifts = prox(t - grad(t) / L, shifts)
    residuals: list[float] = []
    started = reported = time.perf_counter()
    for it in range(1, max_iter + 1):
        g = grad(y)
        t_new, shifts = prox(y - g / L, shifts)
        # restart when the step goes against the momentum
        if float(np.sum((t_new - t) * (y - t_new))) > 0:
            theta = 1.0
        theta_new = 0.5 * (1 + np.sqrt(1 + 4 * theta * theta))
        y = t_new + ((theta - 1) / theta_new) * (t_new - t)
        theta = theta_new
        res = float(np.max(np.abs(t_new - prox(t_new - grad(t_new) / L, shifts)[0]))) * L / scale if it % 10 == 0 \
            else None
        t = t_new
        if res is not None:
            residuals.append(res)
            if res <= tol:
                return ProximalResult(t=t, shifts=shifts, iterations=it, residuals=residuals)
            now = time.perf_counter()
            if now - reported >= _cg.PROGRESS_SECONDS:
                reported = now
                _cg.progress.info("accelerated proximal gradient: step %d of at most %d, residual %.3g (tolerance %g), "
                              "%.0f s", it, max_iter, res, tol, now - started)
    last = f"{residuals[-1]:.3g}" if residuals else "not yet measured"
    raise ConvergenceError(f"accelerated proximal gradient: the residual ({last}, relative to the gap scale) is "
                           f"above {tol:g} after {max_iter} steps", {"residuals": residuals[-5:]})
