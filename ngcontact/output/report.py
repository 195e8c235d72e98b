"""Run outcome and its output: ``report.json``, CSV tables, VTK files, PNG plots.

A driver returns an :class:`Outcome` (plain data plus deferred writers); the
functions here write it.  Writing is atomic: everything goes into a hidden
temporary directory beside the target, which replaces the target only once
every file is written, so a failed run leaves no partial output.  Reports
never contain NaN or infinity: :func:`to_plain` rejects them before any
file is written.

Report keys (schema ``ngcontact-report/1``): ``schema``, ``version``,
``kind``, ``title``, ``scene`` (the validated scene echoed), ``effects`` (the
terms assembled), ``ndof``, ``timings`` (seconds per stage and ``total``),
``solver`` (iterations, residual history, converged), ``results``
(kind-specific), ``files`` (what was written beside the report).
"""
from __future__ import annotations

import csv
import json
import math
import os
import shutil
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ngcontact.errors import OutputError

if TYPE_CHECKING:
    import ngsolve as ng

SCHEMA = "ngcontact-report/1"


@dataclass
class VtkField:
    """Fields on a mesh to write as one ``.vtu`` file."""

    mesh: ng.Mesh
    fields: dict[str, ng.CoefficientFunction]
    subdivision: int = 1


@dataclass
class Outcome:
    """What a driver computed, ready to be written."""

    results: dict[str, Any]
    ndof: int = 0
    solver: dict[str, Any] = field(default_factory=dict)
    tables: dict[str, tuple[list[str], list]] = field(default_factory=dict)
    vtk: dict[str, VtkField] = field(default_factory=dict)
    plots: dict[str, Callable[..., None]] = field(default_factory=dict)


class Clock:
    """Seconds spent per named stage, with progress lines for long runs."""

    def __init__(self, progress: Callable[[str], None] | None = None):
        self.timings: dict[str, float] = {}
        self._start = time.perf_counter()
        self._progress = progress

    @contextmanager
    def stage(self, name: str):
        if self._progress:
            self._progress(f"[{time.perf_counter() - self._start:7.2f} s] {name} ...")
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.timings[name] = self.timings.get(name, 0.0) + time.perf_counter() - t0

    def total(self) -> dict:
        out = dict(self.timings)
        out["total"] = time.perf_counter() - self._start
        return out


def to_plain(obj, path: str = "results"):
    """Convert NumPy scalars/arrays to JSON types and reject non-finite numbers."""
    if isinstance(obj, dict):
        return {str(k): to_plain(v, f"{path}.{k}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_plain(v, f"{path}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return to_plain(obj.tolist(), path)
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        if not math.isfinite(x):
            raise ValueError(f"non-finite number {x} at {path}")
        return x
    if obj is None or isinstance(obj, str):
        return obj
    raise TypeError(f"cannot write {type(obj).__name__} at {path} to JSON")




def build_report(*, kind: str, title: str, scene: dict, effects, outcome: Outcome,
                 timings: dict, version: str) -> dict:
    """Assemble the report dictionary (validated: finite numbers only)."""
    report = {
        "schema": SCHEMA,
        "version": version,
        "kind": kind,
        "title": title,
        "scene": scene,
        "effects": list(effects),
        "ndof": int(outcome.ndof),
        "timings": timings,
        "solver": outcome.solver,
        "results": outcome.results,
        "files": sorted([f"{n}.csv" for n in outcome.tables] + [f"{n}.vtu" for n in outcome.vtk]
                        + [f"{n}.png" for n in outcome.plots]),
    }
    return to_plain(report, "report")


def ensure_writable(out_dir: str) -> None:
    """Fail early when ``out_dir`` cannot be created or replaced."""
    out_dir = os.path.abspath(out_dir)
    parent = os.path.dirname(out_dir)
    probe = parent
    while not os.path.exists(probe):
        probe = os.path.dirname(probe)
    if os.path.exists(out_dir) and not os.path.isdir(out_dir):
        raise OutputError(f"--out {out_dir}: exists and is not a directory")
    if not os.path.isdir(probe) or not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"--out {out_dir}: cannot write in {probe}")


def write_outputs(out_dir: str, report: dict, outcome: Outcome) -> str:
    """Write report, tables, VTK and plots atomically into ``out_dir``."""
    out_dir = os.path.abspath(out_dir)
    parent = os.path.dirname(out_dir)
    ensure_writable(out_dir)
    os.makedirs(parent, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix=".ngcontact-partial-", dir=parent)
    try:
        for name, (header, rows) in outcome.tables.items():
            write_csv(os.path.join(tmp, f"{name}.csv"), header, rows)
        for name, item in outcome.vtk.items():
            write_vtk(os.path.join(tmp, name), item)
        for name, draw in outcome.plots.items():
            draw(os.path.join(tmp, f"{name}.png"))
        with open(os.path.join(tmp, "report.json"), "w") as fh:
            json.dump(report, fh, indent=2, allow_nan=False)
            fh.write("\n")
        _replace_dir(tmp, out_dir)
    except OSError as exc:  # e.g. a full disk: an output problem, reported as such
        shutil.rmtree(tmp, ignore_errors=True)
        raise OutputError(f"--out {out_dir}: writing failed ({exc}); the previous output, if any, "
                          "is unchanged") from exc
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out_dir


def _replace_dir(src: str, dst: str) -> None:
    if os.path.exists(dst):
        old = tempfile.mkdtemp(prefix=".ngcontact-old-", dir=os.path.dirname(dst))
        os.rmdir(old)
        os.rename(dst, old)
        os.rename(src, dst)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.rename(src, dst)


def write_csv(path: str, header, rows) -> None:
    rows = to_plain([list(r) for r in rows], os.path.basename(path))
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def write_vtk(path_noext: str, item: VtkField) -> None:
    import ngsolve as ng
    names = list(item.fields)
    ng.VTKOutput(ma=item.mesh, coefs=[item.fields[n] for n in names], names=names,
                 filename=path_noext, subdivision=item.subdivision, legacy=False).Do()
    # VTKOutput appends ".vtu"; nothing else to do.
