"""The shape-preserving cubic of the two-scale table and its macro law (Fritsch and Carlson)."""
import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from ngcontact.laws import monotone_cubic as mc

RNG = np.random.default_rng(11)


def _data(kind: str, n: int):
    x = np.cumsum(RNG.uniform(0.01, 1.0, n))
    if kind == "nondecreasing":      # with flat stretches, like a table that starts at p = 0
        y = np.concatenate([[0.0], np.cumsum(RNG.uniform(0.0, 1.0, n - 1) * (RNG.uniform(size=n - 1) > 0.2))])
    elif kind == "decreasing":
        y = -np.cumsum(RNG.uniform(0.1, 1.0, n))
    else:
        y = RNG.normal(size=n)
    return x, y


@pytest.mark.parametrize("kind", ["nondecreasing", "decreasing", "any"])
def test_slopes_values_and_integral_are_scipys_pchip(kind):
    for n in (2, 3, 5, 12):
        x, y = _data(kind, n)
        ref = PchipInterpolator(x, y)
        m = mc.slopes(x, y)
        np.testing.assert_allclose(m, ref.derivative()(x), rtol=1e-12, atol=1e-13)
        at = np.linspace(x[0], x[-1], 401)
        np.testing.assert_allclose(mc.evaluate(x, y, m, at), ref(at), rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(mc.integral(x, y, m, at), ref.antiderivative()(at), rtol=1e-11, atol=1e-13)


def test_monotone_data_give_a_monotone_c1_interpolant_that_hits_the_nodes():
    for _ in range(50):
        x, y = _data("nondecreasing", int(RNG.integers(3, 15)))
        m = mc.slopes(x, y)
        at = np.linspace(x[0], x[-1], 2001)
        v = mc.evaluate(x, y, m, at)
        assert np.all(np.diff(v) >= -1e-12 * np.ptp(y)), "the cubic of nondecreasing data decreases"
        np.testing.assert_allclose(mc.evaluate(x, y, m, x), y, rtol=0, atol=1e-12 * np.ptp(y))
        # C1: one-sided difference quotients at an interior node agree with its slope
        k = len(x) // 2
        eps = 1e-7 * np.min(np.diff(x))
        left = (mc.evaluate(x, y, m, x[k]) - mc.evaluate(x, y, m, x[k] - eps)) / eps
        right = (mc.evaluate(x, y, m, x[k] + eps) - mc.evaluate(x, y, m, x[k])) / eps
        scale = np.max(np.abs(np.diff(y) / np.diff(x)))
        assert abs(left - m[k]) <= 1e-4 * scale and abs(right - m[k]) <= 1e-4 * scale


def test_values_are_held_outside_the_nodes_and_the_largest_slope_is_the_maximum():
    x, y = _data("nondecreasing", 8)
    m = mc.slopes(x, y)
    assert mc.evaluate(x, y, m, x[0] - 1.0) == y[0] and mc.evaluate(x, y, m, x[-1] + 1.0) == y[-1]
    sampled = PchipInterpolator(x, y).derivative()(np.linspace(x[0], x[-1], 200001)).max()
    assert sampled * (1 - 1e-12) <= mc.largest_slope(x, y, m) <= sampled * (1 + 1e-4)
