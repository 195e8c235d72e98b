"""The 3D line's crossings of the contact edges: their floor under the estimate of the quantities on the edges.

In 3D each row and column crossing a contact edge holds an edge located by the line to a fraction of a step
whose size and sign jump between grids (:mod:`~ngcontact.cell.spectral.contact_edges`): the differences may
vanish while that error stalls, and the floor ``LINE_STEP N h^2`` (``N`` crossings per direction) bounds it.
"""
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.spectral.contact_edges import LINE, LINE_STEP, crossing_share, island_floor
from ngcontact.cell.spectral.estimate_forms import loose_flags
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.refinement import sweep_to_tolerance

NU, H = 0.3, 0.01
PRESSURES = (0.001, 0.004, 0.01)
ON_EDGES = ("contact_fraction", "coefficient_k_n", "coefficient_g_n")


def _bisinusoid(n):
    s = np.arange(n) / n
    return H * (2 - np.cos(2 * np.pi * s[None, :]) - np.cos(2 * np.pi * s[:, None]))


def _cell(n, dim=3):
    gap = _bisinusoid(n) if dim == 3 else _bisinusoid(n)[0]
    return SpectralCell(dim=dim, period=1.0, grid=n, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                        gap=gap, k_n=1e3, enforcement="exact", tol=1e-12, max_iter=100000)


def test_the_line_share_counts_each_direction_s_crossings_and_the_gap_at_their_last_contact_points():
    cell = _cell(16)
    on = np.zeros((16, 16), bool)
    on[4:9, 2:5] = True                         # 5 rows by 3 columns: 10 crossings along rows, 6 along columns
    share = crossing_share(cell, np.where(on, 1.0, 0.0))
    assert share["crossings"] == 8              # per direction, the two directions averaged
    assert share["share"]["contact_fraction"] == pytest.approx(LINE_STEP * 8 / 256)
    assert share["share"]["coefficient_k_n"] == pytest.approx(cell.k_n * LINE_STEP * 8 / 256)
    last = np.zeros_like(on)
    last[4:9, 2] = last[4:9, 4] = True          # the rows' last contact points, each side
    heights = cell.g0[last].sum() / 2 + (cell.g0[4, 2:5].sum() + cell.g0[8, 2:5].sum()) / 2
    assert share["share"]["coefficient_g_n"] == pytest.approx(cell.k_n * LINE_STEP * heights / 256)
    assert crossing_share(cell, np.ones((16, 16)))["share"] == {}
    assert crossing_share(_cell(16, dim=2), np.where(np.arange(16) < 8, 1.0, 0.0))["share"] == {}     # 3D only


def test_the_line_floor_raises_a_vanished_difference_and_is_flagged_where_far_above_its_tail():
    """A history whose contact fraction's last difference vanished at a Richardson-like rate: the floor lifts the
    estimate to ``LINE_STEP N h^2`` (form ``line``), and the flag names the line's crossings."""
    whole = {"contact_fraction": 1.0, "k_n": 1e3, "g_n": 20.0}
    levels = [0.080, 0.077, 0.0765, 0.07649]
    history = [{"grid": 32 * 2 ** i, "points": (32 * 2 ** i) ** 2, "whole_surface": whole,
                "headline": [{"contact_fraction": v}], "islands": [{"share": {}, "line": {
                    "crossings": 326, "share": {"contact_fraction": LINE_STEP * 326 / 256 ** 2}}}]}
               for i, v in enumerate(levels)]
    estimates, forms = [{"contact_fraction": 1e-6}], [{"contact_fraction": "Richardson"}]
    island_floor(history, estimates, forms)
    assert forms[0]["contact_fraction"] == LINE
    assert estimates[0]["contact_fraction"] == pytest.approx(LINE_STEP * 326 / 256 ** 2)
    assert "line's crossings" in loose_flags(history, estimates, forms)[0]["contact_fraction"]


@pytest.mark.slow
def test_the_bisinusoid_s_estimate_on_the_edges_bounds_its_error_within_ten_times_where_it_stalls():
    """The bisinusoid refined from 32 to 512 points per direction: its contact fraction's error hardly falls from
    256 to 512 (at the lightest load 4.5e-5, then 3.8e-5 against 2048) while their difference is a sixth of it,
    and the differences-only estimate of 512 was below the error (0.93, 0.82 times the contact fraction's at the
    lightest and heaviest load, 0.62 times ``g_n``'s).  With the line's floor each estimate on the edges lies
    between the error and ten times it, against a 2048 x 2048 reference."""
    loads = [cell_load(3, pressure=p) for p in PRESSURES]
    refined = sweep_to_tolerance(_cell, loads, 1e-9, 32, 3, 512 ** 2, required=False)
    assert refined.history[-1]["grid"] == 512 and not refined.met
    reference = _cell(2048).sweep(loads)
    for k, (sol, ref) in enumerate(zip(refined.solutions, reference)):
        value, exact = headline(sol.results), headline(ref.results)
        for name in ON_EDGES:
            error = abs(value[name] - exact[name]) / refined.scales[k][name]
            assert error <= refined.estimates[k][name] <= 10 * error, (k, name, refined.estimates[k][name], error)
