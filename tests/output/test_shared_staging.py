"""Staging directories on a file system shared by several machines, found by the reliability audit of issue 35.

A job array on a cluster writes ``results/<scene>`` for many scenes from many nodes; each run stages in the
existing ``results``.  A process number means something only on its own machine: a run must never remove
another machine's staging directory as 'left by a killed run' (its process is not alive *here*), which made
that run fail while it moved its files into place."""
import os
import subprocess
import sys

from ngcontact.output import writer
from ngcontact.output.writer import STAGING_PREFIX, remove_stale_staging


def _dead_pid() -> str:
    done = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True,
                          check=True)
    return done.stdout.strip()


def test_another_machine_s_staging_is_kept_and_this_one_s_dead_staging_removed(tmp_path):
    pid = _dead_pid()
    other = "0" * 8 if writer.host_tag() != "0" * 8 else "1" * 8
    elsewhere = tmp_path / f"{STAGING_PREFIX}{pid}-{other}-abc"
    here = tmp_path / f"{STAGING_PREFIX}{pid}-{writer.host_tag()}-def"
    for d in (elsewhere, here):
        d.mkdir()
        (d / "report.json").write_text("{}")
    assert remove_stale_staging(str(tmp_path)) == [str(here)]
    assert (elsewhere / "report.json").exists()


def test_a_run_names_its_staging_by_its_process_and_its_machine(tmp_path, monkeypatch):
    seen = []

    def fill(tmp):
        seen.append(os.path.basename(tmp))
        with open(os.path.join(tmp, "report.json"), "w") as fh:
            fh.write("{}")
    writer._staged(str(tmp_path / "out"), ["report.json"], (), fill, "test", keep_previous=False)
    assert seen[0].startswith(f"{STAGING_PREFIX}{os.getpid()}-{writer.host_tag()}-")
