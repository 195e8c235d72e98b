"""Homogenized interface laws on the macro interface ``S_0`` as energy densities.

A law is a function of the macro jump ``J = u_rough - u_counter`` written in
the interface's local frame, ``a = (a_n, a_t)`` with ``a_n = J . n0`` and
``a_t = J . t0`` in 2D and axisymmetry, ``a = (J . n0, J . t1, J . t2)`` in
3D (:func:`local_frame`; ``n0`` points from ``rough`` into ``counter``, so
``a_n > 0`` closes the interface).  The macro normal gap ``g0`` (length,
``g0 < 0`` is an initial interference, i.e. a press fit) shifts the law along
``n0``.  The traction ``tau = dW/da`` is what the rough body transmits to the
counter body; its normal component is the contact pressure ``p = tau_n``
(compression positive), its tangential part the shear.

Laws (frozen dataclasses; the energies are built by :func:`energy`):

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
    A linear tangential stiffness ``k_t`` may be added.
:class:`FieldLaw`
    Unilateral Winkler law whose coefficients vary along ``S_0`` (the
    coupling loop of paper Sec. 3.5): ``k_n0(x)`` and ``g_n0(x)`` of eq. 34
    on the real contact set of the cell at the point ``x``::

        W(a) = k_n0(x)/2 [a_n - g0 - c(x)]_+^2,     c(x) = g_n0(x) / k_n0(x),

    i.e. ``p = [k_n0 (a_n - g0) - g_n0]_+``; ``k_n0`` and ``c`` are
    CoefficientFunctions (fields on the interface).
:class:`Friction`
    Homogenized friction on top of any of them (paper eqs. 38-44): threshold
    ``G = mu0 [p]_+ + G0`` and energy ``G huber(|a_t|, w)`` with
    ``huber(s, w) = s^2/(2w)`` for ``s <= w`` and ``s - w/2`` beyond, so a
    sticking interface slips at most ``w``.  Coulomb's ``G = mu0 p`` is not
    the derivative of an energy; :mod:`ngcontact.macro.macro_problem` treats it by a fixed
    point on the pressure (``G`` frozen at the previous solution's ``p``), see
    there.  The energy here takes ``G`` as given.

All functions work on NumPy arrays (for tests and tables) and on NGSolve
CoefficientFunctions alike.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from ngcontact.errors import ModelError
from ngcontact.laws.huber import huber_of_square, huber_slope, is_numeric

if TYPE_CHECKING:
    import ngsolve as ng


# ------------------------------------------------------------------ laws
@dataclass(frozen=True, kw_only=True)
class LinearLaw:
    """Linear anisotropic Winkler law (paper eqs. 34, 69-71).

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
    gap_force: tuple = (0.0, 0.0)

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


@dataclass(frozen=True, kw_only=True)
class BundleLaw:
    """Unilateral bundle of weighted micro directions (paper eqs. 31-33).

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

    weights: tuple
    directions: tuple
    gaps: tuple = ()

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


@dataclass(frozen=True, kw_only=True)
class TabulatedLaw:
    """Monotone tabulated normal law ``p(c)`` with optional tangential stiffness.

    Attributes
    ----------
    closure
        ``c_i`` [length], strictly increasing.
    pressure
        ``p_i`` [stress], non-decreasing, ``p_0 = 0``.
    kt
        Linear tangential stiffness [stress / length].
    """

    closure: tuple
    pressure: tuple
    kt: float = 0.0

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

    def ramps(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``c_i`` and slope increments ``s_i`` of ``p(c) = sum s_i [c - c_i]_+``."""
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        slopes = np.diff(p) / np.diff(c)
        return c[:-1], np.diff(np.concatenate([[0.0], slopes]))

    @property
    def stiffness(self) -> float:
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        return float(np.max(np.diff(p) / np.diff(c)))


@dataclass(frozen=True, kw_only=True)
class Friction:
    """Homogenized friction: ``G = mu [p]_+ + threshold``, Huber width ``width``.

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


@dataclass(frozen=True, kw_only=True)
class FieldLaw:
    """Unilateral normal law with coefficient fields along ``S_0`` (module docstring).

    Attributes
    ----------
    kn
        ``k_n0(x)`` [stress / length], a CoefficientFunction > 0 on ``S_0``.
    offset
        ``c(x) = g_n0(x) / k_n0(x)`` [length], a CoefficientFunction.
    stiffness
        An upper bound of ``k_n0`` (a number; scales the start of the solve).
    """

    kn: ng.CoefficientFunction
    offset: ng.CoefficientFunction
    stiffness: float

    def __post_init__(self):
        if not self.stiffness > 0:
            raise ModelError(f"stiffness = {self.stiffness!r}: must be > 0")


NormalLaw = LinearLaw | BundleLaw | TabulatedLaw | FieldLaw


@dataclass(frozen=True, kw_only=True)
class InterfaceLaw:
    """A normal (and elastic tangential) law, optionally with friction."""

    normal: NormalLaw
    friction: Friction | None = None

    @property
    def quadratic(self) -> bool:
        """True when the energy is quadratic (one linear solve suffices)."""
        return isinstance(self.normal, LinearLaw) and self.friction is None


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


# -------------------------------------------------------------- backend
def _ramp(x):
    """``[x]_+``."""
    if is_numeric(x):
        return np.maximum(x, 0.0)
    import ngsolve as ng
    return ng.IfPos(x, x, 0.0)


# ----------------------------------------------------------- energies
def normal_energy(law: NormalLaw, a, g0=0.0, closed: bool = False):
    """Energy density of the normal (and elastic tangential) law at local jump ``a``.

    Parameters
    ----------
    law
        :class:`LinearLaw`, :class:`BundleLaw` or :class:`TabulatedLaw`.
    a
        Local jump components ``(a_n, a_t)`` or ``(a_n, a_t1, a_t2)``.
    g0
        Macro normal gap (number or CoefficientFunction); ``< 0`` interference.
    closed
        Replace the law by its quadratic "all closed" surrogate: every bundle
        direction active, the table's first segment extended both ways (a
        start value for Newton that holds every body in place).
    """
    dim = len(a)
    ramp = (lambda x: x) if closed else _ramp
    if isinstance(law, LinearLaw):
        K = law.matrix(dim)
        e = [a[0] - g0] + list(a[1:])
        W = 0.5 * sum(K[i, j] * e[i] * e[j] for i in range(dim) for j in range(dim) if K[i, j] != 0)
        return W - law.gap_force[0] * a[0] - law.gap_force[1] * a[1]
    if isinstance(law, BundleLaw):
        _check_dim(law, dim)
        W = 0
        for w, n, g in zip(law.weights, law.directions, law.g):
            W = W + 0.5 * w * ramp(_dot(n, a) - g - n[0] * g0) ** 2
        return W
    if isinstance(law, TabulatedLaw):
        kinks, slopes = law.ramps()
        c = a[0] - g0
        if closed:
            first = next(k for k, s in enumerate(slopes) if s != 0)
            kinks, slopes = kinks[first:first + 1], slopes[first:first + 1]
        W = sum(0.5 * s * ramp(c - ci) ** 2 for ci, s in zip(kinks, slopes) if s != 0)
        if law.kt > 0:
            W = W + 0.5 * law.kt * sum(ai * ai for ai in a[1:])
        return W
    if isinstance(law, FieldLaw):
        return 0.5 * law.kn * ramp(a[0] - g0 - law.offset) ** 2
    raise TypeError(f"unknown interface law {type(law).__name__}")


def normal_traction(law: NormalLaw, a, g0=0.0) -> list:
    """``dW/da`` of :func:`normal_energy`: local traction components."""
    dim = len(a)
    if isinstance(law, LinearLaw):
        K = law.matrix(dim)
        e = [a[0] - g0] + list(a[1:])
        tau = [sum(K[i, j] * e[j] for j in range(dim) if K[i, j] != 0) for i in range(dim)]
        tau[0] = tau[0] - law.gap_force[0]
        tau[1] = tau[1] - law.gap_force[1]
        return tau
    if isinstance(law, BundleLaw):
        _check_dim(law, dim)
        tau = [0] * dim
        for w, n, g in zip(law.weights, law.directions, law.g):
            f = w * _ramp(_dot(n, a) - g - n[0] * g0)
            tau = [tau[i] + f * n[i] for i in range(dim)]
        return tau
    if isinstance(law, TabulatedLaw):
        kinks, slopes = law.ramps()
        c = a[0] - g0
        p = sum(s * _ramp(c - ci) for ci, s in zip(kinks, slopes) if s != 0)
        return [p] + [law.kt * ai for ai in a[1:]]
    if isinstance(law, FieldLaw):
        return [law.kn * _ramp(a[0] - g0 - law.offset)] + [0.0 * ai for ai in a[1:]]
    raise TypeError(f"unknown interface law {type(law).__name__}")


def pressure(law: NormalLaw, a, g0=0.0):
    """Contact pressure ``p = tau_n`` (compression positive)."""
    return normal_traction(law, a, g0)[0]


def friction_energy(friction: Friction, a, G):
    """``G huber(|a_t|, w)`` with the threshold field ``G`` given."""
    return G * huber_of_square(_tangential_norm2(a), friction.width)


def friction_traction(friction: Friction, a, G) -> list:
    """``d/da`` of :func:`friction_energy` (``G`` frozen)."""
    f = G * huber_slope(_tangential_norm2(a), friction.width)
    return [0.0 * a[0]] + [f * ai for ai in a[1:]]


def threshold(friction: Friction, p):
    """``G = mu [p]_+ + G0`` for a pressure ``p``."""
    return friction.mu * _ramp(p) + friction.threshold


def energy(law: InterfaceLaw, a, g0=0.0, G=None):
    """Total interface energy density; ``G`` is the friction threshold field
    (default: ``threshold(friction, 0)``, i.e. ``G0`` only)."""
    W = normal_energy(law.normal, a, g0)
    if law.friction is not None:
        if G is None:
            G = law.friction.threshold
        W = W + friction_energy(law.friction, a, G)
    return W


def traction(law: InterfaceLaw, a, g0=0.0, G=None) -> list:
    """Local traction ``dW/da`` of :func:`energy` (same ``G``)."""
    tau = normal_traction(law.normal, a, g0)
    if law.friction is not None:
        if G is None:
            G = law.friction.threshold
        ft = friction_traction(law.friction, a, G)
        tau = [t + f for t, f in zip(tau, ft)]
    return tau


def _tangential_norm2(a):
    return sum(ai * ai for ai in a[1:])


def _dot(n, a):
    return sum(float(ni) * ai for ni, ai in zip(n, a) if ni != 0)


def _check_dim(law: BundleLaw, dim: int) -> None:
    if len(law.directions[0]) != dim:
        raise ModelError(f"the bundle's directions have {len(law.directions[0])} components, "
                         f"the interface frame {dim}")


# --------------------------------------------------------------- frame
def local_frame(n0, dim: int, reference=(1.0, 0.0, 0.0)) -> list:
    """Local basis ``[n0, t0]`` (2D) or ``[n0, t1, t2]`` (3D) as CoefficientFunctions.

    2D and axisymmetric: ``t0 = (n0_y, -n0_x)``, i.e. ``n0`` turned clockwise,
    so that ``n0 = e_y`` gives ``t0 = e_x`` as in the cells; on the stem's
    cylinder (``n0 = e_r``) ``t0 = -e_z``.  3D: ``t1`` is the unit
    projection of ``reference`` on the tangent plane (``e_y`` where
    ``reference`` is nearly normal), ``t2 = n0 x t1``.
    """
    import ngsolve as ng
    if dim == 2:
        return [n0, ng.CF((n0[1], -n0[0]))]
    r1 = ng.CF(tuple(float(c) for c in reference))
    alt = np.cross(reference, (0.0, 0.0, 1.0))
    if np.linalg.norm(alt) < 0.5:
        alt = np.cross(reference, (0.0, 1.0, 0.0))
    r2 = ng.CF(tuple(float(c) for c in alt / np.linalg.norm(alt)))
    p1 = r1 - ng.InnerProduct(r1, n0) * n0
    p2 = r2 - ng.InnerProduct(r2, n0) * n0
    use1 = ng.InnerProduct(p1, p1) - 0.25
    t = ng.IfPos(use1, 1, 0) * p1 + ng.IfPos(use1, 0, 1) * p2
    t1 = t / ng.sqrt(ng.InnerProduct(t, t))
    t2 = ng.Cross(n0, t1)
    return [n0, t1, t2]
