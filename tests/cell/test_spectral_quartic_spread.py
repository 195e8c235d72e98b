"""A 2D edge located by the quartic: its error read off the quartic on half its window.

On a smooth profile of three harmonics the window of an edge's quartic is set by its patch, so its length in the
period does not change with the grid, nor does the fit's error at the root: on grids 4096 and 8192 the located
edges of the second load stall a few 1e-7 of the period off, while the differences between levels vanish
(:mod:`~ngcontact.cell.spectral.quartic_spread`).  The spread between the quartic on the window and on its first
half floors the estimate of the quantities on the edges.
"""
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.spectral.grid_measures import edge_window, quartic_root
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.quartic_spread import FIT, SPREAD_STEPS, fit_share, fit_spread
from ngcontact.cell.spectral.refinement import sweep_to_tolerance

NU, H = 0.3, 0.01
PRESSURES = (0.0004, 0.0015, 0.004)


def _smooth(n, seed=11):
    rng = np.random.default_rng(seed)
    s, z = np.arange(n) / n, np.zeros(n)
    for k in (1, 2, 3):
        z += rng.uniform(0.2, 1.0) / k * np.cos(2 * np.pi * k * s + rng.uniform(0.0, 2 * np.pi))
    return 2 * H * (z.max() - z) / (z.max() - z.min())


def _cell(n, gap=_smooth):
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                        gap=gap(n), k_n=1e3, enforcement="exact", tol=1e-12, max_iter=100000)


def test_a_root_the_quartic_holds_exactly_has_no_spread():
    """``r`` a quartic in the step beyond the edge: both windows find its root, the spread is nil."""
    n, i = 2000, 100
    x = np.arange(n) - i - 0.3                               # the edge 0.3 of a step beyond point i
    root = np.where(np.arange(n) > i, np.clip(x + 1e-3 * x ** 2, 0, None), 0.0)
    root[:50] = 0.0
    on = root == 0
    on[np.arange(n) > i] = False
    lo, hi = edge_window(root, on, i, 1)
    assert hi - lo > 20 and quartic_root(root, i, 1, lo, hi, 0.5) == pytest.approx(0.3, abs=1e-9)
    assert fit_spread(root, on, i, 1) == pytest.approx(0.0, abs=1e-9)


def test_no_share_in_3d_with_a_penalty_or_in_full_contact():
    cell = _cell(256)
    assert fit_share(cell, np.ones(256), np.zeros(256))["share"] == {}
    penalty = SpectralCell(dim=2, period=1.0, grid=256, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                           gap=_smooth(256), k_n=1e3, enforcement="penalty", tol=1e-12, max_iter=100000)
    p = np.where(_smooth(256) < 1e-3, 1.0, 0.0)
    assert fit_share(penalty, p, _smooth(256))["share"] == {}


def test_the_spread_bounds_the_stalled_edges_where_the_differences_do_not():
    """Refined to 1e-4, the second load's contact fraction on grid 8192: without the floor its Richardson tail
    is a quarter of its error against 2^16 points; with it, the fit's share bounds the error within ten times."""
    loads = [cell_load(2, pressure=p) for p in PRESSURES]
    cache = {}

    def make(n):
        cache[n] = _cell(n)
        return cache[n]

    refined = sweep_to_tolerance(make, loads, 1e-4, 64, 2, 2 ** 13)
    assert refined.history[-1]["grid"] == 2 ** 13
    exact = headline(_cell(2 ** 16).sweep(loads)[1].results)["contact_fraction"]
    error = abs(headline(refined.solutions[1].results)["contact_fraction"] - exact)
    fit = refined.history[-1]["islands"][1]["fit"]
    assert refined.forms[1]["contact_fraction"] == FIT
    assert refined.estimates[1]["contact_fraction"] == pytest.approx(fit["share"]["contact_fraction"])
    assert fit["share"]["contact_fraction"] == pytest.approx(SPREAD_STEPS * fit["steps"] / 2 ** 13)
    assert 1.0 <= refined.estimates[1]["contact_fraction"] / error <= 10.0
    assert any("step(s) apart from its half window's" in r for r in refined.remarks)
