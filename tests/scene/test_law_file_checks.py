"""A macro interface law read from a law file is held to the rules of a law the scene states or computes: the
table is a monotone law's row by row, and the law's stiffness lies within the magnitude bounds of
ngcontact.scene.magnitudes (k h / E in [MIN_PENALTY_RATIO, MAX_STIFFNESS_RATIO] at the interface mesh size).
A fault ends in exit 2 naming the file, the row or key, the value and what is allowed, with nothing written."""
from __future__ import annotations

import json
import re

import pytest

from ngcontact import cli
from ngcontact.errors import SceneError
from ngcontact.scene import law_file, loader
from ngcontact.scene import magnitudes as MG

from tests.scene.test_bad_input import MACRO, edit, run_bad

#: the interface mesh size and the softer modulus of MACRO
H, E = 0.01, 210e9
FILE_LAW = ('law = "linear"\nkn = 1e12\nkt = 1e11', 'law = "file"\nlaw_file = "law.json"')


def _law(closure, pressure, *, bundle=None, K0=None) -> str:
    return json.dumps({"format": law_file.FORMAT, "format_version": law_file.FORMAT_VERSION,
                       "table": {"closure": closure, "pressure": pressure},
                       "friction": {"mu": 0.0, "stick_slope": 1e11},
                       "bundle": bundle, "coefficients": None if K0 is None else {"K0": K0, "gap_force": [0.0, 0.0]}})


def _scene(form: str = "tabulated") -> str:
    return edit(MACRO, (FILE_LAW[0], FILE_LAW[1] + f'\nlaw_file_form = "{form}"'))


def test_a_law_file_within_the_bounds_is_accepted(tmp_path):
    (tmp_path / "law.json").write_text(_law([0.0, 1e-6, 2e-6], [0.0, 1e6, 5e6]))
    (tmp_path / "scene.toml").write_text(_scene())
    loader.load(str(tmp_path / "scene.toml"))
    assert cli.main(["check", str(tmp_path / "scene.toml")]) == 0


def test_a_table_steeper_than_double_precision_resolves_is_refused_at_its_row(tmp_path, capsys):
    """The steepest slope (rows 1-2) is 4e12 Pa/m: k h / E = 1.9e-1, accepted; 1e24 Pa/m is 4.8e10, refused,
    as the same table given in the scene is."""
    law = tmp_path / "work" / "law.json"
    slope = (1e18 - 1e6) / 1e-6
    ratio = slope * H / E
    run_bad(tmp_path, capsys, _scene(), f"interface.law_file ({law}): table.pressure[2] = 1e+18: dp/dc (rows 1-2) = "
            f"{slope:g}, dp/dc (rows 1-2) h / E = {ratio:.3g} (h = 0.01 the interface mesh size, E = 2.1e+11 the "
            f"softer body's modulus) must stay below {MG.MAX_STIFFNESS_RATIO:g}", prefix=True,
            files={"law.json": _law([0.0, 1e-6, 2e-6], [0.0, 1e6, 1e18])})
    # the same numbers as the scene's own tabulated law: refused by the same bound
    inline = edit(MACRO, (FILE_LAW[0], 'law = "tabulated"\nclosure = [0.0, 1e-6, 2e-6]\npressure = [0.0, 1e6, 1e18]'))
    (tmp_path / "inline.toml").write_text(inline)
    with pytest.raises(SceneError, match=re.escape(f"h / E = {ratio:.3g}") + ".*" +
                       re.escape(f"must stay below {MG.MAX_STIFFNESS_RATIO:g}")):
        loader.load(str(tmp_path / "inline.toml"))


def test_a_slope_beyond_double_precision_is_named_infinite(tmp_path, capsys):
    law = tmp_path / "work" / "law.json"
    run_bad(tmp_path, capsys, _scene(), f"interface.law_file ({law}): table.pressure[1] = 10000000000.0: dp/dc "
            "(rows 0-1) = inf, dp/dc (rows 0-1) h / E = inf", prefix=True,
            files={"law.json": _law([0.0, 5e-324], [0.0, 1e10])})


def test_a_table_too_soft_to_hold_the_bodies_is_refused(tmp_path, capsys):
    law = tmp_path / "work" / "law.json"
    run_bad(tmp_path, capsys, _scene(), f"interface.law_file ({law}): table.pressure[1] = 0.001: dp/dc (rows 0-1) "
            "= 0.001, dp/dc (rows 0-1) h / E = 4.76e-17 (h = 0.01 the interface mesh size, E = 2.1e+11 the softer "
            f"body's modulus) must be at least {MG.MIN_PENALTY_RATIO:g}", prefix=True,
            files={"law.json": _law([0.0, 1.0, 2.0], [0.0, 1e-3, 1e-3])})


@pytest.mark.parametrize("closure, pressure, expected", [
    ([0.0, 1e-6, 2e-6], [0.0, 2e6, 1e6], "table.pressure[2] = 1000000.0: in the law file {law}: the pressures must "
     "not decrease, a monotone law with a convex energy (row 1 has 2000000.0)"),
    ([0.0, 1e-6, 1e-6], [0.0, 1e6, 2e6], "table.closure[2] = 1e-06: in the law file {law}: the closures must "
     "increase strictly (row 1 has 1e-06)"),
    ([0.0, 1e-6], [1e5, 2e6], "table.pressure[0] = 100000.0: in the law file {law}: must be 0 (contact starts at "
     "the first closure)"),
    ([0.0, 1e-6], [0.0, 0.0], "table.pressure = [0.0, 0.0]: in the law file {law}: the table carries no pressure; "
     "a law needs a positive pressure in some row"),
])
def test_a_table_that_is_no_monotone_law_is_refused_at_its_row(tmp_path, capsys, closure, pressure, expected):
    law = tmp_path / "work" / "law.json"
    run_bad(tmp_path, capsys, _scene(), "interface.law_file: " + expected.format(law=law),
            files={"law.json": _law(closure, pressure)})


def test_the_bundle_and_linear_forms_are_bounded_as_the_scenes_own_are(tmp_path, capsys):
    law = tmp_path / "work" / "law.json"
    table = ([0.0, 1e-6], [0.0, 1e6])
    bundle = {"weights": [1e23, 2e23], "directions": [[1.0, 0.0], [0.6, 0.8]], "gaps": [0.0, 0.0]}
    run_bad(tmp_path, capsys, _scene("bundle"), f"interface.law_file ({law}): bundle.weights = [1e+23, 2e+23]: "
            "sum(weights) = 3e+23, sum(weights) h / E = 1.43e+10", prefix=True,
            files={"law.json": _law(*table, bundle=bundle)})
    run_bad(tmp_path, capsys, _scene("linear"), f"interface.law_file ({law}): coefficients.K0[0][0] = 1e-05: "
            "K0_nn = 1e-05, K0_nn h / E = 4.76e-19", prefix=True,
            files={"law.json": _law(*table, K0=[[1e-5, 0.0], [0.0, 0.0]])})
    bundle["weights"] = [1e9, -1.0]
    run_bad(tmp_path, capsys, _scene("bundle"), f"interface.law_file: bundle.weights[1] = -1.0: in the law file "
            f"{law}: each direction's weight (a stiffness, Pa/m) must be > 0",
            files={"law.json": _law(*table, bundle=bundle)})
