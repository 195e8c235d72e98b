"""One end-to-end run per shipped scene and test session, shared by the slow tests that need one.

``tests/drivers/test_scenes.py`` checks a run's report and files, ``tests/drivers/test_gold.py`` its
headline numbers against the gold record: both ask :func:`scene_run` for the run of a scene, which
solves it the first time (``ngcontact run SCENE --out DIR --quiet`` in this process, with
``NGCONTACT_CACHE`` in a fresh directory of its own, so that every cell law is computed in the run)
and hands out the same run afterwards.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import pytest

from ngcontact import cli


@dataclass(frozen=True)
class SceneRun:
    """A finished ``ngcontact run``: its exit status, output directory and ``report.json`` (``None`` unless 0)."""
    status: int
    out: Path
    report: dict | None


@pytest.fixture(scope="session")
def scene_run(tmp_path_factory):
    """``scene_run(path) -> SceneRun``: the session's run of the scene file ``path``, solved on first use."""
    runs: dict[str, SceneRun] = {}

    def run(path: str) -> SceneRun:
        key = os.path.realpath(path)
        if key not in runs:
            base = tmp_path_factory.mktemp(Path(key).stem)
            out = base / "out"
            with pytest.MonkeyPatch.context() as mp:
                mp.setenv("NGCONTACT_CACHE", str(base / "cache"))
                status = cli.main(["run", path, "--out", str(out), "--quiet"])
            report = json.loads((out / "report.json").read_text()) if status == 0 else None
            runs[key] = SceneRun(status, out, report)
        return runs[key]

    return run
