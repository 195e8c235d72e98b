"""What the homogenized laws evaluate with, on NumPy arrays and NGSolve CoefficientFunctions alike.

``[x]_+ = max(x, 0)`` (:func:`ramp`), the dot product of a fixed direction
with a local jump (:func:`dot`), and the tables of the laws as NGSolve
B-splines: one table lookup per quadrature point instead of one ramp per
kink (the two-scale law has dozens of kinks).  The laws of
:mod:`ngcontact.laws.homogenized` build their energies and tractions from
these.
"""
from __future__ import annotations

import functools

import numpy as np

from ngcontact.laws.huber import is_numeric


def ramp(x):
    """``[x]_+``."""
    if is_numeric(x):
        return np.maximum(x, 0.0)
    import ngsolve as ng
    return ng.IfPos(x, x, 0.0)


def dot(n, a):
    """``n . a`` for a direction ``n`` of numbers (its zero components skipped)."""
    return sum(float(ni) * ai for ni, ai in zip(n, a) if ni != 0)


def tangential_norm2(a):
    """``|a_t|^2`` of a local jump ``a = (a_n, a_t...)``."""
    return sum(ai * ai for ai in a[1:])


@functools.lru_cache(maxsize=16)
def table_splines(closure: tuple, pressure: tuple):
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


@functools.lru_cache(maxsize=16)
def cubic_splines(closure: tuple, pressure: tuple, slopes: tuple):
    """``(p, W)`` of a monotone cubic table as NGSolve B-splines.

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


#: a row's spline is held constant out to this multiple of its last jump (the ramps: for ever)
FAR = 1e6


@functools.lru_cache(maxsize=256)
def row_splines(jumps: tuple, shears: tuple):
    """``(T, E)`` of a shear row as NGSolve B-splines (one lookup per point, not a ramp per kink).

    ``T``: the odd polyline through ``(+-s_k, +-T_k)``, flat out to ``+-FAR
    s_last``, by the table splines of :func:`table_splines`; ``E(x) =
    E+(|x|)`` with ``E+`` the integral from 0 of its positive half (even, and
    C1 at 0 where ``T(0) = 0``; from 0, so no large constant cancels).
    """
    import ngsolve as ng
    s, t = list(jumps), list(shears)
    far = FAR * s[-1]
    xs = [-far] + [-v for v in reversed(s[1:])] + s + [far]
    ts = [-t[-1]] + [-v for v in reversed(t[1:])] + t + [t[-1]]
    T = table_splines(tuple(xs), tuple(ts))[0]
    E_half = table_splines(tuple(s + [far]), tuple(t + [t[-1]]))[1]
    return T, lambda x: E_half(ng.IfPos(x, x, -x))
