"""The grid's phase: each 2D level's estimate is at least its change on the same grid sampled half a step over.

On a smooth profile of three harmonics (seed 35 of ``scripts/spectral_effectivity.py --held-out ... --smooth``)
the mean closure of the middle load has errors of +1.8e-7 and +2.1e-7 on 4096 and 8192 points: its differences
stall, and the estimate from them alone was a quarter of the error.  The twin half a step over has errors of the
other sign there, so the change between the two bounds the error (:mod:`~ngcontact.cell.spectral.grid_phase`).
"""
import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline, scale
from ngcontact.cell.spectral.grid_phase import PHASE, PHASE_SAFETY, phase_floor, posed_on, twin_headline
from ngcontact.cell.spectral import refinement
from ngcontact.cell.spectral.grid_level import solve_level, solve_twin
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.refinement import MIN_LEVELS, sweep_to_tolerance

NU, H = 0.3, 0.01
PRESSURES = (0.0004, 0.0015, 0.004)


def _harmonics(seed):
    rng = np.random.default_rng(seed)
    return [(k, rng.uniform(0.2, 1.0) / k, rng.uniform(0.0, 2 * np.pi)) for k in (1, 2, 3)]


def _z(s, harmonics):
    return sum(a * np.cos(2 * np.pi * k * s + phase) for k, a, phase in harmonics)


def _extreme(harmonics, sign):
    s = np.arange(4096) / 4096
    at = s[np.argmax(sign * _z(s, harmonics))]
    found = minimize_scalar(lambda t: -sign * _z(t, harmonics), bounds=(at - 1 / 4096, at + 1 / 4096),
                            method="bounded", options={"xatol": 1e-13})
    return float(_z(found.x, harmonics))


def _smooth(n, seed=35):
    """The profile's gap below its highest point (the continuous profile's extremes: one surface on every grid)."""
    harmonics = _harmonics(seed)
    top, bottom = _extreme(harmonics, 1.0), _extreme(harmonics, -1.0)
    return 2 * H * (top - _z(np.arange(n) / n, harmonics)) / (top - bottom)


def _cell(n, gap=_smooth):
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                        gap=gap(n), k_n=1e3, enforcement="exact", tol=1e-12, max_iter=100000)


def test_the_twin_is_the_same_cell_on_the_surface_sampled_half_a_step_over():
    n = 256
    cell = _cell(n)
    cell.friction_method = "projected"
    twin = posed_on(cell, _smooth(2 * n)[1::2])
    s = (np.arange(n) + 0.5) / n
    harmonics = _harmonics(35)
    top, bottom = _extreme(harmonics, 1.0), _extreme(harmonics, -1.0)
    assert twin.g0 == pytest.approx(2 * H * (top - _z(s, harmonics)) / (top - bottom), abs=1e-15)
    assert (twin.grid, twin.k_n, twin.enforcement, twin.tol, twin.max_iter, twin.friction_method) == (
        n, cell.k_n, cell.enforcement, cell.tol, cell.max_iter, "projected")
    loads = [cell_load(2, pressure=p) for p in PRESSURES]
    sols = cell.sweep(loads)
    heads = twin_headline(_cell, cell, loads, None)
    assert heads == [pytest.approx(headline(s.results), rel=1e-9) for s in twin.sweep(loads)]
    entry = {"seconds": 0.0}                  # from the level's pressures at the twin's points: the same answer
    solve_twin(_cell, loads, cell, sols, entry)
    assert entry["phase"] == [pytest.approx(h, rel=1e-8) for h in heads] and entry["seconds"] > 0
    assert heads[1]["mean_closure"] != pytest.approx(headline(sols[1].results)["mean_closure"], rel=1e-9)


def test_no_twin_in_3d():
    cell = SpectralCell(dim=3, period=1.0, grid=8, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                        gap=np.zeros((8, 8)), k_n=1e3)
    assert twin_headline(lambda n: pytest.fail("no finer grid is built in 3D"), cell, [], None) is None


def _level(value, twin_value):
    head = {"contact_fraction": 0.3, "mean_closure": value}
    return {"grid": 512, "headline": [head], "phase": [dict(head, mean_closure=twin_value)],
            "whole_surface": {}}


def test_the_floor_raises_an_estimate_below_the_change_half_a_step_over_and_names_it():
    level = _level(2.0, 2.0 + 3e-6)
    estimates, forms = [{"mean_closure": 1e-7, "contact_fraction": 1e-9}], [{"mean_closure": "Richardson",
                                                                            "contact_fraction": "guarded"}]
    remarks = phase_floor([level], estimates, forms)
    size = scale("mean_closure", level["headline"][0], {})
    assert estimates[0]["mean_closure"] == pytest.approx(PHASE_SAFETY * 3e-6 / 2 / size)
    assert forms[0] == {"mean_closure": PHASE, "contact_fraction": "guarded"}
    assert estimates[0]["contact_fraction"] == 1e-9          # no change on the twin: no floor
    assert remarks == ["load 0: mean_closure bounded by 2 times half the change on grid 512 sampled half a step over"]
    larger = [{"mean_closure": 1.0}]
    assert phase_floor([level], larger, [{"mean_closure": "guarded"}]) == [] and larger[0]["mean_closure"] == 1.0
    assert phase_floor([dict(level, phase=None)], estimates, forms) == []


def test_a_stalled_mean_closure_is_bounded_by_its_change_half_a_step_over():
    """Seed 35's middle load: the estimate bounds the error of the reported grid, by the phase's floor."""
    loads = [cell_load(2, pressure=p) for p in PRESSURES]
    refined = sweep_to_tolerance(_cell, loads, 1e-2, 64, 2, 2 ** 13)
    exact = headline(_cell(2 ** 17).sweep(loads)[1].results)["mean_closure"]
    value = refined.history[-1]["headline"][1]["mean_closure"]
    error = abs(value - exact) / abs(value)
    assert refined.history[-1]["grid"] == 8192 and error > 1e-7
    assert refined.forms[1]["mean_closure"] == PHASE
    assert error <= refined.estimates[1]["mean_closure"] <= 10 * error
    assert any("mean_closure bounded by 2 times half the change" in r for r in refined.remarks)


def test_the_twin_is_solved_only_where_its_floor_can_change_a_decision(monkeypatch):
    """The floor only raises an estimate: a level whose estimate before it misses the tolerance keeps missing it.
    So the lazy twin (the levels a stop or the report reads) gives the sweep of a twin on every level."""
    loads = [cell_load(2, pressure=p) for p in PRESSURES]
    lazy = sweep_to_tolerance(_cell, loads, 1e-4, 64, 2, 2 ** 13)
    assert [h["phase"] is None for h in lazy.history[:MIN_LEVELS - 1]] == [True] * (MIN_LEVELS - 1)
    assert lazy.history[-1]["phase"] is not None
    assert any(h["phase"] is None for h in lazy.history[MIN_LEVELS - 1:-1])      # a level the lazy twin skipped

    def eager(make_cell, loads, n, coarser=None):
        cell, sols, entry = solve_level(make_cell, loads, n, coarser)
        solve_twin(make_cell, loads, cell, sols, entry)
        return cell, sols, entry

    monkeypatch.setattr(refinement, "solve_level", eager)
    every = sweep_to_tolerance(_cell, loads, 1e-4, 64, 2, 2 ** 13)
    assert [h["grid"] for h in every.history] == [h["grid"] for h in lazy.history]
    assert (every.estimates, every.forms, every.met) == (lazy.estimates, lazy.forms, lazy.met)
