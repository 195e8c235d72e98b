"""Friction in the spectral small-slope cell: tractions through the layers' full compliance.

Friction (Tresca, or Coulomb with the threshold ``G = mu p``, paper eqs.
16-17) needs the tangential traction ``q`` beside the pressure of
:mod:`ngcontact.cell.spectral.layered_cell`: the jump is ``J = -K t - U`` with
``t = (q, p)`` and ``K`` the layers' full 3 x 3 (2D: 2 x 2) compliance, whose normal/tangential coupling vanishes for
identical layers only.  The cell is then the convex problem in tractions of
:mod:`ngcontact.solvers.projected_gradient` (``|q| <= G``, ``p >= 0``),
solved by the active-set (semismooth Newton) method of
:mod:`ngcontact.solvers.active_set_newton`: its free problems are solved
by conjugate gradients preconditioned with the inverse of the full
compliance per wave vector (:class:`TractionPreconditioner`), so the step
count grows like ``log N`` instead of like the ``sqrt(N)`` of accelerated
proximal gradients (:mod:`ngcontact.solvers.projected_gradient`, kept as
``SpectralCell.friction_method = "proximal"`` and as the active-set
method's fallback).  Coulomb friction has no potential; its solution is
the fixed point at which the threshold ``G = mu p`` is taken from the
pressure of the proximal step itself, which both methods meet to the same
tolerance.  With ``"penalty"`` the friction is the FE cell's
Huber-regularized one (width ``w``), with ``"exact"`` it is exact.  As in
the FE cell, the Tresca threshold holds on the whole surface.  The
pointwise terms: :mod:`ngcontact.cell.spectral.traction_constraints`.

Functions of a :class:`~ngcontact.cell.spectral.layered_cell.SpectralCell` ``cell``.
"""
from __future__ import annotations

from functools import partial

import numpy as np

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.spectral.fft_threads import fft_workers
from ngcontact.cell.spectral.layer_compliance import layers_matrix
from ngcontact.cell.spectral.traction_constraints import TractionConstraints
from ngcontact.solvers.active_set_newton import active_set_newton, coulomb_active_set
from ngcontact.solvers.free_directions import SplitPreconditioner
from ngcontact.solvers.projected_gradient import fista


def cell_load_normal(load: CellLoad) -> CellLoad:
    """The normal part of a load (the tangential components free of traction)."""
    d = len(load.traction)
    return CellLoad(traction=(0.0,) * (d - 1) + (load.traction[-1],), jump=(None,) * (d - 1) + (load.jump[-1],),
                    macro_strain=load.macro_strain)


def traction_operator(cell, uniform: tuple[bool, ...]):
    """``(t -> K t, L, K0)``: the full compliance ``K = C_rough + C_counter`` on stacked tractions.

    ``t`` has the components ``(q_x[, q_y], p)`` of the traction the
    rough body exerts on the counter; the jump is ``J = -K t - U``.
    ``uniform[c]``: keep the uniform mode of component ``c`` (its mean is
    free); without it the mean is prescribed and the mode is dropped.
    The coupling is zeroed on the Nyquist rows, where ``k`` and ``-k``
    are the same mode.  ``L`` is the largest eigenvalue of ``K`` and
    ``K0`` the diagonal of the uniform mode (the layers' uniaxial-strain
    and shear compliances).
    """
    d = cell.dim
    K = _full_compliance(cell)
    K0 = np.real(np.diagonal(K.reshape(-1, d, d)[0])).copy()
    zero = (0,) * (d - 1)
    for c in range(d):
        if not uniform[c]:
            K[zero + (c, c)] = 0.0
    L = _largest_eigenvalue(K)
    Km = np.moveaxis(K, (-2, -1), (0, 1)).copy()       # (d, d, *kshape)
    return partial(symbol_product, Km, cell.shape), L, K0


def symbol_product(symbol: np.ndarray, shape: tuple[int, ...], t: np.ndarray) -> np.ndarray:
    """``IFFT(symbol FFT(t))`` for stacked fields ``t`` (shape ``(d, *shape)``), ``symbol`` of shape
    ``(d, d, *kshape)`` on the half spectrum of the real FFT (a new array).

    The product is written into a buffer of its own and the inverse transform made in its two passes,
    complex-to-complex over the leading axes and complex-to-real along the last, each in place (as
    :meth:`~.convolution.Convolution.from_transform`).
    """
    import scipy.fft as sfft  # on use: importing scipy.fft would slow the start of every process
    workers = fft_workers(t.size)
    axes = tuple(range(1, len(shape) + 1))
    T = sfft.rfftn(t, axes=axes, workers=workers)
    U = np.einsum("ab...,b...->a...", symbol, T)
    del T
    if len(shape) > 1:
        U = sfft.ifftn(U, axes=axes[:-1], workers=workers, overwrite_x=True)
    return sfft.irfft(U, n=shape[-1], axis=-1, workers=workers, overwrite_x=True)


def _full_compliance(cell) -> np.ndarray:
    """``K(k) = C_rough + C_counter`` on the half spectrum, shape ``(*kshape, d, d)``, the coupling zeroed on
    the Nyquist rows: a new array, computed once per cell (:meth:`~.layered_cell.SpectralCell.cached`)."""
    return cell.cached(("full compliance",), lambda: _layers_compliance(cell)).copy()


def _layers_compliance(cell) -> np.ndarray:
    import scipy.fft as sfft
    d = cell.dim
    n = cell.grid
    k1 = 2 * np.pi * sfft.rfftfreq(n, d=cell.period / n)
    if d == 2:
        kv = k1[:, None]
        nyq = np.arange(k1.size) == (n // 2 if n % 2 == 0 else -1)
    else:
        k0 = 2 * np.pi * sfft.fftfreq(n, d=cell.period / n)
        kv = np.stack(np.broadcast_arrays(k1[None, :], k0[:, None]), axis=-1)
        half = n // 2 if n % 2 == 0 else -1          # an odd grid has no Nyquist mode
        nyq = (np.arange(n)[:, None] == half) | (np.arange(k1.size)[None, :] == half)
    K = layers_matrix(kv, [(cell.rough.E, cell.rough.nu, cell.rough.h, False),
                           (cell.counter.E, cell.counter.nu, cell.counter.h, True)])
    K[..., :d - 1, d - 1] = np.where(nyq[..., None], 0.0, K[..., :d - 1, d - 1])
    K[..., d - 1, :d - 1] = np.where(nyq[..., None], 0.0, K[..., d - 1, :d - 1])
    return K

def _real_form(K: np.ndarray) -> np.ndarray:
    """``R = S K S^{-1}``, ``S = diag(1, .., 1, i)``: the layers' compliance (real in-plane block and diagonal,
    imaginary normal/tangential coupling, :func:`~.layer_compliance.layers_matrix`) as a real symmetric matrix with
    the same eigenvalues."""
    d = K.shape[-1]
    R = K.real.copy()
    R[..., :d - 1, d - 1] = K[..., :d - 1, d - 1].imag
    R[..., d - 1, :d - 1] = -K[..., d - 1, :d - 1].imag
    return R


def _largest_eigenvalue(K: np.ndarray) -> float:
    """The largest eigenvalue of the Hermitian ``K`` over all wave vectors: the eigenvalues are computed only
    where Gershgorin's bound (a row's diagonal plus the moduli of the rest) reaches the largest diagonal entry,
    a lower bound of the answer."""
    d = K.shape[-1]
    R = np.abs(_real_form(K)).reshape(-1, d, d)
    diagonal = np.real(np.diagonal(K, axis1=-2, axis2=-1)).reshape(-1, d)
    bound = np.max(diagonal + R.sum(axis=-1) - np.abs(diagonal), axis=-1)
    return float(np.max(np.linalg.eigvalsh(K.reshape(-1, d, d)[bound >= diagonal.max()])))


class TractionPreconditioner:
    """``r -> K_full^{-1} r`` by FFTs: the inverse of the full compliance (uniform modes kept, plus the penalty's
    ``winkler`` on the normal component) per wave vector, the preconditioner of
    :mod:`ngcontact.solvers.active_set_newton`, and its split for a free problem with a pointwise curvature
    (:meth:`for_curvature`).
    """

    def __init__(self, cell, winkler: float):
        d = cell.dim
        K = _full_compliance(cell)
        diagonal = np.real(np.diagonal(K, axis1=-2, axis2=-1))
        # the real-space diagonal of K: the mean of its symbol over the whole spectrum (the half spectrum of
        # the real FFT counts its inner columns twice)
        weight = np.full(K.shape[d - 2], 2.0)
        weight[0] = 1.0
        if cell.grid % 2 == 0:
            weight[-1] = 1.0
        weight = weight.reshape((1,) * (d - 2) + (-1, 1))
        #: per component, the compliance of a grid point under its own traction (``K``'s diagonal in real space)
        self.self_compliance = (weight * diagonal).reshape(-1, d).sum(axis=0) / cell.points
        self.included = np.zeros(d)
        self.included[d - 1] = winkler
        K[..., d - 1, d - 1] += winkler
        self.Kinv = np.moveaxis(np.linalg.inv(K), (-2, -1), (0, 1)).copy()
        self.shape = cell.shape

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return symbol_product(self.Kinv, self.shape, r)

    def for_curvature(self, D: np.ndarray) -> SplitPreconditioner:
        """The preconditioner of ``K + D`` (``D`` a pointwise curvature, :mod:`.traction_constraints`).

        Where ``D`` beyond the diagonal already inverted (the penalty's ``winkler``) exceeds a point's
        self-compliance (a slipping point's rim curvature ``L (|z| / G - 1)``, a Huber term ``w / G`` where
        ``G`` is small), the operator is dominated by its diagonal there, and ``K^{-1}``, of order 1, would
        amplify such an entry where it should divide it: those entries are preconditioned by the inverse of
        the diagonal ``k_self + D``, the others by ``R K^{-1} R^T`` as before.  The two blocks make a
        symmetric positive definite preconditioner (block Jacobi across the split).
        """
        d = D.shape[0]
        k_self = self.self_compliance.reshape((d,) + (1,) * (d - 1))
        heavy = D - self.included.reshape(k_self.shape) > k_self
        if not heavy.any():
            return SplitPreconditioner(self)
        return SplitPreconditioner(self, heavy, 1.0 / (k_self + D))


def solve_frictional(cell, load: CellLoad, start) -> dict:
    """Tresca or Coulomb friction in tractions (module docstring)."""
    d, f = cell.dim, cell.friction
    assert f is not None
    poisson = cell.poisson_shift(load.macro_strain)
    prescribed_mean = [load.traction[c] is not None for c in range(d)]
    apply, L, K0 = cell.traction_operator(tuple(not m for m in prescribed_mean))
    b = np.zeros((d,) + cell.shape)
    b[d - 1] = cell.g0
    jumps = [0.0 if j is None else float(j) for j in load.jump]
    tractions = [0.0 if t is None else float(t) for t in load.traction]
    for c in range(d):
        if load.jump[c] is not None:
            b[c] -= jumps[c] - (poisson if c == d - 1 else 0.0)
    mean_p = -tractions[d - 1] if prescribed_mean[d - 1] else None
    mean_q = np.array([-tractions[c] for c in range(d - 1)]) if all(prescribed_mean[:d - 1]) else None
    if any(prescribed_mean[:d - 1]) and mean_q is None:
        raise ValueError("the spectral cell takes either the shear or the tangential jump in every direction")
    exact = cell.enforcement == "exact"
    frictionless = cell.solve_normal(cell_load_normal(load), start)
    t0 = np.zeros((d,) + cell.shape)
    t0[d - 1] = frictionless["p"]
    if mean_q is not None:
        t0[:d - 1] = mean_q.reshape((d - 1,) + (1,) * (d - 1))
    scale = cell.gscale

    def grad(t):
        g = apply(t)        # a new array
        g += b
        return g

    h = TractionConstraints(cell.shape, lambda p: f.threshold(p), L, None if exact else f.w,
                            None if exact else cell.k_n, mean_p, mean_q,
                            slope=f.affine_parts()[1] if f.couples_to_pressure else 0.0)
    if cell.friction_method == "proximal":
        res = fista(grad, h.prox, t0, L, tol=cell.tol, scale=scale, max_iter=cell.max_iter)
    else:
        solver = coulomb_active_set if f.couples_to_pressure else active_set_newton
        res = solver(grad, apply, b, h, cell.traction_preconditioner(0.0 if exact else 1.0 / cell.k_n), t0, L,
                     tol=cell.tol, scale=scale, max_iter=cell.max_iter)
    t = res.t
    sp, sq = res.shifts
    Kt = apply(t)
    # the effective linear term of the reduced problem is b + L * shift on the mean-constrained components
    eff = b.copy()
    if mean_p is not None:
        eff[d - 1] += L * sp
    if mean_q is not None:
        eff[:d - 1] += L * np.asarray(sq).reshape((d - 1,) + (1,) * (d - 1))
    # -J = K_full t - Delta = K t + (b_eff - g0 e_n): on a component of prescribed mean the dropped uniform
    # mode K0 mean(t) and Delta = K0 mean(t) - L shift cancel
    minus_J = Kt + eff - np.where(np.arange(d) == d - 1, 1.0, 0.0).reshape((d,) + (1,) * (d - 1)) * cell.g0
    Delta = np.zeros(d)
    for c in range(d):
        if prescribed_mean[c]:
            Delta[c] = K0[c] * float(t[c].mean()) - L * (sp if c == d - 1 else np.asarray(sq)[c])
        else:
            Delta[c] = jumps[c] - (poisson if c == d - 1 else 0.0)
    Delta[d - 1] += poisson
    J = -minus_J
    G_last = f.threshold(t[d - 1]) * np.ones(cell.shape)
    qn = np.sqrt(np.sum(t[:d - 1] ** 2, axis=0))
    slipping = (qn >= G_last * (1 - 1e-9)) & (G_last > 0)
    return {"p": t[d - 1], "q": t[:d - 1], "closure": J[d - 1], "slip": J[:d - 1], "slipping": slipping,
            "threshold": G_last,
            "far_face_jump": Delta.tolist(), "iterations": res.iterations, "residuals": res.residuals}
