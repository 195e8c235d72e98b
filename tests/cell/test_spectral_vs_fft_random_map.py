"""``scripts/spectral_vs_fft.py`` part 3: issue 38's random map beside Tamaas (its quick grid, 256^2).

Ours and Tamaas' rows pose the same problem (the half-space pair, the same samples and tolerance): one row
per load each, the same contact fractions, pressure fields equal to far below the discretization, the
ratio of their times; without Tamaas only ours, and the published sentence says it was skipped.  A part
run alone is refused with ``--publish`` (exit 2, nothing written).
"""
import importlib.util
import os
import sys

import pytest

_SCRIPTS = os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
sys.path.insert(0, _SCRIPTS)
_SPEC = importlib.util.spec_from_file_location("spectral_vs_fft", os.path.join(_SCRIPTS, "spectral_vs_fft.py"))
assert _SPEC is not None and _SPEC.loader is not None
S = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(S)


def test_ours_and_tamaas_rows_agree_per_load():
    pytest.importorskip("tamaas", reason="Tamaas (the bench extra: pip install '.[bench]') is not installed")
    rows = S.random_map(quick=True)
    ours = [r for r in rows if r["solver"] == "ngcontact spectral"]
    peer = [r for r in rows if r["solver"] == "tamaas"]
    assert len(ours) == len(peer) == 3 and all(r["grid_or_ndof"] == S.MAP_GRID_QUICK for r in rows)
    for a, b in zip(ours, peer):
        assert a["contact_fraction"] == pytest.approx(b["contact_fraction"], abs=1.5 / S.MAP_GRID_QUICK ** 2)
        assert a["pressure_l2_difference"] == b["pressure_l2_difference"] < 1e-6
    assert S.random_map_ratio(rows) == pytest.approx(
        sum(r["seconds"] for r in peer) / sum(r["seconds"] for r in ours))
    assert "ratio" in S.random_map_note(rows)


def test_without_tamaas_only_ours_and_the_note_says_skipped(monkeypatch):
    monkeypatch.setattr(S, "tamaas_available", lambda: False)
    rows = S.random_map(quick=True)
    assert [r["solver"] for r in rows] == ["ngcontact spectral"] * 3
    assert "Tamaas skipped" in S.random_map_note(rows)


def test_a_part_alone_is_refused_with_publish(tmp_path):
    out = tmp_path / "out"
    assert S.main([str(out), "--random-map-only", "--publish"]) == 2
    assert not out.exists()
