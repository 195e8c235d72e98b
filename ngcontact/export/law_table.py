"""The law every exporter writes: the pressure-closure table, the stick slope, what a format cannot carry.

A direction bundle (paper eqs. 31-33; weights ``w_q`` [Pa/m], micro normals
``n_q`` in the local frame ``(n0, t0[, t1])``, micro gaps ``g_q`` [m]) under a
purely normal macro closure ``c`` (the jump ``a = c n0`` minus the macro gap
``g0``) transmits the pressure

    p(c) = sum_q w_q beta_q [beta_q c - g_q]_+ = sum_q s_q [c - c_q]_+,
    beta_q = n_q . n0,   s_q = w_q beta_q^2,   c_q = g_q / beta_q,

a convex piecewise linear curve with a kink at every ``c_q`` (directions with
``beta_q <= 0`` never close under a normal closure and carry no pressure).
Each law gives its curve itself
(:meth:`~ngcontact.laws.law_protocol.NormalLaw.export_rows`; the bundle's:
:meth:`~ngcontact.laws.homogenized.BundleLaw.closing_ramps`).
Beyond its last kink the slope is ``k_n0 = sum_q s_q``, the normal entry of
``K0`` of eq. 34.  This curve is exact; the exported table is a subset of its
kinks (and a last point at the largest pressure asked for) such that linear
interpolation between table nodes stays within ``tolerance * p_max`` of the
curve: the chord of a convex curve lies above it and departs most at an
interior kink, so a greedy walk over the kinks finds the nodes.

Tangential behaviour for the codes' friction cards: Coulomb coefficient
``mu0`` (the macro scene's ``interface.mu``, else the paper's homogenized
``mu0 = |k_nt0| / k_n0`` after eq. 34) and stick slope ``k_t0`` (the
tangential entry of ``K0``, the paper's friction tension ``G_t = |k_t0 u_t|``,
eqs. 42-43 and Fig. 4).

Units: closures and gaps in metres, pressures in pascals, stiffnesses in Pa/m
(force per volume); a cell's lengths are multiplied by its ``length_unit``
(metres per cell unit) before anything is tabulated, the weights are not
(they are ``k_n`` times a ratio of lengths).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ngcontact.errors import ModelError

#: Entries of ``K0`` below this fraction of ``k_n0`` are rounding (``k_nt0`` of a symmetric cell): not carried,
#: not a friction coefficient.
ROUNDING = 1e-12


def number(v: float, spec: str = ".12e") -> str:
    """``v`` as a card writes it (default: at most 20 characters, as ccx reads them, with 13 significant digits,
    relative 5e-14); a non-finite value is refused, so that no card carries ``inf`` or ``nan``."""
    if not math.isfinite(v):
        raise ModelError(f"a non-finite number ({v}) cannot be written into a card")
    return format(v, spec)

@dataclass(frozen=True)
class ExportedLaw:
    """Everything an exporter writes, in SI units and the local frame ``(n0, t0[, t1])``.

    Attributes
    ----------
    kinks, slopes
        The exact normal curve ``p(c) = sum_i s_i [c - c_i]_+`` [m], [Pa/m].
    closure, pressure
        The exported table [m], [Pa]: strictly increasing closures, ``p_0 = 0``.
    tolerance
        Largest departure of the table from the exact curve between nodes, as a fraction of ``p_max``.
    K0
        The tangent in full contact [Pa/m] (eq. 34); ``None`` for a tabulated law.
    bundle
        ``{"weights", "directions", "gaps"}`` of a bundle law, else ``None``.
    mu, mu_source
        Coulomb coefficient and where it comes from.
    stick_slope
        ``k_t0`` [Pa/m].
    gap
        Uniform macro gap ``g0`` [m] (negative: interference).
    source
        Scene file name (no directories), kind, SHA-256 of the scene (and its cell), length unit, the law's type.
    notes
        What the formats with a contact card cannot carry (one sentence each).
    gap_force
        ``(g_n0, g_t0[, g_t1])`` of eq. 34 [Pa] with ``K0``, else ``None``.
    """

    kinks: np.ndarray
    slopes: np.ndarray
    closure: np.ndarray
    pressure: np.ndarray
    tolerance: float
    K0: np.ndarray | None
    bundle: dict | None
    mu: float
    mu_source: str
    stick_slope: float
    gap: float
    source: dict
    notes: tuple[str, ...] = field(default=())
    gap_force: np.ndarray | None = None

    @property
    def k_n0(self) -> float:
        """Slope of the curve beyond its last kink [Pa/m]."""
        return float(self.slopes.sum())

    @property
    def p_max(self) -> float:
        return float(self.pressure[-1])

    def full_contact_pressure(self) -> float:
        """Pressure at the last kink: above it the curve is linear with slope ``k_n0``."""
        return float(curve(self.kinks, self.slopes, np.array([self.kinks.max()]))[0])


def curve(kinks, slopes, c) -> np.ndarray:
    """The exact pressure ``p(c) = sum_i s_i [c - c_i]_+`` [Pa] at closures ``c`` [m].

    Evaluated as ``c S(c) - M(c)`` with the running sums ``S`` of ``s_i`` and
    ``M`` of ``s_i c_i`` over the kinks below ``c`` (memory linear in the
    number of kinks; the rounding is that of ``p_max``'s scale, ~1e-16 of it).
    """
    k = np.asarray(kinks, float)
    order = np.argsort(k, kind="stable")
    k, s = k[order], np.asarray(slopes, float)[order]
    S = np.concatenate([[0.0], np.cumsum(s)])
    M = np.concatenate([[0.0], np.cumsum(s * k)])
    c = np.asarray(c, float)
    below = np.searchsorted(k, c, side="left")
    return np.maximum(c * S[below] - M[below], 0.0)


def exact_nodes(kinks, slopes, p_max: float) -> tuple[np.ndarray, np.ndarray]:
    """Every kink of the curve (equal ones merged) up to ``p_max`` and a last node where ``p = p_max``."""
    c = np.unique(np.asarray(kinks, float))
    scale = max(float(np.max(np.abs(c))), 1e-300)
    c = c[np.concatenate([[True], np.diff(c) > 1e-13 * scale])]
    p = curve(kinks, slopes, c)
    inside = p < p_max
    c, p = c[inside], p[inside]
    slope = float(np.sum(np.asarray(slopes, float)[np.asarray(kinks, float) <= c[-1]]))
    c = np.append(c, c[-1] + (p_max - p[-1]) / slope)
    return c, curve(kinks, slopes, c)


def thinned(c: np.ndarray, p: np.ndarray, tol_abs: float) -> np.ndarray:
    """Indices of the nodes of ``(c, p)`` to keep so that the chords stay within ``tol_abs``.

    Greedy: from each kept node, the farthest next node whose chord passes
    every skipped node within ``tol_abs`` (between nodes both are linear, so
    a chord errs most at a node).  The farthest node is found by doubling the
    step and then bisecting, which is exact where the chord's error grows
    with its length (a convex curve, as every bundle's); elsewhere the
    chosen chord still meets the tolerance, the table is only longer.  The
    first and the last node are always kept.
    """
    n = len(c)

    def fits(i: int, j: int) -> bool:
        k = np.arange(i + 1, j)
        chord = p[i] + (p[j] - p[i]) * (c[k] - c[i]) / (c[j] - c[i])
        return bool(np.all(np.abs(chord - p[k]) <= tol_abs))

    keep = [0]
    i = 0
    while i < n - 1:
        good, step = i + 1, 1
        while good + step < n and fits(i, good + step):
            good += step
            step *= 2
        bad = min(good + step, n)
        while bad - good > 1:
            mid = (good + bad) // 2
            if fits(i, mid):
                good = mid
            else:
                bad = mid
        keep.append(good)
        i = good
    return np.asarray(keep)


def table(kinks, slopes, *, p_max: float, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """The exported table ``(closure, pressure)``: exact at its nodes, within ``tolerance * p_max`` between."""
    if not p_max > 0:
        raise ModelError(f"p_max = {p_max!r}: the table's largest pressure must be > 0")
    if not 0 <= tolerance < 1:
        raise ModelError(f"tolerance = {tolerance!r}: must be in [0, 1)")
    c, p = exact_nodes(kinks, slopes, p_max)
    keep = thinned(c, p, tolerance * p_max)
    return c[keep], p[keep]


def not_carried(directions, K0: np.ndarray | None, *, threshold: float = 0.0, gap_table: bool = False,
                bilateral: bool = False) -> tuple[str, ...]:
    """Sentences naming what a contact card (pressure-overclosure table + Coulomb friction) loses."""
    notes = []
    if bilateral:
        notes.append("the linear law is bilateral (it transmits tension); a contact card transmits compression only")
    if K0 is None:
        return tuple(notes + (["the macro gap table (g0 varying along the interface) is not carried; the gap "
                               "written is 0"] if gap_table else []))
    kn = float(K0[0, 0])
    if np.any(np.abs(K0[0, 1:]) > ROUNDING * kn):
        notes.append(f"k_nt0 = {', '.join(f'{v:.6g}' for v in K0[0, 1:])} Pa/m (normal-tangential coupling of "
                     "eq. 34: a normal closure also shears, a slip also presses) is not carried; only |k_nt0|/k_n0 "
                     "can enter as a friction coefficient")
    if K0.shape[0] == 3 and abs(K0[1, 1] - K0[2, 2]) > 1e-12 * kn:
        notes.append(f"tangential anisotropy k_t1 = {K0[1, 1]:.6g}, k_t2 = {K0[2, 2]:.6g} Pa/m is not carried: "
                     "the stick slope is their mean")
    d = np.round(np.asarray(directions if directions is not None else [[1.0]], float), 9)
    if len({tuple(r) for r in d}) > 1:
        notes.append(f"the bundle's {len(d)} unilateral directions (each micro face opens on its own, e.g. one "
                     "valley wall under shear) are not carried: the table is the response to a purely normal "
                     "closure and the stick slope the full-contact k_t0")
    if threshold > 0:
        notes.append(f"the Tresca threshold G0 = {threshold:.6g} Pa added to mu p is not carried")
    if gap_table:
        notes.append("the macro gap table (g0 varying along the interface) is not carried; the gap written is 0")
    return tuple(notes)
