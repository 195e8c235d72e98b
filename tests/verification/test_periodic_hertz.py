"""The periodic row of Hertz cylinders (:mod:`ngcontact.verification.periodic_hertz`) against the closed forms
it must contain: Westergaard's sinusoid at any width, Hertz for a patch narrow against the period."""
import math

import numpy as np
import pytest

from ngcontact.errors import ModelError

from ngcontact.verification.hertz import hertz_half_width
from ngcontact.verification.moduli import e_star
from ngcontact.verification.periodic_hertz import periodic_hertz_half_width, periodic_load
from ngcontact.verification.westergaard import westergaard_contact_half_width, westergaard_p_star

ES = e_star(1.0, 0.3, 1.0, 0.3)


@pytest.mark.parametrize("a", [0.02, 0.2, 0.4])
def test_the_sinusoidal_gap_gives_westergaards_half_width_to_round_off(a):
    h, wave = 0.01, 2.0
    ps = westergaard_p_star(ES, h, wave)
    P = periodic_load(a * wave, lambda x: 2 * math.pi * h / wave * np.sin(2 * math.pi * x / wave), ES, wave)
    assert westergaard_contact_half_width(P / wave, ps, wave) == pytest.approx(a * wave, rel=1e-12)


def test_a_narrow_row_is_hertz_narrowed_by_its_neighbours():
    R = 0.7
    for b in (1e-3, 0.02):
        P = math.pi * ES * b * b / (4 * R)
        assert hertz_half_width(P, R, ES) == pytest.approx(b, rel=1e-14)
        row = periodic_hertz_half_width(P, R, ES, 1.0)
        # the neighbours' leading term -(pi b)^2 / 12 relative, its own next term of order (pi b)^4
        assert row / b - 1 == pytest.approx(-(math.pi * b) ** 2 / 12, abs=(math.pi * b) ** 4)
    assert periodic_hertz_half_width(0.0, R, ES, 1.0) == 0.0


def test_a_load_beyond_the_rows_reach_is_refused_naming_it():
    with pytest.raises(ModelError, match="load_per_period"):
        periodic_hertz_half_width(10.0, 1.0, ES, 1.0)
