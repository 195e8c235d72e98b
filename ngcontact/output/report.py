"""Run outcome and its output: ``report.json``, CSV tables, VTK files, PNG plots.

A driver returns an :class:`Outcome` (plain data plus deferred writers);
:func:`build_report` makes the report of it and
:mod:`ngcontact.output.writer` writes both into the output directory.
Reports never contain NaN or infinity: :func:`to_plain` rejects them before
any file is written.

Grid fields (the spectral cell's pressure and gap) are written as ``.npy``
arrays.

Report keys (schema ``ngcontact-report/1``): ``schema``, ``version``,
``kind``, ``title``, ``scene`` (the validated scene echoed), ``effects`` (the
terms assembled), ``ndof``, ``timings`` (seconds per stage and ``total``),
``threads`` (of NGSolve's task manager), ``compute`` (where batches of
independent solves ran: executor, workers, scheduler, batches),
``solver`` (iterations, residual history, converged), ``results``
(kind-specific), ``files`` (what was written beside the report).
"""
from __future__ import annotations

import math
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Protocol

import numpy as np


if TYPE_CHECKING:
    import ngsolve as ng

SCHEMA = "ngcontact-report/1"


class Pieces(Protocol):
    """How the fields on a mesh distributed over MPI ranks are written: a ``.vtu`` piece per rank holding
    elements and the ``.pvtu`` file that names them (:mod:`ngcontact.distributed.vtk_pieces`)."""

    def files(self, name: str) -> list[str]:
        """The names of the files of ``name``: the ``.pvtu`` file and the pieces."""

    def write(self, path_noext: str, item: VtkField) -> None:
        """Write ``item`` (every rank its piece), on rank 0."""


@dataclass
class VtkField:
    """Fields on a mesh to write as one ``.vtu`` file (``pieces``: a mesh distributed over MPI ranks)."""

    mesh: ng.Mesh
    fields: dict[str, ng.CoefficientFunction]
    subdivision: int = 1
    pieces: Pieces | None = None

    def files(self, name: str) -> list[str]:
        """The names of the files written for the field set ``name``."""
        return [f"{name}.vtu"] if self.pieces is None else self.pieces.files(name)


@dataclass
class Outcome:
    """What a driver computed, ready to be written."""

    results: dict[str, Any]
    ndof: int = 0
    solver: dict[str, Any] = field(default_factory=dict)
    tables: dict[str, tuple[list[str], list]] = field(default_factory=dict)
    vtk: dict[str, VtkField] = field(default_factory=dict)
    plots: dict[str, Callable[..., None]] = field(default_factory=dict)
    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    #: text files by full name (a scene written beside a study: ``recommended.toml``)
    texts: dict[str, str] = field(default_factory=dict)


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

    def note(self, line: str) -> None:
        """A progress line inside a stage (a long solve's step, a refinement level), timed as the stage lines."""
        if self._progress:
            self._progress(f"[{time.perf_counter() - self._start:7.2f} s] {line}")

    def total(self) -> dict:
        out = dict(self.timings)
        out["total"] = time.perf_counter() - self._start
        return out


def to_plain(obj, path: str = "results"):
    """Convert NumPy scalars/arrays to JSON types and reject non-finite numbers (naming where: ``path``).  The
    path of an element is spelled out only where it is reported, so that a table of a million rows converts at
    the cost of its numbers; a float array is checked as a whole."""
    if isinstance(obj, dict):
        return {str(k): to_plain(v, f"{path}.{k}") for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        out = []
        for i, v in enumerate(obj):
            if isinstance(v, float):                # a Python float, NumPy's float64 too
                x = float(v)
                if not math.isfinite(x):
                    raise ValueError(f"non-finite number {x} at {path}[{i}]")
                out.append(x)
            else:
                out.append(to_plain(v, f"{path}[{i}]"))
        return out
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind == "f" and not np.isfinite(obj).all():
            where = np.argwhere(~np.isfinite(obj))[0]
            raise ValueError(f"non-finite number {obj[tuple(where)]} at {path}"
                             + "".join(f"[{i}]" for i in where))
        return obj.tolist() if obj.dtype.kind in "fiub" else to_plain(obj.tolist(), path)
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


def _error_text(q: dict) -> str:
    """A quantity's error on the terminal line: ``+/- rel``, ``(no estimate)``, or where its value has no
    limit (a stress maximum at a singular corner) ``(mesh dependent: singular at (x, y))``, followed by
    ``not counted`` where the verdict does not count it."""
    if q.get("singular_at") is not None:
        text = "(mesh dependent: singular at (" + ", ".join(f"{c:.4g}" for c in q["singular_at"]) + "))"
        return text + ("" if q.get("counted", True) else " not counted")
    if q.get("relative_error") is None:
        return "(no estimate)"
    return f"+/- {q['relative_error']:.2%}" + ("" if q.get("counted", True) else " not counted")


def method_line(results: dict) -> str | None:
    """The method that solved a cell and why (``results.accuracy.method``) in one terminal line, with a 3D FE
    cell's symmetry (``results.accuracy.symmetry``: its quarter or its period, and why), else ``None``."""
    acc = results.get("accuracy")
    method = acc.get("method") if isinstance(acc, dict) else None
    symmetry = acc.get("symmetry") if isinstance(acc, dict) else None
    parts = [f"cell method {method['statement']}"] if isinstance(method, dict) and method.get("reason") else []
    if isinstance(symmetry, dict):
        parts.append(f"meshed as its {symmetry['statement']}")
    return "; ".join(parts) or None


def accuracy_line(results: dict) -> str | None:
    """The accuracy verdict (``results.accuracy``) in one terminal line: met or not, and per quantity its
    value and estimated relative error (the largest over the loads of a sweep, with that load's value); a
    verdict without an estimate says so and how to get one (``accuracy.how``), never nothing."""
    acc = results.get("accuracy")
    if isinstance(acc, dict) and acc.get("estimated") is False and not acc.get("quantities"):
        return f"accuracy {acc.get('how') or 'not estimated'}"
    if not isinstance(acc, dict) or not acc.get("quantities"):
        return None
    worst: dict[str, dict] = {}
    for q in acc["quantities"]:
        seen = worst.get(q["name"])
        rel = q.get("relative_error")
        if seen is None or rel is None or (seen.get("relative_error") is not None and rel > seen["relative_error"]):
            worst[q["name"]] = q
    parts = [f"{n} {q['value']:.4g} " + _error_text(q) + _where(q) for n, q in worst.items()]
    verdict = "met" if acc.get("met") else "NOT met"
    refined = acc.get("refinement") or {}
    if refined.get("order") is not None:
        verdict += f" at order {refined['order']} (refined from order {refined.get('scene_order')}"
        verdict += f", mesh refined {refined['h_level']} times)" if refined.get("h_level") else ")"
    model = acc.get("modelling") or {}
    tail = (f"; modelling error of the homogenized interface ~ {model['relative_error']:.2%} (estimate C eps / L)"
            if model.get("relative_error") is not None else "")
    return f"accuracy {verdict} (tolerance {acc['tolerance']:.3g}): " + ", ".join(parts) + _away_text(acc) + tail


def _where(q: dict) -> str:
    """Where a maximum away from the singular points is attained (`` at (x, y)``), nothing for the others."""
    if not str(q.get("name", "")).endswith("_away") or q.get("location") is None:
        return ""
    return " at (" + ", ".join(f"{c:.4g}" for c in q["location"]) + ")"


def _away_text(acc: dict) -> str:
    """What the maxima away from the singular points are and that the mesh-dependent ones are not counted
    (``accuracy.exclusion``; nothing without it)."""
    ex = acc.get("exclusion") or {}
    if ex.get("edges"):
        kinds = ", ".join(dict.fromkeys(c["why"] for c in ex["edges"]))
        length = sum(float(c["length"]) for c in ex["edges"])
        return (f"; *_away: outside {ex['radius']:.3g} m of the singular edges ({len(ex['edges'])} curves, "
                f"{length:.3g} m: {kinds}) (counted; the mesh-dependent maxima are listed, not counted)")
    if not ex.get("points"):
        return ""
    pts = ", ".join("(" + ", ".join(f"{c:.4g}" for c in p) + ")" for p in ex["points"])
    return (f"; *_away: outside {ex['radius']:.3g} m of the singular points {pts} (counted; the mesh-dependent "
            "maxima are listed, not counted)")


def file_names(outcome: Outcome) -> list[str]:
    """The names of the files an outcome writes besides ``report.json`` (the report's ``files``)."""
    return sorted([f"{n}.csv" for n in outcome.tables] + [f for n, v in outcome.vtk.items() for f in v.files(n)]
                  + [f"{n}.png" for n in outcome.plots] + [f"{n}.npy" for n in outcome.arrays] + list(outcome.texts))


def build_report(*, kind: str, title: str, scene: dict, effects, outcome: Outcome,
                 timings: dict, version: str, threads: int = 1, compute: dict | None = None) -> dict:
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
        "threads": int(threads),
        "compute": compute if compute is not None else {"executor": "serial", "workers": 1, "batches": []},
        "solver": outcome.solver,
        "results": outcome.results,
        "files": file_names(outcome),
    }
    return to_plain(report, "report")
