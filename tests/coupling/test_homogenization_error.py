"""The modelling-error estimate of a macro run from the ratio of scales
(:mod:`ngcontact.coupling.homogenization_error`)."""
from __future__ import annotations

import pytest

from ngcontact.coupling.homogenization_error import CONSTANTS, estimate


def test_the_bundle_law_is_estimated_from_its_measured_constant():
    out = estimate("bundle", 1e-4, 0.2)
    assert out["estimated"] and out["eps_over_length"] == pytest.approx(5e-4)
    assert out["relative_error"] == pytest.approx(CONSTANTS["bundle"][0] * 5e-4)
    assert "C eps / L" in out["how"] and "may be smaller" in out["how"]


@pytest.mark.parametrize("law, period, reason", [
    ("linear", 1e-4, "does not fall with eps"),
    ("bundle", None, "states no roughness period"),
    ("tabulated", 1e-4, "no epsilon study measures"),
])
def test_a_law_without_a_constant_or_a_period_says_why(law, period, reason):
    out = estimate(law, period, 0.2)
    assert not out["estimated"] and out["relative_error"] is None
    assert out["how"].startswith("not estimated: ") and reason in out["how"], out["how"]
