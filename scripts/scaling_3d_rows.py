"""The rows of ``scripts/scaling_3d.py``: read from an earlier run's CSV or from the folder that keeps them.

A run writes its rows to ``scaling_3d.csv``.  The rows published in docs/benchmarks.md (section
``scaling_3d``) are kept in the folder ``ARCHIVE`` (docs/benchmarks/scaling_3d) with ``MEASURED``, the
Markdown note of which commands, at which commits and under which load, measured them, so that the section is
published again from them, in any clone, by ``python scripts/scaling_3d.py --republish
docs/benchmarks/scaling_3d --publish``.  A folder given to ``--republish`` or ``--keep-rows`` stands for its
``ROWS``.  A run that measures and publishes keeps its rows there and adds its own line to the note (the
note starts again where the run keeps no rows of the folder).
"""
from __future__ import annotations

import csv
import datetime
import os
import shutil

import benchmark_doc
from bisinusoid_accuracy import converged_fraction, extrapolated_rows

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: the folder of the published rows and the note of how they were measured (module docstring)
ARCHIVE = os.path.join(ROOT, "docs", "benchmarks", "scaling_3d")
ROWS, MEASURED = "scaling_3d.csv", "measured_by.md"
#: the note's first line when a run starts it
TITLE = "# How the rows of the section scaling_3d were measured"


def rows_file(path: str) -> str:
    """The rows' CSV file of ``--republish`` / ``--keep-rows``: a folder stands for its ``ROWS``."""
    return os.path.join(path, ROWS) if os.path.isdir(path) else path


def is_archive(path: str | None) -> bool:
    """Whether ``path`` names the kept rows (the folder ``ARCHIVE`` or its ``ROWS``)."""
    return path is not None and os.path.abspath(rows_file(path)) == os.path.join(ARCHIVE, ROWS)


#: the end of the solver of a row derived from the measured ones (:func:`extrapolated_rows`)
EXTRAPOLATED = ", extrapolated"


def measured(rows: list[dict]) -> list[dict]:
    """The measured ``rows``: those not derived from others."""
    return [r for r in rows if not str(r.get("solver", "")).endswith(EXTRAPOLATED)]


def rescored(row: dict, reference=converged_fraction) -> dict:
    """A measured row of the bisinusoid (parts ``accuracy`` and ``scene``) with its ``relative_error`` against
    ``reference(p/p*)``, the converged contact fraction (:func:`bisinusoid_accuracy.converged_fraction`), and
    its ``effectivity`` = estimate / |relative_error| where it has an estimate, whatever reference it was
    measured against; any other row as it is."""
    if row.get("part") not in ("accuracy", "scene") or not isinstance(row.get("contact_fraction"), float):
        return row
    error = row["contact_fraction"] / reference(row["pressure"]) - 1.0
    out = {**row, "relative_error": error}
    if isinstance(row.get("estimate"), float) and error:
        out["effectivity"] = row["estimate"] / abs(error)
    return out


def with_extrapolations(rows: list[dict], reference=converged_fraction) -> list[dict]:
    """The measured ``rows`` in their order, their errors against ``reference`` (:func:`rescored`: the kept rows
    of an earlier reference scored again), then the rows derived from all of them (:func:`extrapolated_rows`).
    A run that keeps an earlier run's rows and a republication of its table make the same table: the derived
    rows last, made from every measured row."""
    rows = [rescored(r, reference) for r in measured(rows)]
    accuracy = [r for r in rows if r["part"] == "accuracy"]
    return rows + extrapolated_rows(accuracy, {p: reference(p) for p in {r["pressure"] for r in accuracy}})


def read_rows(path: str) -> list[dict]:
    """The measured rows of an earlier run's ``scaling_3d.csv`` (or a folder holding one), numbers as numbers."""
    def value(text: str):
        for kind in (int, float):
            try:
                return kind(text)
            except ValueError:
                pass
        return text
    with open(rows_file(path), newline="") as fh:
        return measured([{k: value(v) for k, v in r.items() if v != ""} for r in csv.DictReader(fh)])


def keep(csv_path: str, earlier: str | None, n_earlier: int, n_new: int) -> None:
    """The published rows ``csv_path`` into ``ARCHIVE``, and the note of how they were measured: its first
    ``n_earlier`` rows are those of ``earlier`` (``--republish`` or ``--keep-rows``: the folder's own note
    where they are the folder's rows, else a line naming the file), the ``n_new`` rows below them this run's
    (a line with its command, commit, machine, load and date); the derived rows follow them
    (:func:`with_extrapolations`)."""
    note = os.path.join(ARCHIVE, MEASURED)
    if is_archive(earlier) and not n_new:
        return                                  # published again from the kept rows: they and their note stay
    os.makedirs(ARCHIVE, exist_ok=True)
    if os.path.abspath(csv_path) != os.path.join(ARCHIVE, ROWS):
        shutil.copyfile(csv_path, os.path.join(ARCHIVE, ROWS))
    if is_archive(earlier) and os.path.isfile(note):
        with open(note) as fh:
            lines = [fh.read().rstrip("\n")]
    else:
        lines = [TITLE, ""]
        if earlier is not None and n_earlier:
            lines.append(f"- Rows 1-{n_earlier}: from `{os.path.basename(rows_file(earlier))}`, an earlier run's "
                         "CSV (its command not recorded).")
    if n_new:
        date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
        lines.append(f"- Rows {n_earlier + 1}-{n_earlier + n_new}: `{benchmark_doc.command_line()}` at commit "
                     f"`{benchmark_doc.git_commit()}` on {benchmark_doc.machine()}, {date}.")
    with open(note, "w") as fh:
        fh.write("\n".join(lines) + "\n")
