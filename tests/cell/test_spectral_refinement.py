"""The spectral cell refined to a tolerance: estimate, history, the answer within it, refusals."""
import json
import re

import numpy as np
import pytest

from ngcontact import cli
from sinusoid_cell import sinusoid_cell
from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.refinement import STIFFNESS, next_grid, sweep_to_tolerance
from ngcontact.errors import ConvergenceError
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

NU, H = 0.3, 0.01
P_STAR = westergaard_p_star(e_star(1.0, NU) / 2, H, 1.0)
LOADS = (0.05, 0.5)


def _make(n):
    x = np.arange(n) / n
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 2.0), counter=Layer(1.0, NU, 2.0),
                        gap=2 * H * np.sin(np.pi * x) ** 2, k_n=1.0, enforcement="exact")


def test_the_refined_sweep_meets_its_tolerance_and_the_estimate_bounds_the_true_error():
    loads = [cell_load(2, pressure=r * P_STAR) for r in LOADS]
    refined = sweep_to_tolerance(_make, loads, 1e-5, 256, 2, 2 ** 20)
    # every quantity meets 1e-5, the 2D stiffness too: that of the set with its edges located between points
    assert refined.estimate <= 1e-5 and refined.met and not refined.capped
    assert [h["grid"] for h in refined.history] == [256 * 2 ** k for k in range(len(refined.history))]
    assert len(refined.history) >= 4 and "estimate" not in refined.history[0]
    for r, sol, est in zip(LOADS, refined.solutions, refined.estimates):
        exact = westergaard_contact_fraction(r * P_STAR, P_STAR)
        assert abs(sol.results["contact_fraction"] - exact) <= est["contact_fraction"] + 1e-12
        assert abs(sol.results["contact_fraction"] - exact) <= 1e-5
        # the flat punch of the exact contact width (tests/cell/test_spectral_located_stiffness.py); the layers'
        # finite depth (two periods) changes it by e^(-8 pi)
        error = abs(sol.results["effective_stiffness"]["matrix"][0][0] / _punch_of(r) - 1)
        assert error <= min(est[STIFFNESS], 1e-5), (r, error, est[STIFFNESS])
    # the estimate of a level bounds the change from the level before it
    last, before = refined.history[-1], refined.history[-2]
    change = max(abs(a - b) for a, b in zip(last["contact_fraction"], before["contact_fraction"]))
    assert change <= refined.estimate


def test_a_tolerance_beyond_the_largest_grid_raises_with_the_history():
    loads = [cell_load(2, pressure=0.05 * P_STAR)]
    with pytest.raises(ConvergenceError, match=r"tolerance = 1e-12 not met: the estimate is \S+ \((contact_fraction|"
                                               r"mean_closure|normal_stiffness|coefficient_\w+), \w+.*, at load 0\) on ") as err:
        sweep_to_tolerance(_make, loads, 1e-12, 256, 2, 4096)
    assert [h["grid"] for h in err.value.history["levels"]] == [256, 512, 1024, 2048, 4096]


def test_next_grid_doubles_the_points_per_direction():
    assert next_grid(1024, 2) == 2048 and next_grid(128, 3) == 256


def _scene(tolerance: str) -> str:
    return sinusoid_cell(pressure="0.0034523", depth="2.0",
                         discretization=f'method = "spectral"\ngrid = 256\ntolerance = {tolerance}')


def test_a_spectral_scene_with_a_tolerance_reports_the_estimate_and_the_grids(tmp_path):
    """Every counted quantity held to the stated 1e-3, the 2D stiffness too (the last to meet it)."""
    path = tmp_path / "s.toml"
    path.write_text(_scene("1e-3"))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    rep = json.loads((tmp_path / "o" / "report.json").read_text())
    method, load = rep["results"]["method"], rep["results"]["loads"][0]
    assert method["grid"] == method["refinement"][-1]["grid"] > 256
    assert set(load["error_estimate"]) >= {STIFFNESS, "contact_fraction"} and max(load["error_estimate"].values()) <= 1e-3
    exact = westergaard_contact_fraction(0.0034523, P_STAR)
    assert abs(load["contact_fraction"] - exact) <= load["error_estimate"]["contact_fraction"]
    acc = rep["results"]["accuracy"]                     # the same estimates in the verdict, per quantity
    assert acc["estimated"] and acc["met"] and acc["tolerance"] == 1e-3 and "grids" in acc["how"]
    assert all(q["met"] and q["counted"] for q in acc["quantities"]) and "shortfall" not in acc
    assert "Richardson on" in acc["how"]                # which form each estimate took
    fraction = next(q for q in acc["quantities"] if q["name"] == "contact_fraction")
    assert fraction["error"] == load["error_estimate"]["contact_fraction"] and fraction["controlled"] == "absolute"
    assert fraction["relative_error"] == pytest.approx(fraction["error"] / load["contact_fraction"])


def test_a_stated_tolerance_the_stiffness_misses_at_its_cap_ends_the_run(tmp_path, capsys):
    """1e-5 with a penalty (``k_n = 1e6``): every other quantity meets it, the 2D stiffness, the collocated set's
    (first order in the grid step), would take hundreds of thousands of points: its cap ends the refinement, and a
    stated tolerance out of reach is no answer (issue 35: exit 3 with the figures, never ``met = false`` with
    exit 0), nothing written.  (At ``k_n = 1e5`` the contact fraction's edges, located beyond ``E*/k_n``, are off
    by 1.3e-5 until the grid's step is below ``E*/k_n``: there the stiffness meets it too.)"""
    path = tmp_path / "s.toml"
    path.write_text(sinusoid_cell(pressure="0.0034523", depth="2.0", k_n="1.0e6", enforcement="penalty",
                                  discretization='method = "spectral"\ngrid = 256\ntolerance = 1e-5'))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 3
    err = capsys.readouterr().err
    figures = re.search(r"tolerance = 1e-05 not met: the estimate is (\S+) \(normal_stiffness, relative, at load 0\) "
                        r"on grid (\d+), where refinement stopped at its cap for the stiffness alone", err)
    assert figures is not None, err
    assert float(figures.group(1)) > 1e-5 and int(figures.group(2)) > 256
    assert "points per direction: not met; state a looser discretization.tolerance" in err
    assert not (tmp_path / "o" / "report.json").exists()


def test_a_sampled_map_is_refined_as_its_bilinear_interpolant(tmp_path):
    """A self-affine map's heights are samples; the surface the cell solves is their bilinear interpolant (as the
    FE cell meshes it), so a tolerance refines the grid beyond the samples and converges to that surface's
    contact.  The refined answer is the direct solve on the final grid (to the solver's tolerance: the located
    edges read the gap, which the refinement's solve reaches from the coarser grid's answer)."""
    from pathlib import Path
    text = (Path(__file__).parents[2] / "geometries" / "cells" / "self_affine_spectral.toml").read_text()
    text = text.split("[discretization]")[0].replace("grid = 256, seed", "grid = 64, seed")   # samples: 64 x 64
    own = tmp_path / "own.toml"
    own.write_text(text + "[discretization]\nmethod = \"spectral\"\ngrid = 32\ntolerance = 0.05\n")
    assert cli.main(["run", str(own), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    rep = json.loads((tmp_path / "o" / "report.json").read_text())["results"]
    grids = [level["grid"] for level in rep["method"]["refinement"]]
    assert grids[0] == 32 and rep["method"]["grid"] == grids[-1] > 64
    assert all(max(load["error_estimate"].values()) <= 0.05 for load in rep["loads"])
    direct = tmp_path / "direct.toml"
    # no estimate: the direct solve on that grid alone (else refined to the default tolerance)
    direct.write_text(text + f"[discretization]\nmethod = \"spectral\"\ngrid = {grids[-1]}\nestimate = \"off\"\n")
    assert cli.main(["run", str(direct), "--out", str(tmp_path / "d"), "--quiet"]) == 0
    again = json.loads((tmp_path / "d" / "report.json").read_text())["results"]
    assert again["method"]["grid"] == grids[-1] and not again["accuracy"]["estimated"]
    assert [load["contact_fraction"] for load in again["loads"]] == pytest.approx(
        [load["contact_fraction"] for load in rep["loads"]], rel=1e-9, abs=0)


def _punch_of(r):
    """The stiffness of Westergaard's contact at ``p = r p*``: the periodic flat punch of its half-width
    (tests/cell/test_spectral_located_stiffness.py)."""
    a = np.arcsin(np.sqrt(r)) / np.pi
    return np.pi * e_star(1.0, NU, 1.0, NU) / (2 * np.log(1 / np.sin(np.pi * a)))


@pytest.mark.slow
def test_the_shipped_exact_westergaard_scene_meets_its_tolerance_and_a_millionth_when_stated(tmp_path):
    """The scene states 1e-3, what every counted quantity reaches on the fewest levels a stop needs (8192 points),
    the 2D stiffness's estimate the largest (within 1e-3, beyond 1e-4); the contact fraction is within its estimate
    of Westergaard's and the stiffness of the flat punch's.  Stated, 1e-6 is met too (on 16,384 points), every
    quantity held, the fraction within 1e-6 of Westergaard's and the stiffness of the punch's, as the scene's comment
    says."""
    from pathlib import Path
    scene = Path(__file__).parents[2] / "geometries" / "cells" / "westergaard_exact.toml"
    stated = tmp_path / "e6.toml"
    stated.write_text(scene.read_text().replace("\ntolerance = 1e-3 ", "\ntolerance = 1e-6 "))
    for tolerance, path, grid in ((1e-3, scene, 8192), (1e-6, stated, 16384)):
        out = tmp_path / str(tolerance)
        assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 0
        rep = json.loads((out / "report.json").read_text())
        acc = rep["results"]["accuracy"]
        assert acc["tolerance"] == tolerance and acc["tolerance_from"] == "scene" and acc["met"]
        assert all(q["counted"] and q["met"] for q in acc["quantities"]) and rep["results"]["method"]["grid"] == grid
        stiffness = max(load["error_estimate"][STIFFNESS] for load in rep["results"]["loads"])
        assert (1e-4 < stiffness <= 1e-3) if tolerance == 1e-3 else stiffness <= 1e-6
        for r, load in zip((0.05, 0.2, 0.5, 0.8), rep["results"]["loads"]):
            exact = westergaard_contact_fraction(r * P_STAR, P_STAR)
            assert abs(load["contact_fraction"] - exact) <= min(tolerance * exact, load["error_estimate"]["contact_fraction"])
            # the scene's pressures are r p* rounded to six digits: the punch of each one's own width
            error = abs(load["effective_stiffness"]["matrix"][0][0] / _punch_of(load["mean_pressure"] / P_STAR) - 1)
            assert error <= min(tolerance, load["error_estimate"][STIFFNESS]), (tolerance, r, error)


def _report(tmp_path, text, *args):
    path = tmp_path / "s.toml"
    path.write_text(text)
    code = cli.main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet", *args])
    return code, (json.loads((tmp_path / "o" / "report.json").read_text()) if code == 0 else None)


def test_a_spectral_scene_without_a_tolerance_is_refined_to_the_default_one(tmp_path):
    code, rep = _report(tmp_path, sinusoid_cell(pressure="0.0034523", depth="2.0"))
    assert code == 0
    acc, method = rep["results"]["accuracy"], rep["results"]["method"]
    assert acc["tolerance_from"] == "default" and acc["tolerance"] == 0.01 and acc["estimated"] and acc["met"]
    assert [level["grid"] for level in method["refinement"]][0] == 256 and method["grid"] >= 256 * 8
    exact = westergaard_contact_fraction(0.0034523, P_STAR)
    load = rep["results"]["loads"][0]
    assert abs(load["contact_fraction"] - exact) <= load["error_estimate"]["contact_fraction"] <= 0.01


def test_a_default_tolerance_out_of_reach_is_reported_not_failed(tmp_path, caplog, monkeypatch):
    """Within the default size bound too few grids: the finest is the answer, unmet, with one warning line."""
    from ngcontact.scene import spectral_grid
    monkeypatch.setitem(spectral_grid.DEFAULT_REFINEMENT_POINTS, 2, 1024)
    code, rep = _report(tmp_path, sinusoid_cell(pressure="0.0034523"))
    assert code == 0
    acc = rep["results"]["accuracy"]
    assert rep["results"]["method"]["grid"] == 1024 and acc["tolerance_from"] == "default" and not acc["met"]
    lines = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert sum(m.startswith("accuracy not met") and "default tolerance 0.01" in m for m in lines) == 1, lines


def test_a_stated_tolerance_out_of_reach_ends_the_run(tmp_path, capsys, monkeypatch):
    from ngcontact.scene import spectral_grid
    monkeypatch.setitem(spectral_grid.MAX_SPECTRAL_POINTS, 2, 1024)      # three grids from 256
    code, _ = _report(tmp_path, sinusoid_cell(discretization='method = "spectral"\ngrid = 256\ntolerance = 1e-6'))
    assert code == 3 and "tolerance = 1e-06 not met" in capsys.readouterr().err


def test_independent_loads_are_each_refined_and_estimated_and_geometric_runs_are_not(tmp_path):
    """Each independent load is refined by grid doubling on its own, to the default tolerance, and its estimate
    bounds its error against Westergaard's closed form (layers deep enough to stand for half-spaces; issue 35:
    every number with its error)."""
    pressures = (0.001, 0.003)
    text = sinusoid_cell(pressure=", ".join(map(str, pressures)), depth="2.0").replace(
        "[discretization]", "independent = true\n[discretization]")
    code, rep = _report(tmp_path, text, "--workers", "1")
    assert code == 0
    method, acc = rep["results"]["method"], rep["results"]["accuracy"]
    assert acc["estimated"] and acc["met"] and acc["tolerance_from"] == "default" and "grids" in acc["how"]
    own = [m["refinement"] for m in method["per_load"]]      # each load's own grids, from the scene's
    assert len(own) == 2 and all(levels[0]["grid"] == 256 and len(levels) >= 4 for levels in own)
    for p, load in zip(pressures, rep["results"]["loads"]):
        error = abs(load["contact_fraction"] - westergaard_contact_fraction(p, P_STAR))
        assert error <= load["error_estimate"]["contact_fraction"] <= 0.01
    names = {(q["load"], q["name"]) for q in acc["quantities"]}
    assert {(k, n) for k in (0, 1) for n in ("contact_fraction", "mean_closure")} <= names
    text = sinusoid_cell().replace("[load]\npressure = [0.005]\n", "").replace(
        'enforcement = "exact"', 'enforcement = "exact"\ngeometric_only = true')
    (tmp_path / "g").mkdir()
    code, rep = _report(tmp_path / "g", text)
    assert code == 0 and "whole_surface" in rep["results"] and "loads" not in rep["results"]
