"""Every shipped scene still computes the headline numbers of its gold record (``tests/gold/scenes.json``).

The record is written by ``scripts/gold_record.py``; which numbers it holds and how they compare (a
relative tolerance, an absolute floor for a value that is zero up to round-off) is stated in
``tests/gold/record.py``.  Each scene's run is the one ``test_scenes.py`` checks (``conftest.py``:
``ngcontact run`` once per session), so the comparison costs no solve of its own.  A scene that the
record holds but whose fresh report lacks a key fails; keys a report adds are ignored.  After a change
that is meant to move these numbers, re-record the scenes it moves with
``python scripts/gold_record.py --only NAME`` and commit the record with the change.
"""
from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
GOLD_DIR = ROOT / "tests" / "gold"
_SPEC = importlib.util.spec_from_file_location("gold_record_rules", GOLD_DIR / "record.py")
assert _SPEC is not None and _SPEC.loader is not None
R = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(R)

GOLD = json.loads((GOLD_DIR / "scenes.json").read_text())["scenes"]
PARAMS = [pytest.param(rel, id=rel.removeprefix("geometries/"),
                       marks=[pytest.mark.slow] if entry.get("expensive") else [])
          for rel, entry in sorted(GOLD.items())]


@pytest.mark.slow
def test_every_shipped_scene_is_recorded():
    shipped = {p.relative_to(ROOT).as_posix() for p in (ROOT / "geometries").rglob("*.toml")}
    assert sorted(shipped - set(GOLD)) == [], "scenes without gold: run scripts/gold_record.py --only NAME"
    assert sorted(set(GOLD) - shipped) == [], "gold of scenes no longer shipped: remove them from the record"


@pytest.mark.slow
@pytest.mark.parametrize("rel", PARAMS)
def test_scene_reproduces_its_gold(rel, scene_run):
    entry = GOLD[rel]
    run = scene_run(str(ROOT / rel))
    assert run.status == 0, f"{rel}: ngcontact run ended with exit {run.status}: {run.stderr[-2000:]}"
    assert run.report["kind"] == entry["kind"]
    bad = R.compare(entry["keys"], R.extract(run.report))
    assert not bad, (f"{len(bad)} of {len(entry['keys'])} headline numbers moved beyond rtol {R.RTOL:g} "
                     f"(recorded at {entry.get('commit', '?')}):\n"
                     + R.table([(rel, *b) for b in bad]))


def test_comparison_flags_moved_and_missing_keys_only():
    gold = {"ndof": 100, "loads.0.contact_fraction": 0.5, "loads.0.mean_closure": 2e-6,
            "whole_surface.k_n": 1e3, "whole_surface.k_nt": 1e-13, "whole_surface.G_n": 0.0}
    same = {**gold, "loads.0.contact_fraction": 0.5 * (1 + 0.1 * R.RTOL), "whole_surface.k_nt": -3e-13,
            "whole_surface.G_n": 1e-12, "extra.key": 1.0}
    assert R.compare(gold, same) == []
    moved = {**gold, "ndof": 101, "loads.0.mean_closure": 2e-6 * (1 + 10 * R.RTOL), "whole_surface.k_nt": 1e-3}
    del moved["loads.0.contact_fraction"]
    bad = {key: (ref, new) for key, ref, new, _ in R.compare(gold, moved)}
    assert bad == {"ndof": (100, 101), "loads.0.mean_closure": (2e-6, moved["loads.0.mean_closure"]),
                   "whole_surface.k_nt": (1e-13, 1e-3), "loads.0.contact_fraction": (0.5, None)}
    assert "loads.0.contact_fraction" in R.table([("scene", *b) for b in R.compare(gold, moved)])


def test_a_rate_deviation_is_compared_at_the_size_of_the_rates_it_is_a_difference_of():
    gold = {"rates.1.l2": 4.97, "max_rate_deviation": 0.03}
    spread = {**gold, "max_rate_deviation": 0.03 + 0.1 * R.RTOL * 4.97}     # the rates' round-off, 1.7e-5 of itself
    assert R.compare(gold, spread) == []
    moved = {**gold, "max_rate_deviation": 0.03 + 10 * R.RTOL * 4.97}
    assert [key for key, *_ in R.compare(gold, moved)] == ["max_rate_deviation"]
