"""The 2D contact edges of a map without kinks: the quartic's spread from its half window's, the line's share.

On a smooth profile of three harmonics the window of an edge's quartic is set by its patch, so its length in the
period does not change with the grid, nor does the fit's error at the root: on grids 4096 and 8192 the located
edges of the second load stall a few 1e-7 of the period off, while the differences between levels vanish
(:mod:`~ngcontact.cell.spectral.smooth_edges`).  The spread between the quartic on the window and on its first
half floors the estimate of the quantities on the edges; on those levels the slowing sequence then takes the
guarded bound since its fast contraction (:mod:`~ngcontact.cell.spectral.estimate_forms`).
"""
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.spectral.estimate_forms import GUARDED, tail_estimate
from ngcontact.cell.spectral.grid_measures import LOCATED_STEP, edge_window, quartic_root
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.refinement import sweep_to_tolerance
from ngcontact.cell.spectral.smooth_edges import SMOOTH, fit_spread, smooth_share

NU, H = 0.3, 0.01
PRESSURES = (0.0004, 0.0015, 0.004)


def _smooth(n, seed=11):
    rng = np.random.default_rng(seed)
    s, z = np.arange(n) / n, np.zeros(n)
    for k in (1, 2, 3):
        z += rng.uniform(0.2, 1.0) / k * np.cos(2 * np.pi * k * s + rng.uniform(0.0, 2 * np.pi))
    return 2 * H * (z.max() - z) / (z.max() - z.min())


def _westergaard(n):
    return 2 * H * np.sin(np.pi * np.arange(n) / n) ** 2


def _cell(n, gap=_smooth, enforcement="exact"):
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                        gap=gap(n), k_n=1e3, enforcement=enforcement, tol=1e-12, max_iter=100000)


def _refined(gap, pressures, tolerance):
    loads = [cell_load(2, pressure=p) for p in pressures]
    refined = sweep_to_tolerance(lambda n: _cell(n, gap), loads, tolerance, 64, 2, 2 ** 13)
    exact = [headline(s.results) for s in _cell(2 ** 16, gap).sweep(loads)]
    return refined, exact


def test_a_root_the_quartic_holds_exactly_has_no_spread():
    """``r`` a quartic in the step beyond the edge: both windows find its root, the spread is nil."""
    n, i = 2000, 100
    x = np.arange(n) - i - 0.3                               # the edge 0.3 of a step beyond point i
    root = np.where(np.arange(n) > i, np.clip(x + 1e-3 * x ** 2, 0, None), 0.0)
    on = np.arange(n) <= i
    on[:50] = False
    lo, hi = edge_window(root, on, i, 1)
    assert hi - lo > 20 and quartic_root(root, i, 1, lo, hi, 0.5) == pytest.approx(0.3, abs=1e-9)
    fitted, spread = fit_spread(root, on, i, 1)
    assert fitted and spread == pytest.approx(0.0, abs=1e-9)


def test_no_share_with_a_penalty_on_a_map_with_kinks_or_in_full_contact():
    p = np.where(_smooth(256) < 1e-3, 1.0, 0.0)
    assert smooth_share(_cell(256), np.ones(256), np.zeros(256))["share"] == {}
    assert smooth_share(_cell(256, enforcement="penalty"), p, _smooth(256))["share"] == {}
    kinked = _cell(256, gap=lambda n: np.abs(np.arange(n) / n - 0.5) * 2 * H)
    assert smooth_share(kinked, p, _smooth(256))["share"] == {}


def test_an_edge_the_line_located_holds_its_share_of_a_step():
    """On 64 points the quartic's window is too short: each edge holds ``LOCATED_STEP`` of a step."""
    cell = _cell(64)
    sol = cell.sweep([cell_load(2, pressure=PRESSURES[1])])[0]
    share = smooth_share(cell, sol.fields["pressure"], sol.fields["gap"])
    assert share["fitted"] == 0 and share["lined"] >= 2
    assert share["share"]["contact_fraction"] == pytest.approx(LOCATED_STEP * share["lined"] / 64)


def test_the_spread_bounds_the_stalled_edges_where_the_differences_do_not():
    """Refined to 1e-4, the second load's contact fraction on grid 8192: without the floor its Richardson tail
    was a quarter of its error against 2^16 points; with it, the spread's share bounds the error within ten."""
    refined, exact = _refined(_smooth, PRESSURES, 1e-4)
    assert refined.history[-1]["grid"] == 2 ** 13
    error = abs(headline(refined.solutions[1].results)["contact_fraction"] - exact[1]["contact_fraction"])
    edges = refined.history[-1]["islands"][1]["smooth"]
    assert refined.forms[1]["contact_fraction"] == SMOOTH and edges["fitted"] == 2 and edges["lined"] == 0
    assert refined.estimates[1]["contact_fraction"] == pytest.approx(edges["share"]["contact_fraction"])
    assert 1.0 <= refined.estimates[1]["contact_fraction"] / error <= 10.0
    assert any("bounded by each quartic's spread" in r for r in refined.remarks)


def test_a_slowing_sequence_on_the_quartic_s_levels_takes_the_levels_since_its_fast_contraction():
    """Westergaard's sinusoid at p = 0.0015, refined to 1e-2 (reported on 4096 points): the contact fraction's
    whole window carried the line's last difference onto the quartic's levels, 78 times the error; the levels since
    the fast contraction bound it within ten."""
    refined, exact = _refined(_westergaard, (0.0004, 0.0015), 1e-2)
    error = abs(headline(refined.solutions[1].results)["contact_fraction"] - exact[1]["contact_fraction"])
    assert 1.0 <= refined.estimates[1]["contact_fraction"] / error <= 10.0


def test_the_levels_since_apply_only_where_asked_and_the_sequence_slows_beyond_agree():
    """Differences 1, 0.05, 0.01 (contractions 0.05, then 0.2): the whole window's bound (1/4) unless ``since``,
    then the bound since the fast contraction, ``max(0.01, 0.05 / 2)``; a last difference not contracting by
    ``RATE_CAP`` keeps the whole window's."""
    values = [1.0, 2.0, 2.05, 2.06]
    whole, form, _ = tail_estimate(values, False)
    since, since_form, remark = tail_estimate(values, False, since=True)
    assert form == since_form == GUARDED and whole == pytest.approx(0.25)
    assert since == pytest.approx(0.025) and "levels since" in remark
    stalled = [1.0, 2.0, 2.05, 2.09]                     # the last contraction 0.8: not contracting, the whole window
    assert tail_estimate(stalled, False, since=True)[0] == tail_estimate(stalled, False)[0]
