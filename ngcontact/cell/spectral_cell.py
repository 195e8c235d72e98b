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

Results use the names of the FE cell (:mod:`ngcontact.cell.measures`):
``contact_fraction`` (the share of grid points in contact; in 2D the
contact edges located between grid points, below), ``mean_pressure``,
``mean_closure`` (the mean of ``J_n``), ``far_face_jump``,
``effective_stiffness`` (``d pbar / d Delta_interface`` at the current
contact set, the FE cell's ``(S^-1 - S_0^-1)^-1``) and the coefficients of
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
from ngcontact.cell.layer_compliance import normal_compliance
from ngcontact.solvers.constrained_cg import constrained_cg, masked_cg

log = logging.getLogger(__name__)

ENFORCEMENTS = ("penalty", "exact")


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
    k1 = 2 * np.pi * sfft.rfftfreq(grid, d=period / grid)
    if dim == 2:
        return k1
    k0 = 2 * np.pi * sfft.fftfreq(grid, d=period / grid)
    return np.sqrt(k0[:, None] ** 2 + k1[None, :] ** 2)


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
    """

    def __init__(self, *, dim: int, period: float, grid: int, rough: Layer, counter: Layer,
                 gap: np.ndarray, k_n: float, enforcement: str = "exact", tol: float = 1e-12,
                 max_iter: int = 2000):
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
        for i in range(d - 1):
            if load.traction[i] not in (None, 0.0) or load.jump[i] not in (None, 0.0):
                raise ValueError("a frictionless flat contact surface carries no shear and fixes no tangential "
                                 "jump: the spectral cell takes shear = 0")
        poisson = self.poisson_shift(load.macro_strain)
        tn, jn = load.traction[d - 1], load.jump[d - 1]
        if tn is not None:
            pbar = -tn
            if not pbar > 0:
                raise ValueError(f"pressure = {pbar!r}: the spectral cell needs a compressive mean pressure > 0")
            res = constrained_cg(self._interface_compliance(uniform=False), self.g0, pbar=pbar,
                                 tol=self.tol, max_iter=self.max_iter, gscale=self.gscale, p0=start)
        else:
            assert jn is not None
            # gamma = g0 - Delta + C p (+ p/k_n), uniform mode included: b = g0 - Delta_interface
            res = constrained_cg(self._interface_compliance(uniform=True), self.g0 - (jn - poisson), pbar=None,
                                 tol=self.tol, max_iter=self.max_iter, gscale=self.gscale, p0=start)
        p = res.p
        pbar = float(p.mean())
        winkler = p / self.k_n if self.enforcement == "penalty" else 0.0
        elastic_gap = res.gap - winkler               # g0 - J_n
        closure = self.g0 - elastic_gap               # J_n
        mean_closure = float(closure.mean())
        approach = mean_closure + self.c0 * pbar + poisson
        fraction = self.contact_fraction(p, elastic_gap)
        results: dict[str, Any] = {
            "contact_fraction": fraction,
            "contact_fraction_grid": float(np.count_nonzero(p > 0)) / self.points,
            "mean_pressure": pbar,
            "mean_traction": [0.0] * (d - 1) + [-pbar],
            "transmitted_pressure": pbar,
            "equilibrium_error": abs(pbar - (-tn)) / (-tn) if tn is not None else 0.0,
            "mean_jump": [0.0] * (d - 1) + [mean_closure],
            "mean_closure": mean_closure,
            "far_face_jump": [0.0] * (d - 1) + [approach],
            "max_penetration": float(max(0.0, np.max(-elastic_gap))),
            "max_pressure": float(p.max()),
        }
        results["effective_stiffness"] = self.effective_stiffness(p > 0)
        results["coefficients"] = self.coefficients(p > 0).as_dict()
        fields = {"pressure": p, "gap": np.maximum(elastic_gap, 0.0), "closure": closure}
        log.info("spectral cell: %d constrained CG steps, contact fraction %.8f", res.iterations, fraction)
        return SpectralSolution(load=load, results=results, fields=fields, iterations=res.iterations,
                                residuals=res.residuals)

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

    def coefficients(self, active: np.ndarray) -> Coefficients:
        """Eq. 34 on the real contact set of a flat interface: ``K0 = k_n |S_real| / |T|`` on ``n0``."""
        frac = float(np.count_nonzero(active)) / self.points
        kn0 = self.k_n * frac
        g_n = self.k_n * float(np.where(active, self.g0, 0.0).sum()) / self.points
        nt = self.dim - 1
        K0 = np.zeros((self.dim, self.dim))
        K0[0, 0] = kn0

        def tangential(v):
            return v if nt == 1 else (v, v)
        return Coefficients(k_n=kn0, k_t=tangential(0.0), k_nt=tangential(0.0), g_n=g_n, g_t=tangential(0.0),
                            mu=tangential(0.0), G_n=0.0, G_t=tangential(0.0), K0=K0, contact_fraction=frac)
