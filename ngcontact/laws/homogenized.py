"""Homogenized interface laws on the macro interface ``S_0``: one class per law, its formulas with it.

A law (paper eqs. 31-34, 38-44, 69-71) is an energy density ``W(a)`` of the
macro jump ``J = u_rough - u_counter`` written in the interface's local
frame, ``a = (a_n, a_t)`` with ``a_n = J . n0`` and ``a_t = J . t0`` in 2D
and axisymmetry, ``a = (J . n0, J . t1, J . t2)`` in 3D
(:mod:`ngcontact.laws.local_frame`; ``n0`` points from ``rough`` into
``counter``, so ``a_n > 0`` closes the interface).  The macro normal gap
``g0`` (length, ``g0 < 0`` is an initial interference, i.e. a press fit)
shifts the law along ``n0``.  The traction ``tau = dW/da`` is what the rough
body transmits to the counter body; its normal component is the contact
pressure ``p = tau_n`` (compression positive), its tangential part the shear.

Laws (frozen dataclasses), each a class of the protocol of
:mod:`ngcontact.laws.law_protocol` carrying its own energy ``W(a)``,
traction ``tau = dW/da`` and export rows (the normal laws: subclasses of
:class:`NormalLaw`; the friction laws: of :class:`TangentialLaw`);
:mod:`ngcontact.laws.interface_energy` adds them up:

:class:`LinearLaw`
    Anisotropic Winkler law of paper eqs. 34 and 69-71 with the matrix
    ``K0 = [[k_n0, k_nt0], [k_nt0, k_t0]]`` in ``(n0, t0)`` (3D:
    ``[[k_n0, 0, 0], [0, k_t0, 0], [0, 0, k_t0]]`` plus ``k_nt0`` coupling
    ``n0`` and ``t1``) and the gap terms ``g0_vec = (g_n0, g_t0)`` of eq. 34::

        W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a
        tau  = K0 (a - g0 e_n) - g0_vec

    Quadratic and bilateral: it transmits tension too.
:class:`BundleLaw`
    The unilateral law of paper eqs. 31-33 before linearization, a bundle of
    micro directions ``n_q`` (local frame) with weights ``w_q`` [stress /
    length, ``w_q = k_n |ds_q| / |T|``] and micro gaps ``g_q``::

        W(a) = sum_q w_q / 2 [n_q . a - g_q - beta1_q g0]_+^2,   beta1_q = n_q . e_n

    (a uniform macro offset ``g0`` along ``n0`` is a micro gap
    ``beta1_q g0`` along ``n_q``).  With every direction closed its Hessian
    is ``K0 = sum_q w_q n_q n_q^T`` (eq. 34) and it coincides with the
    :class:`LinearLaw` of :func:`linearized`; each direction opens on its own.
:class:`TabulatedLaw`
    Nonlinear normal law ``p(c)`` of the closure ``c = a_n - g0`` from a
    monotone table ``(c_i, p_i)``, ``p_0 = 0``, interpolated linearly, zero
    below ``c_0``, extrapolated with the last slope; written as a sum of
    ramps ``p(c) = sum_i s_i [c - c_i]_+`` (``s_i`` the slope increments), so
    its energy, the integral of the table, is ``sum_i s_i/2 [c - c_i]_+^2``.
    A linear tangential stiffness ``k_t`` may be added.  With
    ``interpolation = "monotone_cubic"`` the nodes are joined instead by the
    shape-preserving C1 cubic of :mod:`ngcontact.laws.monotone_cubic`
    (Fritsch and Carlson): nondecreasing like the table, with a continuous
    tangent at the nodes, zero below ``c_0``, continued with its last node
    slope beyond ``c_last``; the energy is again the integral.  The
    two-scale loop (paper Sec. 3.5, :mod:`ngcontact.coupling.two_scale`)
    hands the cell's own response over as such a cubic table: closure
    ``c(p)`` against pressure.
:class:`Friction`
    Homogenized friction on top of any of them (paper eqs. 38-44): threshold
    ``G = mu0 [p]_+ + G0`` and energy ``G huber(|a_t|, w)`` with
    ``huber(s, w) = s^2/(2w)`` for ``s <= w`` and ``s - w/2`` beyond, so a
    sticking interface slips at most ``w``.  Coulomb's ``G = mu0 p`` is not
    the derivative of an energy; :mod:`ngcontact.macro.macro_problem` treats it by a fixed
    point on the pressure (``G`` frozen at the previous solution's ``p``), see
    there.  The friction energy takes ``G`` as given.
:class:`CellShear`
    In place of :class:`Friction`: the cell's own tangential response, rows
    of shear against tangential jump tabulated at a set of pressures
    (:mod:`ngcontact.coupling.shear_table`), interpolated linearly in both;
    like Coulomb's threshold it depends on the current pressure, and its
    energy is that of the frozen pressure.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
import numpy as np
from ngcontact.errors import ModelError
from ngcontact.laws import monotone_cubic
from ngcontact.laws.huber import huber_of_square, huber_slope, if_positive, is_numeric
from ngcontact.laws.law_evaluation import cubic_splines, dot, ramp, row_splines, table_splines, tangential_norm2
from ngcontact.laws.law_protocol import ExportRows, NormalLaw, TangentialLaw

__all__ = ["BundleLaw", "CellShear", "ExportRows", "Friction", "InterfaceLaw", "LinearLaw", "NormalLaw",
           "TabulatedLaw", "Tangential", "TangentialLaw", "linearized", "normal_law"]

#: Directions whose normal component is below this never close under a normal closure.
CLOSING = 1e-12


# ------------------------------------------------------------------ laws
@dataclass(frozen=True, kw_only=True)
class LinearLaw(NormalLaw):
    """Linear anisotropic Winkler law (paper eqs. 34, 69-71)::

        W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a
        tau  = K0 (a - g0 e_n) - g0_vec

    Attributes
    ----------
    kn, kt, knt
        ``k_n0``, ``k_t0``, ``k_nt0`` [stress / length].
    gap_force
        ``(g_n0, g_t0)`` of eq. 34 [stress]: traction offset of the micro gaps.
    """

    kn: float
    kt: float = 0.0
    knt: float = 0.0
    gap_force: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        if not self.kn > 0 or self.kt < 0 or self.kn * self.kt < self.knt ** 2:
            raise ModelError(f"K0 = [[{self.kn}, {self.knt}], [{self.knt}, {self.kt}]]: "
                             "must be positive semidefinite with k_n0 > 0")

    def matrix(self, dim: int) -> np.ndarray:
        """``K0`` in the local frame (``dim`` = 2 or 3)."""
        K = np.diag([self.kn] + [self.kt] * (dim - 1))
        K[0, 1] = K[1, 0] = self.knt
        return K

    @property
    def stiffness(self) -> float:
        return self.kn

    def energy(self, a, g0=0.0, closed: bool = False):
        """``W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a`` (eq. 34); quadratic, so ``closed`` is ``W``."""
        dim = len(a)
        K = self.matrix(dim)
        e = [a[0] - g0] + list(a[1:])
        W = 0.5 * sum(K[i, j] * e[i] * e[j] for i in range(dim) for j in range(dim) if K[i, j] != 0)
        return W - self.gap_force[0] * a[0] - self.gap_force[1] * a[1]

    def traction(self, a, g0=0.0) -> list:
        """``tau = K0 (a - g0 e_n) - g0_vec``."""
        dim = len(a)
        K = self.matrix(dim)
        e = [a[0] - g0] + list(a[1:])
        tau = [sum(K[i, j] * e[j] for j in range(dim) if K[i, j] != 0) for i in range(dim)]
        tau[0] = tau[0] - self.gap_force[0]
        tau[1] = tau[1] - self.gap_force[1]
        return tau

    def full_contact_K0(self, dim: int) -> np.ndarray:
        return self.matrix(dim)

    @property
    def quadratic(self) -> bool:
        return True

    def export_rows(self) -> ExportRows:
        """The line ``p(c) = k_n0 c - g_n0 = k_n0 [c - g_n0 / k_n0]_+`` (bilateral: it goes on below its kink,
        which a table does not carry), ``K0`` in 2D, stick slope ``k_t0``."""
        K0 = self.matrix(2)
        return ExportRows(kinks=np.array([self.gap_force[0] / self.kn]), slopes=np.array([self.kn]),
                          stick_slope=float(np.mean(np.diag(K0)[1:])), K0=K0,
                          gap_force=np.asarray(self.gap_force, float), bilateral=True)


@dataclass(frozen=True, kw_only=True)
class BundleLaw(NormalLaw):
    """Unilateral bundle of weighted micro directions (paper eqs. 31-33)::

        W(a) = sum_q w_q/2 [n_q . a - g_q - beta1_q g0]_+^2,    beta1_q = n_q . e_n
        tau  = sum_q w_q   [n_q . a - g_q - beta1_q g0]_+ n_q

    (``tau_n`` and ``tau_t`` are the homogenized stresses of eqs. 32 and 33
    with the integral over ``S_C`` replaced by the weighted directions).

    Attributes
    ----------
    weights
        ``w_q`` [stress / length], > 0.
    directions
        Unit micro normals ``n_q`` in the local frame ``(n0, t0)`` or
        ``(n0, t1, t2)``; a 3D cell's normals under a 2D macro frame are
        their projections on ``(n0, t1)`` (the hoop jump is zero).
    gaps
        Micro gaps ``g_q`` [length] (default zeros).
    """

    weights: tuple[float, ...]
    directions: tuple[tuple[float, ...], ...]
    gaps: tuple[float, ...] = ()

    def __post_init__(self):
        w = np.asarray(self.weights, float)
        d = np.asarray(self.directions, float)
        if w.ndim != 1 or len(w) == 0 or np.any(w <= 0):
            raise ModelError("weights must be a non-empty list of numbers > 0")
        if d.shape[0] != len(w) or d.ndim != 2 or d.shape[1] not in (2, 3):
            raise ModelError(f"directions must be {len(w)} vectors of 2 or 3 components")
        norms = np.linalg.norm(d, axis=1)
        if np.any(norms <= 0) or np.any(norms > 1 + 1e-9):
            raise ModelError("directions must be unit vectors (or their projections on a 2D frame)")
        if self.gaps and len(self.gaps) != len(w):
            raise ModelError(f"gaps must have {len(w)} entries (one per direction)")

    @property
    def g(self) -> np.ndarray:
        return np.asarray(self.gaps, float) if self.gaps else np.zeros(len(self.weights))

    def matrix(self, dim: int | None = None) -> np.ndarray:
        """``K0 = sum_q w_q n_q n_q^T``, the tangent in full contact (eq. 34)."""
        d = np.asarray(self.directions, float)
        return np.einsum("q,qi,qj->ij", np.asarray(self.weights, float), d, d)

    @property
    def stiffness(self) -> float:
        return float(self.matrix()[0, 0])

    def energy(self, a, g0=0.0, closed: bool = False):
        """``W(a)`` of the class docstring; with ``closed`` every direction active (``[x]_+`` replaced by ``x``)."""
        self._check_dim(len(a))
        on = (lambda x: x) if closed else ramp
        W = 0
        for w, n, g in zip(self.weights, self.directions, self.g):
            W = W + 0.5 * w * on(dot(n, a) - g - n[0] * g0) ** 2
        return W

    def traction(self, a, g0=0.0) -> list:
        """``tau = sum_q w_q [n_q . a - g_q - beta1_q g0]_+ n_q``."""
        dim = len(a)
        self._check_dim(dim)
        tau = [0] * dim
        for w, n, g in zip(self.weights, self.directions, self.g):
            f = w * ramp(dot(n, a) - g - n[0] * g0)
            tau = [tau[i] + f * n[i] for i in range(dim)]
        return tau

    def full_contact_K0(self, dim: int) -> np.ndarray:
        return self.matrix(dim)

    def closing_ramps(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``c_q`` and slope increments ``s_q`` of the pressure under a purely normal closure ``c``::

            p(c) = sum_q w_q beta_q [beta_q c - g_q]_+ = sum_q s_q [c - c_q]_+,
            beta_q = n_q . n0,   s_q = w_q beta_q^2,   c_q = g_q / beta_q,

        a convex polyline whose last slope is ``k_n0 = sum_q s_q``, the normal
        entry of ``K0`` (eq. 34); directions with ``beta_q <= CLOSING`` never
        close under a normal closure and carry no pressure.
        """
        w = np.asarray(self.weights, float)
        beta = np.asarray(self.directions, float)[:, 0]
        g = np.asarray(self.g, float)
        closing = beta > CLOSING
        if not np.any(closing):
            raise ModelError("no direction of the bundle closes under a normal closure (all n_q . n0 <= 0)")
        return g[closing] / beta[closing], w[closing] * beta[closing] ** 2

    def export_rows(self) -> ExportRows:
        """:meth:`closing_ramps`, ``K0 = sum_q w_q n_q n_q^T`` and the gap forces ``sum_q w_q g_q n_q`` (eq. 34),
        stick slope the mean tangential entry of ``K0``, the bundle itself."""
        w, n, g = np.asarray(self.weights, float), np.asarray(self.directions, float), self.g
        kinks, slopes = self.closing_ramps()
        K0 = self.matrix()
        return ExportRows(kinks=kinks, slopes=slopes, stick_slope=float(np.mean(np.diag(K0)[1:])), K0=K0,
                          gap_force=np.einsum("q,q,qi->i", w, g, n),
                          bundle={"weights": w, "directions": n, "gaps": g})

    def _check_dim(self, dim: int) -> None:
        if len(self.directions[0]) != dim:
            raise ModelError(f"the bundle's directions have {len(self.directions[0])} components, "
                             f"the interface frame {dim}")

    def merged(self, decimals: int = 12) -> "BundleLaw":
        """The same law with equal ``(n_q, g_q)`` merged (weights added)."""
        acc: dict = {}
        for w, n, g in zip(self.weights, self.directions, self.g):
            key = tuple(np.round(n, decimals)) + (round(float(g), decimals + 6),)
            acc[key] = acc.get(key, 0.0) + float(w)
        keys = list(acc)
        return BundleLaw(weights=tuple(acc[k] for k in keys),
                         directions=tuple(tuple(float(c) for c in k[:-1]) for k in keys),
                         gaps=tuple(float(k[-1]) for k in keys))


#: how a :class:`TabulatedLaw` joins its nodes
INTERPOLATIONS = ("linear", "monotone_cubic")


@dataclass(frozen=True, kw_only=True)
class TabulatedLaw(NormalLaw):
    """Monotone tabulated normal law ``p(c)`` with optional tangential stiffness.

    Closure ``c = a_n - g0``, kinks ``c_i``, slope increments ``s_i``::

        W(a) = sum_i s_i/2 [c - c_i]_+^2 + k_t/2 |a_t|^2
        tau  = (sum_i s_i [c - c_i]_+,  k_t a_t)

    (on CoefficientFunctions the same functions are NGSolve B-splines, one
    table lookup per quadrature point instead of one ramp per kink, see
    :mod:`ngcontact.laws.law_evaluation`).  A ``"monotone_cubic"`` table:
    ``p(c)`` the C1 cubic Hermite interpolant and ``W(c) = int_{c_0}^c p``
    (the formulas of :mod:`ngcontact.laws.monotone_cubic`; on
    CoefficientFunctions a cubic B-spline with triple knots, the Bezier form
    of each piece).  The "all closed" surrogate is the table's first segment
    of nonzero slope, extended both ways.

    Attributes
    ----------
    closure
        ``c_i`` [length], strictly increasing.
    pressure
        ``p_i`` [stress], non-decreasing, ``p_0 = 0``.
    kt
        Linear tangential stiffness [stress / length].
    interpolation
        ``"linear"`` (the polyline) or ``"monotone_cubic"`` (module docstring).
    """

    closure: tuple[float, ...]
    pressure: tuple[float, ...]
    kt: float = 0.0
    interpolation: str = "linear"

    def __post_init__(self):
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        if c.ndim != 1 or len(c) < 2 or len(p) != len(c):
            raise ModelError("closure and pressure must be lists of the same length >= 2")
        if np.any(np.diff(c) <= 0):
            raise ModelError("closure must be strictly increasing")
        if np.any(np.diff(p) < 0):
            raise ModelError("pressure must be non-decreasing (a monotone law has a convex energy)")
        if p[0] != 0.0:
            raise ModelError("the first pressure must be 0 (contact starts there)")
        if np.all(p == 0):
            raise ModelError("the table carries no pressure")
        if self.kt < 0:
            raise ModelError("kt must be >= 0")
        if self.interpolation not in INTERPOLATIONS:
            raise ModelError(f"interpolation = {self.interpolation!r}: must be one of {', '.join(INTERPOLATIONS)}")

    def ramps(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``c_i`` and slope increments ``s_i`` of the polyline ``p(c) = sum s_i [c - c_i]_+`` through
        the table (the law itself when ``interpolation = "linear"``)."""
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        slopes = np.diff(p) / np.diff(c)
        return c[:-1], np.diff(np.concatenate([[0.0], slopes]))

    def node_slopes(self) -> np.ndarray:
        """``dp/dc`` at the nodes of the monotone cubic (:func:`ngcontact.laws.monotone_cubic.slopes`)."""
        return monotone_cubic.slopes(self.closure, self.pressure)

    @property
    def stiffness(self) -> float:
        """The largest slope ``dp/dc`` of the law."""
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        if self.interpolation == "monotone_cubic":
            return monotone_cubic.largest_slope(c, p, self.node_slopes())
        return float(np.max(np.diff(p) / np.diff(c)))

    def energy(self, a, g0=0.0, closed: bool = False):
        """``W(a)`` of the class docstring; with ``closed`` the first segment of nonzero slope, extended both ways."""
        c = a[0] - g0
        if not closed and (self.interpolation != "linear" or not is_numeric(c)):
            W = self._cubic_table(c, energy=True) if is_numeric(c) else self._splines()[1](c)
            return W + 0.5 * self.kt * sum(ai * ai for ai in a[1:]) if self.kt > 0 else W
        on = (lambda x: x) if closed else ramp
        kinks, slopes = self.ramps()
        if closed:
            first = next(k for k, s in enumerate(slopes) if s != 0)
            kinks, slopes = kinks[first:first + 1], slopes[first:first + 1]
        W = sum(0.5 * s * on(c - ci) ** 2 for ci, s in zip(kinks, slopes) if s != 0)
        if self.kt > 0:
            W = W + 0.5 * self.kt * sum(ai * ai for ai in a[1:])
        return W

    def traction(self, a, g0=0.0) -> list:
        """``tau = (p(c), k_t a_t)``."""
        c = a[0] - g0
        if not is_numeric(c):
            p = self._splines()[0](c)
        elif self.interpolation != "linear":
            p = self._cubic_table(c, energy=False)
        else:
            kinks, slopes = self.ramps()
            p = sum(s * ramp(c - ci) for ci, s in zip(kinks, slopes) if s != 0)
        return [p] + [self.kt * ai for ai in a[1:]]

    @property
    def holds_tangentially(self) -> bool:
        return self.kt > 0

    def export_rows(self) -> ExportRows:
        """The polyline itself, :meth:`ramps` (a ``"monotone_cubic"`` table has no exact polyline: it is the
        two-scale loop's own law and is not exported); stick slope ``k_t``, no ``K0``."""
        if self.interpolation != "linear":
            return super().export_rows()
        kinks, slopes = self.ramps()
        return ExportRows(kinks=kinks, slopes=slopes, stick_slope=float(self.kt))

    def _splines(self):
        """``(p, W)`` as B-splines, by the interpolation (:mod:`ngcontact.laws.law_evaluation`)."""
        if self.interpolation == "linear":
            return table_splines(self.closure, self.pressure)
        return cubic_splines(self.closure, self.pressure, tuple(self.node_slopes()))

    def _cubic_table(self, c, energy: bool):
        """``p(c)`` or ``W(c)`` of a monotone cubic table at closures ``c`` (NumPy;
        :mod:`ngcontact.laws.monotone_cubic`), 0 below ``c_0`` and continued with the last node slope beyond
        ``c_last``."""
        cn = np.asarray(self.closure, float)
        pn = np.asarray(self.pressure, float)
        m = self.node_slopes()
        x = np.asarray(c, float)
        d = x - cn[-1]
        if energy:
            inside = monotone_cubic.integral(cn, pn, m, x)
            beyond = float(monotone_cubic.integral(cn, pn, m, cn[-1])) + pn[-1] * d + 0.5 * m[-1] * d * d
        else:
            inside, beyond = monotone_cubic.evaluate(cn, pn, m, x), pn[-1] + m[-1] * d
        return np.where(x < cn[0], 0.0, np.where(x > cn[-1], beyond, inside))


@dataclass(frozen=True, kw_only=True)
class Friction(TangentialLaw):
    """Homogenized friction: ``G = mu [p]_+ + threshold``, Huber width ``width``.

    Paper eqs. 38-44 with the Huber function of eq. 16
    (:mod:`ngcontact.laws.huber`)::

        G      = mu0 [p]_+ + G0                          (eqs. 42-43)
        W_f(a) = G huber(|a_t|, w)
        tau_f  = (0,  G a_t / max(|a_t|, w))            (G held fixed)

    Attributes
    ----------
    mu
        Homogenized Coulomb coefficient ``mu0`` (paper ``k_nt0 / k_n0`` or given).
    threshold
        Tresca-type threshold ``G0`` [stress] (eqs. 42-43).
    width
        Huber regularization width ``w`` [length]: the largest slip of a
        sticking interface.
    """

    mu: float = 0.0
    threshold: float = 0.0
    width: float = 1e-6

    def __post_init__(self):
        if self.mu < 0 or self.threshold < 0 or not self.width > 0:
            raise ModelError("need mu >= 0, threshold >= 0, width > 0")

    @property
    def coulomb(self) -> bool:
        return self.mu > 0

    @property
    def huber_regularized(self) -> bool:
        return True

    def with_width(self, width: float) -> Friction:
        return replace(self, width=width)

    def threshold_at(self, p):
        """``G = mu0 [p]_+ + G0``."""
        return self.mu * ramp(p) + self.threshold

    def energy(self, a, G):
        """``W_f(a) = G huber(|a_t|, w)``."""
        return G * huber_of_square(tangential_norm2(a), self.width)

    def traction(self, a, G) -> list:
        """``tau_f = (0, G a_t / max(|a_t|, w))``."""
        f = G * huber_slope(tangential_norm2(a), self.width)
        return [0.0 * a[0]] + [f * ai for ai in a[1:]]


@dataclass(frozen=True, kw_only=True)
class CellShear(TangentialLaw):
    """The cell's own tangential response, tabulated over pressure and tangential jump.

    Rows ``i`` at pressures ``p_0 = 0 < p_1 < ...`` hold the cell's mean
    shear ``T_i(s)`` at mean tangential interface jumps ``0 = s_i0 < s_i1 <
    ...`` (a polyline, odd in ``s``, held constant beyond the last jump: the
    cell slides there or the macro interface never went further); row 0 is
    zero (an open interface carries no shear).  Between rows the shear is
    interpolated linearly in ``p`` along the rays ``s / p = const``, each
    row stretched by ``r_i = p / p_i`` (so that a response homogeneous in
    the load, as a Coulomb cell's nearly is, ``T(p, s) = p f(s / p)``, is
    reproduced exactly; above the last row the shear grows with ``p`` that way)::

        T(p, s)  = sum_i phi_i(p) r_i T_i(s / r_i),        phi_i the piecewise-linear hats of the p_i
        W_t(a; p) = sum_i phi_i(p) r_i^2 E_i(a_t / r_i),   E_i(s) = int_0^|s| T_i
        tau_t    = dW_t/da_t = T(p, a_t)                   (p frozen)

    Like Coulomb's threshold, the dependence on the pressure is not the
    derivative of an energy: energy, traction and tangent are consistent with
    ``p`` frozen, and the coupled Newton of the macro problem takes ``p`` at
    the current state (:mod:`ngcontact.solvers.coulomb_newton`).  2D (and
    axisymmetric) frames only: one tangential component.

    Attributes
    ----------
    pressure
        ``p_i`` [stress], strictly increasing, ``p_0 = 0``.
    jumps
        Per row the jumps ``s_ij`` [length], strictly increasing from 0.
    shears
        Per row the shears ``T_i(s_ij)`` [stress], 0 at ``s = 0``.
    """

    pressure: tuple[float, ...]
    jumps: tuple[tuple[float, ...], ...]
    shears: tuple[tuple[float, ...], ...]

    def __post_init__(self):
        p = np.asarray(self.pressure, float)
        if p.ndim != 1 or len(p) < 2 or p[0] != 0.0 or np.any(np.diff(p) <= 0):
            raise ModelError("pressure must be >= 2 strictly increasing values starting at 0")
        if len(self.jumps) != len(p) or len(self.shears) != len(p):
            raise ModelError(f"jumps and shears need one row per pressure ({len(p)})")
        for i, (row_s, row_t) in enumerate(zip(self.jumps, self.shears)):
            s, t = np.asarray(row_s, float), np.asarray(row_t, float)
            if s.ndim != 1 or len(s) < 2 or len(t) != len(s) or s[0] != 0.0 or np.any(np.diff(s) <= 0):
                raise ModelError(f"row {i}: jumps must be >= 2 strictly increasing values from 0, one shear each")
            if t[0] != 0.0 or not np.all(np.isfinite(t)):
                raise ModelError(f"row {i}: the shear must be finite and 0 at s = 0")

    @property
    def coulomb(self) -> bool:
        """True: the shear depends on the current pressure (solved like Coulomb friction)."""
        return True

    def threshold_at(self, p):
        """The pressure ``p`` itself: the rows are interpolated at it."""
        return p

    def energy(self, a, G):
        """``W_t(a; p)`` of the class docstring with the frozen pressure ``p = G``."""
        self._check_frame(a)
        return sum(phi * e for phi, e in self._rows(a[1], G, energy=True))

    def traction(self, a, G) -> list:
        """``tau_t = T(p, a_t)`` with the frozen pressure ``p = G``; no normal component."""
        self._check_frame(a)
        return [0.0 * a[0], sum(phi * t for phi, t in self._rows(a[1], G, energy=False))]

    @property
    def width(self) -> float:
        """The smallest tabulated nonzero jump: below it every row is in its first (sticking) segment."""
        return float(min(s[1] for s in self.jumps))

    def hats(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``p_k`` and, per row ``i``, slope increments of ``phi_i(p) = phi_i(0) + sum_k d_ik [p - p_k]_+``."""
        p = np.asarray(self.pressure, float)
        eye = np.eye(len(p))
        slopes = np.diff(eye, axis=1) / np.diff(p)                       # (rows, intervals)
        slopes = np.concatenate([slopes, np.zeros((len(p), 1))], axis=1)  # held constant beyond p_last
        return p, np.diff(np.concatenate([np.zeros((len(p), 1)), slopes], axis=1), axis=1)

    def ramps(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``s_k`` and slope increments ``e_k`` of ``T_i(s) = sum_k e_k [s - s_k]_+`` for ``s >= 0``."""
        s = np.asarray(self.jumps[i], float)
        t = np.asarray(self.shears[i], float)
        slopes = np.concatenate([np.diff(t) / np.diff(s), [0.0]])
        return s, np.diff(np.concatenate([[0.0], slopes]))

    def _rows(self, s, p, energy: bool):
        """``(phi_i(p) r_i^k, E_i(s / r_i) or T_i(s / r_i))`` of the rows ``i >= 1``.

        ``r_i = p / p_i`` (with ``p`` kept above ``1e-12 p_1``: for ``p <= 0``
        every ``phi_i``, ``i >= 1``, is zero and row 0 is zero), ``k = 2`` for the
        energy and 1 for the traction; ``T_i(x) = sum_k e_k ([x - s_k]_+ -
        [-x - s_k]_+)`` (odd), ``E_i(x) = sum_k e_k/2 ([x - s_k]_+^2 + [-x -
        s_k]_+^2)``; ``phi_i(p) = sum_k d_ik [p - p_k]_+``.  On
        CoefficientFunctions ``T_i`` and ``E_i`` are B-splines
        (:func:`ngcontact.laws.law_evaluation.row_splines`).
        """
        kinks, d = self.hats()
        floor = 1e-12 * float(kinks[1])
        q = if_positive(p - floor, p, floor)
        for i in range(1, len(kinks)):
            phi = sum(float(dk) * ramp(p - float(pk)) for pk, dk in zip(kinks, d[i]) if dk != 0)
            r = q / float(kinks[i])
            x = s / r
            if not is_numeric(x):
                T, E = row_splines(tuple(self.jumps[i]), tuple(self.shears[i]))
                yield (phi * r * r, E(x)) if energy else (phi * r, T(x))
                continue
            sk, ek = self.ramps(i)
            if energy:
                f = sum(0.5 * float(e) * (ramp(x - float(k)) ** 2 + ramp(-x - float(k)) ** 2)
                        for k, e in zip(sk, ek) if e != 0)
                yield phi * r * r, f
            else:
                f = sum(float(e) * (ramp(x - float(k)) - ramp(-x - float(k))) for k, e in zip(sk, ek) if e != 0)
                yield phi * r, f

    @staticmethod
    def _check_frame(a) -> None:
        if len(a) != 2:
            raise ModelError("a tabulated cell shear (CellShear) needs a 2D or axisymmetric interface frame "
                             f"(one tangent); this frame has {len(a) - 1}")


#: the friction laws (kept as the name the callers annotate with)
Tangential = TangentialLaw


@dataclass(frozen=True, kw_only=True)
class InterfaceLaw:
    """A normal (and elastic tangential) law, optionally with friction."""

    normal: NormalLaw
    friction: Tangential | None = None

    @property
    def quadratic(self) -> bool:
        """True when the energy is quadratic (one linear solve suffices)."""
        return self.normal.quadratic and self.friction is None

    @property
    def holds_tangentially(self) -> bool:
        """True when a closed interface resists a tangential jump.

        Friction does (the Huber-regularized stick, eq. 34's tangential
        slope), and so does an elastic tangential stiffness ``k_t0 > 0`` of a
        linear, bundle or tabulated law.
        """
        if self.friction is not None:
            return True
        return self.normal.holds_tangentially


def normal_law(law: str, *, kn=None, kt: float = 0.0, knt: float = 0.0, gap_force=(0.0, 0.0),
               weights=None, directions=None, gaps=None, closure=None, pressure=None) -> NormalLaw:
    """The normal law ``law`` ("linear", "bundle" or "tabulated") from its numbers.

    Raises ``ValueError`` (from the law's own checks) when the numbers are
    not admissible; unused numbers are ignored.
    """
    if law == "linear":
        return LinearLaw(kn=kn, kt=kt, knt=knt, gap_force=tuple(gap_force))
    if law == "bundle":
        return BundleLaw(weights=weights, directions=directions, gaps=gaps or ())
    if law == "tabulated":
        return TabulatedLaw(closure=closure, pressure=pressure, kt=kt)
    raise ModelError(f"law {law!r}: must be 'linear', 'bundle' or 'tabulated'")


def linearized(law: BundleLaw) -> LinearLaw:
    """The linear law a bundle equals when every direction is closed.

    ``K0 = sum w_q n_q n_q^T`` and gap forces ``sum w_q g_q n_q`` (eq. 34);
    a 3D bundle must have no ``t2`` coupling for a :class:`LinearLaw`.
    """
    K = law.matrix()
    gf = np.einsum("q,q,qi->i", np.asarray(law.weights, float), law.g, np.asarray(law.directions, float))
    if K.shape[0] == 3 and (abs(K[1, 1] - K[2, 2]) > 1e-12 * K[0, 0] or abs(K[0, 2]) > 1e-12 * K[0, 0]
                            or abs(K[1, 2]) > 1e-12 * K[0, 0]):
        raise ModelError("a 3D bundle is linearized to a LinearLaw only if transversely isotropic")
    return LinearLaw(kn=float(K[0, 0]), kt=float(K[1, 1]), knt=float(K[0, 1]),
                     gap_force=(float(gf[0]), float(gf[1])))
