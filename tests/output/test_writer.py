"""The output directory: only the package's own files are written, replaced or removed; atomic as a whole.

Each test states one requirement of :mod:`ngcontact.output.writer` and the
command line around it, with the defect it guards against.
"""
import json
import logging
import os
import signal
import stat
import subprocess
import sys
import time

import pytest

from ngcontact import cli
from ngcontact.errors import OutputError
from ngcontact.output.report import Outcome, build_report
from ngcontact.output.writer import MANIFEST, STAGING_PREFIX, check_output_dir, remove_stale_staging, write_outputs

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GEOMETRIES = os.path.join(ROOT, "geometries")
#: the smallest shipped scene: a manufactured plane-strain check, orders 1 only
SMALL_SCENE = open(os.path.join(GEOMETRIES, "verify_elasticity.toml")).read().replace(
    "orders = [1, 2, 3]", "orders = [1]")
#: a cell that takes some seconds: long enough to be interrupted while it solves
SLOW_SCENE = open(os.path.join(GEOMETRIES, "cells", "westergaard.toml")).read()


def report_for(outcome):
    return build_report(kind="test", title="t", scene={"kind": "test"}, effects=("elasticity",),
                        outcome=outcome, timings={"total": 0.1}, version="0")


def snapshot(directory):
    """Every entry below ``directory`` with its bytes (files), its target (links) and its mode."""
    out = {}
    for root, dirs, files in os.walk(directory, followlinks=False):
        for name in dirs + files:
            path = os.path.join(root, name)
            rel = os.path.relpath(path, directory)
            st = os.lstat(path)
            if stat.S_ISLNK(st.st_mode):
                out[rel] = ("link", os.readlink(path))
            elif stat.S_ISDIR(st.st_mode):
                out[rel] = ("dir", st.st_mode)
            else:
                out[rel] = ("file", st.st_mode, open(path, "rb").read())
    out["."] = ("dir", os.stat(directory).st_mode)
    return out


def staging_left(directory):
    return [n for n in os.listdir(directory) if n.startswith(STAGING_PREFIX)]


def outcome_with(value, plots=None):
    return Outcome(results={"value": value}, ndof=10, tables={"curve": (["x", "y"], [(0.0, 1.0), (1.0, value)])},
                   plots=plots or {"figure": lambda path: open(path, "wb").write(b"png")})


# ------------------------------------------------------------- the writer
def test_outputs_are_written_together_with_a_manifest_of_them(tmp_path):
    out = tmp_path / "run"
    outcome = outcome_with(2.0)
    write_outputs(str(out), report_for(outcome), outcome)
    assert sorted(os.listdir(out)) == sorted([MANIFEST, "curve.csv", "figure.png", "report.html", "report.json"])
    rep = json.loads((out / "report.json").read_text())
    assert rep["results"] == {"value": 2.0} and rep["files"] == ["curve.csv", "figure.png"]
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["written_by"] == "ngcontact" and manifest["files"] == ["curve.csv", "figure.png", "report.html", "report.json"]
    assert os.listdir(tmp_path) == ["run"], "no staging directory may remain"


def test_the_users_files_survive_a_run_and_a_rerun_replaces_only_the_packages_own(tmp_path):
    """Defect: an existing --out directory was renamed aside and removed with everything in it."""
    out = tmp_path / "study"
    (out / "data").mkdir(parents=True)
    (out / "notes.txt").write_text("mine")
    (out / "data" / "input.csv").write_text("x,y\n0,0\n")
    os.chmod(out, 0o755)
    first = outcome_with(1.0, plots={"figure": lambda p: open(p, "wb").write(b"1"),
                                     "extra": lambda p: open(p, "wb").write(b"e")})
    write_outputs(str(out), report_for(first), first)
    second = outcome_with(2.0)
    write_outputs(str(out), report_for(second), second)
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "data" / "input.csv").read_text() == "x,y\n0,0\n"
    assert not (out / "extra.png").exists(), "a file of the previous run that this run does not write goes"
    assert json.loads((out / "report.json").read_text())["results"] == {"value": 2.0}
    assert stat.S_IMODE(os.stat(out).st_mode) == 0o755, "the directory keeps its mode"
    assert staging_left(out) == []


def test_a_file_of_the_same_name_that_the_package_did_not_write_is_refused_untouched(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    (out / "report.json").write_text("the user's own report")
    before = snapshot(out)
    with pytest.raises(OutputError, match="report.json exists and was not written by ngcontact"):
        write_outputs(str(out), report_for(outcome_with(1.0)), outcome_with(1.0))
    assert snapshot(out) == before


def test_a_hand_edited_manifest_never_gets_a_users_file_deleted(tmp_path, caplog):
    """Defect: a manifest edited to list thesis.tex got thesis.tex deleted by the next run.  Only names the
    package writes are ever replaced or removed; any other entry is ignored with a warning and kept."""
    out = tmp_path / "run"
    first = outcome_with(1.0)
    write_outputs(str(out), report_for(first), first)
    (out / "thesis.tex").write_text("my thesis")
    (out / "data.txt").write_text("mine")
    (tmp_path / "outside.csv").write_text("mine too")
    manifest = json.loads((out / MANIFEST).read_text())
    manifest["files"] += ["thesis.tex", "data.txt", "../outside.csv", "sub/x.csv", ".."]
    (out / MANIFEST).write_text(json.dumps(manifest))
    with caplog.at_level(logging.WARNING, logger="ngcontact.output.writer"):
        write_outputs(str(out), report_for(outcome_with(2.0)), outcome_with(2.0))
    assert (out / "thesis.tex").read_text() == "my thesis" and (out / "data.txt").read_text() == "mine"
    assert (tmp_path / "outside.csv").read_text() == "mine too"
    warned = " ".join(r.getMessage() for r in caplog.records)
    assert "thesis.tex" in warned and "data.txt" in warned and "ignored" in warned, warned
    assert json.loads((out / MANIFEST).read_text())["files"] == ["curve.csv", "figure.png", "report.html",
                                                                "report.json"]


def test_the_package_writes_only_names_of_its_own_kind(tmp_path):
    """What the package may delete is what it can write: a name outside that set is refused before writing."""
    from ngcontact.output.writer import is_own_name, write_text_files
    for name in ("report.json", "report.html", "curve.csv", "surface_load3.csv", "cell.vtu", "contact_curve.png",
                 "pressure_load0.npy", "interface_law.json", "interface_law_calculix.inp", "interface_law_ansys.mac"):
        assert is_own_name(name), name
    for name in ("thesis.tex", "notes.txt", "Data.csv", "../report.json", "sub/report.json", "..", MANIFEST, ""):
        assert not is_own_name(name), name
    with pytest.raises(ValueError, match="thesis.tex"):
        write_text_files(str(tmp_path / "out"), {"thesis.tex": "x"})
    assert not (tmp_path / "out").exists()


def test_a_foreign_file_named_like_the_manifest_is_refused(tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    (out / MANIFEST).write_text("not json")
    with pytest.raises(OutputError, match="is not a manifest of ngcontact"):
        check_output_dir(str(out))


def test_a_symlinked_output_directory_is_followed_not_replaced(tmp_path):
    target = tmp_path / "target"
    target.mkdir()
    (target / "keep.txt").write_text("k")
    link = tmp_path / "link"
    link.symlink_to(target, target_is_directory=True)
    write_outputs(str(link), report_for(outcome_with(1.0)), outcome_with(1.0))
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert (target / "keep.txt").read_text() == "k" and (target / "report.json").exists()


def test_failed_write_leaves_previous_output_untouched_and_no_staging(tmp_path):
    out = tmp_path / "run"
    good = outcome_with(1.0)
    write_outputs(str(out), report_for(good), good)
    (out / "mine.txt").write_text("m")
    before = snapshot(out)

    def broken_plot(path):
        open(path, "wb").write(b"half")
        raise RuntimeError("plot failed")

    bad = outcome_with(2.0, plots={"figure": broken_plot})
    with pytest.raises(RuntimeError, match="plot failed"):
        write_outputs(str(out), report_for(bad), bad)
    assert snapshot(out) == before
    assert staging_left(out) == [] and staging_left(tmp_path) == []


def test_output_directory_that_holds_an_input_is_refused_before_any_work(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text("kind = 'x'")
    for out in (tmp_path, tmp_path.parent):
        with pytest.raises(OutputError, match="contains .*scene.toml, which the scene reads"):
            check_output_dir(str(out), [str(scene)])
    check_output_dir(str(tmp_path / "results"), [str(scene)])


def test_unwritable_output_is_refused_before_any_work(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="exists and is not a directory"):
        check_output_dir(str(blocker))
    with pytest.raises(OutputError, match="cannot write in"):
        check_output_dir(str(blocker / "run"))


@pytest.mark.parametrize("below", ["", "sub"])
def test_an_output_path_through_a_symlink_loop_is_refused_before_any_work(tmp_path, below):
    """Defect: --out a symbolic link loop passed the check, the whole solve ran, then "File exists"."""
    (tmp_path / "a").symlink_to(tmp_path / "b")
    (tmp_path / "b").symlink_to(tmp_path / "a")
    out = tmp_path / "a" / below if below else tmp_path / "a"
    with pytest.raises(OutputError, match=r"--out .*: a symbolic link on the path .*a\) leads into a loop"):
        check_output_dir(str(out))


def test_staging_left_by_a_killed_run_is_removed_by_the_next_and_a_live_one_is_kept(tmp_path):
    """Defect: SIGKILL left .ngcontact-partial-* folders forever."""
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True)
    stale = tmp_path / f"{STAGING_PREFIX}{dead.stdout.strip()}-abc"
    live = tmp_path / f"{STAGING_PREFIX}{os.getpid()}-def"
    for d in (stale, live):
        d.mkdir()
        (d / "report.json").write_text("{}")
    (tmp_path / ".ngcontact-partial-notapid").mkdir()
    assert remove_stale_staging(str(tmp_path)) == [str(stale)]
    assert live.exists() and (tmp_path / ".ngcontact-partial-notapid").exists()


# ------------------------------------------------------------- the command line
@pytest.fixture
def scene_dir(tmp_path):
    work = tmp_path / "work"
    work.mkdir()
    (work / "small.toml").write_text(SMALL_SCENE)
    (work / "other.txt").write_text("keep")
    return work


@pytest.mark.parametrize("out", [".", ".."])
def test_out_dot_keeps_the_scene_and_every_file(scene_dir, monkeypatch, capsys, out):
    """Defect: --out . deleted the scene and every file of the working directory (exit 0)."""
    monkeypatch.chdir(scene_dir)
    before = snapshot(scene_dir.parent)
    assert cli.main(["run", "small.toml", "--out", out, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "which the scene reads" in err, err
    assert snapshot(scene_dir.parent) == before


def test_run_into_a_symlink_loop_exits_2_before_solving(scene_dir, monkeypatch, capsys):
    """Defect: the solve ran to its end before --out (a symbolic link loop) failed with "File exists"."""
    from ngcontact import runner

    def no_solve(*args, **kwargs):
        raise AssertionError("the solve ran although --out cannot be written")

    monkeypatch.setattr(runner, "solve", no_solve)
    (scene_dir / "loop").symlink_to(scene_dir / "loop")
    before = snapshot(scene_dir)
    assert cli.main(["run", str(scene_dir / "small.toml"), "--out", str(scene_dir / "loop"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out" in err and "loop" in err, err
    assert snapshot(scene_dir) == before


def test_a_data_folder_the_scene_reads_is_refused(tmp_path, capsys):
    """Defect: --out data deleted the CSV the scene reads."""
    cells = os.path.join(GEOMETRIES, "cells")
    data = os.path.join(cells, "data")
    before = sorted(os.listdir(data))
    assert cli.main(["run", os.path.join(cells, "tabulated_gap.toml"), "--out", data, "--quiet"]) == 2
    assert "gap_example.csv, which the scene reads" in capsys.readouterr().err
    assert sorted(os.listdir(data)) == before


def test_sigterm_while_writing_leaves_the_directory_byte_identical(scene_dir, monkeypatch, capsys):
    """A SIGTERM that arrives while the files are written: exit 143, nothing changed, no staging left."""
    from ngcontact.output import writer

    out = scene_dir / "results"
    assert cli.main(["run", str(scene_dir / "small.toml"), "--out", str(out), "--quiet"]) == 0
    (out / "mine.txt").write_text("m")
    before = snapshot(out)
    real = writer.write_csv

    def killed_midway(path, header, rows):
        real(path, header, rows)
        os.kill(os.getpid(), signal.SIGTERM)

    monkeypatch.setattr(writer, "write_csv", killed_midway)
    assert cli.main(["run", str(scene_dir / "small.toml"), "--out", str(out), "--quiet"]) == 143
    assert "terminated; the output directory is as it was" in capsys.readouterr().err
    assert snapshot(out) == before and staging_left(out) == []


@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_an_interrupted_run_leaves_a_previous_output_directory_byte_identical(tmp_path, sig, code):
    """Defect: SIGINT printed a traceback; SIGTERM left partial folders.  One line and nothing changed."""
    scene = tmp_path / "slow.toml"
    scene.write_text(SLOW_SCENE)
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("n")
    before = snapshot(out)
    # a child inherits an ignored SIGINT (a shell's background job): give it the default back,
    # so that Python installs its own handler as it does in a terminal
    proc = subprocess.Popen([sys.executable, "-m", "ngcontact.cli", "run", str(scene), "--out", str(out)],
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert proc.stderr is not None
    deadline = time.monotonic() + 15
    for line in proc.stderr:  # progress lines: wait until the solve has begun
        if "solve" in line or time.monotonic() > deadline:
            break
    proc.send_signal(sig)
    rest = proc.stderr.read()
    assert proc.wait(timeout=15) == code, rest
    lines = [ln for ln in rest.splitlines() if ln.startswith("ngcontact:")]
    assert len(lines) == 1 and ("interrupted" in lines[0] or "terminated" in lines[0]), rest
    assert "Traceback" not in rest
    assert snapshot(out) == before and staging_left(out) == [] and staging_left(tmp_path) == []


def test_a_scene_that_names_itself_as_its_cell_is_refused_with_the_chain(tmp_path, capsys):
    """Defect: a scene naming itself as its cell, or A -> B -> A, ended in RecursionError (exit 3)."""
    text = open(os.path.join(GEOMETRIES, "macro", "femur_stem_from_cell.toml")).read()
    assert 'cell = "hip_cell.toml"' in text
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    a.write_text(text.replace('cell = "hip_cell.toml"', 'cell = "b.toml"'))
    b.write_text(text.replace('cell = "hip_cell.toml"', 'cell = "a.toml"'))
    assert cli.main(["check", str(a)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a.toml -> b.toml -> a.toml" in err, err
