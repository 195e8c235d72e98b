"""Hertz's cylinder repeated with period ``lambda``: the contact half-width of a periodic row.

Pure NumPy: nothing here meshes or solves.  The FE cell is periodic, so a
cylinder gap ``x^2 / (2R)`` pressed in a cell of period ``lambda`` is a row of
cylinders, whose neighbours narrow each patch below Hertz's
(:mod:`ngcontact.verification.hertz`) by about ``(pi b / lambda)^2 / 12``
relative.  This module gives the row's half-width itself, to round-off, so
that an answer of the cell can be held against it without that shift.

The surface slope of two elastic half-planes (contact modulus ``E*``) under a
pressure ``p`` of period ``lambda`` (Johnson, Contact Mechanics, eq. 2.25b,
summed over the images ``s + n lambda``) is

    u'(x) = -(2 / (pi E*)) PV int p(s) k cot(k (x - s)) ds,     k = pi / lambda,

and in the patch ``|x| < b`` it is ``-g'(x)``.  With ``t = tan(k x)``,
``tau = tan(k s)``: ``k cot(k(x - s)) ds = [1/(t - tau) + tau/(1 + tau^2)] d tau``,
whose second term integrates to zero against a symmetric pressure, so the
row is the single Hertz-type problem on ``|tau| < A = tan(k b)``:

    PV int_{-A}^{A} p(tau) / (t - tau) d tau = (pi E* / 2) g'(arctan(t) / k) =: F(t).

Its solution bounded at both edges (the smooth gap's patch has no pressure
step there) is ``p(A eta) = sqrt(1 - eta^2) sum_n c_n U_(n-1)(eta)`` with
``pi c_n`` the Chebyshev coefficients ``T_n`` of ``F(A zeta)`` (from
``(1/pi) PV int sqrt(1 - eta^2) U_(n-1)(eta) / (zeta - eta) d eta = T_n(zeta)``),
and the load per period is

    P = int p(s) ds = (A / k) int_{-1}^{1} p(A eta) / (1 + A^2 eta^2) d eta,

integrated by Gauss-Chebyshev quadrature of the second kind.  ``P`` grows
with ``b``; the half-width of a given load is its root.  For ``k b -> 0``
this is Hertz (``F = pi E* t / (2 k R)``, ``c_1 = E* b / (2R)``,
``P = pi E* b^2 / (4 R)``); for the sinusoidal gap it is Westergaard's
``sin^2(k a) = p / p*`` (both held by tests/verification/test_periodic_hertz.py).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np
from numpy.polynomial import chebyshev
from scipy import optimize

from ngcontact.errors import ModelError
from ngcontact.verification.admissible import _nonnegative, _positive

__all__ = ["periodic_load", "periodic_hertz_half_width"]

#: Chebyshev terms of ``F(A zeta)`` and quadrature points: ``F`` is analytic in a wide ellipse around
#: ``[-1, 1]`` (``arctan`` has its poles at ``+- i / A``), so 64 terms reach round-off for ``k b <= 1.4``
TERMS = 64


def periodic_load(half_width: float, slope: Callable[[np.ndarray], np.ndarray], E_star: float,
                  period: float) -> float:
    """Load per period of the symmetric periodic contact of half-width ``half_width`` (module docstring).

    ``slope``: the gap's derivative ``g'(x)``, odd in ``x`` (the gap's minimum at ``x = 0``), vectorized.
    """
    _positive("half_width", half_width)
    _positive("E_star", E_star)
    _positive("period", period)
    k = math.pi / period
    if not k * half_width <= 0.45 * math.pi:
        raise ModelError(f"half_width = {half_width!r}: must be at most 0.45 of the period {period!r}")
    A = math.tan(k * half_width)
    def rhs(z: np.ndarray) -> np.ndarray:
        return 0.5 * math.pi * E_star * np.asarray(slope(np.arctan(A * z) / k), dtype=float)

    F = np.asarray(chebyshev.chebinterpolate(rhs, TERMS), dtype=float)  # type: ignore[type-var]
    c = F[1:] / math.pi                                     # c_n, n = 1 .. TERMS
    j = np.arange(1, TERMS + 2)
    theta = j * math.pi / (TERMS + 2)
    eta, w = np.cos(theta), math.pi / (TERMS + 2) * np.sin(theta) ** 2
    # U_(n-1)(cos theta) = sin(n theta) / sin(theta)
    n = np.arange(1, len(c) + 1)
    u = np.sin(np.outer(theta, n)) / np.sin(theta)[:, None]
    return float(A / k * np.sum(w * (u @ c) / (1.0 + (A * eta) ** 2)))


def periodic_hertz_half_width(load_per_period: float, R: float, E_star: float, period: float) -> float:
    """Half-width of each patch of a row of cylinders ``x^2 / (2R)`` of period ``period`` under
    ``load_per_period`` (the root of :func:`periodic_load` in ``b``; Hertz's ``sqrt(4 P R / (pi E*))`` for
    a patch narrow against the period)."""
    _nonnegative("load_per_period", load_per_period)
    _positive("R", R)
    if load_per_period == 0:
        return 0.0

    def excess(b: float) -> float:
        return periodic_load(b, lambda x: x / R, E_star, period) - load_per_period

    high = 0.45 * period
    if excess(high) < 0:
        raise ModelError(f"load_per_period = {load_per_period!r}: beyond the load of a patch 0.45 of the period")
    return float(optimize.brentq(excess, 1e-12 * period, high, xtol=1e-15 * period, rtol=1e-15))
