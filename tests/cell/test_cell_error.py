"""Every cell answer with its error (issue 35): the FE cell's estimate where it cannot be graded, the
penalty's share of a penalized cell's answer, and ``k_n`` only where it means something."""
import json
import os
import re

import pytest

from ngcontact import cli
from ngcontact.cell.penalty_share import penalty_share
from ngcontact.drivers.build import cell_loads, cell_solver, spectral_variant
from ngcontact.errors import ConvergenceError
from ngcontact.scene.loader import load

from sinusoid_cell import sinusoid_cell

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CELLS = os.path.join(ROOT, "geometries", "cells")

#: a conforming sinusoidal profile (a curved S_C: no grading), coarse, one pressure
CURVED = """\
kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "sinusoid"
arrangement = "conforming"
amplitude = 0.05
period = 1.0
h_rough = 0.6
h_counter = 0.6
[contact]
k_n = 1.0e3
[load]
pressure = [0.01]
[discretization]
order = 1
maxh = 0.3
interface_maxh = 0.1
"""


def _run(tmp_path, text, capsys):
    tmp_path.mkdir(exist_ok=True)
    path = tmp_path / "scene.toml"
    path.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    code = cli.main(["run", str(path), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    report = json.loads((out / "report.json").read_text()) if (out / "report.json").exists() else None
    return code, err, report


def test_the_westergaard_penalty_s_share_is_the_one_its_comment_states():
    """``westergaard.toml``'s comment: the penalty raises the contact fraction by +0.88, +0.49, +0.33, +0.30,
    0 % at its loads; measured by the protocol on the FE cell's spectral twin, with exact enforcement and the
    contact fraction's part within ``E*/k_n`` extrapolated from penalties its grid resolves (0.888, 0.489, 0.335,
    0.303 % on 1,048,576 points, whose step is a 576th of ``E*/k_n``; 0.86, 0.48, 0.33, 0.30 before)."""
    text = open(os.path.join(CELLS, "westergaard.toml"), encoding="utf-8").read()
    stated = [float(v) for v in re.search(r"by ([-+0-9., ]+) % at these loads", text).group(1).split(",")]
    scene = load(os.path.join(CELLS, "westergaard.toml"))
    cell, loads = cell_solver(scene), cell_loads(scene)
    twin = cell.share_solver()
    assert twin is not cell and twin.penalty() == cell.penalty() == 1e3
    share = penalty_share(cell, loads, [s.results for s in twin.sweep(loads)])
    assert share is not None and share["how"].startswith("exact enforcement") and not share["counted"]
    fraction = [q for q in share["quantities"] if q["name"] == "contact_fraction"]
    assert [q["load"] for q in fraction] == list(range(len(stated)))
    for q, percent in zip(fraction, stated):
        assert 100 * q["relative_share"] == pytest.approx(percent, abs=0.01)    # the comment's two decimals
        assert q["value"] - q["exact_limit"] == pytest.approx(q["share"], rel=1e-12)


def test_without_exact_enforcement_the_share_comes_from_a_second_k_n():
    """The extrapolation in ``1/k_n``: for a quantity ``q = a + b / k_n`` it is exact."""
    from ngcontact.cell.penalty_share import shares
    a, b, k = 0.3, 40.0, 1e3
    out = shares([{"contact_fraction": a + b / k}], [{"contact_fraction": a + b / k}],
                 [{"contact_fraction": a + b / (2 * k)}], extrapolate=True)
    assert out[0]["exact_limit"] == pytest.approx(a, rel=1e-12) and out[0]["share"] == pytest.approx(b / k)


def test_a_penalty_scene_reports_the_penalty_s_share_apart_from_its_accuracy(tmp_path, capsys):
    """The share is an entry of ``results.accuracy.model``, printed, not counted against the tolerance; an
    exact scene has none."""
    code, err, report = _run(tmp_path, sinusoid_cell(enforcement="penalty", pressure="0.001, 0.005",
                                                     discretization='method = "spectral"\ngrid = 512'), capsys)
    assert code == 0
    model = report["results"]["accuracy"]["model"]
    assert model["name"] == "penalty" and model["k_n"] == 1e3 and model["counted"] is False
    names = {(q["load"], q["name"]) for q in model["quantities"]}
    assert names == {(k, n) for k in (0, 1) for n in ("contact_fraction", "mean_closure")}
    assert all(q["share"] > 0 for q in model["quantities"])       # the Winkler layer's jump closes more
    code, err, report = _run(tmp_path / "exact", sinusoid_cell(enforcement="exact"), capsys)
    assert code == 0 and "model" not in report["results"]["accuracy"]


def test_k_n_is_required_with_the_penalty_only(tmp_path, capsys):
    text = sinusoid_cell(enforcement="exact").replace("k_n = 1.0e3\n", "")
    scene_path = tmp_path / "exact.toml"
    scene_path.write_text(text, encoding="utf-8")
    scene = load(str(scene_path))
    assert scene.contact.k_n == pytest.approx(10 * 1.0 / (1.0 / 256))    # 10 E / h, h the grid step
    code, err, report = _run(tmp_path / "p", text.replace('enforcement = "exact"', 'enforcement = "penalty"'),
                             capsys)
    assert code == 2 and "contact.k_n" in err and "required with enforcement = 'penalty'" in err


def test_a_cell_that_cannot_be_graded_is_refined_by_halving_its_interface_mesh(caplog):
    """A curved S_C: the sweep on interface_maxh h, h/2, h/4, ..., the last reported with the observed-rate
    tail of the levels as its estimate; a stated tolerance out of reach fails with the figures, the default one
    returns the estimate with one warning."""
    import tomllib
    from ngcontact.cell.fe.second_discretization import HALVING_RATE
    from ngcontact.scene.loader import from_dict
    scene = from_dict(tomllib.loads(CURVED))
    cell, loads = cell_solver(scene), cell_loads(scene)
    assert cell.default_refinement() == "sequence"
    first = cell.sweep(loads)[0].results
    refined = cell.refine_to(0.5, loads, required=False)
    levels = refined.per_load[0]["discretizations"]
    assert len(levels) >= 3          # two observed ratios at least (this coarse cell needs a fourth level)
    assert [d["discretization"] for d in levels] == [f"interface_maxh {0.1 / 2 ** k:g}" for k in range(len(levels))]
    assert levels[0]["contact_fraction"] == pytest.approx(first["contact_fraction"], rel=1e-9)
    values = [d["contact_fraction"] for d in levels]
    got = refined.solutions[0].results
    assert got["contact_fraction"] == values[-1]
    assert refined.estimates[0]["contact_fraction"] == pytest.approx(HALVING_RATE.tail(values, False)[0],
                                                                     rel=1e-12, abs=1e-15)
    assert levels[-1]["discretization"] in refined.how and cell.problem.ndof == levels[-1]["ndof"]
    record = cell.solver_record(refined.solutions, refined)       # the report's solver entry
    assert record["iterations"] == refined.solutions[0].iterations and len(record["per_load"]) == 1
    with pytest.raises(ConvergenceError, match="discretization.tolerance = 1e-12 not met"):
        cell_solver(scene).refine_to(1e-12, loads, required=True)
    caplog.clear()
    assert cell_solver(scene).refine_to(1e-12, loads, required=False).estimates[0]["contact_fraction"] > 1e-12
    said = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert len(said) == 1 and said[0].startswith("accuracy not met: the FE cell's estimated error")


@pytest.mark.slow
def test_the_3d_fe_estimate_bounds_its_error_against_the_converged_spectral_twin():
    """The shipped bisinusoid (3D, penalty): the estimate by halved interface meshes against the same model
    converged on the spectral grid of 512 x 512 points; effectivity between 1 and 10."""
    scene = load(os.path.join(CELLS, "bisinusoid.toml"))
    cell, loads = cell_solver(scene), cell_loads(scene)
    reference = spectral_variant(scene, 512).sweep(loads)
    refined = cell.refine_to(0.01, loads, required=False)
    for sol, estimate, ref in zip(refined.solutions, refined.estimates, reference):
        f, fr = sol.results["contact_fraction"], ref.results["contact_fraction"]
        assert abs(f - fr) <= estimate["contact_fraction"] <= 10 * abs(f - fr)
        c, cr = sol.results["mean_closure"], ref.results["mean_closure"]
        assert abs(c - cr) / abs(cr) <= estimate["mean_closure"] <= 10 * abs(c - cr) / abs(cr)


def test_a_failed_limit_sweep_leaves_the_share_unknown_not_the_answer(caplog):
    """The exact limit is a second model: when its sweep fails the answer stands, the share says why not."""
    class Failing:
        def sweep(self, loads):
            raise ConvergenceError("Uzawa stalled", {})

    class Penalized:
        def penalty(self):
            return 1e3

        def share_solver(self):
            return self

        def varied(self, *, enforcement=None, k_n=None):
            return Failing()

    share = penalty_share(Penalized(), [], [])
    assert share["quantities"] == [] and "Uzawa stalled" in share["how"] and not share["counted"]
    assert any("penalty's share is not known" in r.getMessage() for r in caplog.records)
