"""Richardson extrapolation in the edge size (:mod:`ngcontact.cell.fe.edge_size_extrapolation`)."""
from __future__ import annotations

import pytest

from ngcontact.cell.fe.edge_size_extrapolation import extrapolate


def test_two_sizes_remove_a_first_order_error_and_bound_it_by_the_correction():
    out = extrapolate([0.02, 0.01], [0.5 + 3.0 * 0.02, 0.5 + 3.0 * 0.01])
    assert out.value == pytest.approx(0.5)
    assert out.rate == 1.0 and out.estimate == pytest.approx(0.03)


def test_three_sizes_find_the_rate_and_estimate_by_the_coarser_pair():
    sizes = [0.04, 0.02, 0.01]
    out = extrapolate(sizes, [1.0 + 2.0 * h ** 1.5 for h in sizes])
    assert out.rate == pytest.approx(1.5, rel=1e-6)
    assert out.value == pytest.approx(1.0, abs=1e-12)
    assert out.estimate >= abs(out.value - 1.0)


def test_a_rate_out_of_range_keeps_the_first_order_and_says_so():
    out = extrapolate([0.02, 0.014, 0.01], [1.0598, 1.0469, 1.0345])
    assert out.rate == 1.0 and "outside" in out.how
    assert out.estimate > abs(out.value - 1.0)


def test_bad_sizes_are_refused():
    with pytest.raises(ValueError, match="two or more"):
        extrapolate([0.01], [1.0])
    with pytest.raises(ValueError, match="distinct"):
        extrapolate([0.01, 0.01], [1.0, 1.1])
