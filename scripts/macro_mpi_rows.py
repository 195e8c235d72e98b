"""The rows of ``scripts/macro_mpi_scaling.py``: read from earlier runs' CSV files or from a folder, and kept.

A run's rows (one per scene, size, ranks and BDDC flags) and its ranks'
memory by phase are CSV files; a folder holding ``ROWS``, ``PHASES`` and
``MEASURED`` (the Markdown note of how its rows were measured, and what they
show) stands for all three.  The rows published in docs/benchmarks.md are
kept in such a folder, ``ARCHIVE``, so that their sections can be published
again from it in any clone (``--rows-from docs/benchmarks/macro_mpi``).
"""
from __future__ import annotations

import csv
import os
import shutil

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KEYS = ("code", "scene", "size", "refinements", "order", "ranks", "threads", "bddc", "ndof", "work_s", "wall_s",
        "newton", "cg_iterations", "coarse_s", "peak_mb_rank0", "peak_mb_parts_max", "peak_mb_each")
#: the folder of the published rows, phase tables and the note of how they were measured (module docstring)
ARCHIVE = os.path.join(ROOT, "docs", "benchmarks", "macro_mpi")
ROWS, PHASES, MEASURED = "macro_mpi_scaling.csv", "macro_mpi_phases.csv", "measured_by.md"


def read_table(path: str) -> list[dict]:
    """The rows of a CSV file as dicts of strings."""
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def read_rows(path: str) -> list[dict]:
    """The rows of a ``macro_mpi_scaling.csv`` written by an earlier run."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    numbers = {"size": float, "refinements": int, "order": int, "ranks": int, "ndof": int, "work_s": float,
               "wall_s": float, "newton": int, "cg_iterations": int, "peak_mb_rank0": float, "peak_mb_parts_max": float}
    defaults = {"bddc": "default", "coarse_s": "", "order": 2, "code": "", "threads": ""}   # rows before these columns
    return [{k: numbers[k](row.get(k) or 0) if k in numbers else row.get(k) or defaults.get(k, "") for k in KEYS}
            for row in rows]


def inputs(paths: list[str]) -> tuple[list[str], list[str], list[str]]:
    """The rows' CSV files, the phase tables and the notes of how they were measured of ``--rows-from``: a
    folder stands for its ``ROWS``, ``PHASES`` and ``MEASURED`` (those present)."""
    rows, phases, notes = [], [], []
    for path in paths:
        if not os.path.isdir(path):
            rows.append(path)
            continue
        rows.append(os.path.join(path, ROWS))
        phases += [os.path.join(path, PHASES)] if os.path.isfile(os.path.join(path, PHASES)) else []
        notes += [os.path.join(path, MEASURED)] if os.path.isfile(os.path.join(path, MEASURED)) else []
    return rows, phases, notes


def keep(csv_path: str, phases_path: str | None, notes: list[str]) -> None:
    """The published rows, phase tables and notes of how they were measured into ``ARCHIVE``."""
    os.makedirs(ARCHIVE, exist_ok=True)
    texts = []
    for path in notes:
        with open(path) as fh:
            texts.append(fh.read().strip())
    for src, name in ((csv_path, ROWS), (phases_path, PHASES)):
        if src is not None and os.path.abspath(src) != os.path.join(ARCHIVE, name):
            shutil.copyfile(src, os.path.join(ARCHIVE, name))
    if texts:
        with open(os.path.join(ARCHIVE, MEASURED), "w") as fh:
            fh.write("\n\n".join(texts) + "\n")
