"""An FE cell scene that states no tolerance is estimated by default (issue 35, "right by default"): its own
answer, its error from one order more on the same mesh (ngcontact.cell.fe.saturation), judged against the
default tolerance, and a miss is never silent."""
import json
import logging
from dataclasses import dataclass, field

import pytest

from ngcontact import cli
from ngcontact.cell.fe.saturation import SATURATION, estimate_on_scene, saturation_estimates
from ngcontact.drivers.build import cell_loads, fe_variant, spectral_variant

from fe_cells import fe_scene, fe_table, toml

#: the 2D spectral contact fraction's collocation error at 65,536 points (ngcontact.cell.spectral.grid_measures)
COLLOCATION = 2e-5


def test_the_bound_of_the_saturation_assumption():
    """``|q_p - q| <= d / (1 - beta)``: the contact fraction absolutely, the closure relative to the reported
    value; a quantity one of the two lacks is not estimated."""
    low = [{"contact_fraction": 0.30, "mean_closure": 2.0, "normal_stiffness": 5.0}]
    high = [{"contact_fraction": 0.31, "mean_closure": 2.1}]
    (got,) = saturation_estimates(low, high)
    assert got["contact_fraction"] == pytest.approx(0.01 / (1 - SATURATION), rel=1e-12)
    assert got["mean_closure"] == pytest.approx(0.05 / (1 - SATURATION), rel=1e-12)
    assert "normal_stiffness" not in got
    # a sequence that keeps exactly the fraction beta of its error: the bound is the error itself
    q, e = 0.5, 0.04
    (tight,) = saturation_estimates([{"contact_fraction": q + e}], [{"contact_fraction": q + SATURATION * e}])
    assert tight["contact_fraction"] == pytest.approx(e, rel=1e-12)


@dataclass
class _Sol:
    results: dict
    iterations: int = 1
    newton: list = field(default_factory=list)


@dataclass
class _Cell:
    """A stand-in FE cell whose scene refuses one order more."""

    model: object = field(default_factory=lambda: type("M", (), {"order": 10})())
    variant: object = None

    def sweep(self, loads):
        return [_Sol({"contact_fraction": 0.2, "mean_closure": 1.0}) for _ in loads]

    def unknowns(self):
        return 10


def test_a_cell_that_cannot_raise_its_order_is_not_estimated_and_not_met():
    done = estimate_on_scene(_Cell(), [None, None])
    assert len(done.solutions) == 2 and done.estimates == [] and not done.met and done.scene_discretization
    assert done.how.startswith("not estimated: the scene refuses order 11")


@pytest.mark.parametrize("order", [1, 2])
def test_the_default_estimate_bounds_the_error_on_the_stem_grooves(order):
    """The stem-groove cell (flat 2D, penalty) on a coarser interface mesh, against its spectral twin on
    65,536 points: the estimate of the scene's own answer is at least its error and at most ten times it."""
    scene = fe_scene("stem_grooves")      # the shipped scene is solved by the spectral cell; here its FE cell
    loads = cell_loads(scene)
    reference = spectral_variant(scene, 65536).sweep(loads)[0].results
    # the estimate of the scene's own answer (which the default refines where it misses 1 %)
    done = estimate_on_scene(fe_variant(scene, interface_maxh=4e-6, order=order), loads)
    got, estimate = done.solutions[0].results, done.estimates[0]
    assert done.scene_discretization
    fraction = abs(got["contact_fraction"] - reference["contact_fraction"])
    assert max(fraction - COLLOCATION, 0) <= estimate["contact_fraction"] <= 10 * fraction, (fraction, estimate)
    closure = abs(got["mean_closure"] - reference["mean_closure"]) / reference["mean_closure"]
    assert closure <= estimate["mean_closure"] <= 10 * closure, (closure, estimate)


def _coarse_stem(tmp_path, order: int):
    table = fe_table("stem_grooves")
    table["discretization"].update(order=order, interface_maxh=4e-6, estimate="estimate")  # not refined
    text = toml(table)
    path = tmp_path / f"stem_order{order}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_default_run_beyond_one_percent_warns_once_and_is_not_met(tmp_path, capsys, caplog):
    """Order 1 on a coarse interface mesh, estimated and not refined (discretization.estimate = "estimate"):
    the closure's estimate exceeds the default 1 %; the run ends (exit 0) with accuracy.met = false, the estimate per load, one warning line naming the quantity, and the
    terminal's accuracy line with the estimates."""
    out = tmp_path / "out"
    with caplog.at_level(logging.WARNING):
        code = cli.main(["run", str(_coarse_stem(tmp_path, 1)), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    assert "accuracy NOT met (tolerance 0.01): contact_fraction" in err and "mean_closure" in err
    results = json.loads((out / "report.json").read_text())["results"]
    acc = results["accuracy"]
    assert acc["tolerance_from"] == "default" and acc["estimated"] and not acc["met"]
    unmet = [q for q in acc["quantities"] if not q["met"]]
    assert [q["name"] for q in unmet] == ["mean_closure"] and unmet[0]["relative_error"] > 0.01
    entry = results["loads"][0]
    assert entry["error_estimate"]["mean_closure"] > 0.01 and entry["next_order"]["order"] == 2
    lines = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    unmet_lines = [m for m in lines if "scene's own discretization" in m]
    assert len(unmet_lines) == 1 and "load 0's mean_closure exceeds the default tolerance 0.01" in unmet_lines[0]
