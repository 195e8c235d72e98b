"""One end-to-end run per shipped scene and test session, shared by the slow tests that need one.

``tests/drivers/test_scenes.py`` checks a run's report and files, ``tests/drivers/test_gold.py`` its
headline numbers against the gold record: both ask :func:`scene_run` for the run of a scene, which
solves it the first time (``python -m ngcontact run SCENE --out DIR --quiet`` in a process of its own, as a
user runs it, with ``NGCONTACT_CACHE`` in a fresh directory of its own, so that every cell law is computed in
the run) and hands out the same run afterwards.  A process per scene keeps the scenes from sharing native
state: a crash of one is that scene's failure, with its exit status and its stderr, not the session's end.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class SceneRun:
    """A finished ``ngcontact run``: its exit status, output directory, ``report.json`` (``None`` unless 0) and
    what it wrote on stderr."""
    status: int
    out: Path
    report: dict | None
    stderr: str = ""


@pytest.fixture(scope="session")
def scene_run(tmp_path_factory):
    """``scene_run(path) -> SceneRun``: the session's run of the scene file ``path``, solved on first use."""
    runs: dict[str, SceneRun] = {}

    def run(path: str) -> SceneRun:
        key = os.path.realpath(path)
        if key not in runs:
            base = tmp_path_factory.mktemp(Path(key).stem)
            out = base / "out"
            env = dict(os.environ, NGCONTACT_CACHE=str(base / "cache"),
                       PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
            done = subprocess.run([sys.executable, "-m", "ngcontact", "run", path, "--out", str(out), "--quiet"],
                                  env=env, capture_output=True, text=True)
            status = done.returncode
            report = json.loads((out / "report.json").read_text()) if status == 0 else None
            runs[key] = SceneRun(status, out, report, done.stderr)
        return runs[key]

    return run
