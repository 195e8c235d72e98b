"""The small-slope cell problem solved on the grid of its gap, with FFTs.

In the small-slope model (a flat interface ``S_C`` whose initial gap ``g0`` is
the height below the highest summit) both bodies of the cell of paper eqs.
49-51 are flat periodic layers, each linear and invariant under in-plane
translations.  A normal traction ``p`` on the interface (compression
positive) then moves the two faces towards each other by ``C * p``, the
convolution with the sum of the two layers' normal compliances
(:mod:`ngcontact.cell.layer_compliance`), diagonal in Fourier space.
Frictionless contact is the problem (eq. 57 in the small-slope form, with
``Delta`` the far-face approach and ``J_n`` the normal jump)

    gap  gamma = g0 - J_n = g0 - Delta + C * p (+ p / k_n),
    p >= 0,  gamma >= 0,  p gamma = 0,   mean(p) = pbar (or Delta given),

where the term ``p / k_n`` is the paper's penalty layer (eq. 65,
``contact.enforcement = "penalty"``) and is absent for exact
non-penetration (``"exact"``, the rigid limit ``k_n -> infinity``).  The
uniform mode of ``C`` is the layers' uniaxial-strain compliance
``h_r / M_r + h_c / M_c`` (``M`` the P-wave modulus); an in-plane macro
strain ``E`` (eq. 63) only shifts it, by the Poisson term
``-(h_r lam_r / M_r + h_c lam_c / M_c) tr E``.  Pressure and gap are
collocated at the grid points ``x_j = j P / N`` (the trigonometric
interpolant of the pressure loads the layers), and the contact problem is
solved by constrained conjugate gradients
(:mod:`ngcontact.solvers.constrained_cg`).

Friction (Tresca, or Coulomb with the threshold ``G = mu p``, paper eqs.
16-17) needs the tangential traction ``q`` too: the
jump is ``J = -K t - U`` with ``t = (q, p)`` and ``K`` the layers' full
3 x 3 (2D: 2 x 2) compliance, whose normal/tangential coupling vanishes for
identical layers only.  The cell is then the convex problem in tractions of
:mod:`ngcontact.solvers.projected_gradient` (``|q| <= G``, ``p >= 0``),
solved by accelerated proximal gradients.  Coulomb friction has no such
potential; its threshold is taken from the pressure of the same proximal
step, so that a fixed point of the iteration meets Coulomb's conditions
with its own pressure (no outer fixed point of Tresca problems, which cost
six passes of 300 to 400 steps each on a 256^2 cell).  With ``"penalty"`` the friction
is the FE cell's Huber-regularized one (width ``w``), with ``"exact"`` it is
exact.  As in the FE cell, the Tresca threshold holds on the whole surface.

Results use the names of the FE cell (:mod:`ngcontact.cell.measures`):
``contact_fraction`` (the share of grid points in contact; in 2D the
contact edges located between grid points, below), ``mean_pressure``,
``mean_closure`` (the mean of ``J_n``), ``far_face_jump``,
``effective_stiffness`` (``d pbar / d Delta_interface`` at the current
contact set, the FE cell's ``(S^-1 - S_0^-1)^-1``; its normal component
only, also with friction) and the coefficients of
eq. 34 on the real contact set.

Contact edges in 2D: beyond an edge at ``a`` the gap of a smooth contact
grows like ``(x - a)^(3/2)``, so ``gap^(2/3)`` is linear in ``x``; each edge
is placed where the line through ``gap^(2/3)`` at the first two open points
meets zero, within the grid step before the first open point (tried against
Westergaard: the other side's ``p^2``, linear for a ``sqrt`` edge, is biased
by the collocation error of the pressure at the last contact points, 2e-5
of the fraction at 65,536 points where the gap gives 1e-5).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.fft as sfft

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.coefficients import Coefficients
from ngcontact.cell.layer_compliance import layer_matrix, normal_compliance
from ngcontact.geometry.random_surface import wave_vectors
from ngcontact.laws.penalty import Friction
from ngcontact.solvers.constrained_cg import constrained_cg, masked_cg
from ngcontact.solvers.projected_gradient import fista, prox_friction, prox_pressure

log = logging.getLogger(__name__)

ENFORCEMENTS = ("penalty", "exact")


def cell_load_normal(load: CellLoad) -> CellLoad:
    """The normal part of a load (the tangential components free of traction)."""
    d = len(load.traction)
    return CellLoad(traction=(0.0,) * (d - 1) + (load.traction[-1],), jump=(None,) * (d - 1) + (load.jump[-1],),
                    macro_strain=load.macro_strain)


@dataclass(frozen=True)
class Layer:
    """An isotropic layer of thickness ``h`` bonded to a rigid face."""

    E: float
    nu: float
    h: float

    @property
    def lam(self) -> float:
        return self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))

    @property
    def M(self) -> float:
        """P-wave (uniaxial-strain) modulus ``lam + 2 mu``."""
        return self.E * (1 - self.nu) / ((1 + self.nu) * (1 - 2 * self.nu))


@dataclass
class SpectralSolution:
    """One load of the spectral cell: results (plain numbers) and the grid fields."""

    load: CellLoad
    results: dict[str, Any]
    fields: dict[str, np.ndarray]
    iterations: int
    residuals: list[float] = field(default_factory=list)


def wave_numbers(dim: int, grid: int, period: float) -> np.ndarray:
    """``|k|`` on the half spectrum of ``scipy.fft.rfftn`` for a grid of ``grid`` points per period."""
    return np.broadcast_to(wave_vectors(dim, grid, period)[1], (grid // 2 + 1,) if dim == 2
                           else (grid, grid // 2 + 1)).copy()


class SpectralCell:
    """A small-slope cell on a uniform grid (module docstring).

    Parameters
    ----------
    dim
        2 (profile along ``x``) or 3 (height map, ``gap[i, j]`` at
        ``x = j P/N, y = i P/N``).
    period, grid
        Cell period and points per period and direction.
    rough, counter
        The two :class:`Layer` objects.
    gap
        Initial gap ``g0 >= 0`` at the grid points, shape ``(N,)`` or ``(N, N)``.
    k_n
        Penalty stiffness of the interface layer (used by ``"penalty"``; by
        ``"exact"`` only in the eq. 34 coefficients).
    enforcement
        ``"penalty"`` or ``"exact"``.
    tol, max_iter
        Stopping rule of the constrained CG: complementarity residual
        relative to the peak-to-valley height of the gap.
    friction
        :class:`~ngcontact.laws.penalty.Friction` (Tresca or Coulomb; its
        Huber width with ``"penalty"``, exact friction with ``"exact"``);
        ``None``: frictionless.
    """

    def __init__(self, *, dim: int, period: float, grid: int, rough: Layer, counter: Layer,
                 gap: np.ndarray, k_n: float, enforcement: str = "exact", tol: float = 1e-12,
                 max_iter: int = 2000, friction: Friction | None = None):
        if dim not in (2, 3):
            raise ValueError(f"dim = {dim!r}: must be 2 or 3")
        if enforcement not in ENFORCEMENTS:
            raise ValueError(f"enforcement = {enforcement!r}: must be one of {ENFORCEMENTS}")
        shape = (grid,) * (dim - 1)
        g0 = np.asarray(gap, dtype=float)
        if g0.shape != shape:
            raise ValueError(f"gap of shape {g0.shape}: a grid of {grid} points per direction needs {shape}")
        if not np.all(np.isfinite(g0)) or g0.min() < 0:
            raise ValueError("the initial gap must be finite and >= 0 at every grid point")
        self.dim, self.period, self.grid, self.shape = dim, float(period), int(grid), shape
        self.rough, self.counter = rough, counter
        self.g0, self.k_n, self.enforcement = g0, float(k_n), enforcement
        self.tol, self.max_iter = tol, max_iter
        self.friction = friction
        self._operators: dict[tuple[bool, ...], Any] = {}
        k = wave_numbers(dim, grid, period)
        self.symbol = (normal_compliance(k, rough.E, rough.nu, rough.h)
                       + normal_compliance(k, counter.E, counter.nu, counter.h))
        #: compliance of the uniform mode: the two layers in uniaxial strain (= symbol at k = 0)
        self.c0 = rough.h / rough.M + counter.h / counter.M
        self.fluctuation = self.symbol.copy()
        self.fluctuation.flat[0] = 0.0
        ptp = float(np.ptp(g0))
        self.gscale = ptp if ptp > 0 else 1.0
        self.area = self.period ** (dim - 1)

    @property
    def points(self) -> int:
        return int(np.prod(self.shape))

    def convolve(self, p: np.ndarray, symbol: np.ndarray) -> np.ndarray:
        """``IFFT(symbol FFT(p))`` on the grid (all cores)."""
        return sfft.irfftn(symbol * sfft.rfftn(p, workers=-1), s=self.shape, workers=-1)

    def _interface_compliance(self, uniform: bool):
        """``p -> C p (+ p / k_n)``, with or without the uniform mode of ``C``."""
        sym = self.symbol if uniform else self.fluctuation
        winkler = 1.0 / self.k_n if self.enforcement == "penalty" else 0.0

        def apply(p):
            out = self.convolve(p, sym)
            return out + winkler * p if winkler else out
        return apply

    def poisson_shift(self, macro_strain) -> float:
        """Far-face approach due to an in-plane macro strain at fixed interface state (module docstring)."""
        if not macro_strain:
            return 0.0
        tr = macro_strain[0] if self.dim == 2 else macro_strain[0] + macro_strain[1]
        return (self.rough.h * self.rough.lam / self.rough.M
                + self.counter.h * self.counter.lam / self.counter.M) * tr

    # ----------------------------------------------------------------- solve
    def solve(self, load: CellLoad, start: np.ndarray | None = None) -> SpectralSolution:
        """Solve one load (pressure or far-face approach prescribed), from ``start`` if given."""
        d = self.dim
        if self.friction is None:
            for i in range(d - 1):
                if load.traction[i] not in (None, 0.0) or load.jump[i] not in (None, 0.0):
                    raise ValueError("a frictionless flat contact surface carries no shear and fixes no "
                                     "tangential jump: the spectral cell takes shear = 0")
        tn = load.traction[d - 1]
        if tn is not None and not -tn > 0:
            raise ValueError(f"pressure = {-tn!r}: the spectral cell needs a compressive mean pressure > 0")
        state = self._normal(load, start) if self.friction is None else self._frictional(load, start)
        p, q = state["p"], state["q"]
        pbar = float(p.mean())
        qbar = [float(c.mean()) for c in q]
        closure = state["closure"]                    # J_n
        elastic_gap = self.g0 - closure
        slip = np.sqrt(np.sum(state["slip"] ** 2, axis=0))
        mean_closure = float(closure.mean())
        fraction = self.contact_fraction(p, elastic_gap)
        results: dict[str, Any] = {
            "contact_fraction": fraction,
            "contact_fraction_grid": float(np.count_nonzero(p > 0)) / self.points,
            "mean_pressure": pbar,
            "mean_traction": [-v for v in qbar] + [-pbar],
            "transmitted_pressure": pbar,
            "equilibrium_error": abs(pbar - (-tn)) / (-tn) if tn is not None else 0.0,
            "mean_jump": [float(c.mean()) for c in state["slip"]] + [mean_closure],
            "mean_closure": mean_closure,
            "far_face_jump": list(state["far_face_jump"]),
            "max_penetration": float(max(0.0, np.max(-elastic_gap))),
            "max_pressure": float(p.max()),
        }
        if self.friction is not None:
            results["max_slip"] = float(slip.max())
            results["slip_fraction"] = float(np.count_nonzero(state["slipping"])) / self.points
        results["effective_stiffness"] = self.effective_stiffness(p > 0)
        results["coefficients"] = self.coefficients(p > 0, state.get("threshold")).as_dict()
        fields = {"pressure": p, "gap": np.maximum(elastic_gap, 0.0), "closure": closure}
        if self.friction is not None:
            fields.update(shear=q, slip=state["slip"])
        log.info("spectral cell: %d iterations, contact fraction %.8f", state["iterations"], fraction)
        return SpectralSolution(load=load, results=results, fields=fields, iterations=state["iterations"],
                                residuals=state["residuals"])

    def _normal(self, load: CellLoad, start) -> dict:
        """Frictionless: the pressure by constrained CG (module docstring)."""
        d = self.dim
        poisson = self.poisson_shift(load.macro_strain)
        tn, jn = load.traction[d - 1], load.jump[d - 1]
        if tn is not None:
            res = constrained_cg(self._interface_compliance(uniform=False), self.g0, pbar=-tn,
                                 tol=self.tol, max_iter=self.max_iter, gscale=self.gscale, p0=start)
        else:
            assert jn is not None
            # gamma = g0 - Delta + C p (+ p/k_n), uniform mode included: b = g0 - Delta_interface
            res = constrained_cg(self._interface_compliance(uniform=True), self.g0 - (jn - poisson), pbar=None,
                                 tol=self.tol, max_iter=self.max_iter, gscale=self.gscale, p0=start)
        p = res.p
        winkler = p / self.k_n if self.enforcement == "penalty" else 0.0
        closure = self.g0 - (res.gap - winkler)
        approach = float(closure.mean()) + self.c0 * float(p.mean()) + poisson
        return {"p": p, "q": np.zeros((d - 1,) + self.shape), "closure": closure,
                "slip": np.zeros((d - 1,) + self.shape), "far_face_jump": [0.0] * (d - 1) + [approach],
                "iterations": res.iterations, "residuals": res.residuals}

    # ------------------------------------------------------------ friction
    def traction_operator(self, uniform: tuple[bool, ...]):
        """The cached :meth:`build_traction_operator` (a sweep's loads share it)."""
        if uniform not in self._operators:
            self._operators[uniform] = self.build_traction_operator(uniform)
        return self._operators[uniform]

    def build_traction_operator(self, uniform: tuple[bool, ...]):
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
        d = self.dim
        n = self.grid
        k1 = 2 * np.pi * sfft.rfftfreq(n, d=self.period / n)
        if d == 2:
            kv = k1[:, None]
            nyq = np.arange(k1.size) == n // 2
        else:
            k0 = 2 * np.pi * sfft.fftfreq(n, d=self.period / n)
            kv = np.stack(np.broadcast_arrays(k1[None, :], k0[:, None]), axis=-1)
            nyq = (np.arange(n)[:, None] == n // 2) | (np.arange(k1.size)[None, :] == n // 2)
        K = (layer_matrix(kv, self.rough.E, self.rough.nu, self.rough.h)
             + layer_matrix(kv, self.counter.E, self.counter.nu, self.counter.h, above=True))
        K[..., :d - 1, d - 1] = np.where(nyq[..., None], 0.0, K[..., :d - 1, d - 1])
        K[..., d - 1, :d - 1] = np.where(nyq[..., None], 0.0, K[..., d - 1, :d - 1])
        K0 = np.real(np.diagonal(K.reshape(-1, d, d)[0])).copy()
        zero = (0,) * (d - 1)
        for c in range(d):
            if not uniform[c]:
                K[zero + (c, c)] = 0.0
        L = float(np.max(np.linalg.eigvalsh(K)))
        Km = np.moveaxis(K, (-2, -1), (0, 1)).copy()       # (d, d, *kshape)
        axes = tuple(range(1, d))

        def apply(t):
            T = sfft.rfftn(t, axes=axes, workers=-1)
            U = np.einsum("ab...,b...->a...", Km, T)
            return sfft.irfftn(U, s=self.shape, axes=axes, workers=-1)
        return apply, L, K0

    def _frictional(self, load: CellLoad, start) -> dict:
        """Tresca (or a Coulomb fixed point of Tresca problems) by FISTA in tractions."""
        d, f = self.dim, self.friction
        assert f is not None
        poisson = self.poisson_shift(load.macro_strain)
        prescribed_mean = [load.traction[c] is not None for c in range(d)]
        apply, L, K0 = self.traction_operator(tuple(not m for m in prescribed_mean))
        b = np.zeros((d,) + self.shape)
        b[d - 1] = self.g0
        jumps = [0.0 if j is None else float(j) for j in load.jump]
        tractions = [0.0 if t is None else float(t) for t in load.traction]
        for c in range(d):
            if load.jump[c] is not None:
                b[c] -= jumps[c] - (poisson if c == d - 1 else 0.0)
        mean_p = -tractions[d - 1] if prescribed_mean[d - 1] else None
        mean_q = np.array([-tractions[c] for c in range(d - 1)]) if all(prescribed_mean[:d - 1]) else None
        if any(prescribed_mean[:d - 1]) and mean_q is None:
            raise ValueError("the spectral cell takes either the shear or the tangential jump in every direction")
        exact = self.enforcement == "exact"
        damp_p = 1.0 if exact else 1.0 + 1.0 / (L * self.k_n)
        frictionless = self._normal(cell_load_normal(load), start)
        t0 = np.zeros((d,) + self.shape)
        t0[d - 1] = frictionless["p"]
        if mean_q is not None:
            t0[:d - 1] = mean_q.reshape((d - 1,) + (1,) * (d - 1))
        scale = self.gscale

        def grad(t):
            return apply(t) + b

        def prox(v, shifts):
            sp, sq = shifts if shifts else (0.0, None)
            p, sp = prox_pressure(v[d - 1], damp_p, mean_p, sp)
            # Tresca: the fixed threshold; Coulomb: mu times the pressure of this very step
            G = (f.G or 0.0) * np.ones(self.shape) if f.law == "tresca" else (f.mu or 0.0) * p
            damp_q = 1.0 if exact else 1.0 + f.w / (L * np.maximum(G, 1e-300))
            q, sq = prox_friction(v[:d - 1], G, damp_q, mean_q, sq)
            return np.concatenate([q, p[None]]), (sp, sq)
        res = fista(grad, prox, t0, L, tol=self.tol, scale=scale, max_iter=self.max_iter)
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
        minus_J = Kt + eff - np.where(np.arange(d) == d - 1, 1.0, 0.0).reshape((d,) + (1,) * (d - 1)) * self.g0
        Delta = np.zeros(d)
        for c in range(d):
            if prescribed_mean[c]:
                Delta[c] = K0[c] * float(t[c].mean()) - L * (sp if c == d - 1 else np.asarray(sq)[c])
            else:
                Delta[c] = jumps[c] - (poisson if c == d - 1 else 0.0)
        Delta[d - 1] += poisson
        J = -minus_J
        G_last = (f.G or 0.0) * np.ones(self.shape) if f.law == "tresca" else (f.mu or 0.0) * t[d - 1]
        qn = np.sqrt(np.sum(t[:d - 1] ** 2, axis=0))
        slipping = (qn >= G_last * (1 - 1e-9)) & (G_last > 0)
        return {"p": t[d - 1], "q": t[:d - 1], "closure": J[d - 1], "slip": J[:d - 1], "slipping": slipping,
                "threshold": G_last,
                "far_face_jump": Delta.tolist(), "iterations": res.iterations, "residuals": res.residuals}

    def sweep(self, loads) -> list[SpectralSolution]:
        """Solve loads in order, each starting from the previous pressure."""
        out: list[SpectralSolution] = []
        for load in loads:
            start = out[-1].fields["pressure"] if out and load.traction[-1] is not None else None
            out.append(self.solve(load, start=start))
        return out

    # -------------------------------------------------------------- measures
    def contact_fraction(self, p: np.ndarray, gap: np.ndarray) -> float:
        """Contact area per period: grid points in 3D; in 2D edges between points (module docstring)."""
        on = p > 0
        if self.dim == 3 or on.all() or not on.any():
            return float(np.count_nonzero(on)) / self.points
        n = self.grid
        length = float(np.count_nonzero(on))
        root = np.maximum(gap, 0.0) ** (2.0 / 3.0)       # linear in the distance from a smooth contact edge
        for step in (1, -1):                            # edges on the right, then on the left of a patch
            last = on & ~np.roll(on, -step)             # in contact, the next point (in this direction) is not
            for i in np.flatnonzero(last):
                first, second = (i + step) % n, (i + 2 * step) % n
                a, b = root[first], root[second]
                # the edge lies where the line through the first two open points' root meets zero
                open_share = a / (b - a) if (b > a and not on[second]) else 0.5
                length += 1.0 - min(max(open_share, 0.0), 1.0) - 0.5
        return length / n

    def effective_stiffness(self, active: np.ndarray) -> dict:
        """``K = d pbar / d Delta_interface`` on the contact set ``active`` (the FE cell's names).

        At a fixed contact set a unit interface approach needs the pressure
        ``p'`` with ``(C p' + p'/k_n) = 1`` on the set and 0 elsewhere
        (uniform mode of ``C`` excluded: it is the bulk's share), so
        ``K = mean(p')``; the far-face stiffness adds the layers in series,
        ``S = (1/K + c0)^-1``, and the reference ``S_0 = 1/c0``.
        """
        idx = np.flatnonzero(active.ravel())
        S0 = 1.0 / self.c0
        if idx.size == 0:
            return {"components": ["n0"], "matrix": [[0.0]], "compliance": None, "total": [[0.0]],
                    "reference": [[S0]]}
        # the fluctuation operator is singular on the full surface (constants): in full contact K is infinite
        if idx.size == self.points and self.enforcement == "exact":
            return {"components": ["n0"], "matrix": None, "compliance": [[0.0]], "total": [[S0]],
                    "reference": [[S0]]}
        x, _ = masked_cg(self._interface_compliance(uniform=False), active, np.ones(self.shape))
        K = float(x.sum()) / self.points
        S = 1.0 / (1.0 / K + self.c0)
        return {"components": ["n0"], "matrix": [[K]], "compliance": [[1.0 / K]], "total": [[S]],
                "reference": [[S0]]}

    def coefficients(self, active: np.ndarray, threshold: np.ndarray | None = None) -> Coefficients:
        """Eqs. 34, 42-43 on the real contact set of a flat interface (``n = n0`` everywhere).

        ``K0 = k_n |S_real| / |T|`` on ``n0`` only, ``g_n = k_n mean(1_real g0)``,
        and the friction threshold ``G_t = mean(1_real G)`` per tangential
        direction (``G`` the Tresca threshold or ``mu p``), ``G_n = 0``.
        """
        frac = float(np.count_nonzero(active)) / self.points
        kn0 = self.k_n * frac
        g_n = self.k_n * float(np.where(active, self.g0, 0.0).sum()) / self.points
        G_t = float(np.where(active, threshold, 0.0).sum()) / self.points if threshold is not None else 0.0
        nt = self.dim - 1
        K0 = np.zeros((self.dim, self.dim))
        K0[0, 0] = kn0

        def tangential(v):
            return v if nt == 1 else (v, v)
        return Coefficients(k_n=kn0, k_t=tangential(0.0), k_nt=tangential(0.0), g_n=g_n, g_t=tangential(0.0),
                            mu=tangential(0.0), G_n=0.0, G_t=tangential(G_t), K0=K0, contact_fraction=frac)
