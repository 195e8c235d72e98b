"""The analytic oracles of :mod:`ngcontact.verification.oracles`, each against an independent computation.

No formula is checked against itself: Westergaard's pressure is integrated
numerically and fed through the periodic half-plane response (Fourier
series) to see that it closes the gap exactly where it is positive; Hertz is
integrated and recovered as the small-load limit of Westergaard; Lamé is the
4x4 linear system of the ring boundary conditions solved here; the laminate
is read off the 3D isotropic stiffness matrix; the bar is an explicit
two-spring equilibrium.
"""
import math

import numpy as np
import pytest
from scipy import integrate

from ngcontact.errors import ModelError
from ngcontact.verification import oracles as O

E, NU = 1.0, 0.3
H, WAVE = 0.01, 1.0


# ------------------------------------------------------------ contact modulus
def test_e_star_of_two_equal_bodies_and_of_a_rigid_one():
    assert O.e_star(E, NU, E, NU) == pytest.approx(E / (2 * (1 - NU ** 2)), rel=1e-15)
    assert O.e_star(E, NU) == pytest.approx(E / (1 - NU ** 2), rel=1e-15)
    assert O.e_star(E, NU, math.inf) == O.e_star(E, NU)
    assert O.e_star(2.0, 0.2, 5.0, 0.4) == pytest.approx(O.e_star(5.0, 0.4, 2.0, 0.2), rel=1e-15)
    with pytest.raises(ModelError, match="nu2"):
        O.e_star(1.0, 0.3, 2.0)
    with pytest.raises(ModelError, match=r"nu1 = 0\.5: must lie in"):
        O.e_star(1.0, 0.5)


# ---------------------------------------------------------------- Westergaard
def _p_star():
    return O.westergaard_p_star(O.e_star(E, NU, E, NU), H, WAVE)


def test_westergaard_p_star_of_the_shipped_scene():
    # geometries/cells/westergaard.toml states p* = 0.0172615 for these numbers
    assert _p_star() == pytest.approx(0.0172615, rel=1e-6)
    assert O.westergaard_p_star(2.0, 0.1, 4.0) == pytest.approx(math.pi * 0.05, rel=1e-15)


@pytest.mark.parametrize("ratio", [0.05, 0.3, 0.8, 0.999, 1.0, 1.2, 3.0])
def test_westergaard_pressure_integrates_to_the_mean_pressure(ratio):
    ps = _p_star()
    p = ratio * ps
    a = O.westergaard_contact_half_width(p, ps, WAVE)
    edges = [-a, a] if a < WAVE / 2 else []
    total, _ = integrate.quad(lambda x: O.westergaard_pressure(x, p, ps, WAVE), -WAVE / 2, WAVE / 2,
                              points=edges or None, limit=200, epsabs=1e-14, epsrel=1e-12)
    assert total / WAVE == pytest.approx(p, rel=1e-9)
    x = np.linspace(-WAVE / 2, WAVE / 2, 2001)
    q = O.westergaard_pressure(x, p, ps, WAVE)
    assert np.all(q >= 0)
    if ratio < 1:
        assert np.all(q[np.abs(x) >= a] == 0) and np.all(q[np.abs(x) < 0.99 * a] > 0)
        assert O.westergaard_contact_fraction(p, ps) == pytest.approx(2 * a / WAVE, rel=1e-15)
    else:
        assert O.westergaard_contact_fraction(p, ps) == 1.0


def test_westergaard_pressure_is_continuous_at_full_contact_and_periodic():
    ps = _p_star()
    x = np.linspace(-1.3, 2.7, 801)
    below = O.westergaard_pressure(x, ps * (1 - 1e-12), ps, WAVE)
    above = O.westergaard_pressure(x, ps, ps, WAVE)
    np.testing.assert_allclose(below, above, atol=1e-6 * ps)
    np.testing.assert_allclose(above, 2 * ps * np.cos(math.pi * x) ** 2, atol=1e-15)
    p = 0.4 * ps
    np.testing.assert_allclose(O.westergaard_pressure(x + 3 * WAVE, p, ps, WAVE),
                               O.westergaard_pressure(x, p, ps, WAVE), atol=1e-12 * ps)
    assert O.westergaard_contact_fraction(0.0, ps) == 0.0
    assert O.westergaard_pressure(0.1, 0.0, ps, WAVE) == 0.0


@pytest.mark.parametrize("ratio", [0.1, 0.5, 0.9, 1.5])
def test_westergaard_pressure_closes_the_gap_exactly_where_it_acts(ratio):
    """The periodic half-plane response to the pressure, a Fourier series.

    A load ``q cos(k x)`` on two half-planes compresses them together by
    ``2 q cos(k x) / (E* k)`` (plus a constant set by the far field): that is
    the surface Green's function of plane elasticity, independent of the
    closed form.  After a rigid approach the remaining gap is ``g + w - const``:
    where the pressure acts, compression plus gap must be constant; where it
    vanishes, the gap must stay open (compression plus gap above that level).
    """
    ps, es = _p_star(), O.e_star(E, NU, E, NU)
    p = ratio * ps
    n = 2 ** 14
    x = (np.arange(n) + 0.5) * WAVE / n - WAVE / 2      # midpoints: no sample on a contact edge
    q = O.westergaard_pressure(x, p, ps, WAVE)
    coef = np.fft.rfft(q) / n
    k = 2 * math.pi * np.fft.rfftfreq(n, d=WAVE / n)
    comp = np.zeros_like(coef)
    comp[1:] = 2 * coef[1:] / (es * k[1:])
    w = np.fft.irfft(comp, n) * n                         # compression, up to a constant
    gap = 2 * H * np.sin(math.pi * x / WAVE) ** 2
    mismatch = w + gap
    a = O.westergaard_contact_half_width(p, ps, WAVE)
    inside = np.abs(x) < 0.98 * a
    level = mismatch[inside].mean()
    # the truncated series of the square-root edges: ~1e-6 h at 2^14 samples (1e-5 h at 2^12)
    assert np.ptp(mismatch[inside]) < 1e-5 * H, f"p/p* = {ratio}: compression plus gap varies"
    outside = np.abs(x) > 1.02 * a
    if outside.any():
        assert np.all(mismatch[outside] > level), "the surfaces would overlap outside the contact patch"


# ---------------------------------------------------------------------- Hertz
def test_hertz_pressure_integrates_to_the_load_and_peaks_at_the_centre():
    P, R, es = 3.0, 0.7, 11.0
    a = O.hertz_half_width(P, R, es)
    total, _ = integrate.quad(lambda x: O.hertz_pressure(x, P, R, es), -a, a, epsrel=1e-12)
    assert total == pytest.approx(P, rel=1e-10)
    x = np.linspace(-2 * a, 2 * a, 4001)
    q = O.hertz_pressure(x, P, R, es)
    assert q.max() == pytest.approx(O.hertz_peak_pressure(P, R, es), rel=1e-12)
    assert O.hertz_peak_pressure(P, R, es) == pytest.approx(math.sqrt(P * es / (math.pi * R)), rel=1e-14)
    assert np.all(q[np.abs(x) >= a] == 0)
    assert O.hertz_half_width(0.0, R, es) == 0.0 and O.hertz_peak_pressure(0.0, R, es) == 0.0


def test_hertz_is_the_small_load_limit_of_westergaard():
    """Near its zeros the sinusoidal gap is a parabola ``x^2 / (2R)`` with ``R = lambda^2/(4 pi^2 h)``;
    a contact patch much narrower than the period is then Hertzian with ``P' = p lambda``."""
    es = O.e_star(E, NU, E, NU)
    ps = O.westergaard_p_star(es, H, WAVE)
    R = WAVE ** 2 / (4 * math.pi ** 2 * H)
    p = 1e-6 * ps
    a_w = O.westergaard_contact_half_width(p, ps, WAVE)
    a_h = O.hertz_half_width(p * WAVE, R, es)
    assert a_w == pytest.approx(a_h, rel=1e-5)
    # inside the patch (the square-root edges amplify the 1e-6 relative difference of the widths)
    x = np.linspace(-0.99 * a_h, 0.99 * a_h, 101)
    np.testing.assert_allclose(O.westergaard_pressure(x, p, ps, WAVE), O.hertz_pressure(x, p * WAVE, R, es),
                               atol=1e-4 * O.hertz_peak_pressure(p * WAVE, R, es))


# ----------------------------------------------------------------------- Lamé
def _lame_system(a, b, c, Ei, nui, Eo, nuo, delta, kn):
    """Solve the ring boundary conditions for ``u_r = A r + B/r`` in each ring (plane strain).

    Unknowns ``(A_in, B_in, A_out, B_out)``; rows: free bore (or a bounded
    centre, ``B_in = 0``), equal radial stress at ``b``, free mantle, and the
    interference taken up by both rings and the layer: ``u_out(b) - u_in(b) + p/k_n = delta``.
    """
    def lame(E_, nu_):
        lam = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_))
        return lam, E_ / (2 * (1 + nu_))

    li, mi = lame(Ei, nui)
    lo, mo = lame(Eo, nuo)

    def srr(lam, mu, r):          # sigma_rr coefficients of (A, B)
        return [2 * (lam + mu), -2 * mu / r ** 2]

    M = np.zeros((4, 4))
    rhs = np.zeros(4)
    M[0, :2] = srr(li, mi, a) if a > 0 else [0.0, 1.0]
    M[1, :2] = srr(li, mi, b)
    M[1, 2:] = [-v for v in srr(lo, mo, b)]
    M[2, 2:] = srr(lo, mo, c)
    comp = 0.0 if math.isinf(kn) else 1.0 / kn
    # p = -sigma_rr,out(b)
    M[3, 2:] = [b, 1 / b]
    M[3, 2:] -= comp * np.array(srr(lo, mo, b))
    M[3, :2] = [-b, -1 / b]
    rhs[3] = delta
    A_in, B_in, A_out, B_out = np.linalg.solve(M, rhs)
    p = -(srr(lo, mo, b)[0] * A_out + srr(lo, mo, b)[1] * B_out)
    return p, (A_in, B_in), (A_out, B_out)


CASES = [(0.5, 1.0, 2.0, 200.0, 0.3, 70.0, 0.25, 1e-3, 300.0),     # the tubes of tests/test_macro.py
         (0.0, 1.0, 1.5, 100e9, 0.3, 9e9, 0.27, 5e-5, 32e9),        # solid stem in bone, hip-like numbers
         (0.2, 0.3, 0.9, 1.0, 0.45, 3.0, 0.1, 0.01, math.inf)]      # rigid interface


@pytest.mark.parametrize("case", CASES)
def test_lame_press_fit_pressure_solves_the_ring_boundary_conditions(case):
    a, b, c, Ei, nui, Eo, nuo, delta, kn = case
    p_sys, (Ai, Bi), (Ao, Bo) = _lame_system(*case)
    p = O.lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta, k_n=kn)
    assert p > 0 and p == pytest.approx(p_sys, rel=1e-12)
    r_in = np.linspace(max(a, 1e-3 * b), b, 7)
    r_out = np.linspace(b, c, 7)
    np.testing.assert_allclose(O.lame_radial_displacement(r_in, a, b, Ei, nui, p_out=p), Ai * r_in + Bi / r_in,
                               rtol=1e-11, atol=1e-11 * abs(Ai * b + Bi / b))
    np.testing.assert_allclose(O.lame_radial_displacement(r_out, b, c, Eo, nuo, p_in=p), Ao * r_out + Bo / r_out,
                               rtol=1e-11, atol=1e-11 * abs(Ao * b + Bo / b))


def test_lame_interface_compliance_limits():
    a, b, c, Ei, nui, Eo, nuo, delta = CASES[0][:8]
    rigid = O.lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta)
    stiff = O.lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta, k_n=1e12)
    assert stiff == pytest.approx(rigid, rel=1e-8) and stiff < rigid
    for kn in (1e-3, 1e-5):      # soft layer: the rings barely deform, the layer takes it all
        soft = O.lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta, k_n=kn)
        assert soft == pytest.approx(kn * delta, rel=1e2 * kn)
    assert O.lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, -delta) == 0.0
    with pytest.raises(ModelError, match="need 0 <= a < b < c"):
        O.lame_press_fit_pressure(1.0, 1.0, 2.0, Ei, nui, Eo, nuo, delta)


def test_lame_solid_disk_under_external_pressure_is_uniformly_compressed():
    # plane strain, sigma_rr = sigma_tt = -p: eps = -p (1 + nu)(1 - 2 nu) / E in both directions
    r = np.array([0.0, 0.3, 1.0])
    u = O.lame_radial_displacement(r, 0.0, 1.0, 5.0, 0.2, p_out=2.0)
    np.testing.assert_allclose(u, -2.0 * 1.2 * 0.6 / 5.0 * r, rtol=1e-14, atol=0)


# ------------------------------------------------------------------- laminate
def _isotropic_voigt(E_, nu_):
    lam = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_))
    mu = E_ / (2 * (1 + nu_))
    C = np.zeros((6, 6))
    C[:3, :3] = lam
    C[np.arange(3), np.arange(3)] += 2 * mu
    C[np.arange(3, 6), np.arange(3, 6)] = mu
    return C


def test_laminate_is_two_springs_in_series_read_off_the_3d_stiffness():
    h1, E1, nu1, h2, E2, nu2 = 0.3, 2.0, 0.25, 0.7, 50.0, 0.45
    C1, C2 = _isotropic_voigt(E1, nu1), _isotropic_voigt(E2, nu2)
    # uniaxial strain along 3: sigma_33 = C33 eps_33; simple shear 13: sigma_13 = C55 gamma_13
    kn = 1 / (h1 / C1[2, 2] + h2 / C2[2, 2])
    kt = 1 / (h1 / C1[4, 4] + h2 / C2[4, 4])
    K2 = O.laminate_stiffness(h1, E1, nu1, h2, E2, nu2)
    np.testing.assert_allclose(K2, np.diag([kn, kt]), rtol=1e-13)
    K3 = O.laminate_stiffness(h1, E1, nu1, h2, E2, nu2, dim=3)
    np.testing.assert_allclose(K3, np.diag([kn, kt, kt]), rtol=1e-13)
    np.testing.assert_allclose(O.laminate_stiffness(h2, E2, nu2, h1, E1, nu1), K2, rtol=1e-14)
    # one material split into two layers is one layer of the summed thickness
    np.testing.assert_allclose(O.laminate_stiffness(0.2, E1, nu1, 0.5, E1, nu1),
                               np.diag([C1[2, 2] / 0.7, C1[4, 4] / 0.7]), rtol=1e-13)
    # an interface spring adds its compliance: the far-face jump of tests/test_hard_cases.py
    Kk = O.laminate_stiffness(h1, E1, nu1, h2, E2, nu2, k_n=1e3, k_t=4e2)
    np.testing.assert_allclose(1 / np.diag(Kk), 1 / np.diag(K2) + [1e-3, 1 / 4e2], rtol=1e-13)
    with pytest.raises(ModelError, match="dim"):
        O.laminate_stiffness(h1, E1, nu1, h2, E2, nu2, dim=1)


# ------------------------------------------------------------------------ bar
def test_penalty_bar_force_patch_values_and_equilibrium():
    # L/(EA) = 2/(4 * 0.5) = 1, 1/(kA) = 1/(8 * 0.5) = 0.25: F = (3 - 1)/1.25
    assert O.penalty_bar_force(3.0, 1.0, 2.0, 4.0, 0.5, 8.0) == pytest.approx(1.6, rel=1e-15)
    assert O.penalty_bar_force(1.0, 1.0, 2.0, 4.0, 0.5, 8.0) == 0.0
    assert O.penalty_bar_force(0.5, 1.0, 2.0, 4.0, 0.5, 8.0) == 0.0
    # the contact end u: bar force E A (d - u)/L equals layer force k A (u - g0)
    d, g0, L, E_, A, k = 2e-3, 5e-4, 0.3, 70e9, 1e-4, 1e13
    u = np.linalg.solve([[E_ * A / L + k * A]], [E_ * A / L * d + k * A * g0])[0]
    F = O.penalty_bar_force(d, g0, L, E_, A, k)
    assert F == pytest.approx(E_ * A * (d - u) / L, rel=1e-12) and F == pytest.approx(k * A * (u - g0), rel=1e-9)
    # rigid-wall limit: the bar alone
    assert O.penalty_bar_force(d, g0, L, E_, A, 1e30) == pytest.approx(E_ * A * (d - g0) / L, rel=1e-12)
