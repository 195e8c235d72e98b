"""The report's ``effects`` and ``solver`` entries say what was assembled and how it was solved.

* A scene without friction assembles no friction term: its effects name none,
  and the solve shows it (the cell's interface has no tangential stiffness
  and no Coulomb passes; the macro solve has no fixed point on the pressure).
* A macro scene whose law is linear (quadratic energy) is solved by one
  linear solve, not a Newton loop; a unilateral law of the same stiffness
  takes Newton steps.  (A cell's penalty contact is always unilateral, so the
  cell kind has no linear case.)

Each run goes through the command line and reads ``report.json``; the
contrasting scene (with friction, with a nonlinear law) shows that the
entries respond to the scene and so can fail.
"""
import json

from ngcontact import cli

CELL = """\
kind = "cell"

[materials.solid]
E = 1.0
nu = 0.3

[bodies]
rough = "solid"
counter = "solid"

[geometry]
profile = "flat"

[contact]
k_n = 1.0e3
{friction}

[load]
pressure = [0.01, 0.02]

[discretization]
order = 1
maxh = 0.25
estimate = "off"   # the effects, not the accuracy: no second solve
"""

MACRO = """\
kind = "macro"

[materials.steel]
E = 210e9
nu = 0.3

[bodies]
rough = "steel"
counter = "steel"

[geometry]
shape = "block"
setting = "plane_strain"

[geometry.dimensions]
length = 0.02
h_block = 0.005
h_base = 0.005

[interface]
{law}

[[supports]]
boundary = "bottom"

[[loads]]
boundary = "top"
pressure = 10e6
traction = [1e6, 0.0]

[discretization]
order = 1
maxh = 0.0025
"""


def report_of(tmp_path, name, text):
    scene = tmp_path / f"{name}.toml"
    scene.write_text(text)
    out = tmp_path / name
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    return json.loads((out / "report.json").read_text())


def test_cell_without_friction_assembles_no_friction_term(tmp_path):
    none = report_of(tmp_path, "none", CELL.format(friction=""))
    assert none["effects"] == ["elasticity", "normal_contact", "pressure_load"]
    for load in none["results"]["loads"]:
        # no friction term: the interface has no tangential stiffness, only the normal one
        assert load["effective_stiffness"]["components"] == ["n0"]
        assert load["coulomb_iterations"] == 0
    assert all(len(passes) == 1 for passes in none["solver"]["per_load"])

    tresca = report_of(tmp_path, "tresca", CELL.format(friction='friction = "tresca"\nG = 1.0\nw = 1e-3'))
    assert "tresca_friction" in tresca["effects"]
    for load in tresca["results"]["loads"]:
        eff = load["effective_stiffness"]
        assert eff["components"] == ["t0", "n0"]
        k_tt = eff["matrix"][0][0]
        assert abs(k_tt - 1.0 / 1e-3) < 1e-6 * k_tt  # the sticking Huber zone: G / w

    coulomb = report_of(tmp_path, "coulomb", CELL.format(friction='friction = "coulomb"\nmu = 0.3\nw = 1e-3'))
    assert "coulomb_friction" in coulomb["effects"]
    assert all(load["coulomb_iterations"] >= 1 for load in coulomb["results"]["loads"])


def test_macro_linear_law_is_one_linear_solve_and_no_friction_term(tmp_path):
    linear = report_of(tmp_path, "linear", MACRO.format(law='law = "linear"\nkn = 1e13\nkt = 1e12'))
    assert linear["effects"] == ["elasticity", "interface_linear", "surface_loads"]
    s = linear["solver"]
    assert s["linear_solve_only"] is True and s["converged"] is True
    assert s["iterations"] == 1 and len(s["solves"]) == 1
    assert s["solves"][0]["linear_solve_only"] is True
    assert s["coulomb_changes"] == []
    # one linear solve of a quadratic energy is exact: the residual drops to round-off
    r = s["solves"][0]["residuals"]
    assert r[-1] <= 1e-8 * r[0]

    # a symmetric sawtooth bundle: carries the shear under compression, but opens in tension
    bundle = report_of(tmp_path, "bundle", MACRO.format(law='law = "bundle"\nweights = [1e13, 1e13]\n'
                                                        'directions = [[0.8, 0.6], [0.8, -0.6]]'))
    assert bundle["effects"] == ["elasticity", "interface_bundle", "surface_loads"]
    assert bundle["solver"]["linear_solve_only"] is False
    assert bundle["solver"]["solves"][0]["linear_solve_only"] is True  # the closed, quadratic start
    assert bundle["solver"]["solves"][-1]["linear_solve_only"] is False

    friction = report_of(tmp_path, "friction", MACRO.format(law='law = "linear"\nkn = 1e13\nkt = 1e12\nmu = 0.3'))
    assert "coulomb_friction" in friction["effects"]
    assert friction["solver"]["linear_solve_only"] is False
    assert friction["solver"]["coulomb"]["method"] == "coupled Newton"
    assert friction["solver"]["coulomb_changes"] == [] and linear["solver"]["coulomb"] is None


def test_failures_after_the_solve_leave_the_previous_output_and_no_partial_files(tmp_path, monkeypatch, capsys):
    """Atomic output through the command line: a non-finite result found after the solve
    (exit 3) and a write that fails halfway (exit 2) both leave the earlier run intact."""
    from ngcontact.output import writer as writer_mod
    from ngcontact.cell.fe.cell_problem import CellProblem

    scene = tmp_path / "cell.toml"
    scene.write_text(CELL.format(friction=""))
    out = tmp_path / "out"
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def unchanged():
        assert {p.name: p.read_bytes() for p in out.iterdir()} == before
        assert sorted(p.name for p in tmp_path.iterdir()) == ["cell.toml", "out"]

    measure = CellProblem.measure

    def measure_with_nan(self, load):
        return dict(measure(self, load), spoiled=float("nan"))

    monkeypatch.setattr(CellProblem, "measure", measure_with_nan)
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "non-finite number nan at report.results.loads[0].spoiled" in err, err
    unchanged()
    monkeypatch.setattr(CellProblem, "measure", measure)

    def full_disk(path, item):  # the CSV tables are already in the temporary directory
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(writer_mod, "write_vtk", full_disk)
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err == (f"ngcontact: error: --out {out}: writing failed ([Errno 28] No space left on device); "
                   "the previous output, if any, is unchanged\n")
    unchanged()
