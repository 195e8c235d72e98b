"""The accuracy study under a target no level meets, found by the reliability audit of issue 35: a miss is
never silent (one warning line beside ``results.target.met = false``), and nothing is recommended."""
from __future__ import annotations

import json
import logging
import os
import sys

from ngcontact import cli

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from sinusoid_cell import sinusoid_cell  # noqa: E402


def test_a_target_no_level_meets_is_warned_on_the_terminal(tmp_path, caplog):
    """Was: exit 0 and not a word on the terminal; the miss only in report.json."""
    scene = tmp_path / "cell.toml"
    scene.write_text(sinusoid_cell(discretization='method = "spectral"\ngrid = 64\ntolerance = 0.1'))
    out = tmp_path / "study"
    with caplog.at_level(logging.WARNING):
        assert cli.main(["study", "accuracy", str(scene), "--target", "1e-12", "--levels", "3", "--out", str(out),
                         "--workers", "1", "--quiet"]) == 0
    verdict = json.loads((out / "report.json").read_text())["results"]["target"]
    assert not verdict["met"] and not (out / "recommended.toml").exists()
    warned = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    assert [m for m in warned if m == f"accuracy study: {verdict['statement']}"], warned
