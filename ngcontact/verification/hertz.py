"""Hertz's line contact of a cylinder on a plane (2D, plane strain).

Pure NumPy: nothing here meshes or solves.  Lengths and stresses are in any
consistent set of units; pressures are **compression positive**, as in every
report of the package.

A cylinder of effective radius ``R`` (``1/R = 1/R1 + 1/R2``) on a plane, gap
``R - sqrt(R^2 - x^2)`` (about ``x^2/(2R)``), load ``P'`` per unit length,
contact modulus ``E*`` (:func:`ngcontact.verification.moduli.e_star`):

    a = sqrt(4 P' R / (pi E*)),   p(x) = (2P'/(pi a^2)) sqrt(a^2 - x^2),
    p_max = 2P'/(pi a).

Inadmissible arguments (a radius or modulus <= 0, a negative load) raise
:class:`ngcontact.errors.ModelError` naming the argument, its value and what
is allowed.
"""
from __future__ import annotations

import math

import numpy as np

from ngcontact.verification.admissible import _nonnegative, _out, _positive

__all__ = ["hertz_half_width", "hertz_pressure", "hertz_peak_pressure"]


def hertz_half_width(load_per_length: float, R: float, E_star: float) -> float:
    """Half-width of the Hertzian line contact of a cylinder on a plane.

    Parameters
    ----------
    load_per_length
        Normal load per unit length ``P'`` (``>= 0``).
    R
        Effective radius, ``1/R = 1/R1 + 1/R2``.
    E_star
        Contact modulus (:func:`~ngcontact.verification.moduli.e_star`).

    Returns
    -------
    float
        ``a = sqrt(4 P' R / (pi E*))``.
    """
    _nonnegative("load_per_length", load_per_length)
    _positive("R", R)
    _positive("E_star", E_star)
    return math.sqrt(4.0 * load_per_length * R / (math.pi * E_star))


def hertz_pressure(x, load_per_length: float, R: float, E_star: float):
    """Hertzian line-contact pressure at ``x`` (measured from the contact centre).

    Parameters
    ----------
    x
        Position(s) along the surface.
    load_per_length, R, E_star
        As in :func:`hertz_half_width`.

    Returns
    -------
    float or numpy.ndarray
        ``(2P'/(pi a^2)) sqrt(a^2 - x^2)`` for ``|x| < a``, 0 outside;
        compression positive.
    """
    a = hertz_half_width(load_per_length, R, E_star)
    x = np.asarray(x, dtype=float)
    if a == 0:
        return _out(np.zeros_like(x))
    return _out(2.0 * load_per_length / (math.pi * a ** 2) * np.sqrt(np.maximum(a ** 2 - x ** 2, 0.0)))


def hertz_peak_pressure(load_per_length: float, R: float, E_star: float) -> float:
    """Largest Hertzian line-contact pressure, at the centre.

    Parameters
    ----------
    load_per_length, R, E_star
        As in :func:`hertz_half_width`.

    Returns
    -------
    float
        ``p_max = 2P'/(pi a) = sqrt(P' E* / (pi R))``.
    """
    a = hertz_half_width(load_per_length, R, E_star)
    return 2.0 * load_per_length / (math.pi * a) if a > 0 else 0.0
