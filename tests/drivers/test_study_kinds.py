"""``ngcontact study accuracy`` on two-scale and resolved scenes: their knobs, their headline quantities and
indicators, the loop cell's discretization keys, and (slow) the whole study with a recommended scene that
meets its target when run."""
from __future__ import annotations

import csv
import json
import os
from pathlib import Path

import pytest

from ngcontact import cli
from ngcontact.drivers import study_accuracy as sa
from ngcontact.drivers.headline_quantities import headline, measure
from ngcontact.errors import SceneError
from ngcontact.scene import loader
from ngcontact.scene.refinement_ladder import ladder
from ngcontact.scene.studied_kinds import studied_kind

ROOT = Path(__file__).resolve().parents[2]

#: the press fit's materials, shared by the loop's cell and the macro scene
BODIES = """\
[materials.inner]
E = 200.0
nu = 0.3
[materials.outer]
E = 70.0
nu = 0.25
[bodies]
rough = "inner"
counter = "outer"
"""

#: the loop's cell: Westergaard's sinusoidal gap on a flat interface between the press fit's materials,
#: solved by the spectral cell (lengths in two_scale.cell_length_unit)
LOOP_CELL = """\
kind = "cell"
""" + BODIES + """\
[geometry]
profile = "flat"
h_rough = 1.0
h_counter = 1.0
[contact]
k_n = 1e3
enforcement = "exact"
gap = { kind = "sinusoid", h = 0.01 }
[load]
pressure = [0.05]
[discretization]
method = "spectral"
grid = 64
"""

#: Lame's press fit (a quarter of two coaxial rings in plane strain) coupled with the cell above
TWO_SCALE = """\
kind = "macro"
title = "two-scale press fit"
""" + BODIES + """\
[geometry]
shape = "coaxial"
setting = "plane_strain"
[geometry.dimensions]
a = 0.5
b = 1.0
c = 2.0
[interface]
law = "linear"
kn = 300.0
gap = -1e-3
[[supports]]
boundary = "sym_x"
components = ["x"]
[[supports]]
boundary = "sym_y"
components = ["y"]
[discretization]
order = 2
maxh = 0.3
[two_scale]
cell = "cell.toml"
cell_length_unit = 0.01
tol = 1e-5
table_tol = 0.02
"""


def two_scale_scene(tmp_path: Path, extra: str = "") -> Path:
    (tmp_path / "cell.toml").write_text(LOOP_CELL)
    path = tmp_path / "two_scale.toml"
    path.write_text(TWO_SCALE + extra)
    return path


def resolved_scene(tmp_path: Path) -> Path:
    """The shipped block with resolved rectangular valleys, 4 periods at order 2 on coarse meshes."""
    text = (ROOT / "geometries" / "direct" / "block_rect_valleys.toml").read_text().split("[study]")[0]
    cell = ROOT / "geometries" / "direct" / "rect_valleys_cell.toml"
    for old, new in (('cell = "rect_valleys_cell.toml"', f'cell = "{cell}"'), ("periods = 8 ", "periods = 4 "),
                     ("order = 3", "order = 2"), ("maxh = 0.05 ", "maxh = 0.2 "),
                     ("elements_per_period = 8 ", "elements_per_period = 4 ")):
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / "resolved.toml"
    path.write_text(text)
    return path


def knobs_of(path: Path, n: int = 3) -> dict[str, list[dict]]:
    levels, dropped = ladder(loader.load(path), loader.parsed(path), n)
    assert not dropped, dropped
    out: dict[str, list[dict]] = {}
    for lv in levels:
        out.setdefault(lv.knob, []).append(lv.changes)
    return out


def test_a_two_scale_scene_refines_its_macro_solve_its_loop_and_its_cell(tmp_path):
    path = two_scale_scene(tmp_path)
    assert studied_kind(loader.load(path)).name == "two-scale"
    knobs = knobs_of(path)
    assert list(knobs) == ["h", "order", "table_tol", "loop_tol", "cell_grid"]
    assert [c["two_scale.table_tol"] for c in knobs["table_tol"]] == pytest.approx([0.08, 0.02, 0.005])
    assert [c["two_scale.tol"] for c in knobs["loop_tol"]] == pytest.approx([4e-5, 1e-5, 2.5e-6])
    assert [c["two_scale.cell_grid"] for c in knobs["cell_grid"]] == [32, 64, 128]


def test_the_scene_own_level_of_every_ladder_is_the_scene_itself(tmp_path):
    """A loop-cell level at the cell's own grid leaves ``two_scale.cell_grid`` unset, as the scene does: one run."""
    path = two_scale_scene(tmp_path)
    scene = loader.load(path)
    levels, _ = ladder(scene, loader.parsed(path), 3)
    own = json.dumps(loader.as_dict(scene), sort_keys=True, default=str)
    assert [lv.knob for lv in levels if lv.key == own] == ["h", "order", "table_tol", "loop_tol", "cell_grid"]
    assert all(lv.index == 1 for lv in levels if lv.key == own)


def test_an_fe_penalty_cell_in_the_loop_gives_its_mesh_order_and_penalty_knobs():
    path = ROOT / "geometries" / "femur_stem_two_scale.toml"
    data = loader.parsed(path)
    data["two_scale"]["cell_method"] = "fe"
    # the groove cell leaves its method to "auto" (the spectral cell): its FE mesh through the loop's keys
    data["two_scale"].update(cell_maxh=25e-6, cell_interface_maxh=1e-6)
    levels, _ = ladder(loader.from_dict(data, base_dir=str(path.parent)), data, 3)
    knobs = {lv.knob: lv.changes for lv in levels}
    assert {"cell_h", "cell_order", "cell_k_n"} <= set(knobs) and "cell_grid" not in knobs
    cell_h = [lv.changes for lv in levels if lv.knob == "cell_h"]
    assert [c["two_scale.cell_maxh"] for c in cell_h] == pytest.approx([50e-6, 25e-6, 12.5e-6])
    assert [c["two_scale.cell_interface_maxh"] for c in cell_h] == pytest.approx([2e-6, 1e-6, 0.5e-6])
    assert [lv.scene.two_scale.cell_order for lv in levels if lv.knob == "cell_order"] == [1, None, 3]


def test_a_resolved_scene_refines_its_far_field_and_interface_mesh_and_its_order(tmp_path):
    path = resolved_scene(tmp_path)
    assert studied_kind(loader.load(path)).name == "resolved"
    knobs = knobs_of(path)
    assert list(knobs) == ["h", "order"]
    assert [(c["discretization.maxh"], c["discretization.elements_per_period"]) for c in knobs["h"]] == [
        (0.4, 2.0), (0.2, 4.0), (0.1, 8.0)]


@pytest.mark.parametrize("extra, key, words", [
    ("cell_grid = 65\n", "two_scale.cell_grid", "even"),
    ("cell_maxh = 0.1\n", "two_scale.cell_maxh", "by method 'spectral'"),
    ('cell_method = "fe"\ncell_grid = 128\n', "two_scale.cell_grid", "by method 'fe'"),
])
def test_a_loop_cell_key_the_cell_cannot_take_is_refused_by_name(tmp_path, extra, key, words):
    with pytest.raises(SceneError) as err:
        loader.load(two_scale_scene(tmp_path, extra))
    assert err.value.path == key and words in str(err.value), str(err.value)


def test_the_loop_cell_keys_reach_the_cell_the_loop_solves(tmp_path):
    from ngcontact.drivers.run_two_scale import PressureSolve
    from ngcontact.scene.cell_table_knobs import loop_cell
    scene = loader.load(two_scale_scene(tmp_path, "cell_grid = 256\n"))
    assert loop_cell(scene).discretization.grid == 256
    task = PressureSolve(str(tmp_path / "cell.toml"), 0.01, discretization={"grid": 256})
    other = PressureSolve(str(tmp_path / "cell.toml"), 0.01)
    assert task.key != other.key        # another cell table in the cache


def two_scale_report(peak: float, change: float, table: float) -> dict:
    return {"kind": "macro", "ndof": 100, "timings": {"total": 1.0}, "results": {
        "maxima": {"pressure": {"pressure": peak}, "von_mises": {"max": {"value": 2 * peak}}},
        "resultant": {"x": peak, "y": peak},
        "two_scale": {"history": [{"max_pressure": peak, "max_change": None},
                                  {"max_pressure": peak, "max_change": change}]},
        "accuracy": {"quantities": [
            {"name": "two_scale_residual", "value": change, "error": change, "relative_error": change / peak},
            {"name": "cell_table_interpolation", "value": table, "error": table, "relative_error": table}]}}}


def test_the_loop_residual_and_table_error_are_indicators_held_to_the_target():
    """Their value is a relative error of the answer already: no error against the reference, their own value
    as the estimate (not 1, the estimate over itself)."""
    got = headline(two_scale_report(2.0, 0.002, 0.004))
    assert measure("two_scale_residual") == "indicator"
    assert got["two_scale_residual"] == {"value": pytest.approx(1e-3), "estimate": pytest.approx(1e-3)}
    assert got["cell_table_interpolation"] == {"value": 0.004, "estimate": 0.004}
    assert sa.estimate_of("two_scale_residual", got["two_scale_residual"]) == pytest.approx(1e-3)


def test_a_two_scale_study_judges_its_levels_by_their_indicators(tmp_path):
    """The study's plumbing on the real ladder of the two-scale scene, each level a stand-in report whose
    table error is its table_tol and whose peak pressure converges in the mesh size: no solve."""
    path = two_scale_scene(tmp_path)
    scene = loader.load(path)
    levels, dropped = ladder(scene, loader.parsed(path), 3)

    def solve(level):
        s = level.two_scale
        return two_scale_report(1.0 + 0.1 * level.discretization.maxh ** 2, 0.1 * s.tol, s.table_tol)
    own = json.dumps(loader.as_dict(scene), sort_keys=True, default=str)
    out = sa.run_study(scene, levels, dropped, solve, own_key=own, target=0.015)
    res = out.results
    assert res["distinct_runs"] == 11
    own_row = next(r for r in res["levels"] if r["own_scene"])
    q = own_row["quantities"]["cell_table_interpolation"]
    assert q["measure"] == "indicator" and q["error"] is None and q["estimated_error"] == pytest.approx(0.02)
    # the scene's table (0.02) misses 0.015; the finer table level is the ladder's reference: no level meets it
    assert not res["target"]["met"]
    out = sa.run_study(scene, levels, dropped, solve, own_key=own, target=0.03)
    assert res["rates"]["table_tol"]["rates"]["cell_table_interpolation"] == pytest.approx(1.0)
    verdict = out.results["target"]
    assert verdict["met"] and "recommended.toml" in out.texts


def run_and_check_the_recommended_scene(tmp_path: Path, scene: Path, target: float, args=()) -> dict:
    """Run the study with ``target``, then its recommended scene as a user runs it: every headline quantity
    within the target of the study's reference and every estimate the run reports within the target."""
    out = tmp_path / "study"
    assert cli.main(["study", "accuracy", str(scene), "--target", str(target), "--levels", "3", "--out", str(out),
                     "--workers", "1", "--quiet", *args]) == 0
    res = json.loads((out / "report.json").read_text())["results"]
    with open(out / "accuracy_study.csv", newline="") as fh:
        assert {r["knob"] for r in csv.DictReader(fh)} == set(res["ladder"])
    assert (out / "accuracy_peak_pressure.png").is_file() or (out / "accuracy_contact_force.png").is_file()
    verdict = res["target"]
    assert verdict["met"] and (out / "recommended.toml").is_file(), verdict
    ref = next(lv for lv in res["levels"] if lv["knob"] == verdict["knob"] and lv["reference"])
    run = tmp_path / "recommended"
    assert cli.main(["run", str(out / "recommended.toml"), "--out", str(run), "--quiet", "--workers", "1"]) == 0
    got = headline(json.loads((run / "report.json").read_text()))
    for name, q in ref["quantities"].items():
        if measure(name) == "indicator":
            assert got[name]["value"] <= target, (name, got[name])
        else:
            assert sa.error_of(name, got[name]["value"], q["value"]) <= target, (name, got[name], q)
            if got[name]["estimate"] is not None:
                assert sa.estimate_of(name, got[name]) <= target, (name, got[name])
    return res


@pytest.mark.slow
def test_the_study_of_a_small_two_scale_scene_recommends_one_that_meets_its_target(tmp_path, monkeypatch):
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    res = run_and_check_the_recommended_scene(tmp_path, two_scale_scene(tmp_path), 0.3)
    assert set(res["ladder"]) == {"h", "order", "table_tol", "loop_tol", "cell_grid"}


@pytest.mark.slow
def test_the_study_of_a_small_resolved_scene_recommends_one_that_meets_its_target(tmp_path):
    res = run_and_check_the_recommended_scene(tmp_path, resolved_scene(tmp_path), 0.01)
    assert set(res["ladder"]) == {"h", "order"}
    assert os.path.isfile(tmp_path / "study" / "accuracy_contact_force.png")


def test_what_the_study_still_refuses_names_why():
    """A cell with [ensemble] (random members) and a manufactured scene (a convergence study of its own)."""
    with pytest.raises(SceneError) as err:
        studied_kind(loader.load(ROOT / "geometries" / "cells" / "self_affine_ensemble.toml"))
    assert err.value.path == "ensemble" and "random" in str(err.value)
    with pytest.raises(SceneError) as err:
        studied_kind(loader.load(ROOT / "geometries" / "verify_elasticity.toml"))
    assert err.value.path == "kind" and all(k in str(err.value) for k in ("two-scale", "resolved", "macro", "cell"))
