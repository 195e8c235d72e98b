"""ngcontact export: the table is the cell's pressure-closure curve, the JSON law comes back unchanged,
and bad input is refused before anything is written.

Requirements:
* the exported table reproduces the bundle's pressure-closure curve at its nodes to 1e-12 (also as printed
  in the Abaqus and CalculiX files) and between nodes within the table tolerance;
* a macro scene reading the exported JSON (interface.law = "file") gives the same result as the scene the law
  came from, to 1e-12;
* what a format cannot carry is a comment in the file and a warning on stderr;
* an unknown format, a missing or law-less scene, a user's file in --out, a bad law file: a clear error,
  exit 2, nothing written.
"""
import json
import os
import re
import warnings as warnings_module

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.errors import ModelError, SceneError
from ngcontact.export import law_table as lt
from ngcontact.export.law_source import exported_law
from ngcontact.scene import loader

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GAP_CELL = os.path.join(ROOT, "geometries", "macro", "sinusoid_gap_cell.toml")
SAWTOOTH_BLOCK = os.path.join(ROOT, "geometries", "macro", "block_on_sawtooth.toml")
UNIT, P_MAX, TOL = 1e-4, 1e8, 1e-3


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))


def _bundle_pressure(bundle, c):
    """The bundle law's normal traction at the jump a = (c, 0), straight from eqs. 31-33 (no ramps)."""
    w, n, g = (np.asarray(bundle[k], float) for k in ("weights", "directions", "gaps"))
    return np.array([np.sum(w * n[:, 0] * np.maximum(n[:, 0] * ci - g, 0.0)) for ci in c])


def _rows(text):
    """(pressure, overclosure) data lines after the tabular *SURFACE BEHAVIOR card."""
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if "PRESSURE-OVERCLOSURE=TABULAR" in ln) + 1
    rows = []
    for ln in lines[start:]:
        if ln.startswith("*"):
            break
        rows.append([float(v) for v in ln.split(",")])
    return np.array(rows)


def test_table_is_the_curve_at_its_nodes_and_within_the_tolerance_between(tmp_path):
    law = exported_law(GAP_CELL, length_unit=UNIT, p_max=P_MAX, tolerance=TOL)
    assert law.bundle is not None and len(law.kinks) > 20, "the gap cell must have many kinks"
    exact = _bundle_pressure(law.bundle, law.closure)
    assert np.max(np.abs(law.pressure - exact)) <= 1e-12 * P_MAX
    assert law.pressure[0] == 0.0 and np.all(np.diff(law.closure) > 0) and law.pressure[-1] == pytest.approx(P_MAX)
    c = np.linspace(law.closure[0] - 1e-6, law.closure[-1] * 1.2, 20001)
    between = np.abs(np.interp(c, law.closure, law.pressure, left=0.0,
                               right=np.nan) - _bundle_pressure(law.bundle, c))
    inside = c <= law.closure[-1]
    assert np.max(between[inside]) <= TOL * P_MAX * (1 + 1e-9)
    # the tolerance is what thins the table: a tenfold tighter one keeps more nodes, and is met too
    fine = exported_law(GAP_CELL, length_unit=UNIT, p_max=P_MAX, tolerance=TOL / 10)
    assert len(fine.closure) > len(law.closure)
    assert np.max(np.abs(np.interp(c[inside], fine.closure, fine.pressure)
                         - _bundle_pressure(fine.bundle, c[inside]))) <= TOL / 10 * P_MAX * (1 + 1e-9)
    # beyond the last kink the slope is k_n0 of eq. 34 (what Abaqus extrapolates with)
    assert law.k_n0 == pytest.approx(law.K0[0, 0], rel=1e-12)
    for fmt in ("abaqus", "calculix"):
        out = tmp_path / fmt
        assert cli.main(["export", GAP_CELL, "--format", fmt, "--out", str(out), "--length-unit", str(UNIT),
                         "--max-pressure", str(P_MAX), "--table-tol", str(TOL), "--mu", "0.3"]) == 0
        text = next(out.glob("*.inp")).read_text()
        rows = _rows(text)
        assert rows[0, 0] == 0.0 and np.all(np.diff(rows[:, 1]) > 0)
        assert np.max(np.abs(rows[:, 0] - _bundle_pressure(law.bundle, rows[:, 1]))) <= 1e-12 * P_MAX
        assert "pressure range 0 .. 1e+08 Pa" in text
        assert all(len(v.strip()) <= 20 for r in text.splitlines() if r and r[0].isdigit() for v in r.split(","))
        friction = text.splitlines()[text.splitlines().index(next(ln for ln in text.splitlines()
                                                                 if ln.startswith("*FRICTION"))) + 1]
        assert float(friction.split(",")[0]) == pytest.approx(0.3)
        if fmt == "calculix":
            assert float(friction.split(",")[1]) == pytest.approx(law.K0[1, 1], rel=1e-12)


def test_ansys_stiffness_is_the_last_segment_of_the_curve(tmp_path):
    assert cli.main(["export", GAP_CELL, "--format", "ansys", "--out", str(tmp_path), "--length-unit", str(UNIT),
                     "--max-pressure", str(P_MAX)]) == 0
    text = (tmp_path / "interface_law_ansys.mac").read_text()
    value = {k: float(re.search(rf"^{k} = (\S+)", text, re.M).group(1)) for k in ("NGC_FKN", "NGC_FKT", "NGC_CNOF")}
    law = exported_law(GAP_CELL, length_unit=UNIT, p_max=P_MAX)
    assert value["NGC_FKN"] == pytest.approx(-law.K0[0, 0], rel=1e-15)
    assert value["NGC_FKT"] == pytest.approx(-law.K0[1, 1], rel=1e-15)
    d = law.kinks.max() + np.array([0.0, 1e-6])  # on and beyond the last kink (gap 0: overclosure = closure)
    line = -value["NGC_FKN"] * (d + value["NGC_CNOF"])
    assert np.allclose(line, _bundle_pressure(law.bundle, d), rtol=1e-10, atol=1e-6 * P_MAX * 1e-6)
    assert "RMODIF,NGC_REAL,3,NGC_FKN" in text and "MP,MU,NGC_MAT,NGC_MU" in text


def test_what_a_format_cannot_carry_is_a_comment_and_a_warning(tmp_path, capsys):
    assert cli.main(["export", SAWTOOTH_BLOCK, "--format", "calculix", "--out", str(tmp_path / "c"),
                     "--max-pressure", "1e8"]) == 0
    err = capsys.readouterr().err
    assert "warning: calculix cannot carry: k_nt0" in err
    assert "NOT CARRIED: k_nt0" in (tmp_path / "c" / "interface_law_calculix.inp").read_text()
    assert cli.main(["export", SAWTOOTH_BLOCK, "--format", "json", "--out", str(tmp_path / "j"),
                     "--max-pressure", "1e8"]) == 0
    assert "warning" not in capsys.readouterr().err  # JSON carries the whole law


def _solve(path):
    from ngcontact import solve
    return solve(loader.load(path))[0]["results"]


@pytest.mark.parametrize("source", ["macro", "cell"])
def test_json_round_trip_gives_the_same_macro_result(tmp_path, source):
    """Exported from the macro scene (sawtooth cell, no gaps) or from a cell with gaps (its length unit
    scaling them), read back by a macro scene: the same macro solution to 1e-12."""
    cell = os.path.join(ROOT, "geometries", "macro", "sawtooth_cell.toml") if source == "macro" else GAP_CELL
    original = tmp_path / "original.toml"
    text = open(SAWTOOTH_BLOCK).read().replace("maxh = 0.0025", "maxh = 0.005")
    original.write_text(re.sub(r"^cell = .*$", f'cell = "{cell}"', text, flags=re.M))
    out = tmp_path / "law"
    scene = str(original) if source == "macro" else GAP_CELL
    assert cli.main(["export", scene, "--format", "json", "--out", str(out), "--max-pressure", "1e8",
                     "--length-unit", "1e-4"]) == 0
    data = json.loads((out / "interface_law.json").read_text())
    assert data["units"]["weights"] == "Pa/m" and len(data["source"]["cell_sha256"]) == 64
    back = tmp_path / "from_file.toml"
    text = re.sub(r"^cell = .*$", f'law = "file"\nlaw_file = "{out / "interface_law.json"}"', text, flags=re.M)
    back.write_text(re.sub(r"^cell_length_unit.*$", "", text, flags=re.M))
    assert loader.effects(loader.load(str(back)))[1] == "interface_bundle_from_file"
    a, b = _solve(str(original)), _solve(str(back))
    for key in ("pressure", "shear", "jump_n", "jump_t"):
        x, y = np.asarray(a["interface"][key]), np.asarray(b["interface"][key])
        assert np.max(np.abs(x - y)) <= 1e-12 * np.max(np.abs(x)), key
    assert b["resultant"]["y"] == pytest.approx(a["resultant"]["y"], rel=1e-12)
    if source == "cell":  # the gaps (up to 2h = 0.02 cell units) arrive in metres
        assert max(data["bundle"]["gaps"]) == pytest.approx(0.02 * 1e-4, rel=1e-2)


@pytest.mark.parametrize("args, message", [
    (["--format", "nastran"], "--format nastran: unknown format"),
    (["--format", "json", "--max-pressure", "-1"], "--max-pressure -1.0"),
    (["--format", "json", "--table-tol", "1.5"], "--table-tol 1.5: a fraction of the table's largest pressure"),
    (["--format", "json", "--length-unit", "0"], "--length-unit 0.0: metres per cell unit"),
])
def test_bad_options_are_refused_and_nothing_is_written(tmp_path, capsys, args, message):
    out = tmp_path / "out"
    assert cli.main(["export", GAP_CELL, "--out", str(out), *args]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_a_missing_or_lawless_scene_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert cli.main(["export", str(tmp_path / "nope.toml"), "--format", "json", "--out", str(out)]) == 2
    assert "nope.toml" in capsys.readouterr().err
    elasticity = os.path.join(ROOT, "geometries", "verify_elasticity.toml")
    assert cli.main(["export", elasticity, "--format", "json", "--out", str(out)]) == 2
    assert "export takes a 'cell' scene or a 'macro' scene" in capsys.readouterr().err
    assert not out.exists()


def test_a_users_file_in_out_is_never_overwritten(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    mine = out / "interface_law.json"
    mine.write_text("mine")
    assert cli.main(["export", GAP_CELL, "--format", "json", "--out", str(out), "--length-unit", "1e-4",
                     "--max-pressure", "1e8"]) == 2
    assert "interface_law.json exists and was not written by ngcontact" in capsys.readouterr().err
    assert mine.read_text() == "mine" and sorted(p.name for p in out.iterdir()) == ["interface_law.json"]
    # a directory holding the scene is refused as by `run --out`
    assert cli.main(["export", GAP_CELL, "--format", "json", "--out", os.path.dirname(GAP_CELL)]) == 2
    assert "which the scene reads" in capsys.readouterr().err
    # a second export into a package directory keeps the first one's file
    other = tmp_path / "other"
    for fmt in ("json", "abaqus"):
        assert cli.main(["export", GAP_CELL, "--format", fmt, "--out", str(other), "--length-unit", "1e-4",
                         "--max-pressure", "1e8"]) == 0
    assert {"interface_law.json", "interface_law_abaqus.inp"} <= {p.name for p in other.iterdir()}


def _macro_with_file(tmp_path, law_file, form="bundle"):
    text = open(SAWTOOTH_BLOCK).read()
    text = re.sub(r"^cell = .*$", f'law = "file"\nlaw_file = "{law_file}"\nlaw_file_form = "{form}"', text,
                  flags=re.M)
    path = tmp_path / "m.toml"
    path.write_text(text)
    return str(path)


def test_bad_law_files_name_the_key(tmp_path):
    with pytest.raises(SceneError, match="interface.law_file.*no such law file"):
        loader.load(_macro_with_file(tmp_path, "missing.json"))
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(SceneError, match="interface.law_file.*readable JSON"):
        loader.load(_macro_with_file(tmp_path, "bad.json"))
    (tmp_path / "foreign.json").write_text('{"format": "other"}')
    with pytest.raises(SceneError, match="ngcontact-interface-law"):
        loader.load(_macro_with_file(tmp_path, "foreign.json"))
    law = exported_law(GAP_CELL, length_unit=UNIT, p_max=P_MAX)
    from ngcontact.export import json_law
    data = json_law.as_dict(law)
    data["table"]["closure"][1] = data["table"]["closure"][0]  # not strictly increasing
    (tmp_path / "flat.json").write_text(json.dumps(data))
    with pytest.raises(SceneError, match=r"table\.closure\[1\] = .*flat\.json: the closures must increase strictly"):
        loader.load(_macro_with_file(tmp_path, "flat.json"))
    data = json_law.as_dict(law)
    data["bundle"] = None
    (tmp_path / "nobundle.json").write_text(json.dumps(data))
    with pytest.raises(SceneError, match="interface.law_file_form.*holds no bundle law"):
        loader.load(_macro_with_file(tmp_path, "nobundle.json"))


def test_greedy_thinning_keeps_the_ends_and_meets_the_tolerance():
    c = np.linspace(0.0, 1.0, 101)
    p = c ** 2
    keep = lt.thinned(c, p, 1e-3)
    assert keep[0] == 0 and keep[-1] == 100 and 2 < len(keep) < 101
    assert np.max(np.abs(np.interp(c, c[keep], p[keep]) - p)) <= 1e-3


@pytest.mark.parametrize("law, numbers", [
    ("linear", "kn = 2e10\nkt = 5e9\n"),
    ("tabulated", "closure = [1e-6, 2e-6, 5e-6]\npressure = [0.0, 1e6, 2e7]\nkt = 5e9\n"),
])
def test_explicit_laws_export_their_curve(tmp_path, law, numbers):
    text = open(SAWTOOTH_BLOCK).read()
    text = re.sub(r"^cell = .*$", f'law = "{law}"\n{numbers}', text, flags=re.M)
    text = re.sub(r"^cell_length_unit.*$", "", text, flags=re.M)
    path = tmp_path / "m.toml"
    path.write_text(text)
    exp = exported_law(str(path), p_max=5e7, tolerance=0.0)
    assert exp.stick_slope == 5e9
    if law == "linear":
        assert exp.k_n0 == 2e10 and any("bilateral" in n for n in exp.notes)
        assert np.allclose(exp.pressure, 2e10 * exp.closure, rtol=1e-14, atol=1e-6)
    else:
        assert np.allclose(np.interp([1e-6, 2e-6, 5e-6], exp.closure, exp.pressure), [0.0, 1e6, 2e7], rtol=1e-13)
        assert exp.k_n0 == pytest.approx((2e7 - 1e6) / 3e-6, rel=1e-12)  # extrapolated with the last slope


def test_a_law_file_scene_checks_its_gap_like_every_macro_scene(tmp_path):
    """The gap checks hold whatever the law's source (they were skipped for a law from a cell or a file)."""
    law = exported_law(GAP_CELL, length_unit=UNIT, p_max=P_MAX)
    from ngcontact.export import json_law
    (tmp_path / "law.json").write_text(json_law.text(law))
    path = _macro_with_file(tmp_path, "law.json")
    loader.load(path)  # valid as written
    text = open(path).read().replace('law = "file"', 'law = "file"\ngap = -1e-6\ngap_table = [[0.0, 0.0], [1.0, 0.0]]')
    (tmp_path / "both.toml").write_text(text)
    with pytest.raises(SceneError, match="interface.gap.*give either gap or gap_table"):
        loader.load(str(tmp_path / "both.toml"))
    cell_scene = open(SAWTOOTH_BLOCK).read().replace("[interface]", "[interface]\ngap_table = [[1.0, 0.0], [0.0, 0.0]]")
    cell_scene = cell_scene.replace('"sawtooth_cell.toml"',
                                    '"' + os.path.join(ROOT, "geometries", "macro", "sawtooth_cell.toml") + '"')
    (tmp_path / "cell.toml").write_text(cell_scene)
    with pytest.raises(SceneError, match="interface.gap_table.*increase strictly"):
        loader.load(str(tmp_path / "cell.toml"))


def test_the_running_sum_curve_is_the_sum_of_ramps():
    rng = np.random.default_rng(3)
    kinks, slopes = rng.normal(size=400), rng.random(400)  # unsorted, negative kinks too
    c = np.linspace(-4.0, 4.0, 3001)
    direct = np.maximum(c[:, None] - kinks[None, :], 0.0) @ slopes
    assert np.max(np.abs(lt.curve(kinks, slopes, c) - direct)) <= 1e-13 * direct.max()


# ------------------------------------------------------------- every written card admissible
@pytest.mark.parametrize("args, message", [
    (["--mu", "inf"], "--mu inf: the friction coefficient, must be a finite number >= 0"),
    (["--mu", "nan"], "--mu nan: the friction coefficient, must be a finite number >= 0"),
    (["--max-pressure", "inf"], "--max-pressure inf: the table's largest pressure [Pa], must be a finite number > 0"),
    (["--table-tol", "inf"], "--table-tol inf: a fraction of the table's largest pressure, must lie in [0, 1)"),
    (["--length-unit", "inf"], "--length-unit inf: metres per cell unit, must be a finite number in [1e-12, 1000]"),
    (["--length-unit", "1e300"], "--length-unit 1e+300: metres per cell unit, must be a finite number in"),
    (["--length-unit", "1e-300"], "--length-unit 1e-300: metres per cell unit, must be a finite number in"),
])
def test_non_finite_or_out_of_range_options_are_refused_naming_the_option(tmp_path, capsys, args, message):
    """Defect: --mu inf wrote '*FRICTION, ELASTIC SLIP=inf' and a line 'inf' (exit 0); --length-unit inf, 1e300,
    1e-300 printed numpy warnings, then blamed --max-pressure."""
    out = tmp_path / "out"
    with warnings_module.catch_warnings(record=True) as caught:
        warnings_module.simplefilter("always")
        code = cli.main(["export", GAP_CELL, "--format", "abaqus", "--out", str(out), *args])
    err = capsys.readouterr().err
    assert code == 2 and message in err, err
    assert len(err.strip().splitlines()) == 1 and "--max-pressure" not in err.replace(message, "") or \
        args[0] == "--max-pressure", err
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)], [str(w.message) for w in caught]
    assert not out.exists()


def test_a_table_of_identical_rows_is_refused_naming_max_pressure(tmp_path, capsys):
    """Defect: --max-pressure 1e-30 wrote two identical zero rows (exit 0)."""
    out = tmp_path / "out"
    assert cli.main(["export", GAP_CELL, "--format", "calculix", "--out", str(out), "--length-unit", str(UNIT),
                     "--max-pressure", "1e-30"]) == 2
    err = capsys.readouterr().err
    assert "--max-pressure 1e-30: " in err and "too small" in err and "Pa" in err, err
    assert not out.exists()
    with pytest.raises(ModelError, match="--max-pressure 1e-30"):
        exported_law(GAP_CELL, length_unit=UNIT, p_max=1e-30)


def _numbers(text, comment):
    """Every number on the lines of a card that are not comments."""
    found = []
    for line in text.splitlines():
        if line.startswith(comment):
            continue
        found += re.findall(r"(?<![A-Za-z_])[-+]?(?:\d+\.?\d*(?:[eE][-+]?\d+)?|inf|nan)(?![A-Za-z_\d])",
                            line.split("!")[0], flags=re.I)
    return [float(v) for v in found]


@pytest.mark.parametrize("fmt, comment", [("abaqus", "**"), ("calculix", "**"), ("ansys", "!")])
@pytest.mark.parametrize("options", [["--max-pressure", "1e8"], ["--max-pressure", "1e8", "--mu", "0.3"], []])
def test_every_written_card_is_finite_with_strictly_increasing_rows(tmp_path, fmt, comment, options):
    out = tmp_path / "out"
    assert cli.main(["export", GAP_CELL, "--format", fmt, "--out", str(out), "--length-unit", str(UNIT),
                     *options]) == 0
    text = next(out.glob("interface_law*")).read_text()
    values = _numbers(text, comment)
    assert values and all(np.isfinite(values)), [v for v in values if not np.isfinite(v)]
    if fmt != "ansys":
        rows = _rows(text)
        assert rows[0, 0] == 0.0 and np.all(np.diff(rows[:, 0]) > 0) and np.all(np.diff(rows[:, 1]) > 0), rows
        friction = [ln for ln in text.splitlines() if ln.startswith("*FRICTION")]
        if "--mu" not in options:  # the cell is symmetric: its k_nt0 is rounding, its mu0 = |k_nt0|/k_n0 zero
            assert friction == [], "a friction coefficient of rounding noise is no friction coefficient"


def test_the_card_names_the_scene_without_the_users_directories(tmp_path):
    """Defect: the exported card recorded the scene's absolute path (the user's directory layout)."""
    for fmt in ("abaqus", "calculix", "ansys", "json"):
        out = tmp_path / fmt
        assert cli.main(["export", GAP_CELL, "--format", fmt, "--out", str(out), "--length-unit", str(UNIT),
                         "--max-pressure", "1e8"]) == 0
        text = next(out.glob("interface_law*")).read_text()
        assert os.path.dirname(GAP_CELL) not in text and ROOT not in text, fmt
        assert os.path.basename(GAP_CELL) in text, fmt


def test_a_law_without_tangential_stiffness_writes_no_zero_sticking_stiffness(tmp_path):
    """ANSYS reads FKT = 0 as its default factor, not as an absolute stiffness: no zero stiffness is written."""
    text = open(SAWTOOTH_BLOCK).read()
    text = re.sub(r"^cell = .*$", 'law = "tabulated"\nclosure = [1e-6, 2e-6, 5e-6]\npressure = [0.0, 1e6, 2e7]\n',
                  text, flags=re.M)
    text = re.sub(r"^cell_length_unit.*$", "", text, flags=re.M)
    path = tmp_path / "m.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert cli.main(["export", str(path), "--format", "ansys", "--out", str(out), "--max-pressure", "5e7",
                     "--mu", "0.3"]) == 0
    mac = (out / "interface_law_ansys.mac").read_text()
    fkt = re.search(r"^NGC_FKT = (\S+)", mac, re.M)
    assert fkt is None or float(fkt.group(1)) < 0, mac
    assert "RMODIF,NGC_REAL,12" not in mac or (fkt is not None and float(fkt.group(1)) < 0)


def test_a_tabulated_plateau_is_admissible(tmp_path):
    """Non-decreasing pressures (a plateau of a tabulated law) are a valid table; only overclosures must
    increase strictly."""
    text = open(SAWTOOTH_BLOCK).read()
    text = re.sub(r"^cell = .*$", 'law = "tabulated"\nclosure = [1e-6, 2e-6, 3e-6, 5e-6]\n'
                  'pressure = [0.0, 1e6, 1e6, 2e7]\nkt = 5e9\n', text, flags=re.M)
    text = re.sub(r"^cell_length_unit.*$", "", text, flags=re.M)
    path = tmp_path / "m.toml"
    path.write_text(text)
    exp = exported_law(str(path), p_max=5e7, tolerance=0.0)
    assert np.all(np.diff(exp.closure) > 0) and list(exp.pressure[:3]) == [0.0, 1e6, 1e6]
