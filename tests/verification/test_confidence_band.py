"""The confidence band of an ensemble's mean: Student's t interval, refused below two members.

Requirement: the band of ``M`` independent samples is ``m -+ t_{0.975, M-1} s / sqrt(M)``
(:mod:`ngcontact.verification.confidence_band`), the interval scipy's Student's t gives for the same samples.
"""
import numpy as np
import pytest
from scipy import stats

from ngcontact.verification import confidence_band


def test_the_band_is_students_t_interval_of_the_mean():
    rng = np.random.default_rng(1)
    x = rng.normal(2.0, 0.3, size=(12, 3))
    b = confidence_band.band(x)
    low, high = stats.t.interval(0.95, 11, loc=x.mean(axis=0), scale=stats.sem(x, axis=0))
    np.testing.assert_allclose(b["low"], low, rtol=1e-13)
    np.testing.assert_allclose(b["high"], high, rtol=1e-13)
    with pytest.raises(ValueError, match="at least 2 members"):
        confidence_band.band(x[:1])
