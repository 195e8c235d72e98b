"""Runs use NGSolve's task manager with the threads NGCONTACT_THREADS names (default: every available core)."""
import json
import os

import pytest

from ngcontact import cli

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "geometries", "cells", "sinusoid.toml")


def _run(tmp_path, monkeypatch, value, name):
    if value is None:
        monkeypatch.delenv("NGCONTACT_THREADS", raising=False)
    else:
        monkeypatch.setenv("NGCONTACT_THREADS", value)
    out = tmp_path / name
    assert cli.main(["run", SCENE, "--out", str(out), "--quiet"]) == 0
    return json.loads((out / "report.json").read_text())


def test_the_report_states_the_threads_and_they_do_not_change_the_answer(tmp_path, monkeypatch):
    one = _run(tmp_path, monkeypatch, "1", "one")
    two = _run(tmp_path, monkeypatch, "2", "two")
    default = _run(tmp_path, monkeypatch, None, "default")
    assert one["threads"] == 1 and two["threads"] == 2
    assert default["threads"] == len(os.sched_getaffinity(0))
    for a, b in zip(one["results"]["loads"], two["results"]["loads"]):
        for key in ("contact_fraction", "mean_closure", "mean_pressure"):
            assert b[key] == pytest.approx(a[key], rel=1e-9, abs=1e-15), key


@pytest.mark.parametrize("value", ["0", "two", "-3"])
def test_a_bad_thread_count_is_refused_before_anything_is_written(tmp_path, monkeypatch, capsys, value):
    monkeypatch.setenv("NGCONTACT_THREADS", value)
    out = tmp_path / "out"
    assert cli.main(["run", SCENE, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"environment variable NGCONTACT_THREADS = {value!r}: the number of threads: an integer >= 1" in err
    assert not out.exists()
