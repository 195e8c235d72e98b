"""Every shipped scene is valid, and runs end to end to a report of finite numbers.

Validation is in the default tier; the full runs (the shipped settings, some
of them 3D) are in the slow tier, which CI runs after the default one.
"""
import base64
import glob
import math
import os
import re

import pytest

from ngcontact.scene import loader as scene

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENES = sorted(glob.glob(os.path.join(ROOT, "geometries", "**", "*.toml"), recursive=True))
IDS = [os.path.relpath(p, os.path.join(ROOT, "geometries")) for p in SCENES]


def test_scenes_are_shipped():
    assert len(SCENES) >= 10


@pytest.mark.parametrize("path", SCENES, ids=IDS)
def test_scene_is_valid_and_names_its_effects(path):
    sc = scene.load(path)
    effects = scene.effects(sc)
    assert effects, f"{path}: a scene must call for at least one effect"
    assert len(set(effects)) == len(effects)


def _numbers(obj, where="report"):
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _numbers(v, f"{where}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _numbers(v, f"{where}[{i}]")
    elif isinstance(obj, float):
        yield where, obj


@pytest.mark.slow
@pytest.mark.parametrize("path", SCENES, ids=IDS)
def test_scene_runs_to_a_finite_report(path, scene_run):
    run = scene_run(path)  # `ngcontact run` in a fresh cache, shared with test_gold.py (conftest.py)
    assert run.status == 0, run.stderr[-2000:]
    out, rep = run.out, run.report
    sc = scene.load(path)
    assert rep["kind"] == sc.kind
    assert rep["effects"] == list(scene.effects(sc))
    bad = [w for w, x in _numbers(rep) if not math.isfinite(x)]
    assert not bad, f"non-finite numbers at {bad[:5]}"
    for name in rep["files"]:
        assert (out / name).is_file(), f"{name} listed but not written"
    # the page beside the report: every PNG embedded, no non-finite number in its text
    page = (out / "report.html").read_text(encoding="utf-8")
    embedded = {base64.b64decode(m) for m in re.findall(r"data:image/png;base64,([A-Za-z0-9+/=]+)", page)}
    assert all((out / n).read_bytes() in embedded for n in rep["files"] if n.endswith(".png"))
    text = re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", page)
    assert not re.search(r"\b(nan|inf|infinity)\b", text, re.IGNORECASE)
