"""Westergaard's periodic sinusoidal contact of two elastic half-planes (2D, small slopes).

Pure NumPy: nothing here meshes or solves.  Lengths and stresses are in any
consistent set of units; pressures are **compression positive**, as in every
report of the package.

Initial gap ``g(x) = 2h sin^2(pi x/lambda)`` between two half-planes, ``x``
measured from a point where the gap vanishes (the contact centre), mean
pressure ``p`` per period ``lambda``, contact modulus ``E*``
(:func:`ngcontact.verification.moduli.e_star`).  Full contact needs

    p* = pi E* h / lambda.

Below it the contact patches have half-width ``a`` with

    p = p* sin^2(pi a/lambda),   contact fraction 2a/lambda,

and carry, for ``|x| < a`` (periodically repeated),

    p(x) = 2p |cos(pi x/lambda)| sqrt(sin^2(pi a/lambda) - sin^2(pi x/lambda))
           / sin^2(pi a/lambda),

zero elsewhere.  For ``p >= p*`` the surfaces touch everywhere and

    p(x) = p + p* cos(2 pi x/lambda).

Both forms agree at ``p = p*``, where ``p(x) = 2p* cos^2(pi x/lambda)``.

Inadmissible arguments (a modulus, amplitude or wavelength <= 0, a negative
pressure) raise :class:`ngcontact.errors.ModelError` naming the argument, its
value and what is allowed.
"""
from __future__ import annotations

import math

import numpy as np

from ngcontact.verification.admissible import _nonnegative, _out, _positive

__all__ = [
    "westergaard_p_star",
    "westergaard_contact_half_width",
    "westergaard_contact_fraction",
    "westergaard_pressure",
]


def westergaard_p_star(E_star: float, h: float, wavelength: float) -> float:
    """Mean pressure that closes a sinusoidal gap ``2h sin^2(pi x/lambda)`` completely.

    Parameters
    ----------
    E_star
        Contact modulus (:func:`~ngcontact.verification.moduli.e_star`).
    h
        Gap amplitude: the gap ranges over ``[0, 2h]``.
    wavelength
        Period ``lambda`` of the gap.

    Returns
    -------
    float
        ``p* = pi E* h / lambda``.
    """
    _positive("E_star", E_star)
    _positive("h", h)
    _positive("wavelength", wavelength)
    return math.pi * E_star * h / wavelength


def westergaard_contact_half_width(p: float, p_star: float, wavelength: float) -> float:
    """Half-width ``a`` of each contact patch at the mean pressure ``p``.

    Parameters
    ----------
    p
        Mean pressure over one period, compression positive (``>= 0``).
    p_star
        Pressure of full contact (:func:`westergaard_p_star`).
    wavelength
        Period ``lambda``.

    Returns
    -------
    float
        ``a = (lambda/pi) asin(sqrt(p/p*))`` for ``p < p*``; ``lambda/2``
        (full contact) for ``p >= p*``.
    """
    _nonnegative("p", p)
    _positive("p_star", p_star)
    _positive("wavelength", wavelength)
    if p >= p_star:
        return 0.5 * wavelength
    return wavelength / math.pi * math.asin(math.sqrt(p / p_star))


def westergaard_contact_fraction(p: float, p_star: float) -> float:
    """Share of each period in contact, ``2a/lambda``, at the mean pressure ``p``.

    Parameters
    ----------
    p
        Mean pressure, compression positive (``>= 0``).
    p_star
        Pressure of full contact.

    Returns
    -------
    float
        ``(2/pi) asin(sqrt(p/p*))``, and 1 for ``p >= p*``.
    """
    return 2.0 * westergaard_contact_half_width(p, p_star, 1.0)


def westergaard_pressure(x, p: float, p_star: float, wavelength: float):
    """Contact pressure of Westergaard's sinusoid at ``x``.

    Parameters
    ----------
    x
        Position(s) along the interface, measured from the contact centre
        (where the gap is zero); any real values, the solution is periodic.
    p
        Mean pressure, compression positive (``>= 0``).
    p_star
        Pressure of full contact.
    wavelength
        Period ``lambda``.

    Returns
    -------
    float or numpy.ndarray
        The pressure (compression positive), shaped like ``x``: partial
        contact (``p < p*``) ``2p |cos(pi x/lambda)| sqrt(s_a - sin^2(pi
        x/lambda)) / s_a`` with ``s_a = p/p* = sin^2(pi a/lambda)`` inside
        the patches and 0 outside; full contact ``p + p* cos(2 pi x/lambda)``.
    """
    _nonnegative("p", p)
    _positive("p_star", p_star)
    _positive("wavelength", wavelength)
    phase = math.pi * np.asarray(x, dtype=float) / wavelength
    if p >= p_star:
        return _out(p + p_star * np.cos(2.0 * phase))
    if p == 0:
        return _out(np.zeros_like(phase))
    s_a = p / p_star                       # sin^2(pi a / lambda)
    room = s_a - np.sin(phase) ** 2        # > 0 inside the patches
    inside = 2.0 * p * np.abs(np.cos(phase)) * np.sqrt(np.maximum(room, 0.0)) / s_a
    return _out(np.where(room > 0, inside, 0.0))
