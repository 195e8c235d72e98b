"""The verdict of a cell's answer (:mod:`ngcontact.cell.admissibility`): a converged solve whose pressure
field misses its own load is not reported as met, and one that misses it by the load's size is no answer.

The case: Westergaard's sinusoidal gap made 100 times deeper than the shipped scene's, on the same mesh.  The
contact patch at the lightest load is then narrower than the interface elements, the energy's quadrature
sees only part of it, and the accurately integrated pressure exceeds the load by a few per cent while the
discrete balance holds to round-off.
"""
import json
import os

import pytest

from ngcontact import cli
from ngcontact.cell import admissibility
from ngcontact.cell.admissibility import DEFAULT_TOLERANCE, PLAINLY_WRONG, verdict

from height_map_cell import fe_height_map

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHIPPED = os.path.join(ROOT, "geometries", "cells", "westergaard.toml")


def _sinusoid(tmp_path, h: float):
    text = open(SHIPPED, encoding="utf-8").read()
    text = text.replace("gap = { kind = \"sinusoid\", h = 0.01 }", f"gap = {{ kind = \"sinusoid\", h = {h!r} }}")
    text = "\n".join("pressure = [0.00863075]" if line.startswith("pressure = [") else line
                     for line in text.splitlines())
    # the checks of one discretization, not its refinement: estimated on the scene's mesh, not refined
    text = text.replace("[discretization]\n", '[discretization]\nestimate = "estimate"\n')
    path = tmp_path / f"sinusoid_{h:g}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _balance(report, k=0):
    """The ``pressure_balance`` check of load ``k``."""
    return next(c for c in report["results"]["accuracy"]["checks"] if c["name"] == "pressure_balance"
                and c["load"] == k)


def _run(tmp_path, path, capsys):
    out = tmp_path / "out"
    code = cli.main(["run", str(path), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    report = json.loads((out / "report.json").read_text()) if (out / "report.json").exists() else None
    return code, err, report


def test_the_verdict_of_synthetic_results():
    good = {"pressure_balance": 1e-6}
    off = {"pressure_balance": 0.03}
    v, failed = verdict([good, off], None)
    assert v["tolerance"] == DEFAULT_TOLERANCE and v["tolerance_from"] == "default" and not v["met"]
    assert [c.load for c in failed] == [1] and not failed[0].plainly_wrong
    assert "load 1: pressure_balance = 0.03 exceeds 0.01" in failed[0].message()
    v, failed = verdict([good, off], 0.05)
    assert v["met"] and not failed and v["tolerance_from"] == "scene"
    _, failed = verdict([{"pressure_balance": 19.0}], None)     # the pressure 20 times the load
    assert failed[0].plainly_wrong and PLAINLY_WRONG < 19.0
    assert verdict([{}], None)[0]["checks"] == []                # nothing to check: nothing claimed


def test_a_resolved_patch_meets_the_default_accuracy(tmp_path, capsys):
    code, err, report = _run(tmp_path, _sinusoid(tmp_path, 0.01), capsys)
    assert code == 0
    acc = report["results"]["accuracy"]
    assert acc["met"] and _balance(report)["value"] < 1e-3


def test_a_patch_narrower_than_the_elements_is_not_reported_as_met(tmp_path, capsys, caplog):
    """Before the verdict this run ended with exit 0 and nothing said; its pressure field carries 3 % more
    than its load."""
    code, err, report = _run(tmp_path, _sinusoid(tmp_path, 100.0), capsys)
    assert code == 0
    acc = report["results"]["accuracy"]
    assert not acc["met"] and 0.01 < _balance(report)["value"] < PLAINLY_WRONG
    # a gap 100 times deeper is no small slope either: the cell's own check says so too
    slope = next(c for c in acc["checks"] if c["name"] == "rms_slope")
    assert slope["load"] is None and not slope["ok"] and slope["value"] > 100
    lines = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert sum(m.startswith("accuracy not met: load 0: pressure_balance") for m in lines) == 1, lines


def test_an_answer_that_contradicts_its_load_is_no_answer(tmp_path, capsys, monkeypatch):
    """The same run with the 'plainly wrong' limit below its imbalance: exit 3, one line, nothing written."""
    monkeypatch.setattr(admissibility, "PLAINLY_WRONG", 0.02)
    code, err, report = _run(tmp_path, _sinusoid(tmp_path, 100.0), capsys)
    assert code == 3 and report is None and not (tmp_path / "out").exists()
    assert "contradicts its own load" in err and "refine the interface mesh" in err


@pytest.mark.parametrize("name", ["westergaard_spectral"])
def test_the_spectral_cell_carries_the_same_verdict(tmp_path, capsys, name):
    code, err, report = _run(tmp_path, os.path.join(ROOT, "geometries", "cells", f"{name}.toml"), capsys)
    assert code == 0
    acc = report["results"]["accuracy"]
    balances = [c for c in acc["checks"] if c["name"] == "pressure_balance"]
    assert acc["met"] and [c["load"] for c in balances] == list(range(len(report["results"]["loads"])))
    # the estimates the refinement states may exceed their error by more than ten times: per quantity, as in `how`
    loose = {(q["load"], q["name"]): q["loose"] for q in acc["quantities"]}
    assert all(why is None or isinstance(why, str) for why in loose.values())
    flagged = [(k, name, why) for (k, name), why in loose.items() if why]
    assert flagged and all(f"load {k} {name} ({why})" in acc["how"] for k, name, why in flagged)
    from ngcontact.output.report_html import render
    page = render(report, str(tmp_path), [])
    k, name, why = flagged[0]
    assert f"<td>load {k}, {name}</td>" in page and f"<td>{why}</td>" in page.split(f"<td>load {k}, {name}</td>")[1]


def test_the_page_shows_a_missed_accuracy_at_its_top():
    from ngcontact.output.report_html import render
    report = {"title": "t", "results": {"accuracy": {"tolerance": 0.01, "met": False, "checks": [
        {"load": 0, "name": "pressure_balance", "value": 0.03, "limit": 0.01, "ok": False}]}}}
    page = render(report, ".", [])
    top = page.split("<h2>")[0]
    assert '<p class="warn">Accuracy not met (tolerance 0.01): load 0, pressure_balance = 0.03 &gt; 0.01</p>' in top
    report["results"]["accuracy"]["met"] = True
    assert "Accuracy not met" not in render(report, ".", [])


def test_the_slopes_of_westergaard_s_gap():
    """``g = 2h sin^2(pi x)`` has ``g' = 2 pi h sin(2 pi x)``: rms ``sqrt(2) pi h``, largest ``2 pi h``."""
    import numpy as np
    from ngcontact.cell.admissibility import gap_slopes
    h, n = 0.01, 512
    x = np.arange(n) / n
    rms, top = gap_slopes(2 * h * np.sin(np.pi * x) ** 2, 1.0)
    assert abs(rms - np.sqrt(2) * np.pi * h) < 1e-4 * rms and abs(top - 2 * np.pi * h) < 1e-4 * top
    xx, yy = np.meshgrid(x, x)                        # 3D: |grad g| of g(x) alone is the same
    assert abs(gap_slopes(2 * h * np.sin(np.pi * xx) ** 2, 1.0)[0] - rms) < 1e-12


def _height_map_scene(tmp_path, interface_maxh):
    path = tmp_path / "map.toml"
    path.write_text(fe_height_map(interface_maxh) + 'estimate = "off"\n', encoding="utf-8")
    return path


def test_an_fe_mesh_coarser_than_its_height_map_says_so_before_solving(tmp_path, capsys, caplog):
    code, err, report = _run(tmp_path, _height_map_scene(tmp_path, 0.3), capsys)
    assert code == 0
    checks = {c["name"]: c for c in report["results"]["accuracy"]["checks"] if c["load"] is None}
    assert checks["interface_resolution"]["value"] > 2 and not checks["interface_resolution"]["ok"]
    assert not report["results"]["accuracy"]["met"]
    lines = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    said = [m for m in lines if "known before solving: the cell: interface_resolution" in m]
    assert len(said) == 1 and "discretization.method = 'spectral'" in said[0]


def test_the_estimated_quantities_of_a_refinement():
    from ngcontact.cell.admissibility import quantities
    loads = [{"contact_fraction": 0.2, "mean_closure": -0.5}]
    got = {q["name"]: q for q in quantities(loads, [{"contact_fraction": 0.004, "mean_closure": 0.02}], 0.01)}
    assert got["contact_fraction"]["error"] == 0.004 and got["contact_fraction"]["relative_error"] == 0.02
    assert got["contact_fraction"]["met"] and not got["mean_closure"]["met"]
    assert got["mean_closure"]["error"] == 0.01 and got["mean_closure"]["relative_error"] == 0.02
    v, failed = verdict(loads, 0.01, estimates=[{"contact_fraction": 0.004, "mean_closure": 0.02}], how="x")
    assert not v["met"] and not failed and v["estimated"] and v["how"] == "x"      # no check failed: an estimate
    v, _ = verdict(loads, None)
    assert not v["estimated"] and v["quantities"] == [] and "not estimated" in v["how"]


def test_an_estimate_that_may_be_loose_says_so_beside_its_quantity():
    """``loose``: the refinement's statement that an estimate may exceed its error by more than ten times, per
    quantity of the verdict (``None`` where it makes none) and in the page's accuracy table beside it."""
    from ngcontact.output.report_html import render
    loads = [{"contact_fraction": 0.2, "mean_closure": -0.5}, {"contact_fraction": 0.3, "mean_closure": -0.4}]
    estimates = [{"contact_fraction": 0.004, "mean_closure": 0.002}] * 2
    v, _ = verdict(loads, 0.01, estimates=estimates, how="x", loose=[{}, {"mean_closure": "an earlier difference"}])
    assert [(q["load"], q["name"], q["loose"]) for q in v["quantities"]] == [
        (0, "contact_fraction", None), (0, "mean_closure", None), (1, "contact_fraction", None),
        (1, "mean_closure", "an earlier difference")]
    assert all(q["loose"] is None for q in verdict(loads, 0.01, estimates=estimates, how="x")[0]["quantities"])
    page = render({"title": "t", "kind": "cell", "results": {"accuracy": v}}, ".", [])
    row = page.split("<td>load 1, mean_closure</td>")[1].split("</tr>")[0]
    assert "<td>an earlier difference</td>" in row and "may exceed the error by more than 10 times" in page
    v, _ = verdict(loads, 0.01, estimates=estimates, how="x")
    assert "may exceed" not in render({"title": "t", "kind": "cell", "results": {"accuracy": v}}, ".", [])
