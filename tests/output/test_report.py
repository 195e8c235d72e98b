"""Report writing: finite numbers only, atomic replacement, nothing left behind on failure."""
import json
import math
import os

import numpy as np
import pytest

from ngcontact.output.report import Clock, Outcome, build_report, ensure_writable, to_plain, write_outputs
from ngcontact.errors import OutputError


def report_for(outcome):
    return build_report(kind="test", title="t", scene={"kind": "test"}, effects=("elasticity",),
                        outcome=outcome, timings={"total": 0.1}, version="0")


def test_to_plain_converts_numpy_and_rejects_nan_with_its_path():
    assert to_plain({"a": np.float64(1.5), "b": np.arange(3), "c": np.bool_(True)}) == \
        {"a": 1.5, "b": [0, 1, 2], "c": True}
    with pytest.raises(ValueError, match=r"non-finite number nan at results\.x\[1\]"):
        to_plain({"x": [1.0, math.nan]})
    with pytest.raises(ValueError, match="inf"):
        to_plain({"y": np.array([np.inf])})


def test_outputs_are_written_together(tmp_path):
    out = tmp_path / "run"
    outcome = Outcome(results={"value": 2.0}, ndof=10,
                      tables={"curve": (["x", "y"], [(0.0, 1.0), (1.0, 2.0)])},
                      plots={"figure": lambda path: open(path, "wb").write(b"png")})
    write_outputs(str(out), report_for(outcome), outcome)
    assert sorted(os.listdir(out)) == ["curve.csv", "figure.png", "report.json"]
    rep = json.loads((out / "report.json").read_text())
    assert rep["results"] == {"value": 2.0} and rep["ndof"] == 10
    assert rep["files"] == ["curve.csv", "figure.png"]
    assert (out / "curve.csv").read_text().splitlines() == ["x,y", "0.0,1.0", "1.0,2.0"]
    assert os.listdir(tmp_path) == ["run"], "no temporary directories may remain"


def test_failed_write_leaves_previous_output_untouched_and_no_partial_files(tmp_path):
    out = tmp_path / "run"
    good = Outcome(results={"value": 1.0})
    write_outputs(str(out), report_for(good), good)
    before = (out / "report.json").read_text()

    def broken_plot(path):
        open(path, "wb").write(b"half")
        raise RuntimeError("plot failed")

    bad = Outcome(results={"value": 2.0}, plots={"figure": broken_plot})
    with pytest.raises(RuntimeError, match="plot failed"):
        write_outputs(str(out), report_for(bad), bad)
    assert (out / "report.json").read_text() == before
    assert sorted(os.listdir(tmp_path)) == ["run"]
    assert os.listdir(out) == ["report.json"]


def test_unwritable_output_is_refused_before_any_work(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    with pytest.raises(OutputError, match="exists and is not a directory"):
        ensure_writable(str(blocker))
    with pytest.raises(OutputError, match="cannot write in"):
        ensure_writable(str(blocker / "run"))


def test_clock_accumulates_stages():
    lines = []
    clock = Clock(lines.append)
    with clock.stage("mesh"):
        pass
    with clock.stage("mesh"):
        pass
    t = clock.total()
    assert set(t) == {"mesh", "total"} and t["total"] >= t["mesh"] >= 0
    assert len(lines) == 2 and "mesh" in lines[0]
