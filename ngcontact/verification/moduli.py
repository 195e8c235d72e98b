"""Elastic moduli of an isotropic material, and the plane-strain contact modulus.

Pure arithmetic: nothing here meshes or solves.  Moduli are in any
consistent unit of stress.

Plane-strain contact modulus
    Two elastic bodies pressed together respond like one body of modulus
    ``E*`` against a rigid one, with

        1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2

    (the second term is dropped for a rigid second body).

P-wave (uniaxial-strain) modulus
    ``M = E(1 - nu)/((1 + nu)(1 - 2nu))``: normal stress over normal strain
    when the lateral strains are held at zero.

Shear modulus
    ``G = E/(2(1 + nu))``.

Inadmissible arguments (a modulus <= 0, Poisson's ratio outside (-1, 0.5))
raise :class:`ngcontact.errors.ModelError` naming the argument, its value and
what is allowed.
"""
from __future__ import annotations

import math

from ngcontact.errors import ModelError
from ngcontact.verification.admissible import _poisson, _positive

__all__ = ["e_star", "p_wave_modulus", "shear_modulus"]


def e_star(E1: float, nu1: float, E2: float | None = None, nu2: float | None = None) -> float:
    """Plane-strain contact modulus ``E*`` of two elastic bodies.

    Parameters
    ----------
    E1, nu1
        Young's modulus and Poisson's ratio of the first body.
    E2, nu2
        The same for the second body; ``E2 = None`` (or ``math.inf``) makes
        it rigid, and then ``nu2`` is not used.

    Returns
    -------
    float
        ``E*`` with ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2``.
    """
    _positive("E1", E1)
    _poisson("nu1", nu1)
    compliance = (1.0 - nu1 ** 2) / E1
    if E2 is not None and not math.isinf(E2):
        _positive("E2", E2)
        if nu2 is None:
            raise ModelError("nu2 = None: give Poisson's ratio of the second body with E2 (or E2 = None: rigid)")
        _poisson("nu2", nu2)
        compliance += (1.0 - nu2 ** 2) / E2
    return 1.0 / compliance


def p_wave_modulus(E: float, nu: float) -> float:
    """Uniaxial-strain (P-wave) modulus ``M = E(1 - nu)/((1 + nu)(1 - 2nu))``.

    Parameters
    ----------
    E, nu
        Young's modulus and Poisson's ratio.

    Returns
    -------
    float
        ``M``.
    """
    _positive("E", E)
    _poisson("nu", nu)
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


def shear_modulus(E: float, nu: float) -> float:
    """Shear modulus ``G = E/(2(1 + nu))``.

    Parameters
    ----------
    E, nu
        Young's modulus and Poisson's ratio.

    Returns
    -------
    float
        ``G``.
    """
    _positive("E", E)
    _poisson("nu", nu)
    return E / (2.0 * (1.0 + nu))
