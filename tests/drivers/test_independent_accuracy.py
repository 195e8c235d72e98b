"""Independent loads are held to the default accuracy as a chained sweep is (issue 35, "right by default" and
"a result that misses its accuracy is never silent"; ngcontact.drivers.cell_members): one scene, one accuracy,
whether its loads are solved in a chain or each on its own as a member of a batch.

Requirements: with ``load.independent = true`` an FE cell scene that states no tolerance is estimated and
refined to the default 1 % within ``discretization.budget_dofs`` load by load; its answers agree with the
chained sweep's within their estimates; a budget spent first reports ``accuracy.met = false``, the same
shortfall and the same one warning line as the chained sweep; ``discretization.estimate = "estimate"``
estimates every load on the scene's mesh as the chained sweep does.  The spectral cell's independent loads
are each refined on their own grids (tests/cell/test_spectral_refinement.py,
``test_independent_loads_are_each_refined_and_estimated_and_geometric_runs_are_not``).
"""
import logging
import re

import pytest

from ngcontact.cell.fe.default_refinement import BUDGET_KEY
from ngcontact.runner import solve

from sinusoid_cell import sinusoid_cell

#: Westergaard's sinusoid (exact contact, p* = 0.0172615) on a coarse order-1 mesh at two loads: p / p* = 0.2,
#: whose own answer misses 1 % (graded refinement), and full contact, whose own answer meets it
PRESSURES = "0.0034523, 0.02"
#: every estimated quantity and whether its measure is relative (ngcontact.cell.admissibility.ESTIMATED)
MEASURES = {"contact_fraction": False, "mean_closure": True}


def _scene(tmp_path, name: str, discretization: str, independent: bool) -> str:
    text = sinusoid_cell(k_n="1.0e4", pressure=PRESSURES,
                         discretization="order = 1\nmaxh = 0.4\ninterface_maxh = 0.1\n" + discretization)
    if independent:
        text = text.replace("[discretization]", "independent = true\n[discretization]")
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return str(path)


def _both(tmp_path, caplog, discretization: str) -> dict:
    """``{mode: (results, warning lines)}`` of the scene chained and with independent loads (one worker)."""
    out = {}
    for mode in ("chained", "independent"):
        caplog.clear()
        with caplog.at_level(logging.WARNING):
            report, _ = solve(_scene(tmp_path, mode, discretization, mode == "independent"), workers=1)
        lines = [r.getMessage() for r in caplog.records if "accuracy not met" in r.getMessage()]
        out[mode] = (report["results"], lines)
    return out


def _words(lines: list[str]) -> list[str]:
    """Warning lines without their numbers: the two modes start each solve from other states (a chain, the
    unloaded cell), so an estimate of round-off size may differ in its digits."""
    return [re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "#", line) for line in lines]


def _no_stiffness_in_full_contact(results: dict) -> None:
    """The full-contact load under exact non-penetration has an interface closed at every node: no compliance
    beyond the bulk's, an infinite stiffness (``matrix = None``, as the spectral cell says), neither reported
    as a number nor estimated.  (Its inverse of a round-off compliance, 1.6e9 to 4.2e10 on these meshes, had
    estimates of 2.8 to 25 whose largest named the chained sweep's shortfall: the full-contact load is graded
    with the sweep there, alone it keeps the scene's mesh.)"""
    full = results["loads"][1]
    assert full["contact_fraction"] == pytest.approx(1.0) and full["effective_stiffness"]["matrix"] is None
    assert "normal_stiffness" not in full["error_estimate"]


def _agree(chained: dict, alone: dict) -> None:
    """Each load's quantities agree within the sum of the two estimates (each in its measure)."""
    for k, (a, b) in enumerate(zip(chained["loads"], alone["loads"])):
        for name, relative in MEASURES.items():
            diff = abs(a[name] - b[name]) / (abs(a[name]) if relative else 1.0)
            bound = a["error_estimate"][name] + b["error_estimate"][name]
            assert diff <= bound, (k, name, diff, bound)


@pytest.mark.slow
def test_independent_loads_spend_the_budget_and_say_so_as_the_chained_sweep(tmp_path, caplog):
    """budget_dofs = 1000: the load at p / p* = 0.2 stops at its second graded mesh in both modes; the report
    says not met with the same shortfall and the same single warning line (its figures those of that load, the
    same in both); the full-contact load, alone, keeps the scene's mesh (its own answer meets 1 %), in the
    chained sweep it is refined with the sweep; the answers agree within their estimates."""
    runs = _both(tmp_path, caplog, "budget_dofs = 1000\n")
    (chained, warned), (alone, said) = runs["chained"], runs["independent"]
    for acc in (chained["accuracy"], alone["accuracy"]):
        assert acc["tolerance_from"] == "default" and acc["estimated"] and not acc["met"]
        assert f"{BUDGET_KEY} = 1000" in acc["shortfall"] and "meeting it would take about" in acc["shortfall"]
    assert alone["accuracy"]["shortfall"] == chained["accuracy"]["shortfall"]
    finest = chained["loads"][0]["mesh_history"][-1]                    # the shortfall names load 0's finest mesh
    assert f"grading level {finest['level']} at order {finest['order']}, {finest['ndof']} dofs" in \
        chained["accuracy"]["shortfall"]
    assert len(warned) == 1 and said == warned, (warned, said)
    for results in (chained, alone):
        _no_stiffness_in_full_contact(results)

    def verdict(acc):
        return [(q["load"], q["name"], q["met"]) for q in acc["quantities"]]

    assert verdict(alone["accuracy"]) == verdict(chained["accuracy"])
    assert "mesh_history" in alone["loads"][0] and "next_order" in alone["loads"][1]
    assert alone["accuracy"]["how"].startswith("load 0: each load on meshes graded")
    assert "load 1: the scene's discretization" in alone["accuracy"]["how"]
    _agree(chained, alone)


def test_independent_loads_estimated_on_the_scene_mesh_match_the_chained_sweep(tmp_path, caplog):
    """discretization.estimate = "estimate": every load on the scene's mesh, its error from one order more,
    not refined, in both modes: the same estimates and verdict, and one warning line each."""
    runs = _both(tmp_path, caplog, 'estimate = "estimate"\n')
    (chained, warned), (alone, said) = runs["chained"], runs["independent"]
    assert alone["accuracy"]["how"] == chained["accuracy"]["how"]
    assert alone["accuracy"]["met"] is chained["accuracy"]["met"] is False
    assert len(warned) == 1 and _words(said) == _words(warned)
    for results in (chained, alone):
        _no_stiffness_in_full_contact(results)
    for a, b in zip(chained["loads"], alone["loads"]):
        assert b["next_order"]["order"] == 2 and "mesh_history" not in b
        for name in MEASURES:
            assert b["error_estimate"][name] == pytest.approx(a["error_estimate"][name], rel=1e-6, abs=1e-9)
    _agree(chained, alone)
