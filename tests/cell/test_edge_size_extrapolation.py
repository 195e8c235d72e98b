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
    out = extrapolate(sizes, [1.0 + 2.0 * h ** 0.75 for h in sizes])
    assert out.rate == pytest.approx(0.75, rel=1e-6)
    assert out.value == pytest.approx(1.0, abs=1e-12)
    assert out.estimate >= abs(out.value - 1.0)


def test_a_rate_faster_than_first_order_is_not_taken():
    """Sizes that shrink the difference faster than first order (here ``h^1.5``) extrapolate at first order,
    say so, and the estimate (3 x the correction) still bounds the error left."""
    sizes = [0.04, 0.02, 0.01]
    out = extrapolate(sizes, [1.0 + 2.0 * h ** 1.5 for h in sizes])
    assert out.rate == 1.0 and "outside (0.5, 1.0)" in out.how
    assert 1.0 <= out.estimate / abs(out.value - 1.0) <= 10.0


def test_a_rate_out_of_range_keeps_the_first_order_and_says_so():
    out = extrapolate([0.02, 0.014, 0.01], [1.0598, 1.0469, 1.0345])
    assert out.rate == 1.0 and "outside" in out.how
    assert out.estimate > abs(out.value - 1.0)


def test_bad_sizes_are_refused():
    with pytest.raises(ValueError, match="two or more"):
        extrapolate([0.01], [1.0])
    with pytest.raises(ValueError, match="distinct"):
        extrapolate([0.01, 0.01], [1.0, 1.1])


def test_an_error_the_sizes_do_not_see_is_bounded_by_the_grid_convergence_index():
    """``f(h) = f + E_0 + C h^q``: the differences see ``C h^q`` only, Richardson keeps ``E_0``; the estimate
    (1.25 x the correction) bounds it while ``|E_0|`` is at most 1.25 x the finest size's ``C h^q``, where
    the extrapolations' disagreement alone (zero here: three sizes fit exactly) does not."""
    sizes, q, C = [0.01, 0.005, 0.0025], 0.8, 0.05
    for share in (-1.2, -0.5, 0.5, 1.2):
        e0 = share * C * 0.0025 ** q
        out = extrapolate(sizes, [1.0 + e0 + C * h ** q for h in sizes])
        assert out.rate == pytest.approx(q, rel=1e-6) and out.value == pytest.approx(1.0 + e0, abs=1e-12)
        assert 1.0 <= out.estimate / abs(out.value - 1.0) <= 10.0


#: the quarter cell's order-2 contact fractions on the bisinusoid at edge sizes 0.01, 0.005, 0.0025 and the
#: converged spectral value, per p/p* (docs/benchmarks.md, section scaling_3d: ``scripts/bisinusoid_accuracy.py``)
QUARTER_ROWS = {0.005: ([0.01473, 0.01466, 0.0145], 0.014213),
                0.02: ([0.03764, 0.03724, 0.03701], 0.036435),
                0.05: ([0.0707, 0.07008, 0.0697], 0.068702)}


@pytest.mark.parametrize("ratio", sorted(QUARTER_ROWS))
def test_effectivity_against_the_converged_bisinusoid_is_between_1_and_10(ratio):
    """Issue 35: the estimate of the extrapolated contact fraction over its true error against the converged
    spectral cell, on the quarter cell's measured rows at the three loads of issue 38, within [1, 10]."""
    values, converged = QUARTER_ROWS[ratio]
    out = extrapolate([0.01, 0.005, 0.0025], values)
    assert abs(out.value / converged - 1.0) < 0.01
    assert 1.0 <= out.estimate / abs(out.value - converged) <= 10.0


#: the bisinusoid scene's refined levels (``tolerance = 0.01``, every other key at its default: the quarter, edge
#: sizes l/10, l/20, l/40 from the twin's patch width l, the bodies at maxh 0.3) per p/p*: sizes, contact
#: fractions, the converged spectral value (docs/benchmarks.md, section bisinusoid_scene_accuracy:
#: ``scripts/bisinusoid_scene_accuracy.py``)
SCENE_ROWS = {0.005: ([0.00674277, 0.00337138, 0.00168569], [0.0146636899, 0.0145026041, 0.0143814811], 0.014212),
              0.02: ([0.0108198, 0.00540991, 0.00270496], [0.0382832003, 0.0372453862, 0.0368912175], 0.036436),
              0.05: ([0.0146269, 0.00731344, 0.00365672], [0.0714462863, 0.0702622774, 0.0697866310], 0.068701)}


@pytest.mark.parametrize("ratio", sorted(SCENE_ROWS))
def test_the_scenes_ladder_is_within_1_percent_with_an_effectivity_between_1_and_10(ratio):
    """Issues 35 and 38 on the scene's own ladder: its three refined levels (rates 0.41, 1.55, 1.32 observed:
    first order taken at every load) extrapolate within 1 % of the converged value, the estimate between 1
    and 10 times the true error."""
    sizes, values, converged = SCENE_ROWS[ratio]
    out = extrapolate(sizes, values)
    assert abs(out.value / converged - 1.0) < 0.01
    assert 1.0 <= out.estimate / abs(out.value - converged) <= 10.0
