"""Elastic layers and bars as springs in series: the flat bonded laminate and the penalty bar.

Pure NumPy: nothing here meshes or solves.  Lengths, stresses and stiffnesses
are in any consistent set of units; forces are **compression positive**, as
in every report of the package.

Flat bonded laminate
    Two layers of thicknesses ``h1, h2`` stacked along the normal, loaded by a
    uniform traction on their far faces.  Per unit area each layer is a spring
    of normal stiffness ``M/h`` (uniaxial strain, P-wave modulus
    ``M = E(1 - nu)/((1 + nu)(1 - 2nu))``) and shear stiffness ``G/h``
    (``G = E/(2(1 + nu))``; both in :mod:`ngcontact.verification.moduli`);
    in series

        K_n = 1/(h1/M1 + h2/M2),   K_t = 1/(h1/G1 + h2/G2)

    (an interface spring ``k_n``, ``k_t`` between them adds ``1/k``).

Penalty bar against a wall
    An elastic bar of length ``L``, modulus ``E``, cross-section ``A``, pushed
    by ``d`` at one end towards a wall at the distance ``g0`` from its other
    end, whose contact is a penalty layer of stiffness ``k`` per unit area:
    bar and layer are springs in series,

        F = (d - g0) / (L/(E A) + 1/(k A))    for d > g0, else 0.

Inadmissible arguments (a thickness, modulus or stiffness <= 0, Poisson's
ratio outside (-1, 0.5)) raise :class:`ngcontact.errors.ModelError` naming the
argument, its value and what is allowed.
"""
from __future__ import annotations

import math

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.verification.admissible import _positive
from ngcontact.verification.moduli import p_wave_modulus, shear_modulus

__all__ = ["laminate_stiffness", "penalty_bar_force"]


def laminate_stiffness(h1: float, E1: float, nu1: float, h2: float, E2: float, nu2: float, *,
                       dim: int = 2, k_n: float = math.inf, k_t: float = math.inf) -> np.ndarray:
    """Stiffness per unit area of two bonded layers in series (far-face traction / far-face jump).

    Parameters
    ----------
    h1, E1, nu1
        Thickness and elastic constants of the first layer.
    h2, E2, nu2
        The same for the second layer.
    dim
        2: the 2x2 matrix in the basis (normal, shear); 3: the 3x3 matrix in
        (normal, shear 1, shear 2).
    k_n, k_t
        Optional interface springs between the layers (stress per length);
        ``math.inf`` (the default) bonds them.

    Returns
    -------
    numpy.ndarray
        ``diag(K_n, K_t[, K_t])`` with ``K_n = 1/(h1/M1 + h2/M2 + 1/k_n)`` and
        ``K_t = 1/(h1/G1 + h2/G2 + 1/k_t)``
        (:func:`~ngcontact.verification.moduli.p_wave_modulus`,
        :func:`~ngcontact.verification.moduli.shear_modulus`).
    """
    _positive("h1", h1)
    _positive("h2", h2)
    _positive("k_n", k_n)
    _positive("k_t", k_t)
    if dim not in (2, 3):
        raise ModelError(f"dim = {dim!r}: must be 2 or 3")
    k_normal = 1.0 / (h1 / p_wave_modulus(E1, nu1) + h2 / p_wave_modulus(E2, nu2) + 1.0 / k_n)
    k_shear = 1.0 / (h1 / shear_modulus(E1, nu1) + h2 / shear_modulus(E2, nu2) + 1.0 / k_t)
    return np.diag([k_normal] + [k_shear] * (dim - 1))


def penalty_bar_force(d: float, g0: float, L: float, E: float, A: float, k: float) -> float:
    """Force of an elastic bar pushed against a wall through a penalty layer.

    Parameters
    ----------
    d
        Displacement imposed at the far end of the bar, towards the wall.
    g0
        Initial gap between the bar and the wall.
    L, E, A
        Length, Young's modulus and cross-section of the bar.
    k
        Penalty stiffness of the contact layer per unit area (stress per
        length).

    Returns
    -------
    float
        ``F = (d - g0)/(L/(E A) + 1/(k A))`` (compression positive) when
        ``d > g0``, else 0.
    """
    _positive("L", L)
    _positive("E", E)
    _positive("A", A)
    _positive("k", k)
    if d <= g0:
        return 0.0
    return (d - g0) / (L / (E * A) + 1.0 / (k * A))
