"""The ``ngcontact`` command: check, run, exit codes, messages and atomic output."""
import json
import math
import os
import shutil
import subprocess
import sys

import pytest

from ngcontact import cli
from ngcontact.errors import ConvergenceError

REQUIRED_KEYS = {"schema", "kind", "scene", "effects", "ndof", "timings", "solver", "results"}

SMALL_SCENE = """\
kind = "manufactured"
title = "small plane-strain check"

[materials.steel]
E = 210e9
nu = 0.3

[manufactured]
setting = "plane_strain"
body = "steel"
orders = [1, 2]
maxh = 0.5
levels = 3
"""


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SMALL_SCENE)
    return path


def invalid_scene(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(SMALL_SCENE.replace("nu = 0.3", "nu = 0.5"))
    return path


def leftovers(directory):
    return [n for n in os.listdir(directory) if n.startswith(".ngcontact-")]


def assert_finite(obj, path="report"):
    if isinstance(obj, dict):
        for k, v in obj.items():
            assert_finite(v, f"{path}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            assert_finite(v, f"{path}[{i}]")
    elif isinstance(obj, float):
        assert math.isfinite(obj), path


def reject_constant(name):
    raise ValueError(f"non-finite constant {name} in report.json")


def test_check_accepts_a_valid_scene(scene_file, capsys):
    assert cli.main(["check", str(scene_file)]) == 0
    out = capsys.readouterr().out
    assert "valid manufactured scene" in out and "elasticity" in out


def test_shipped_scenes_are_valid(capsys):
    root = os.path.join(os.path.dirname(__file__), os.pardir, "geometries")
    for name in ("verify_elasticity", "verify_axisymmetric", "verify_3d", "verify_periodic_cell"):
        assert cli.main(["check", os.path.join(root, f"{name}.toml")]) == 0, name
    capsys.readouterr()


def test_run_writes_a_complete_report(scene_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert cli.main(["run", str(scene_file), "--out", str(out), "--quiet"]) == 0
    with open(out / "report.json") as fh:
        report = json.load(fh, parse_constant=reject_constant)
    assert REQUIRED_KEYS <= set(report)
    assert_finite(report)
    assert report["kind"] == "manufactured"
    assert report["scene"]["manufactured"]["orders"] == [1, 2]
    assert report["effects"] == ["elasticity"]
    assert report["ndof"] == max(r["ndof"] for r in report["results"]["rows"]) > 0
    assert report["timings"]["total"] > 0
    solver = report["solver"]
    assert solver["converged"] and solver["linear_solve_only"] and solver["iterations"] == 6
    assert max(solver["residuals"]) < 1e-10
    results = report["results"]
    assert len(results["rows"]) == 6
    assert set(results["rates"]) == {"1", "2"}
    assert results["expected_rates"]["2"] == {"l2": 3.0, "h1": 2.0}
    assert results["verified"] is True
    for name in report["files"]:
        assert (out / name).stat().st_size > 0, name
    assert {"convergence.csv", "rates.csv", "convergence.png", "finest.vtu"} <= set(report["files"])
    header = (out / "convergence.csv").read_text().splitlines()[0]
    assert header.startswith("setting,order,level,h,ndof,l2,h1,seconds")
    assert leftovers(tmp_path) == []


def test_invalid_scene_exits_2_with_one_line(tmp_path, capsys):
    bad = invalid_scene(tmp_path)
    for command in (["check", str(bad)], ["run", str(bad), "--out", str(tmp_path / "out")]):
        assert cli.main(command) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1, err
        assert "materials.steel.nu = 0.5: must lie in (-1, 0.5)" in err
    assert not (tmp_path / "out").exists()


def test_unwritable_output_exits_2(scene_file, tmp_path, capsys):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a directory")
    for out in (blocker, blocker / "sub"):
        assert cli.main(["run", str(scene_file), "--out", str(out), "--quiet"]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "--out" in err, err
    assert blocker.read_text() == "not a directory"


def test_solver_failure_exits_3_and_leaves_nothing(scene_file, tmp_path, monkeypatch, capsys):
    from ngcontact.drivers import run_manufactured as driver

    def failing(scene, clock):
        raise ConvergenceError("Newton did not converge in 3 steps", {"iterations": 3})

    monkeypatch.setattr(driver, "run", failing)
    out = tmp_path / "out"
    assert cli.main(["run", str(scene_file), "--out", str(out), "--quiet"]) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "did not converge" in err
    assert not out.exists() and leftovers(tmp_path) == []


def test_inaccurate_linear_solve_exits_3_and_keeps_old_output(scene_file, tmp_path, monkeypatch, capsys):
    """The driver's own residual check: with a zero tolerance no solve is accurate enough."""
    from ngcontact.drivers import run_manufactured as driver

    out = tmp_path / "out"
    out.mkdir()
    (out / "previous.txt").write_text("earlier run")
    monkeypatch.setattr(driver, "LINEAR_RTOL", 0.0)
    assert cli.main(["run", str(scene_file), "--out", str(out), "--quiet"]) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "relative residual" in err
    assert os.listdir(out) == ["previous.txt"] and leftovers(tmp_path) == []


def console_script():
    found = shutil.which("ngcontact", path=os.path.dirname(sys.executable))
    assert found, "the console script ngcontact is not installed beside the interpreter"
    return found


def test_console_script(scene_file, tmp_path):
    exe = console_script()
    version = subprocess.run([exe, "--version"], capture_output=True, text=True)
    assert version.returncode == 0 and version.stdout.startswith("ngcontact ")
    out = tmp_path / "out"
    done = subprocess.run([exe, "run", str(scene_file), "--out", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "levels: 6/6 finished" in done.stderr  # progress lines of the batch of levels
    assert (out / "report.json").is_file()
    bad = subprocess.run([exe, "check", str(invalid_scene(tmp_path))], capture_output=True, text=True)
    assert bad.returncode == 2
    assert bad.stderr.count("\n") == 1 and "materials.steel.nu = 0.5" in bad.stderr


def test_unexpected_error_is_one_line_exit_3_and_no_output(tmp_path, monkeypatch, capsys):
    """A failure nobody anticipated (here: inside the driver) still ends in one line, exit 3."""
    import ngcontact.drivers.run_manufactured as drv

    def boom(scene, clock):
        raise RuntimeError("mesher exploded")

    monkeypatch.setattr(drv, "run", boom)
    out = tmp_path / "out"
    scene_path = os.path.join(os.path.dirname(__file__), os.pardir, "geometries", "verify_elasticity.toml")
    assert cli.main(["run", scene_path, "--out", str(out)]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].endswith("unexpected error (RuntimeError): mesher exploded; rerun with --debug for the traceback")
    assert not out.exists()
    with pytest.raises(RuntimeError, match="mesher exploded"):
        cli.main(["--debug", "run", scene_path, "--out", str(out)])


def test_inadmissible_model_input_exits_2_with_the_quantity(scene_file, tmp_path, monkeypatch, capsys):
    """A ModelError from the numerics is bad input (exit 2, one line naming the quantity), not a solver failure."""
    from ngcontact.drivers import run_manufactured as driver
    from ngcontact.fem.materials import isotropic

    def inadmissible(scene, clock):
        isotropic(E=-1.0, nu=0.3)

    monkeypatch.setattr(driver, "run", inadmissible)
    out = tmp_path / "out"
    assert cli.main(["run", str(scene_file), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith("inadmissible model input: E = -1.0: must be > 0"), err
    assert not out.exists()


def test_quiet_prints_nothing_not_even_the_mesher_s_own_lines(tmp_path):
    """Was: --quiet still printed Netgen's 'identify surfaces' lines of a periodic 3D cell.  The shipped scene,
    meshed and solved as shipped, opting out of the default estimate (a second sweep of the cell one order
    higher, which the property does not depend on)."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    text = open(os.path.join(root, "geometries", "cells", "hip_hills.toml"), encoding="utf-8").read()
    assert "[discretization]\n" in text
    scene = tmp_path / "hip_hills.toml"
    scene.write_text(text.replace("[discretization]\n", '[discretization]\nestimate = "off"\n'), encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "ngcontact.cli", "run", str(scene),
                           "--out", str(tmp_path / "out"), "--quiet"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout == "" and done.stderr == "", (done.stdout, done.stderr)


@pytest.mark.parametrize("address, problem", [("garbage", "missing port number"),
                                              ("http://10.0.0.5:8786", "unknown scheme 'http'")])
def test_a_malformed_scheduler_option_exits_2_at_once_naming_it_and_the_allowed_forms(scene_file, tmp_path,
                                                                                       capsys, address, problem):
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as info:
        cli.main(["run", str(scene_file), "--out", str(out), "--scheduler", address])
    assert info.value.code == 2
    last = capsys.readouterr().err.splitlines()[-1]
    assert last == (f"ngcontact run: error: argument --scheduler: '{address}': {problem}; the address of a "
                    "dask.distributed scheduler: tcp://HOST:PORT or HOST:PORT (also tls://, ws://, wss://, ucx:// "
                    "HOST:PORT)")
    assert not out.exists()


@pytest.mark.parametrize("command", [["run"], ["export"], ["study", "accuracy"]])
def test_an_empty_out_option_exits_2_and_writes_nowhere(scene_file, tmp_path, capsys, monkeypatch, command):
    """Was: ``--out ""`` quietly wrote to the default results/<scene name>."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as info:
        cli.main(command + [str(scene_file), "--out", ""])
    assert info.value.code == 2
    last = capsys.readouterr().err.splitlines()[-1]
    assert last == (f"ngcontact {command[0]}: error: argument --out: '': must name a directory (omit --out for the "
                    "default, results/<scene name>)")
    assert os.listdir(tmp_path) == ["small.toml"]


@pytest.mark.parametrize("command", ["check", "run"])
def test_a_malformed_compute_scheduler_exits_2_naming_the_key(tmp_path, capsys, command):
    cell = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "geometries", "cells",
                        "sinusoid.toml")
    path = tmp_path / "sched.toml"
    path.write_text(open(cell).read() + '\n[compute]\nscheduler = "garbage"\n')
    out = tmp_path / "out"
    assert cli.main([command, str(path)] + (["--out", str(out), "--quiet"] if command == "run" else [])) == 2
    assert capsys.readouterr().err == (
        f"ngcontact: error: {path}: compute.scheduler = 'garbage': missing port number; the address of a "
        "dask.distributed scheduler: tcp://HOST:PORT or HOST:PORT (also tls://, ws://, wss://, ucx:// HOST:PORT)\n")
    assert not out.exists()
