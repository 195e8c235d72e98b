"""The interface energy ``W(a)`` of a homogenized law and its gradient, the traction.

Evaluates the laws of :mod:`ngcontact.laws.homogenized` at the local jump
``a = (a_n, a_t)`` (2D, axisymmetry) or ``(a_n, a_t1, a_t2)`` (3D) of
:mod:`ngcontact.laws.local_frame`, with the macro normal gap ``g0``, ``e_n``
the first local axis and ``[x]_+ = max(x, 0)`` (:func:`_ramp`).  The traction
``tau = dW/da`` is what the rough body transmits to the counter body, its
normal component the contact pressure ``p = tau_n`` (compression positive).

Normal (and elastic tangential) laws, :func:`normal_energy` and
:func:`normal_traction`:

``LinearLaw`` (paper eqs. 34 and 69-71)::

    W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a
    tau  = K0 (a - g0 e_n) - g0_vec

``BundleLaw`` (paper eqs. 31-33; ``tau_n`` and ``tau_t`` are the
homogenized stresses of eqs. 32 and 33 with the integral over ``S_C``
replaced by the weighted directions)::

    W(a) = sum_q w_q/2 [n_q . a - g_q - beta1_q g0]_+^2,    beta1_q = n_q . e_n
    tau  = sum_q w_q   [n_q . a - g_q - beta1_q g0]_+ n_q

``TabulatedLaw`` (closure ``c = a_n - g0``, kinks ``c_i``, slope increments ``s_i``)::

    W(a) = sum_i s_i/2 [c - c_i]_+^2 + k_t/2 |a_t|^2
    tau  = (sum_i s_i [c - c_i]_+,  k_t a_t)

(on CoefficientFunctions the same functions are NGSolve B-splines, one
table lookup per quadrature point instead of one ramp per kink; the
two-scale law has dozens of kinks).  A ``"monotone_cubic"`` table: ``p(c)``
the C1 cubic Hermite interpolant of :class:`~ngcontact.laws.homogenized.TabulatedLaw`
and ``W(c) = int_{c_0}^c p`` (the formulas of :mod:`ngcontact.laws.monotone_cubic`;
on CoefficientFunctions a cubic B-spline with triple knots, the Bezier form
of each piece).

With ``closed=True`` :func:`normal_energy` is the quadratic "all closed"
surrogate (a start value for Newton): every ramp ``[x]_+`` replaced by ``x``,
and a table reduced to its first segment of nonzero slope, extended both ways.

Friction (paper eqs. 38-44; the Huber function of eq. 16,
:mod:`ngcontact.laws.huber`), :func:`threshold`, :func:`friction_energy`
and :func:`friction_traction`::

    G     = mu0 [p]_+ + G0                          (eqs. 42-43)
    W_f(a) = G huber(|a_t|, w)
    tau_f  = (0,  G a_t / max(|a_t|, w))            (G held fixed)

The cell's tabulated shear :class:`CellShear` (rows ``T_i(s)`` at pressures
``p_i``, hats ``phi_i`` in ``p``, each row stretched along the ray
``s / p = const`` by ``r_i = p / p_i``) in place of the Huber friction, with
the frozen pressure ``p`` in the place of ``G``::

    W_t(a; p) = sum_i phi_i(p) r_i^2 E_i(a_t / r_i),   E_i(s) = int_0^|s| T_i
    tau_t     = sum_i phi_i(p) r_i   T_i(a_t / r_i)

Total (the interface integrand of eq. 44), :func:`energy` and
:func:`traction`: ``W = W_normal + W_f`` and ``tau = tau_normal + tau_f``,
with ``G = G0`` unless a threshold field is given.

All functions work on NumPy arrays (for tests and tables) and on NGSolve
CoefficientFunctions alike.
"""
from __future__ import annotations

import functools

import numpy as np
from ngcontact.errors import ModelError
from ngcontact.laws.homogenized import (
    BundleLaw,
    CellShear,
    InterfaceLaw,
    LinearLaw,
    NormalLaw,
    TabulatedLaw,
    Tangential,
)
from ngcontact.laws import monotone_cubic
from ngcontact.laws.huber import huber_of_square, huber_slope, if_positive, is_numeric


# -------------------------------------------------------------- backend
def _ramp(x):
    """``[x]_+``."""
    if is_numeric(x):
        return np.maximum(x, 0.0)
    import ngsolve as ng
    return ng.IfPos(x, x, 0.0)


@functools.lru_cache(maxsize=16)
def _splines(closure: tuple, pressure: tuple):
    """``(p, W)`` of a table as NGSolve B-splines: one table lookup per point instead of a sum of ramps.

    ``p(c)`` piecewise linear (0 below ``c_0``, the last slope beyond
    ``c_last``) as a quadratic B-spline whose interior knots are doubled (so
    it is only C0 there, and exactly the polyline: control values at the
    table points and the segment midpoints); quadratic because NGSolve's
    linear B-splines have no second derivatives, which a Newton tangent of
    an energy holding ``p`` (the Coulomb threshold ``mu p``) needs.  ``W``
    its integral from ``c_0``.  tests/laws compare both with the ramps.
    """
    import ngsolve as ng
    c = [float(x) for x in closure]
    p = [float(x) for x in pressure]
    values = [v for a, b in zip(p[:-1], p[1:]) for v in (a, 0.5 * (a + b))] + [p[-1]]
    knots = [c[0]] * 3 + [x for x in c[1:-1] for _ in (0, 1)] + [c[-1]] * 3
    return ng.BSpline(3, knots, values), ng.BSpline(2, [c[0]] + c + [c[-1]], p).Integrate()


def _table_splines(law: TabulatedLaw):
    """``(p, W)`` of a table as B-splines, by its interpolation."""
    if law.interpolation == "linear":
        return _splines(law.closure, law.pressure)
    return _cubic_splines(law.closure, law.pressure, tuple(law.node_slopes()))


@functools.lru_cache(maxsize=16)
def _cubic_splines(closure: tuple, pressure: tuple, slopes: tuple):
    """``(p, W)`` of a monotone cubic table as NGSolve B-splines (module docstring).

    ``p`` is a cubic B-spline with every interior knot tripled, so that its
    control values are the Bezier points of each Hermite piece, ``p_i``,
    ``p_i + h m_i / 3``, ``p_i+1 - h m_i+1 / 3``, ``p_i+1``: the Hermite
    cubic exactly, 0 below ``c_0``.  A last straight piece of slope
    ``m_last`` (as long as the table) makes the continuation beyond the last
    node linear, like the polyline's.  ``W`` its integral from ``c_0``.
    """
    import ngsolve as ng
    c = [float(x) for x in closure]
    p = [float(x) for x in pressure]
    m = [float(x) for x in slopes]
    values = [p[0]]
    for i in range(len(c) - 1):
        h = c[i + 1] - c[i]
        values += [p[i] + h * m[i] / 3.0, p[i + 1] - h * m[i + 1] / 3.0, p[i + 1]]
    far = c[-1] - c[0]
    values += [p[-1] + far * m[-1] / 3.0, p[-1] + 2.0 * far * m[-1] / 3.0, p[-1] + far * m[-1]]
    knots = [c[0]] * 4 + [x for x in c[1:] for _ in range(3)] + [c[-1] + far] * 4
    spline = ng.BSpline(4, knots, values)
    return spline, spline.Integrate()


def _cubic_table(law: TabulatedLaw, c, energy: bool):
    """``p(c)`` or ``W(c)`` of a monotone cubic table at closures ``c`` (NumPy; :mod:`ngcontact.laws.monotone_cubic`),
    0 below ``c_0`` and continued with the last node slope beyond ``c_last``."""
    cn = np.asarray(law.closure, float)
    pn = np.asarray(law.pressure, float)
    m = law.node_slopes()
    x = np.asarray(c, float)
    d = x - cn[-1]
    if energy:
        inside = monotone_cubic.integral(cn, pn, m, x)
        beyond = float(monotone_cubic.integral(cn, pn, m, cn[-1])) + pn[-1] * d + 0.5 * m[-1] * d * d
    else:
        inside, beyond = monotone_cubic.evaluate(cn, pn, m, x), pn[-1] + m[-1] * d
    return np.where(x < cn[0], 0.0, np.where(x > cn[-1], beyond, inside))


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
        c = a[0] - g0
        if not closed and (law.interpolation != "linear" or not is_numeric(c)):
            W = _cubic_table(law, c, energy=True) if is_numeric(c) else _table_splines(law)[1](c)
            return W + 0.5 * law.kt * sum(ai * ai for ai in a[1:]) if law.kt > 0 else W
        kinks, slopes = law.ramps()
        if closed:
            first = next(k for k, s in enumerate(slopes) if s != 0)
            kinks, slopes = kinks[first:first + 1], slopes[first:first + 1]
        W = sum(0.5 * s * ramp(c - ci) ** 2 for ci, s in zip(kinks, slopes) if s != 0)
        if law.kt > 0:
            W = W + 0.5 * law.kt * sum(ai * ai for ai in a[1:])
        return W
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
        c = a[0] - g0
        if not is_numeric(c):
            p = _table_splines(law)[0](c)
        elif law.interpolation != "linear":
            p = _cubic_table(law, c, energy=False)
        else:
            kinks, slopes = law.ramps()
            p = sum(s * _ramp(c - ci) for ci, s in zip(kinks, slopes) if s != 0)
        return [p] + [law.kt * ai for ai in a[1:]]
    raise TypeError(f"unknown interface law {type(law).__name__}")


def pressure(law: NormalLaw, a, g0=0.0):
    """Contact pressure ``p = tau_n`` (compression positive)."""
    return normal_traction(law, a, g0)[0]


def friction_energy(friction: Tangential, a, G):
    """``G huber(|a_t|, w)`` with the threshold field ``G`` given; for a :class:`CellShear`,
    ``W_t(a; p)`` with the frozen pressure ``p = G`` (:func:`threshold`)."""
    if isinstance(friction, CellShear):
        _check_cell_shear(a)
        return sum(phi * e for phi, e in _cell_shear_rows(friction, a[1], G, energy=True))
    return G * huber_of_square(_tangential_norm2(a), friction.width)


def friction_traction(friction: Tangential, a, G) -> list:
    """``d/da`` of :func:`friction_energy` (``G`` frozen)."""
    if isinstance(friction, CellShear):
        _check_cell_shear(a)
        return [0.0 * a[0], sum(phi * t for phi, t in _cell_shear_rows(friction, a[1], G, energy=False))]
    f = G * huber_slope(_tangential_norm2(a), friction.width)
    return [0.0 * a[0]] + [f * ai for ai in a[1:]]


def threshold(friction: Tangential, p):
    """``G = mu [p]_+ + G0`` for a pressure ``p``; a :class:`CellShear` depends on ``p`` itself."""
    if isinstance(friction, CellShear):
        return p
    return friction.mu * _ramp(p) + friction.threshold


def _cell_shear_rows(shear: CellShear, s, p, energy: bool):
    """``(phi_i(p) r_i^k, E_i(s / r_i) or T_i(s / r_i))`` of the rows ``i >= 1`` of a :class:`CellShear`.

    ``r_i = p / p_i`` (with ``p`` kept above ``1e-12 p_1``: for ``p <= 0``
    every ``phi_i``, ``i >= 1``, is zero and row 0 is zero), ``k = 2`` for the
    energy and 1 for the traction; ``T_i(x) = sum_k e_k ([x - s_k]_+ -
    [-x - s_k]_+)`` (odd), ``E_i(x) = sum_k e_k/2 ([x - s_k]_+^2 + [-x -
    s_k]_+^2)``; ``phi_i(p) = sum_k d_ik [p - p_k]_+``.
    """
    kinks, d = shear.hats()
    floor = 1e-12 * float(kinks[1])
    q = if_positive(p - floor, p, floor)
    for i in range(1, len(kinks)):
        phi = sum(float(dk) * _ramp(p - float(pk)) for pk, dk in zip(kinks, d[i]) if dk != 0)
        r = q / float(kinks[i])
        x = s / r
        if not is_numeric(x):
            T, E = _row_splines(tuple(shear.jumps[i]), tuple(shear.shears[i]))
            yield (phi * r * r, E(x)) if energy else (phi * r, T(x))
            continue
        sk, ek = shear.ramps(i)
        if energy:
            f = sum(0.5 * float(e) * (_ramp(x - float(k)) ** 2 + _ramp(-x - float(k)) ** 2)
                    for k, e in zip(sk, ek) if e != 0)
            yield phi * r * r, f
        else:
            f = sum(float(e) * (_ramp(x - float(k)) - _ramp(-x - float(k))) for k, e in zip(sk, ek) if e != 0)
            yield phi * r, f


#: a row's spline is held constant out to this multiple of its last jump (the ramps: for ever)
FAR = 1e6


@functools.lru_cache(maxsize=256)
def _row_splines(jumps: tuple, shears: tuple):
    """``(T, E)`` of a :class:`CellShear` row as NGSolve B-splines (one lookup per point, not a ramp per kink).

    ``T``: the odd polyline through ``(+-s_k, +-T_k)``, flat out to ``+-FAR
    s_last``, by the table splines of :func:`_splines`; ``E(x) = E+(|x|)``
    with ``E+`` the integral from 0 of its positive half (even, and C1 at 0
    where ``T(0) = 0``; from 0, so no large constant cancels).
    """
    import ngsolve as ng
    s, t = list(jumps), list(shears)
    far = FAR * s[-1]
    xs = [-far] + [-v for v in reversed(s[1:])] + s + [far]
    ts = [-t[-1]] + [-v for v in reversed(t[1:])] + t + [t[-1]]
    T = _splines(tuple(xs), tuple(ts))[0]
    E_half = _splines(tuple(s + [far]), tuple(t + [t[-1]]))[1]
    return T, lambda x: E_half(ng.IfPos(x, x, -x))


def _check_cell_shear(a) -> None:
    if len(a) != 2:
        raise ModelError("a tabulated cell shear (CellShear) needs a 2D or axisymmetric interface frame "
                         f"(one tangent); this frame has {len(a) - 1}")


def energy(law: InterfaceLaw, a, g0=0.0, G=None):
    """Total interface energy density; ``G`` is the friction threshold field
    (default: ``threshold(friction, 0)``, i.e. ``G0`` only)."""
    W = normal_energy(law.normal, a, g0)
    if law.friction is not None:
        if G is None:
            G = threshold(law.friction, 0.0)
        W = W + friction_energy(law.friction, a, G)
    return W


def traction(law: InterfaceLaw, a, g0=0.0, G=None) -> list:
    """Local traction ``dW/da`` of :func:`energy` (same ``G``)."""
    tau = normal_traction(law.normal, a, g0)
    if law.friction is not None:
        if G is None:
            G = threshold(law.friction, 0.0)
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
