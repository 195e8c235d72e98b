"""scripts/scaling_3d_rows.py: the published rows of the section scaling_3d, kept and published again alike."""
import csv
import os
import sys

import pytest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import scaling_3d_rows as S  # noqa: E402

KEYS = ["part", "solver", "cell", "size", "ndof", "seconds", "contact_fraction", "pressure", "relative_error"]


def _row(size: float, fraction: float, converged: float = 0.0147) -> dict:
    return {"part": "accuracy", "solver": "fe exact order 2, edge-refined", "cell": "quarter", "size": size,
            "ndof": int(1000 / size), "seconds": 1.0, "contact_fraction": fraction, "pressure": 0.005,
            "relative_error": fraction / converged - 1.0}


def _write(path, rows: list[dict]) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, KEYS, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)


@pytest.mark.slow
def test_kept_rows_and_new_ones_make_the_table_their_republication_makes(tmp_path):
    """An earlier run's rows (two edge sizes and their extrapolation) kept above a new size: the measured rows in
    their order, then one extrapolation over all three sizes, the table that republishing its CSV makes again."""
    earlier = [_row(0.01, 0.0152), _row(0.005, 0.01485)]
    table = S.with_extrapolations(earlier)
    assert [r["solver"].endswith(S.EXTRAPOLATED) for r in table] == [False, False, True]
    _write(tmp_path / S.ROWS, table)
    kept = S.read_rows(str(tmp_path))                       # a folder stands for its scaling_3d.csv
    assert [r["size"] for r in kept] == [0.01, 0.005]
    joined = S.with_extrapolations(kept + [_row(0.0025, 0.014725)])
    assert [r["size"] for r in joined] == [0.01, 0.005, 0.0025, "0.01 0.005 0.0025"]
    _write(tmp_path / "joined.csv", joined)
    again = S.with_extrapolations(S.read_rows(str(tmp_path / "joined.csv")))
    assert [r["size"] for r in again] == [r["size"] for r in joined]
    assert again[-1]["contact_fraction"] == pytest.approx(joined[-1]["contact_fraction"], rel=1e-12)


def test_the_note_numbers_the_kept_rows_then_the_new_ones(tmp_path, monkeypatch):
    """A run that measures starts the note; one that keeps the folder's rows adds its own line after the kept
    rows' numbers; republishing the folder changes neither file."""
    monkeypatch.setattr(S, "ARCHIVE", str(tmp_path / "archive"))
    out = tmp_path / "out.csv"
    _write(out, S.with_extrapolations([_row(0.01, 0.0152), _row(0.005, 0.01485)]))
    S.keep(str(out), None, 0, 2)
    note = tmp_path / "archive" / S.MEASURED
    lines = note.read_text().splitlines()
    assert lines[0] == S.TITLE and lines[2].startswith("- Rows 1-2: `python ")
    S.keep(str(out), S.ARCHIVE, 2, 1)
    assert note.read_text().splitlines()[:3] == lines[:3] and note.read_text().splitlines()[3].startswith("- Rows 3-3:")
    before = note.read_text(), (tmp_path / "archive" / S.ROWS).read_text()
    S.keep(str(out), S.ARCHIVE, 3, 0)
    assert (note.read_text(), (tmp_path / "archive" / S.ROWS).read_text()) == before


def test_an_extrapolation_carries_the_ladders_estimate():
    """The extrapolated row's estimate is the contact-edge ladder's: the larger of the grid convergence index and
    the spectral twin's floor |q - q_N| + 2 |q_N - q_N/2| on the ladder's floor grid N (FLOOR_GRID = 2048,
    whatever the finest edge size), each in its own column."""
    import bisinusoid_accuracy as B
    rows = [_row(0.01, 0.0152), _row(0.005, 0.01485), _row(0.0025, 0.014725)]
    asked = []

    def twin(grid, ratio, values={2048: 0.0147, 1024: 0.0146}):
        asked.append((grid, ratio))
        return values[grid]
    (row,) = B.extrapolated_rows(rows, {0.005: 0.0147}, twin)
    assert sorted(asked) == [(1024, 0.005), (2048, 0.005)]
    q = row["contact_fraction"]
    assert row["estimate_twin"] == pytest.approx((abs(q - 0.0147) + 2 * 0.0001) / q, rel=1e-12)
    assert row["estimate"] == max(row["estimate_gci"], row["estimate_twin"])
    assert row["effectivity"] == pytest.approx(row["estimate"] / abs(q / 0.0147 - 1.0), rel=1e-12)
    (close,) = B.extrapolated_rows(rows, {0.005: 0.0147}, lambda grid, ratio: q)
    assert close["estimate_twin"] == 0.0 and close["estimate"] == close["estimate_gci"]


def test_kept_rows_are_scored_against_the_reference_not_the_one_they_were_measured_against():
    """A kept row's relative error (and a scene's effectivity) is made again against the reference given, the
    converged value of today, whatever the error it was kept with; rows of other parts stay as they are."""
    order1 = {**_row(0.01, 0.0139), "solver": "fe exact order 1, patch-refined"}    # kept against 0.0147
    scene = {"part": "scene", "solver": "ngcontact run: fe exact order 2, contact-edge ladder", "cell": "quarter",
             "size": "4 levels", "seconds": 200.0, "cpu_seconds": 34.0, "contact_fraction": 0.01414,
             "pressure": 0.02, "relative_error": 0.5, "estimate": 0.02, "effectivity": 0.04}
    cell = {"part": "cell", "solver": "iterative", "size": 0.1, "ndof": 3000, "seconds": 2.0, "contact_fraction": 0.2,
            "pressure": 0.00185}
    asked = []

    def reference(ratio):
        asked.append(ratio)
        return {0.005: 0.0140, 0.02: 0.0141}[ratio]
    table = S.with_extrapolations([order1, scene, cell], reference)
    assert sorted(set(asked)) == [0.005, 0.02]
    assert table[0]["relative_error"] == pytest.approx(0.0139 / 0.0140 - 1.0, rel=1e-12)
    assert table[1]["relative_error"] == pytest.approx(0.01414 / 0.0141 - 1.0, rel=1e-12)
    assert table[1]["effectivity"] == pytest.approx(0.02 / (0.01414 / 0.0141 - 1.0), rel=1e-12)
    assert table[2] == cell and len(table) == 3


def test_the_scenes_section_scores_against_the_one_reference():
    """The scene's section takes its converged value from the module scaling_3d scores its rows against (one
    reference, not a copy)."""
    import bisinusoid_accuracy as B
    import bisinusoid_scene_accuracy as scene
    assert scene.converged is B.converged


@pytest.mark.slow  # the spectral cell at 1024^2 and 2048^2
def test_the_sections_rows_are_scored_against_the_converged_bisinusoid():
    """scaling_3d's rows carry their error against the converged bisinusoid."""
    import bisinusoid_accuracy as B
    theirs = B.converged(0.05)
    assert S.with_extrapolations([{**_row(0.01, 0.07), "pressure": 0.05}])[0]["relative_error"] == pytest.approx(
        0.07 / theirs["contact_fraction"] - 1.0, rel=1e-9)


@pytest.mark.slow
def test_the_published_extrapolations_bound_their_errors():
    """On the kept rows of the section (docs/benchmarks/scaling_3d), scored against the spectral cell
    extrapolated from 1024^2 and 2048^2, every extrapolation's estimate (with the real spectral twin) is at
    least its true error: effectivity >= 1."""
    rows = [r for r in S.with_extrapolations(S.read_rows(S.ARCHIVE)) if r["solver"].endswith(S.EXTRAPOLATED)]
    assert rows
    for r in rows:
        assert r["estimate"] >= abs(r["relative_error"]), r
