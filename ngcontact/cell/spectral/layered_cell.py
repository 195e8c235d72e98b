"""The small-slope cell problem solved on the grid of its gap, with FFTs.

In the small-slope model (a flat interface ``S_C`` whose initial gap ``g0`` is
the height below the highest summit) both bodies of the cell of paper eqs.
49-51 are flat periodic layers, each linear and invariant under in-plane
translations.  A normal traction ``p`` on the interface (compression
positive) then moves the two faces towards each other by ``C * p``, the
convolution with the sum of the two layers' normal compliances
(:mod:`ngcontact.cell.spectral.layer_compliance`), diagonal in Fourier space.
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

Friction: :mod:`ngcontact.cell.spectral.frictional_contact`; results of a load:
:mod:`ngcontact.cell.spectral.grid_measures`.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ngcontact.cell.spectral import grid_measures as measures
from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.spectral.convolution import Convolution
from ngcontact.cell.spectral.layer_compliance import normal_compliance
from ngcontact.cell.spectral.fft_threads import fft_workers
from ngcontact.cell.spectral.frictional_contact import TractionPreconditioner, solve_frictional, traction_operator
from ngcontact.geometry.random_surface import wave_vectors
from ngcontact.laws.friction import FrictionLaw
from ngcontact.solvers.constrained_cg import ConstrainedResult, constrained_cg

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
        :class:`~ngcontact.laws.friction.FrictionLaw` (Tresca or Coulomb; its
        Huber width with ``"penalty"``, exact friction with ``"exact"``);
        ``None``: frictionless.

    Solvers (class attributes; the older ones kept for comparison): ``preconditioned``: the frictionless
    constrained CG preconditioned by the inverse compliance on the contact set
    (:mod:`ngcontact.solvers.constrained_cg`), ``False`` without; ``friction_method``: ``"active_set"``
    (:mod:`ngcontact.solvers.active_set_newton`) or ``"proximal"`` (accelerated proximal gradients,
    :mod:`ngcontact.solvers.projected_gradient`).
    """

    preconditioned: bool = True
    friction_method: str = "active_set"

    def __init__(self, *, dim: int, period: float, grid: int, rough: Layer, counter: Layer,
                 gap: np.ndarray, k_n: float, enforcement: str = "exact", tol: float = 1e-12,
                 max_iter: int = 2000, friction: FrictionLaw | None = None):
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
        self._operators: dict[tuple, Any] = {}
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
        self._last: SpectralSolution | None = None

    @property
    def points(self) -> int:
        return int(np.prod(self.shape))

    def convolve(self, p: np.ndarray, symbol: np.ndarray) -> np.ndarray:
        """``IFFT(symbol FFT(p))`` on the grid (real FFTs on the run's threads, :mod:`.fft_threads`), a new
        array."""
        import scipy.fft as sfft  # on use: importing scipy.fft would slow the start of every process (and batch worker)
        workers = fft_workers(p.size)
        spectrum = sfft.rfftn(p, workers=workers)
        spectrum *= symbol
        return sfft.irfftn(spectrum, s=self.shape, workers=workers, overwrite_x=True)

    def interface_compliance(self, uniform: bool) -> Convolution:
        """``p -> C p (+ p / k_n)``, with or without the uniform mode of ``C``: a
        :class:`~ngcontact.cell.spectral.convolution.Convolution`, which the constrained CG also asks for its
        step lengths by Parseval's identity."""
        winkler = 1.0 / self.k_n if self.enforcement == "penalty" else 0.0
        return Convolution(self.symbol if uniform else self.fluctuation, self.shape, winkler)

    def poisson_shift(self, macro_strain) -> float:
        """Far-face approach due to an in-plane macro strain at fixed interface state (module docstring)."""
        if not macro_strain:
            return 0.0
        tr = macro_strain[0] if self.dim == 2 else macro_strain[0] + macro_strain[1]
        return (self.rough.h * self.rough.lam / self.rough.M
                + self.counter.h * self.counter.lam / self.counter.M) * tr

    # ----------------------------------------------------------------- solve
    def solve(self, load: CellLoad, start: np.ndarray | None = None) -> SpectralSolution:
        """Solve one load (pressure or far-face approach prescribed), from ``start`` if given.

        The last solution from no start is kept and returned again for the same load: a spectral twin is
        asked for one load by the seed and every mesh of a graded solve (:mod:`ngcontact.cell.fe.edge_grading`).
        """
        if start is None and self._last is not None and self._last.load == load:
            return self._last
        sol = self._solve(load, start)
        if start is None:
            self._last = sol
        return sol

    def _solve(self, load: CellLoad, start: np.ndarray | None) -> SpectralSolution:
        d = self.dim
        if self.friction is None:
            for i in range(d - 1):
                if load.traction[i] not in (None, 0.0) or load.jump[i] not in (None, 0.0):
                    raise ValueError("a frictionless flat contact surface carries no shear and fixes no "
                                     "tangential jump: the spectral cell takes shear = 0")
        tn = load.traction[d - 1]
        if tn is not None and not -tn > 0:
            raise ValueError(f"pressure = {-tn!r}: the spectral cell needs a compressive mean pressure > 0")
        state = self.solve_normal(load, start) if self.friction is None else solve_frictional(self, load, start)
        p, q = state["p"], state["q"]
        pbar = float(p.mean())
        qbar = [float(c.mean()) for c in q]
        closure = state["closure"]                    # J_n
        elastic_gap = self.g0 - closure
        slip = np.sqrt(np.sum(state["slip"] ** 2, axis=0))
        mean_closure = float(closure.mean())
        weights = measures.contact_weights(self, p, elastic_gap)
        fraction = float(weights.sum()) / self.points
        results: dict[str, Any] = {
            "contact_fraction": fraction,
            "contact_fraction_grid": float(np.count_nonzero(p > 0)) / self.points,
            "mean_pressure": pbar,
            "mean_traction": [-v for v in qbar] + [-pbar],
            "transmitted_pressure": pbar,
            "equilibrium_error": abs(pbar - (-tn)) / (-tn) if tn is not None else 0.0,
            # the grid's pressure is the field itself: its mean is the force the report integrates
            "pressure_balance": abs(pbar - (-tn)) / (-tn) if tn is not None else 0.0,
            "mean_jump": [float(c.mean()) for c in state["slip"]] + [mean_closure],
            "mean_closure": mean_closure,
            "far_face_jump": list(state["far_face_jump"]),
            "max_penetration": float(max(0.0, np.max(-elastic_gap))),
            "max_pressure": float(p.max()),
        }
        if self.friction is not None:
            results["max_slip"] = float(slip.max())
            results["slip_fraction"] = float(np.count_nonzero(state["slipping"])) / self.points
        results["effective_stiffness"] = measures.effective_stiffness(self, p > 0, elastic_gap)
        results["coefficients"] = measures.coefficients(self, p > 0, state.get("threshold"), weights).as_dict()
        fields = {"pressure": p, "gap": np.maximum(elastic_gap, 0.0), "closure": closure}
        if self.friction is not None:
            fields.update(shear=q, slip=state["slip"])
        log.info("spectral cell: %d iterations, contact fraction %.8f", state["iterations"], fraction)
        return SpectralSolution(load=load, results=results, fields=fields, iterations=state["iterations"],
                                residuals=state["residuals"])

    def solve_normal(self, load: CellLoad, start) -> dict:
        """Frictionless: the pressure by constrained CG (module docstring)."""
        d = self.dim
        poisson = self.poisson_shift(load.macro_strain)
        tn, jn = load.traction[d - 1], load.jump[d - 1]
        uniform = tn is None
        # gamma = g0 - Delta + C p (+ p/k_n); a prescribed jump: uniform mode included, b = g0 - Delta_interface
        if tn is not None:
            b, pbar = self.g0, -tn
        else:
            assert jn is not None
            b, pbar = self.g0 - (jn - poisson), None
        res = self.full_contact(b, pbar)
        if res is None:
            res = constrained_cg(self.interface_compliance(uniform=uniform), b, pbar=pbar, tol=self.tol,
                                 max_iter=self.max_iter, gscale=self.gscale, p0=start, norm=self.norm(uniform),
                                 precondition=self.inverse_compliance() if self.preconditioned else None)
        p = res.p
        winkler = p / self.k_n if self.enforcement == "penalty" else 0.0
        closure = self.g0 - (res.gap - winkler)
        approach = float(closure.mean()) + self.c0 * float(p.mean()) + poisson
        return {"p": p, "q": np.zeros((d - 1,) + self.shape), "closure": closure,
                "slip": np.zeros((d - 1,) + self.shape), "far_face_jump": [0.0] * (d - 1) + [approach],
                "iterations": res.iterations, "residuals": res.residuals}

    def inverse_compliance(self) -> Convolution:
        """``r -> (C + 1/k_n)^{-1} r`` with the uniform mode kept: the preconditioner of the constrained CG."""
        return Convolution(1.0 / (self.symbol + (1.0 / self.k_n if self.enforcement == "penalty" else 0.0)),
                           self.shape)

    def norm(self, uniform: bool) -> float:
        """Largest eigenvalue of :meth:`interface_compliance`: the largest value of its symbol."""
        sym = self.symbol if uniform else self.fluctuation
        return float(np.max(sym)) + (1.0 / self.k_n if self.enforcement == "penalty" else 0.0)

    def full_contact(self, b: np.ndarray, pbar: float | None) -> ConstrainedResult | None:
        """The solution with every point closed, where it is admissible (``p >= 0``); else ``None``.

        Closed everywhere, the gap ``A p + b - c`` vanishes (``A`` the interface compliance, ``c`` the
        multiplier of a prescribed mean, 0 without it): in Fourier space ``p_k = -b_k / A_k`` for every mode
        ``k != 0``, and ``p_0 = pbar`` under a prescribed mean pressure, ``-b_0 / A_0`` under a prescribed
        approach (``A_0`` the uniform mode, ``c0`` plus the penalty's ``1/k_n``).  It is the solution of the
        contact problem exactly when it is non-negative: the conditions of the module docstring hold with
        ``gamma = 0``.  Answered directly, with no iteration: at a pressure far above the gap's scale
        (``p`` of 1e6 on a gap of 1e-2 and ``E = 1``) the iteration would have to resolve a gap of round-off
        size.  A prescribed approach below every summit needs no such answer: the iteration's start is
        then already zero pressure (:func:`~ngcontact.solvers.constrained_cg.constrained_cg`).
        """
        import scipy.fft as sfft
        winkler = 1.0 / self.k_n if self.enforcement == "penalty" else 0.0
        sym = (self.fluctuation if pbar is not None else self.symbol) + winkler
        bh = sfft.rfftn(b, workers=fft_workers(b.size))
        ph = np.zeros_like(bh)
        nonzero = sym > 0
        ph[nonzero] = -bh[nonzero] / sym[nonzero]
        if pbar is not None:
            ph.flat[0] = pbar * self.points
        p = sfft.irfftn(ph, s=self.shape, workers=fft_workers(b.size))
        if pbar is not None:
            p += pbar - float(p.mean())
        if not (np.all(np.isfinite(p)) and p.min() >= 0.0):
            return None
        g = self.interface_compliance(uniform=pbar is None)(p) + b
        shift = float(g.mean()) if pbar is not None else 0.0
        return ConstrainedResult(p=p, gap=g - shift, shift=shift, iterations=0, residuals=[])

    # ------------------------------------------------------------ friction
    def cached(self, key: tuple, build):
        """``build()``, built once per cell and ``key`` (the friction operators of a sweep)."""
        if key not in self._operators:
            self._operators[key] = build()
        return self._operators[key]

    def traction_operator(self, uniform: tuple[bool, ...]):
        """:func:`~.frictional_contact.traction_operator`, built once per kind of load of a sweep."""
        return self.cached(uniform, lambda: traction_operator(self, uniform))

    def traction_preconditioner(self, winkler: float) -> TractionPreconditioner:
        """:class:`~ngcontact.cell.spectral.frictional_contact.TractionPreconditioner`, built once per cell."""
        return self.cached(("preconditioner", winkler), lambda: TractionPreconditioner(self, winkler))

    def sweep(self, loads, starts: list[np.ndarray | None] | None = None) -> list[SpectralSolution]:
        """Solve loads in order, each from its pressure in ``starts`` where given (e.g. a coarser grid's,
        interpolated), else from the previous load's pressure."""
        out: list[SpectralSolution] = []
        for i, load in enumerate(loads):
            start = starts[i] if starts is not None else None
            if start is None and out and load.traction[-1] is not None:
                start = out[-1].fields["pressure"]
            out.append(self.solve(load, start=start))
        return out
