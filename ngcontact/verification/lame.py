"""Lamé's thick rings, and the press fit of two coaxial cylinders through a Winkler layer (plane strain).

Pure NumPy: nothing here meshes or solves.  Lengths and stresses are in any
consistent set of units; pressures are **compression positive**, as in every
report of the package.

Thick ring
    In a ring ``r1 < r < r2`` (a solid disk when ``r1 = 0``) the radial
    displacement is ``u_r = A r + B/r`` and the radial stress
    ``sigma_rr = 2(lam + mu) A - 2 mu B/r^2``; with ``sigma_rr = -p_in`` at
    the inner and ``-p_out`` at the outer radius

        u_r(r) = (1 + nu)/E * [ (1 - 2nu) s r + t / r ],
        s = (p_in r1^2 - p_out r2^2)/(r2^2 - r1^2),
        t = (p_in - p_out) r1^2 r2^2/(r2^2 - r1^2)

    (for a solid disk ``r1 = 0``: ``t = 0``, ``s = -p_out``).

Press fit
    An inner cylinder ``a < r < b`` (solid when ``a = 0``) is forced into an
    outer one ``b < r < c`` with radial interference ``delta``.  Under the
    interface pressure ``p`` the outer bore opens by ``p C_out`` and the
    inner mantle closes by ``p C_in``,

        C_out = (1 + nu_out) b ((1 - 2nu_out) b^2 + c^2) / (E_out (c^2 - b^2)),
        C_in  = (1 + nu_in)  b ((1 - 2nu_in)  b^2 + a^2) / (E_in  (b^2 - a^2)).

    A Winkler interface layer of stiffness ``k_n`` (pressure ``p = k_n x``
    its compression ``x``) takes up the rest of the interference,
    ``delta = p C_in + p C_out + p/k_n``, so the compliances add in series:

        p = delta / (C_in + C_out + 1/k_n)    (0 when delta <= 0).

Inadmissible arguments (a modulus <= 0, Poisson's ratio outside (-1, 0.5),
radii out of order) raise :class:`ngcontact.errors.ModelError` naming the
argument, its value and what is allowed.
"""
from __future__ import annotations

import math

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.verification.admissible import _nonnegative, _out, _poisson, _positive

__all__ = ["lame_radial_displacement", "lame_press_fit_pressure"]


def lame_radial_displacement(r, r_in: float, r_out: float, E: float, nu: float,
                             p_in: float = 0.0, p_out: float = 0.0):
    """Radial displacement of a thick ring (plane strain) under pressures on its faces.

    Parameters
    ----------
    r
        Radius (radii) at which to evaluate, ``r_in <= r <= r_out``.
    r_in, r_out
        Inner and outer radius; ``r_in = 0`` is a solid disk (then ``p_in``
        is not used: the displacement stays bounded at the centre).
    E, nu
        Young's modulus and Poisson's ratio.
    p_in, p_out
        Pressures on the inner and outer face, compression positive
        (``sigma_rr = -p_in`` at ``r_in``, ``-p_out`` at ``r_out``).

    Returns
    -------
    float or numpy.ndarray
        ``u_r(r) = (1 + nu)/E [(1 - 2nu) s r + t/r]`` with
        ``s = (p_in r_in^2 - p_out r_out^2)/(r_out^2 - r_in^2)`` and
        ``t = (p_in - p_out) r_in^2 r_out^2/(r_out^2 - r_in^2)``; positive
        outward.
    """
    _nonnegative("r_in", r_in)
    if not r_out > r_in:
        raise ModelError(f"r_out = {r_out!r}: must be > r_in = {r_in!r}")
    _positive("E", E)
    _poisson("nu", nu)
    r = np.asarray(r, dtype=float)
    span = r_out ** 2 - r_in ** 2
    s = (p_in * r_in ** 2 - p_out * r_out ** 2) / span
    t = (p_in - p_out) * r_in ** 2 * r_out ** 2 / span
    with np.errstate(divide="ignore", invalid="ignore"):
        hole = np.where(r > 0, t / np.where(r > 0, r, 1.0), 0.0)
    return _out((1.0 + nu) / E * ((1.0 - 2.0 * nu) * s * r + hole))


def lame_press_fit_pressure(a: float, b: float, c: float, E_in: float, nu_in: float, E_out: float,
                            nu_out: float, interference: float, k_n: float = math.inf) -> float:
    """Interface pressure of a plane-strain press fit of two coaxial cylinders.

    Parameters
    ----------
    a, b, c
        Bore of the inner cylinder (0: solid), interface radius, outer
        radius of the outer cylinder; ``0 <= a < b < c``.
    E_in, nu_in, E_out, nu_out
        Elastic constants of the inner and the outer cylinder.
    interference
        Radial interference ``delta`` (inner outer radius minus outer bore
        radius before assembly); ``<= 0`` is a clearance and gives 0.
    k_n
        Winkler stiffness of the interface layer (pressure per unit
        compression); ``math.inf`` is a rigid interface.

    Returns
    -------
    float
        ``p = delta / (C_in + C_out + 1/k_n)``, compression positive, with
        the compliances ``C_in = -u_r,in(b)/p`` and ``C_out = u_r,out(b)/p``
        of the two rings (:func:`lame_radial_displacement`).
    """
    if not 0 <= a < b < c:
        raise ModelError(f"(a, b, c) = {(a, b, c)!r}: need 0 <= a < b < c")
    _positive("k_n", k_n)
    if interference <= 0:
        return 0.0
    c_in = -lame_radial_displacement(b, a, b, E_in, nu_in, p_out=1.0)
    c_out = lame_radial_displacement(b, b, c, E_out, nu_out, p_in=1.0)
    return interference / (c_in + c_out + 1.0 / k_n)
