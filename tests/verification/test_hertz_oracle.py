"""Hertz's line contact of :mod:`ngcontact.verification.hertz`, against an independent computation.

The pressure is integrated numerically (it must carry the load) and
recovered as the small-load limit of Westergaard's sinusoid
(:mod:`ngcontact.verification.westergaard`), whose narrow patches see a
parabolic gap.
"""
import math

import numpy as np
import pytest
from scipy import integrate

from ngcontact.verification.hertz import hertz_half_width, hertz_peak_pressure, hertz_pressure
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_half_width, westergaard_p_star, westergaard_pressure

E, NU = 1.0, 0.3
H, WAVE = 0.01, 1.0


def test_hertz_pressure_integrates_to_the_load_and_peaks_at_the_centre():
    P, R, es = 3.0, 0.7, 11.0
    a = hertz_half_width(P, R, es)
    total, _ = integrate.quad(lambda x: hertz_pressure(x, P, R, es), -a, a, epsrel=1e-12)
    assert total == pytest.approx(P, rel=1e-10)
    x = np.linspace(-2 * a, 2 * a, 4001)
    q = hertz_pressure(x, P, R, es)
    assert q.max() == pytest.approx(hertz_peak_pressure(P, R, es), rel=1e-12)
    assert hertz_peak_pressure(P, R, es) == pytest.approx(math.sqrt(P * es / (math.pi * R)), rel=1e-14)
    assert np.all(q[np.abs(x) >= a] == 0)
    assert hertz_half_width(0.0, R, es) == 0.0 and hertz_peak_pressure(0.0, R, es) == 0.0


def test_hertz_is_the_small_load_limit_of_westergaard():
    """Near its zeros the sinusoidal gap is a parabola ``x^2 / (2R)`` with ``R = lambda^2/(4 pi^2 h)``;
    a contact patch much narrower than the period is then Hertzian with ``P' = p lambda``."""
    es = e_star(E, NU, E, NU)
    ps = westergaard_p_star(es, H, WAVE)
    R = WAVE ** 2 / (4 * math.pi ** 2 * H)
    p = 1e-6 * ps
    a_w = westergaard_contact_half_width(p, ps, WAVE)
    a_h = hertz_half_width(p * WAVE, R, es)
    assert a_w == pytest.approx(a_h, rel=1e-5)
    # inside the patch (the square-root edges amplify the 1e-6 relative difference of the widths)
    x = np.linspace(-0.99 * a_h, 0.99 * a_h, 101)
    np.testing.assert_allclose(westergaard_pressure(x, p, ps, WAVE), hertz_pressure(x, p * WAVE, R, es),
                               atol=1e-4 * hertz_peak_pressure(p * WAVE, R, es))
