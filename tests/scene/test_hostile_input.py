"""Hostile numbers a new user may write, found by the reliability audit of issue 35: each ends in exit 2, one
line naming the key, the value and what is allowed, and nothing written (``run_bad`` of
:mod:`tests.scene.test_bad_input`), never in a solver failure, an unexpected error or a non-finite number."""
import json
import logging
import os

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.scene.resolved_scene import MAX_SAMPLES

from sinusoid_cell import sinusoid_cell
from test_bad_input import MACRO, edit, run_bad

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SPECTRAL = sinusoid_cell(discretization='method = "spectral"\ngrid = 64\ntolerance = 0.1')

LENGTHS = "must lie in [1e-09, 1e+09]: choose a length unit (e.g. mm or um) in which the geometry's sizes fall in " \
          "that range"


@pytest.mark.parametrize("key, value", [("period", "1e-300"), ("h_rough", "1e300")])
def test_a_spectral_cell_scaled_beyond_the_lengths_the_fe_cell_takes(tmp_path, capsys, key, value):
    """Was: exit 3, 'non-finite number nan at report.results.method.refinement[0].mean_closure[0]'."""
    text = edit(SPECTRAL, ('profile = "flat"', f'profile = "flat"\n{key} = {value}')) if key == "period" else \
        edit(SPECTRAL, ("h_rough = 1.0", f"h_rough = {value}"))
    run_bad(tmp_path, capsys, text, f"geometry.{key} = {float(value)!r}: {LENGTHS}")


@pytest.mark.parametrize("old, new, key, shown", [
    ("h = 0.01", "h = 1e300", "contact.gap.h", "1e+300"),
    ('{ kind = "sinusoid", h = 0.01 }', '{ kind = "constant", value = 1e300 }', "contact.gap.value", "1e+300"),
    ("pressure = [0.005]", "normal_jump = [1e300]", "load.normal_jump[0]", "1e+300")])
@pytest.mark.parametrize("method", ["spectral", "fe"])
def test_a_gap_or_jump_beyond_the_length_range(tmp_path, capsys, old, new, key, shown, method):
    """Was: exit 3 ('unexpected error (OverflowError)', 'complementarity residual nan', 'the start value gives
    a non-finite energy or residual')."""
    text = SPECTRAL if method == "spectral" else sinusoid_cell(
        enforcement="penalty", discretization="order = 1\nmaxh = 0.5")
    run_bad(tmp_path, capsys, edit(text, (old, new)),
            f"{key} = {float(shown)!r}: must be at most 1e+09 in magnitude: choose a length unit (e.g. mm or um) in "
            "which the geometry's sizes fall in [1e-09, 1e+09]")


def test_the_strain_of_a_load_beyond_small_strain_is_warned_and_one_beyond_the_modulus_refused(tmp_path, caplog,
                                                                                                 capsys):
    """Was: 'unexpected error (OverflowError)', exit 3: the far-face strain squared the jump of 1e300 / E; then
    exit 0 with a far-face strain of 1e300, warned.  A load straining the bodies beyond small strain but less
    than by their own size is solved, its strain recorded and warned; one beyond it (1e300 here) is refused
    before the solve (:mod:`ngcontact.scene.magnitudes`, tests/scene/test_absurd_magnitudes.py)."""
    scene = tmp_path / "scene.toml"
    scene.write_text(edit(SPECTRAL, ("pressure = [0.005]", "pressure = [0.5]")))
    with caplog.at_level(logging.WARNING):
        assert cli.main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert any("is beyond small strain" in r.getMessage() for r in caplog.records)
    load = json.loads((tmp_path / "out" / "report.json").read_text())["results"]["loads"][0]
    assert 0.05 < load["far_face_strain"] < 1.0
    (tmp_path / "refused").mkdir()
    run_bad(tmp_path / "refused", capsys, edit(SPECTRAL, ("pressure = [0.005]", "pressure = [1e300]")),
            "load.pressure[0] = 1e+300: strains the softer body (materials.solid, E = 1) by 1e+300; ", prefix=True)


HEIGHT_MAP = sinusoid_cell(discretization='method = "spectral"\ntolerance = 0.1', profile="height_map")


def test_a_height_map_spanning_beyond_the_length_range(tmp_path, capsys):
    """Was: exit 3, 'constrained CG: the complementarity residual nan' (heights of 1e298 on a period of 1)."""
    x = np.linspace(0.0, 1.0, 17)
    H = 1e298 * np.cos(2 * np.pi * x)[None, :] * np.cos(2 * np.pi * x)[:, None]
    text = edit(HEIGHT_MAP, ('profile = "height_map"', 'profile = "height_map"\nfile = "map.npy"\n'
                                                       'arrangement = "summit"'),
                ('gap = { kind = "sinusoid", h = 0.01 }\n', ""))
    run_bad(tmp_path, capsys, text, "geometry.file (map.npy) = 'heights spanning 2e+298': must span at most 1e+09: "
            "choose a length unit (e.g. mm or um) in which the geometry's sizes fall in [1e-09, 1e+09]",
            files={"map.npy": H})


def test_a_gap_table_beyond_the_length_range(tmp_path, capsys):
    """Was: exit 3, 'constrained CG: the complementarity residual nan' (a tabulated gap of 1e300)."""
    text = edit(SPECTRAL, ('{ kind = "sinusoid", h = 0.01 }', '{ kind = "tabulated", file = "gap.csv" }'))
    run_bad(tmp_path, capsys, text, "contact.gap.file (gap.csv) = 'heights spanning 1e+300': must span at most "
            "1e+09: choose a length unit (e.g. mm or um) in which the geometry's sizes fall in [1e-09, 1e+09]",
            files={"gap.csv": "x,g\n0,0\n0.5,1e300\n1,0\n"})


def test_the_span_bound_of_tabulated_data_is_the_scene_s_length_range():
    from ngcontact.geometry.tabulated import MAX_SPAN
    from ngcontact.scene.mesh_size import LENGTH_RANGE
    assert MAX_SPAN == LENGTH_RANGE[1] and f"[{LENGTH_RANGE[0]:g}, {LENGTH_RANGE[1]:g}]" in LENGTHS


@pytest.mark.parametrize("line, key, shown", [("gap = -1e300", "interface.gap", "-1e+300"),
                                              ("gap_table = [[0.0, 1e300], [0.02, 0.0]]", "interface.gap_table[0]",
                                               "1e+300")])
def test_a_macro_gap_beyond_the_length_range(tmp_path, capsys, line, key, shown):
    """Was: exit 3, 'the start value gives a non-finite energy or residual' (an interference of 1e300 m)."""
    run_bad(tmp_path, capsys, edit(MACRO, ("kt = 1e11", f"kt = 1e11\n{line}")),
            f"{key} = {float(shown)!r}: must be at most 1e+09 in magnitude: choose a length unit (e.g. mm or um) in "
            "which the geometry's sizes fall in [1e-09, 1e+09]")


def test_a_strain_beyond_small_strain_is_no_met_accuracy(tmp_path, caplog):
    """Was: accuracy.met = true beside a far-face strain of 7e299 (and of 10 in a cell 2 high): the warning
    said the linear cell model does not hold, the verdict did not.  The strain is now a check of each load,
    against the small-strain bound, and a miss makes the result not met (reported, not refused)."""
    text = sinusoid_cell(k_n="1e-2", enforcement="penalty", pressure="1e-5, 0.2",
                         discretization='method = "spectral"\ngrid = 64')
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    with caplog.at_level(logging.WARNING):
        assert cli.main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    acc = json.loads((tmp_path / "out" / "report.json").read_text())["results"]["accuracy"]
    strain = {c["load"]: c for c in acc["checks"] if c["name"] == "far_face_strain"}
    assert strain[0]["ok"] and not strain[1]["ok"] and strain[1]["limit"] == 0.05
    assert not acc["met"]
    assert len([r for r in caplog.records if "far_face_strain" in r.getMessage() or "small strain" in
                r.getMessage()]) == 1      # the small-strain warning, said once


SELF_AFFINE = edit(SPECTRAL, ('profile = "flat"', 'profile = "self_affine"\narrangement = "summit"\nspectrum = { '
                              'hurst = 0.8, rms_slope = 0.1, rolloff = 0.25, cutoff = 0.0625, grid = 32, seed = 3 }'),
                   ('gap = { kind = "sinusoid", h = 0.01 }\n', ""))


@pytest.mark.parametrize("key", ["rms_slope", "rms_height"])
def test_a_random_surface_drawn_beyond_the_length_range(tmp_path, capsys, key):
    """Was: exit 3, 'constrained CG: the complementarity residual nan' (rms_slope or rms_height = 1e300).  The
    surface is drawn when the scene runs (``check`` does not draw it)."""
    run_bad(tmp_path, capsys, edit(SELF_AFFINE, ("rms_slope = 0.1", f"{key} = 1e300")),
            f"inadmissible model input: {key} = 1e+300: draws heights spanning ", prefix=True, commands=("run",))


def test_a_rolloff_longer_than_the_period_is_named(tmp_path, capsys):
    """Was: 'cutoff = 0.0625: need ... rolloff (100) <= longest (1)': the key named was not the one at fault."""
    run_bad(tmp_path, capsys, edit(SELF_AFFINE, ("rolloff = 0.25", "rolloff = 100.0")),
            "inadmissible model input: rolloff = 100.0: need 2 grid steps (0.0625) <= cutoff < rolloff (100) <= "
            "longest (1) <= period (1)", commands=("run",))


def test_an_epsilon_study_sampling_grid_beyond_its_bound(tmp_path, capsys):
    """Was: accepted by check and run; the grid of 1e8 x 1e8 points is allocated only after every level's
    solves (a MemoryError at the end of the study)."""
    direct = os.path.join(ROOT, "geometries", "direct")
    text = edit(open(os.path.join(direct, "block_rect_valleys.toml")).read(),
                ("grid = [100, 50]", "grid = [100000000, 100000000]"))
    run_bad(tmp_path, capsys, text, f"study.grid = [100000000, 100000000]: must lie in [4, {MAX_SAMPLES}]",
            files={"rect_valleys_cell.toml": open(os.path.join(direct, "rect_valleys_cell.toml")).read()},
            commands=("check",))


@pytest.mark.parametrize("old, new, key, shown", [
    ('boundary = "bottom"', 'boundary = "bottom"\ncomponents = ["y"]\ndisplacement = [-1e300]',
     "supports[0].displacement[0]", "-1e+300"),
    ('boundary = "bottom"', 'boundary = "bottom"\ncomponents = ["y"]\nslope = [1e300]', "supports[0].slope[0]",
     "1e+300")])
def test_a_prescribed_displacement_or_gradient_beyond_the_length_range(tmp_path, capsys, old, new, key, shown):
    """Was: exit 3, 'the start value gives a non-finite energy or residual' (a macro or direct scene's support
    displacement or slope of 1e300)."""
    text = edit(MACRO, (old, new), ("[[loads]]", '[[supports]]\nboundary = "bottom"\ncomponents = ["x"]\n\n[[loads]]'))
    run_bad(tmp_path, capsys, text, f"{key} = {float(shown)!r}: must be at most 1e+09 in magnitude", prefix=True)



@pytest.mark.parametrize("rows, line, x", [("0,0\n1e-9,-0.1\n0.7,-0.2\n1,0\n", 3, "1e-09"),
                                           ("0,0\n0.3,-0.1\n0.3000000001,-0.2\n1,0\n", 4, "0.3000000001")])
def test_a_profile_wall_closer_than_the_mesher_resolves(tmp_path, capsys, rows, line, x):
    """Was: a point 1e-9 from the cell's side hung Netgen's mesher for over ten minutes, deaf to Ctrl-C."""
    with open(os.path.join(ROOT, "geometries", "cells", "tabulated_profile.toml")) as f:
        text = f.read().replace('file = "data/profile_example.csv"', 'file = "p.csv"')
    run_bad(tmp_path, capsys, text, f"geometry.file (p.csv)[line {line}].x = {x}: x must increase by at least 1e-06 of the "
            "period (1e-06; previous x = ", prefix=True, files={"p.csv": "x,y\n" + rows})


def test_a_sweep_of_more_loads_than_a_run_can_hold():
    """Was: a list of 100,000 pressures was accepted (hours of solves, files per load)."""
    from ngcontact.scene.cell_scene import MAX_LOADS, LoadSpec
    from ngcontact.errors import SceneError
    LoadSpec(pressure=(0.01,) * MAX_LOADS).check("load")
    with pytest.raises(SceneError, match=rf"load.pressure = '{MAX_LOADS + 1} entries': must not be empty; a sweep "
                                         rf"takes at most {MAX_LOADS} loads \({MAX_LOADS} entries\)"):
        LoadSpec(pressure=(0.01,) * (MAX_LOADS + 1)).check("load")
    with pytest.raises(SceneError, match=rf"load.shear = '{2 * MAX_LOADS + 1} entries'"):
        LoadSpec(pressure=(0.01,), shear=(0.0,) * (2 * MAX_LOADS + 1)).check("load")
    with pytest.raises(SceneError, match="load.pressure = '0 entries': must not be empty"):
        LoadSpec(pressure=()).check("load")
