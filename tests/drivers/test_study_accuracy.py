"""``ngcontact study accuracy``: the ladder, its files, the recommended scene, and refusals of bad input."""
from __future__ import annotations

import csv
import json
import math
import os
import sys
import time
from pathlib import Path

import pytest

from ngcontact import cli
from ngcontact.drivers.headline_quantities import headline, measure
from ngcontact.drivers.study_accuracy import error_of
from ngcontact.scene import loader
from ngcontact.scene.refinement_ladder import ladder

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from sinusoid_cell import sinusoid_cell  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
TARGET = 0.05


def small_cell(tmp_path: Path) -> Path:
    """A spectral penalty cell of two loads on a coarse grid: its ladders are the grid and k_n.  Each level
    answers on its own grid, estimated from coarser ones: on 64 points the 2D stiffness's estimate from grids 8
    to 64 is about 0.5, so the scene's grid is 256 (every level still below 0.1 s)."""
    path = tmp_path / "cell.toml"
    path.write_text(sinusoid_cell(enforcement="penalty", pressure="0.002, 0.008",
                                  discretization='method = "spectral"\ngrid = 256'))
    return path


def test_the_study_writes_its_files_and_a_scene_that_meets_the_target(tmp_path):
    scene = small_cell(tmp_path)
    out = tmp_path / "study"
    assert cli.main(["study", "accuracy", str(scene), "--target", str(TARGET), "--out", str(out),
                     "--workers", "1", "--quiet"]) == 0
    report = json.loads((out / "report.json").read_text())
    res = report["results"]
    assert report["kind"] == "accuracy-study"
    assert set(res["ladder"]) == {"grid", "k_n"} and all(len(v) == 4 for v in res["ladder"].values())
    with open(out / "accuracy_study.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert {r["knob"] for r in rows} == {"grid", "k_n"}
    assert sum(r["reference"] == "1" for r in rows) == 2 * 6      # one reference level per knob, 6 quantities
    assert (out / "accuracy_contact_fraction_load0.png").stat().st_size > 0
    assert "Accuracy study" in (out / "report.html").read_text()
    assert res["rates"]["grid"]["rates"]["mean_closure_load1"] > 0
    # each grid level answers on its own grid (not refined to the default tolerance, which would end every
    # level on one grid), and the scene's own level is found in both ladders
    assert [lv["ndof"] for lv in res["levels"] if lv["knob"] == "grid"] == [64, 128, 256, 512]
    assert [lv["setting"] for lv in res["levels"] if lv["own_scene"]] == ["discretization.grid = 256",
                                                                          "contact.k_n = 1000"]
    # the recommended scene, run as a user runs it, meets the target against the study's reference
    verdict = res["target"]
    assert verdict["met"] and (out / "recommended.toml").is_file()
    ref = next(lv for lv in res["levels"] if lv["knob"] == verdict["knob"] and lv["reference"])
    run = tmp_path / "recommended"
    assert cli.main(["run", str(out / "recommended.toml"), "--out", str(run), "--quiet", "--workers", "1"]) == 0
    got = headline(json.loads((run / "report.json").read_text()))
    errors = {name: error_of(name, got[name]["value"], q["value"]) for name, q in ref["quantities"].items()}
    assert max(errors.values()) <= TARGET, errors


def test_a_scene_not_refined_by_the_study_is_refused_and_nothing_written(tmp_path, capsys):
    scene = tmp_path / "m.toml"
    scene.write_text('kind = "manufactured"\n[materials.steel]\nE = 210e9\nnu = 0.3\n[manufactured]\n'
                     'setting = "plane_strain"\nbody = "steel"\norders = [1]\nmaxh = 0.5\nlevels = 3\n')
    out = tmp_path / "out"
    assert cli.main(["study", "accuracy", str(scene), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "kind" in err and "'manufactured'" in err and "cell" in err and "macro" in err
    assert not out.exists()


@pytest.mark.parametrize("option, value, words", [("--target", "0", "--target"), ("--target", "-0.1", "--target"),
                                                  ("--target", "1.5", "(0, 1)"), ("--levels", "9", "--levels")])
def test_a_bad_option_exits_2_and_writes_nothing(tmp_path, capsys, option, value, words):
    out = tmp_path / "out"
    assert cli.main(["study", "accuracy", str(small_cell(tmp_path)), option, value, "--out", str(out),
                     "--quiet"]) == 2
    assert words in capsys.readouterr().err
    assert not out.exists()


def test_the_femur_ladder_brackets_the_scene_and_refines_it_once():
    path = ROOT / "geometries" / "femur_stem.toml"
    scene = loader.load(path)
    levels, dropped = ladder(scene, loader.parsed(path), 4)
    assert not dropped
    h = [lv for lv in levels if lv.knob == "h"]
    order = [lv for lv in levels if lv.knob == "order"]
    assert [lv.changes["discretization.maxh"] for lv in h] == pytest.approx([0.016, 0.008, 0.004, 0.002])
    assert [lv.changes["discretization.order"] for lv in order] == [2, 3, 4, 5]   # order 1 is not on the axis
    assert h[2].key == order[1].key      # the scene's own level, run once


def test_a_macro_tolerance_is_kept_only_by_the_tolerance_ladder():
    """A macro tolerance raises the order until met: the levels of the other knobs drop it, so that each
    level is its own setting; the tolerance ladder divides it."""
    path = ROOT / "geometries" / "femur_stem.toml"
    data = loader.parsed(path)
    data.setdefault("discretization", {})["tolerance"] = 0.02
    levels, _ = ladder(loader.from_dict(data, base_dir=str(path.parent)), data, 4)
    by_knob = {knob: [lv for lv in levels if lv.knob == knob] for knob in ("h", "order", "tolerance")}
    assert all(lv.scene.discretization.tolerance is None for lv in by_knob["h"] + by_knob["order"])
    assert [lv.scene.discretization.tolerance for lv in by_knob["tolerance"]] == pytest.approx(
        [0.02 * 4.0 ** -s for s in range(-2, 2)])


@pytest.mark.parametrize("scene, knobs", [
    ("femur_stem_two_scale.toml", {"h": "discretization.maxh", "order": "discretization.order",
                                   "table_tol": "two_scale.table_tol", "loop_tol": "two_scale.tol",
                                   "cell_grid": "two_scale.cell_grid", "cell_k_n": "interface.cell_k_n"}),
    ("direct/block_rect_valleys.toml", {"h": "discretization.elements_per_period", "order": "discretization.order"}),
    ("cells/westergaard_exact.toml", {"grid": "discretization.grid", "tolerance": "discretization.tolerance"}),
])
def test_each_kind_gets_the_knobs_it_has(scene, knobs):
    path = ROOT / "geometries" / scene
    levels, _ = ladder(loader.load(path), loader.parsed(path), 4)
    assert {lv.knob: next(iter(k for k in lv.changes if k == knobs[lv.knob])) for lv in levels} == knobs


def test_a_scene_written_as_toml_reads_back_the_same():
    import glob
    import tomllib
    from ngcontact.scene.scene_text import dumps
    for path in glob.glob(str(ROOT / "geometries" / "**" / "*.toml"), recursive=True):
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
        assert tomllib.loads(dumps(data, "a comment\non two lines")) == data, path


def test_measures():
    assert measure("contact_fraction_load3") == "absolute" and measure("safety_factor") == "relative"
    assert error_of("safety_factor", 4.4, 4.0) == pytest.approx(0.1)
    assert error_of("contact_fraction_load0", 0.25, 0.2) == pytest.approx(0.05)


@pytest.mark.slow
def test_the_femur_study_gives_rates_within_20_solves(tmp_path):
    """At least four levels per knob; the errors of peak pressure and safety factor fall; the whole study
    costs less than 20 runs of the scene itself (its own level's wall time inside the study)."""
    out = tmp_path / "femur"
    t0 = time.perf_counter()
    assert cli.main(["study", "accuracy", str(ROOT / "geometries" / "femur_stem.toml"), "--out", str(out),
                     "--quiet"]) == 0
    wall = time.perf_counter() - t0
    res = json.loads((out / "report.json").read_text())["results"]
    assert all(len(v) >= 4 for v in res["ladder"].values())
    for knob in ("h", "order"):
        rates = res["rates"][knob]["rates"]
        assert rates["safety_factor"] > 0.5 and rates["peak_pressure"] > 0
    assert wall < 20 * res["seconds_own_scene"], (wall, res["seconds_own_scene"])


def _fake_solve(scene):
    """A stand-in for a run: the 'quantity' converges like h^2 towards 1; k_n's share is 1/k_n."""
    if scene["fail"]:
        raise ValueError("the mesher gave up")
    seconds = 1 / scene["h"] ** 2 + 1e-4 * scene["k_n"]
    return {"kind": "direct", "ndof": int(1 / scene["h"] ** 2), "timings": {"total": seconds},
            "results": {"contact_fraction": 0.5 + scene["h"] ** 2 + 1 / scene["k_n"], "contact_force": 2.0}}


def test_failed_levels_references_other_knobs_and_the_target():
    from ngcontact.drivers import study_accuracy as sa
    from ngcontact.scene.refinement_ladder import Level

    def level(knob, k, h, k_n, fail=False):
        data = {"h": h, "k_n": k_n, "fail": fail}
        return Level(knob, k, {"h": h} if knob == "h" else {"k_n": k_n}, h if knob == "h" else 1 / k_n, None,
                     data, scene=None)

    levels = [level("h", 0, 0.4, 1e3), level("h", 1, 0.2, 1e3), level("h", 2, 0.1, 1e3), level("h", 3, 0.05, 1e3,
                                                                                              fail=True),
              level("k_n", 0, 0.2, 1e1), level("k_n", 1, 0.2, 1e2), level("k_n", 2, 0.2, 1e3), level("k_n", 3, 0.2, 1e4)]
    runs = {lv.key: sa.level_member((lambda s: _fake_solve(s), lv.data)) for lv in levels}
    rows = sa.level_rows(levels, runs, own_key=levels[1].key)
    h = [r for r in rows if r["knob"] == "h"]
    assert "mesher gave up" in h[3]["failed"] and h[2]["reference"]          # the finest level that ran
    assert h[1]["own_scene"] and h[1]["quantities"]["contact_fraction"]["error"] == pytest.approx(0.04 - 0.01)
    # the h ladder's levels keep k_n = 1e3, whose error the scene's own level measures in the k_n ladder
    assert h[0]["quantities"]["contact_fraction"]["error_other_knobs"] == pytest.approx(1e-3 - 1e-4)
    # against the finest level the slope overestimates the rate 2 (the docstring's upper estimate)
    assert sa.rates(rows)["h"]["rates"]["contact_fraction"] == pytest.approx(math.log2(0.15 / 0.03))
    assert sa.rates(rows)["k_n"]["rates"]["contact_force"] is None       # the same on every level
    # k_n = 100 at the scene's h: 0.0099 along k_n plus the scene's 0.03 along h; cheaper than the scene
    verdict, texts = sa.recommendation(rows, levels, 0.05, ".", "t")
    assert verdict["met"] and verdict["knob"] == "k_n" and verdict["setting"] == "k_n = 100"
    assert verdict["error"] == pytest.approx(0.0099 + 0.03)
    assert "recommended.toml" in texts
    verdict, texts = sa.recommendation(rows, levels, 0.02, ".", "t")   # every level keeps 0.03 along h
    assert not verdict["met"] and "no level" in verdict["statement"] and not texts


def test_the_reports_own_estimates_join_the_headline_quantities():
    report = {"kind": "macro", "results": {
        "maxima": {"pressure": {"pressure": 2.0e6}, "von_mises": {"max": {"value": 5.0e6}}},
        "resultant": {"r": 3.0, "z": 4.0},
        "accuracy": {"quantities": [{"name": "peak_pressure", "value": 2.0e6, "error": 2.0e4},
                                    {"name": "tresca", "value": 4.0e6, "error": 4.0e3},
                                    {"name": "contact_fraction", "load": 1, "value": 0.5, "error": None}]}}}
    got = headline(report)
    assert got["resultant"] == {"value": 5.0, "estimate": None}
    assert got["peak_pressure"]["estimate"] == 2.0e4 and got["tresca"] == {"value": 4.0e6, "estimate": 4.0e3}
    assert "safety_factor" not in got and "contact_fraction_load1" not in got    # no strength; no error given
    from ngcontact.drivers.study_accuracy import estimate_of
    assert estimate_of("peak_pressure", got["peak_pressure"]) == pytest.approx(0.01)
