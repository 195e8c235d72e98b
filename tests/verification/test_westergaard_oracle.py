"""Westergaard's sinusoid of :mod:`ngcontact.verification.westergaard`, against an independent computation.

No formula is checked against itself: the pressure is integrated numerically
(it must average to the mean pressure) and fed through the periodic
half-plane response (Fourier series) to see that it closes the gap exactly
where it is positive.
"""
import math

import numpy as np
import pytest
from scipy import integrate

from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import (
    westergaard_contact_fraction,
    westergaard_contact_half_width,
    westergaard_p_star,
    westergaard_pressure,
)

E, NU = 1.0, 0.3
H, WAVE = 0.01, 1.0


def _p_star():
    return westergaard_p_star(e_star(E, NU, E, NU), H, WAVE)


def test_westergaard_p_star_of_the_shipped_scene():
    # geometries/cells/westergaard.toml states p* = 0.0172615 for these numbers
    assert _p_star() == pytest.approx(0.0172615, rel=1e-6)
    assert westergaard_p_star(2.0, 0.1, 4.0) == pytest.approx(math.pi * 0.05, rel=1e-15)


@pytest.mark.parametrize("ratio", [0.05, 0.3, 0.8, 0.999, 1.0, 1.2, 3.0])
def test_westergaard_pressure_integrates_to_the_mean_pressure(ratio):
    ps = _p_star()
    p = ratio * ps
    a = westergaard_contact_half_width(p, ps, WAVE)
    edges = [-a, a] if a < WAVE / 2 else []
    total, _ = integrate.quad(lambda x: westergaard_pressure(x, p, ps, WAVE), -WAVE / 2, WAVE / 2,
                              points=edges or None, limit=200, epsabs=1e-14, epsrel=1e-12)
    assert total / WAVE == pytest.approx(p, rel=1e-9)
    x = np.linspace(-WAVE / 2, WAVE / 2, 2001)
    q = westergaard_pressure(x, p, ps, WAVE)
    assert np.all(q >= 0)
    if ratio < 1:
        assert np.all(q[np.abs(x) >= a] == 0) and np.all(q[np.abs(x) < 0.99 * a] > 0)
        assert westergaard_contact_fraction(p, ps) == pytest.approx(2 * a / WAVE, rel=1e-15)
    else:
        assert westergaard_contact_fraction(p, ps) == 1.0


def test_westergaard_pressure_is_continuous_at_full_contact_and_periodic():
    ps = _p_star()
    x = np.linspace(-1.3, 2.7, 801)
    below = westergaard_pressure(x, ps * (1 - 1e-12), ps, WAVE)
    above = westergaard_pressure(x, ps, ps, WAVE)
    np.testing.assert_allclose(below, above, atol=1e-6 * ps)
    np.testing.assert_allclose(above, 2 * ps * np.cos(math.pi * x) ** 2, atol=1e-15)
    p = 0.4 * ps
    np.testing.assert_allclose(westergaard_pressure(x + 3 * WAVE, p, ps, WAVE),
                               westergaard_pressure(x, p, ps, WAVE), atol=1e-12 * ps)
    assert westergaard_contact_fraction(0.0, ps) == 0.0
    assert westergaard_pressure(0.1, 0.0, ps, WAVE) == 0.0


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
    ps, es = _p_star(), e_star(E, NU, E, NU)
    p = ratio * ps
    n = 2 ** 14
    x = (np.arange(n) + 0.5) * WAVE / n - WAVE / 2      # midpoints: no sample on a contact edge
    q = westergaard_pressure(x, p, ps, WAVE)
    coef = np.fft.rfft(q) / n
    k = 2 * math.pi * np.fft.rfftfreq(n, d=WAVE / n)
    comp = np.zeros_like(coef)
    comp[1:] = 2 * coef[1:] / (es * k[1:])
    w = np.fft.irfft(comp, n) * n                         # compression, up to a constant
    gap = 2 * H * np.sin(math.pi * x / WAVE) ** 2
    mismatch = w + gap
    a = westergaard_contact_half_width(p, ps, WAVE)
    inside = np.abs(x) < 0.98 * a
    level = mismatch[inside].mean()
    # the truncated series of the square-root edges: ~1e-6 h at 2^14 samples (1e-5 h at 2^12)
    assert np.ptp(mismatch[inside]) < 1e-5 * H, f"p/p* = {ratio}: compression plus gap varies"
    outside = np.abs(x) > 1.02 * a
    if outside.any():
        assert np.all(mismatch[outside] > level), "the surfaces would overlap outside the contact patch"
