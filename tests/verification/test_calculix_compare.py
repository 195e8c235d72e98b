"""The comparison half of the CalculiX harness, on made-up ccx results (no ccx needed).

Requirement: a row is ``(quantity, unit, ngcontact, ccx, |ngcontact - ccx| / |ccx|)``; ccx's numbers are read at
the interface's centre (two blocks) and at 45 degrees (press fit), the mean pressure over the arc is the
trapezoidal mean, and the stick ratio ``|tau| / (mu p)`` is taken over the closed nodes only.  The end-to-end
check with ccx is tests/export/test_calculix.py.
"""
import numpy as np
import pytest

from ngcontact.verification import calculix_compare as CC
from ngcontact.verification.calculix_model import Blocks, PressFit

BLOCKS = Blocks(length=0.02, h_block=0.005, h_base=0.005, E=210e9, nu=0.3, nx=4, ny_block=2, ny_base=2,
                press=2e-6, shear=0.5e-6)
FIT = PressFit(a=0.01, b=0.02, c=0.03, E=210e9, nu=0.3, n_theta=4, n_inner=2, n_outer=2)


def test_a_row_is_the_relative_difference_to_ccx():
    rows = CC.rows({"q": ("a quantity", "Pa")}, {"q": 1.01}, {"q": -1.0})
    assert rows == [("a quantity", "Pa", 1.01, -1.0, pytest.approx(2.01))]


def test_ccx_is_read_at_the_centre_of_the_blocks():
    cx = {"rf_x": 3.0, "rf_y": -40.0, "pressure": np.array([1.0, 2.0, 5.0, 2.0, 1.0]),
          "shear": np.array([0.1, 0.2, -0.3, 0.2, 0.1])}
    theirs = CC.block_ccx(cx, BLOCKS)
    assert theirs == {"R_x": 3.0, "R_y": -40.0, "mean": 40.0 / 0.02, "p_mid": 5.0, "p_max": 5.0,
                      "tau_mid": pytest.approx(0.3)}
    assert set(theirs) == set(CC.BLOCK_ROWS)


def test_the_stick_ratio_is_taken_over_the_closed_nodes():
    cx = {"pressure": np.array([0.0, 2.0, 4.0]), "shear": np.array([9.0, -0.5, 0.4])}
    assert CC.stick(cx, 0.5) == pytest.approx(0.5)      # |-0.5| / (0.5 * 2); the open node is left out
    assert CC.stick(cx, 0.0) == 0.0


def test_ccx_is_read_at_45_degrees_and_averaged_over_the_arc():
    theta = np.linspace(0.0, np.pi / 2, 5)
    cx = {"hoop": -7.0, "u_mantle": 1e-6, "u_bore": -2e-6, "theta": theta, "pressure": 3.0 + theta}
    theirs = CC.press_fit_ccx(cx, FIT)
    assert theirs["hoop"] == 7.0 and theirs["p_45"] == pytest.approx(3.0 + np.pi / 4)
    assert theirs["p_mean"] == pytest.approx(3.0 + np.pi / 4)      # the trapezoidal mean is exact on a line
    assert set(theirs) == set(CC.PRESS_FIT_ROWS)
