"""Closed-form solutions the numerical contact models are checked against.

Pure NumPy: nothing here meshes or solves.  Lengths, stresses and stiffnesses
are in any consistent set of units; pressures are **compression positive**,
as in every report of the package.

Plane-strain contact modulus
    Two elastic bodies pressed together respond like one body of modulus
    ``E*`` against a rigid one, with

        1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2

    (the second term is dropped for a rigid second body).

Westergaard's periodic sinusoid (2D, small slopes)
    Initial gap ``g(x) = 2h sin^2(pi x/lambda)`` between two half-planes,
    ``x`` measured from a point where the gap vanishes (the contact centre),
    mean pressure ``p`` per period ``lambda``.  Full contact needs

        p* = pi E* h / lambda.

    Below it the contact patches have half-width ``a`` with

        p = p* sin^2(pi a/lambda),   contact fraction 2a/lambda,

    and carry, for ``|x| < a`` (periodically repeated),

        p(x) = 2p |cos(pi x/lambda)| sqrt(sin^2(pi a/lambda) - sin^2(pi x/lambda))
               / sin^2(pi a/lambda),

    zero elsewhere.  For ``p >= p*`` the surfaces touch everywhere and

        p(x) = p + p* cos(2 pi x/lambda).

    Both forms agree at ``p = p*``, where ``p(x) = 2p* cos^2(pi x/lambda)``.

Hertz line contact (2D)
    A cylinder of effective radius ``R`` (``1/R = 1/R1 + 1/R2``) on a plane,
    gap ``R - sqrt(R^2 - x^2)`` (about ``x^2/(2R)``), load ``P'`` per unit
    length:

        a = sqrt(4 P' R / (pi E*)),   p(x) = (2P'/(pi a^2)) sqrt(a^2 - x^2),
        p_max = 2P'/(pi a).

Lamé press fit (plane strain)
    An inner cylinder ``a < r < b`` (solid when ``a = 0``) is forced into an
    outer one ``b < r < c`` with radial interference ``delta``.  In each ring
    the radial displacement is ``u_r = A r + B/r`` and the radial stress
    ``sigma_rr = 2(lam + mu) A - 2 mu B/r^2``; with ``sigma_rr = -p_in`` at
    the inner and ``-p_out`` at the outer radius ``r1 < r2``

        u_r(r) = (1 + nu)/E * [ (1 - 2nu) s r + t / r ],
        s = (p_in r1^2 - p_out r2^2)/(r2^2 - r1^2),
        t = (p_in - p_out) r1^2 r2^2/(r2^2 - r1^2)

    (for a solid disk ``r1 = 0``: ``t = 0``, ``s = -p_out``).  Under the
    interface pressure ``p`` the outer bore opens by ``p C_out`` and the inner
    mantle closes by ``p C_in``,

        C_out = (1 + nu_out) b ((1 - 2nu_out) b^2 + c^2) / (E_out (c^2 - b^2)),
        C_in  = (1 + nu_in)  b ((1 - 2nu_in)  b^2 + a^2) / (E_in  (b^2 - a^2)).

    A Winkler interface layer of stiffness ``k_n`` (pressure ``p = k_n x``
    its compression ``x``) takes up the rest of the interference,
    ``delta = p C_in + p C_out + p/k_n``, so the compliances add in series:

        p = delta / (C_in + C_out + 1/k_n)    (0 when delta <= 0).

Flat bonded laminate
    Two layers of thicknesses ``h1, h2`` stacked along the normal, loaded by a
    uniform traction on their far faces.  Per unit area each layer is a spring
    of normal stiffness ``M/h`` (uniaxial strain, P-wave modulus
    ``M = E(1 - nu)/((1 + nu)(1 - 2nu))``) and shear stiffness ``G/h``
    (``G = E/(2(1 + nu))``); in series

        K_n = 1/(h1/M1 + h2/M2),   K_t = 1/(h1/G1 + h2/G2)

    (an interface spring ``k_n``, ``k_t`` between them adds ``1/k``).

Penalty bar against a wall
    An elastic bar of length ``L``, modulus ``E``, cross-section ``A``, pushed
    by ``d`` at one end towards a wall at the distance ``g0`` from its other
    end, whose contact is a penalty layer of stiffness ``k`` per unit area:
    bar and layer are springs in series,

        F = (d - g0) / (L/(E A) + 1/(k A))    for d > g0, else 0.

Inadmissible arguments (a modulus <= 0, Poisson's ratio outside (-1, 0.5),
radii out of order, a negative pressure) raise
:class:`ngcontact.errors.ModelError` naming the argument, its value and what
is allowed.
"""
from __future__ import annotations

import math

import numpy as np

from ngcontact.errors import ModelError

__all__ = [
    "e_star",
    "westergaard_p_star",
    "westergaard_contact_half_width",
    "westergaard_contact_fraction",
    "westergaard_pressure",
    "hertz_half_width",
    "hertz_pressure",
    "hertz_peak_pressure",
    "lame_radial_displacement",
    "lame_press_fit_pressure",
    "p_wave_modulus",
    "shear_modulus",
    "laminate_stiffness",
    "penalty_bar_force",
]


def _positive(name: str, value: float) -> None:
    if not value > 0:
        raise ModelError(f"{name} = {value!r}: must be > 0")


def _nonnegative(name: str, value: float) -> None:
    if not value >= 0:
        raise ModelError(f"{name} = {value!r}: must be >= 0")


def _poisson(name: str, value: float) -> None:
    if not -1.0 < value < 0.5:
        raise ModelError(f"{name} = {value!r}: must lie in (-1, 0.5)")


def _out(value):
    """A 0-d result as a Python float, arrays unchanged."""
    value = np.asarray(value, dtype=float)
    return float(value) if value.ndim == 0 else value


# ------------------------------------------------------------ contact modulus
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


# ---------------------------------------------------------------- Westergaard
def westergaard_p_star(E_star: float, h: float, wavelength: float) -> float:
    """Mean pressure that closes a sinusoidal gap ``2h sin^2(pi x/lambda)`` completely.

    Parameters
    ----------
    E_star
        Contact modulus (:func:`e_star`).
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


# ---------------------------------------------------------------------- Hertz
def hertz_half_width(load_per_length: float, R: float, E_star: float) -> float:
    """Half-width of the Hertzian line contact of a cylinder on a plane.

    Parameters
    ----------
    load_per_length
        Normal load per unit length ``P'`` (``>= 0``).
    R
        Effective radius, ``1/R = 1/R1 + 1/R2``.
    E_star
        Contact modulus (:func:`e_star`).

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


# ----------------------------------------------------------------------- Lamé
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


# ------------------------------------------------------------------- laminate
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
        ``K_t = 1/(h1/G1 + h2/G2 + 1/k_t)`` (:func:`p_wave_modulus`,
        :func:`shear_modulus`).
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
