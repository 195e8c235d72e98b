"""``discretization.method = "auto"``: the cell that solves a scene, chosen once and stated with its reason.

The rule (:mod:`ngcontact.scene.cell_method`): spectral for a small-slope cell that sets no key only the FE
cell reads, fe otherwise; ``grid`` asks for the spectral cell.  Every consumer sees the resolved method: the
validated scene, the report, the accuracy study's knobs and the links of a macro scene.
"""
import json
import os

import pytest

from ngcontact import cli
from ngcontact.errors import SceneError
from ngcontact.output.report import method_line
from ngcontact.scene import loader
from ngcontact.scene.discretization_knobs import MeshSize, SpectralGrid
from ngcontact.scene.two_scale_section import TwoScaleSpec, load_cell

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GEOMETRIES = os.path.join(ROOT, "geometries")


def cell(*, geometry=None, contact=None, discretization=None, solver=None) -> dict:
    """A flat 2D cell with Westergaard's sinusoidal gap, sections replaced by the arguments."""
    data = {"kind": "cell", "materials": {"solid": {"E": 1.0, "nu": 0.3}},
            "bodies": {"rough": "solid", "counter": "solid"},
            "geometry": geometry or {"profile": "flat"},
            "contact": contact or {"k_n": 1e3, "gap": {"kind": "sinusoid", "h": 0.01}},
            "load": {"pressure": [0.005]}}
    if discretization is not None:
        data["discretization"] = discretization
    if solver is not None:
        data["solver"] = solver
    return data


def test_auto_is_the_default_and_picks_the_spectral_cell_for_a_flat_frictionless_cell():
    scene = loader.from_dict(cell())
    choice = scene.method_choice
    assert choice.requested == "auto" and choice.automatic
    assert choice.method == "spectral" and scene.discretization.method == "spectral"
    assert choice.statement == ("spectral: a small-slope cell (flat interface, a sinusoid initial gap), no FE-only "
                                "key set")
    assert loader.as_dict(scene)["discretization"]["method"] == "spectral"     # the echo and the cache keys
    # the exact contact's default scale is the grid step's, the accuracy study refines the grid
    exact = loader.from_dict(cell(contact={"enforcement": "exact", "gap": {"kind": "sinusoid", "h": 0.01}}))
    assert exact.contact.k_n == pytest.approx(10.0 * 1.0 / (1.0 / 1024))
    assert SpectralGrid().applies(scene) and not MeshSize().applies(scene)


def test_a_3d_summit_surface_is_small_slope_and_spectral():
    scene = loader.from_dict(cell(geometry={"profile": "bisinusoid", "arrangement": "summit", "amplitude": 0.005,
                                            "h_rough": 0.6, "h_counter": 0.6},
                                  contact={"k_n": 1e3}))
    assert scene.method_choice.statement == ("spectral: a small-slope cell (flat interface, the bisinusoid "
                                             "roughness in the initial gap), no FE-only key set")


def test_auto_picks_fe_for_a_conforming_profile():
    scene = loader.from_dict(cell(geometry={"profile": "sinusoid", "arrangement": "conforming", "amplitude": 0.05},
                                  contact={"k_n": 1e3}))
    assert scene.discretization.method == "fe" and scene.method_choice.automatic
    assert scene.method_choice.statement == ("fe: geometry.profile 'sinusoid' in the 'conforming' arrangement is "
                                             "not small-slope")
    assert MeshSize().applies(scene) and not SpectralGrid().applies(scene)


@pytest.mark.parametrize("section, key, value", [("discretization", "maxh", 0.2),
                                                 ("discretization", "order", 2),     # the default, written
                                                 ("discretization", "interface_maxh", 0.01),
                                                 ("solver", "max_iter", 60),
                                                 ("solver", "start", "rigid"),
                                                 ("solver", "linear", "direct")])
def test_auto_picks_fe_when_a_key_only_the_fe_cell_reads_is_set_and_names_it(section, key, value):
    scene = loader.from_dict(cell(**{section: {key: value}}))
    assert scene.discretization.method == "fe"
    assert scene.method_choice.reason == (f"a small-slope cell, but {section}.{key} is set, which only the FE cell "
                                          "reads")


def test_exact_friction_with_a_huber_width_is_the_fe_cell_s_and_without_one_the_spectral_cell_s():
    friction = {"enforcement": "exact", "friction": "tresca", "G": 0.002, "gap": {"kind": "sinusoid", "h": 0.01}}
    with_w = loader.from_dict(cell(contact=dict(friction, w=1e-5)))
    assert with_w.discretization.method == "fe" and "contact.w is set" in with_w.method_choice.reason
    assert "exact friction has no Huber width" in with_w.method_choice.reason
    assert loader.from_dict(cell(contact=friction)).discretization.method == "spectral"
    # under the penalty both cells regularize friction with w: the spectral cell
    penalty = dict(friction, enforcement="penalty", k_n=1e3, w=1e-5)
    assert loader.from_dict(cell(contact=penalty)).discretization.method == "spectral"


def test_a_tolerance_below_the_spectral_solver_s_floor_is_the_fe_cell_s():
    scene = loader.from_dict(cell(discretization={"tolerance": 1e-10}, solver={"rtol": 1e-10}))
    assert scene.discretization.method == "fe"
    assert "below what the spectral cell's solver resolves (10 x solver.rtol = 1e-09)" in scene.method_choice.reason


def test_a_method_set_by_the_scene_is_kept_and_said_so():
    for method in ("fe", "spectral"):
        scene = loader.from_dict(cell(discretization={"method": method}))
        assert scene.discretization.method == method and not scene.method_choice.automatic
        assert scene.method_choice.statement == f"{method}: set by discretization.method = {method!r}"


def test_a_grid_asks_for_the_spectral_cell_and_is_refused_where_it_cannot_solve_the_cell():
    scene = loader.from_dict(cell(discretization={"grid": 256}))
    assert scene.discretization.method == "spectral" and scene.discretization.grid == 256
    assert scene.method_choice.reason.startswith("discretization.grid = 256 is set, which only the spectral cell reads")
    conforming = cell(geometry={"profile": "sinusoid", "arrangement": "conforming", "amplitude": 0.05},
                      contact={"k_n": 1e3}, discretization={"grid": 256})
    with pytest.raises(SceneError) as err:
        loader.from_dict(conforming)
    assert str(err.value) == ("discretization.grid = 256: sets the spectral cell's grid, which solves the small-slope "
                              "cell only, but geometry.profile 'sinusoid' in the 'conforming' arrangement is not "
                              "small-slope: remove it (the FE cell solves this cell), or set discretization.method = "
                              "'fe'")
    with pytest.raises(SceneError) as err:
        loader.from_dict(cell(discretization={"grid": 256, "maxh": 0.2}))
    assert str(err.value).startswith("discretization.grid = 256: sets the spectral cell's grid, but "
                                     "discretization.maxh is set too, which only the FE cell reads")


def test_the_report_states_the_method_and_why(tmp_path, capsys):
    path = tmp_path / "cell.toml"
    path.write_text('kind = "cell"\n[materials.solid]\nE = 1.0\nnu = 0.3\n[bodies]\nrough = "solid"\n'
                    'counter = "solid"\n[geometry]\nprofile = "flat"\n[contact]\nenforcement = "exact"\n'
                    'gap = { kind = "sinusoid", h = 0.01 }\n[load]\npressure = [0.005]\n'
                    '[discretization]\nestimate = "off"\n')
    out = tmp_path / "out"
    assert cli.main(["run", str(path), "--out", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    stated = report["results"]["accuracy"]["method"]
    assert stated == {"method": "spectral", "requested": "auto",
                      "reason": "a small-slope cell (flat interface, a sinusoid initial gap), no FE-only key set",
                      "statement": "spectral: a small-slope cell (flat interface, a sinusoid initial gap), no "
                                   "FE-only key set"}
    assert report["scene"]["discretization"]["method"] == "spectral"
    assert report["results"]["method"]["name"] == "spectral"
    assert "cell method spectral: a small-slope cell" in capsys.readouterr().err     # the progress lines
    assert "spectral: a small-slope cell (flat interface, a sinusoid initial gap)" in (out / "report.html").read_text()
    assert method_line(report["results"]) == "cell method " + stated["statement"]
    assert cli.main(["check", str(path)]) == 0             # said before solving too
    assert f"{path}: cell method " + stated["statement"] in capsys.readouterr().out


def _auto_cell(tmp_path, friction: str = "") -> str:
    """A copy of the shipped stem-groove cell, which sets no FE-only key (``method = "auto"`` picks the spectral
    cell), with ``friction`` added to its ``[contact]``."""
    text = open(os.path.join(GEOMETRIES, "cells", "stem_grooves.toml"), encoding="utf-8").read()
    if friction:
        text = text.replace("[load]", friction + "\n[load]")
    path = tmp_path / "auto_cell.toml"
    path.write_text(text)
    return str(path)


def test_a_two_scale_loop_and_a_macro_scene_see_the_auto_cell_resolved(tmp_path):
    path = _auto_cell(tmp_path)
    spec = TwoScaleSpec(cell=path, tol=1e4)
    loop = load_cell(loader.load_with_contact, path, path, {}, spec)
    assert loop.discretization.method == "spectral" and loop.method_choice.automatic
    # the macro scene: its loop cell as the study's knobs see it (cell_grid, not cell_h)
    from ngcontact.scene.cell_table_knobs import CellGrid, CellMeshSize, loop_cell
    data = loader.parsed(os.path.join(GEOMETRIES, "femur_stem_3d_two_scale.toml"))
    data["two_scale"]["cell"] = path
    macro = loader.from_dict(data, base_dir=GEOMETRIES)
    assert loop_cell(macro).discretization.method == "spectral"
    assert CellGrid().applies(macro) and not CellMeshSize().applies(macro)
    # a cell_maxh of the loop is an FE-only key: the loop's cell is then the FE cell
    fe_loop = load_cell(loader.load_with_contact, path, path, {}, TwoScaleSpec(cell=path, tol=1e4, cell_maxh=25e-6))
    assert fe_loop.discretization.method == "fe" and "discretization.maxh is set" in fe_loop.method_choice.reason


def test_links_that_need_the_fe_cell_solve_an_auto_cell_by_fe(tmp_path):
    path = _auto_cell(tmp_path, friction='friction = "tresca"\nG = 1e5\nw = 1e-9')
    assert loader.load(path).discretization.method == "spectral"
    spec = TwoScaleSpec(cell=path, tol=1e4)
    assert load_cell(loader.load_with_contact, path, path, {}, spec).discretization.method == "spectral"
    shear = load_cell(loader.load_with_contact, path, path, {}, spec, shear_from_cell=True)
    assert shear.discretization.method == "fe"
    assert shear.method_choice.statement == "fe: set by discretization.method = 'fe'"
    # the strength recovery's cell
    from ngcontact.drivers.build import recovery_cell_problem
    scene, problem = recovery_cell_problem(path, key="strength.cell")
    assert scene.discretization.method == "fe" and problem is not None


def test_a_geometric_only_cell_states_its_method_too():
    from ngcontact.drivers import run_cell
    from ngcontact.output.report import Clock
    data = cell(contact={"k_n": 1e3, "geometric_only": True})
    del data["load"]
    outcome = run_cell.run(loader.from_dict(data), Clock())
    # the flat grid's whole-surface coefficients are exact (SpectralCellSolver.whole_surface_error)
    accuracy = outcome.results["accuracy"]
    assert accuracy["estimated"] and accuracy["met"] and accuracy["how"].startswith("exact")
    assert accuracy["quantities"] and all(q["error"] == 0.0 for q in accuracy["quantities"])
    assert accuracy["method"] == {
        "method": "spectral", "requested": "auto", "reason": "a small-slope cell (flat interface, no initial gap), no "
        "FE-only key set", "statement": "spectral: a small-slope cell (flat interface, no initial gap), no FE-only "
        "key set"}
