"""Driver part of ``[two_scale]`` (macro kind): the coupling loop of :mod:`ngcontact.coupling.two_scale`.

No file I/O here except the cell-table cache of :mod:`ngcontact.coupling.cell_law`
(``$NGCONTACT_CACHE``): the table of cell responses is stored under the
SHA-256 of the validated cell scene with its overrides, the data files it
names, the cell length unit and the table tolerance, so a second run of the
same scene solves no cell problem; an edited cell scene or data file gives
another key.

The cell solves of one table level go through ``map_tasks`` (default:
:func:`executor_map`, one batch of the run's executor, ``--workers`` local
processes or a Dask cluster): each task is a :class:`PressureSolve`, a
picklable callable that builds its cell problem once per process.  Measured
on ``femur_stem_two_scale.toml`` (cold cache, 23 cell solves, a loaded
machine): solve stage 139 s with ``--workers 1``, 88 s with 2, the same
safety factor to 15 digits.

``results["two_scale"]``: ``converged``, ``iterations`` (law updates),
``macro_solves``, ``cell_solves`` (cell problems solved in this run),
``history`` (per iteration the largest macro pressure [Pa], ``max_change``
= max |sigma_n(k) - sigma_n(k-1)| [Pa] at the interface sampling points,
cumulative cell solves, Newton iterations, whether the law changed and the
solve was warm-started), ``newton_per_solve``, ``tolerance`` [Pa],
``table`` (pressures [Pa], contact fraction, ``k_n0`` [Pa/m], ``g_n0``
[Pa], ``closure`` [m], ``tolerance``, ``error_estimate``: the largest
relative midpoint discrepancy accepted, ``nodes``), ``cache`` (key, whether
the table came from it, its path), ``law`` (the macro law: the cell's
tabulated response), ``cell`` (scene, ndof, overrides) and the coefficients
at the interface samples (``contact_fraction``, ``k_n0``; along the profile
in 2D and axisymmetry, on the interface surface in 3D).
"""
from __future__ import annotations

import hashlib
import logging
from collections.abc import Callable, Sequence

import numpy as np

from ngcontact.coupling import cell_law
from ngcontact.coupling import two_scale as T
from ngcontact.macro.macro_measures import interface_samples
from ngcontact.scene import cell_links
from ngcontact.scene.sections import resolve
from ngcontact.solvers import executor

log = logging.getLogger(__name__)

TABLE_FORMAT = "cell-table-1"
TABLE_ARRAYS = ("pressure",) + T.KEYS + ("error_estimate",)


class PressureSolve:
    """``p -> cell response`` of one cell scene; picklable (the cell problem is rebuilt per process)."""

    def __init__(self, path: str, length_unit: float, overrides: dict | None = None):
        self.path, self.length_unit, self.overrides = path, length_unit, dict(overrides or {})
        self._problem = None

    def __getstate__(self):
        return {"path": self.path, "length_unit": self.length_unit, "overrides": self.overrides, "_problem": None}

    def problem(self):
        if self._problem is None:
            from ngcontact.drivers.run_strength import cell_problem_of
            _, self._problem = cell_problem_of(self.path, key="two_scale.cell", overrides=self.overrides)
        return self._problem

    def __call__(self, pressure: float) -> T.Response:
        return T.cell_response(self.problem(), pressure, self.length_unit)


def table_key(cell_scene, length_unit: float, tol: float) -> str:
    """Cache key of a cell table: the cell (scene, overrides, data files), its length unit and tolerance."""
    from ngcontact.drivers.build import cell_key
    h = hashlib.sha256()
    h.update(f"{TABLE_FORMAT}|{cell_key(cell_scene)}|{length_unit!r}|{tol!r}".encode())
    return h.hexdigest()


def _table_shapes(arrays: dict) -> str | None:
    n = arrays["pressure"].shape
    if len(n) != 1 or n[0] < 2 or any(arrays[k].shape != n for k in T.KEYS) or arrays["error_estimate"].shape != (1,):
        return "arrays of shapes " + ", ".join(str(arrays[k].shape) for k in TABLE_ARRAYS)
    if np.any(np.diff(arrays["pressure"]) <= 0):
        return "pressures not increasing"
    return None


def cached_table(key: str, response, tol: float, map_tasks, cache_dir: str | None = None) -> tuple[T.CellTable, bool]:
    """A :class:`~ngcontact.coupling.two_scale.CellTable` filled from the cache when it holds ``key``."""
    found = cell_law.read_cached(key, TABLE_ARRAYS, TABLE_FORMAT, cache_dir, _table_shapes)
    table = T.CellTable(response, tol=tol, map_tasks=map_tasks)
    if found is None:
        return table, False
    for i, p in enumerate(found["pressure"]):
        table.values[float(p)] = {k: float(found[k][i]) for k in T.KEYS}
    table.error_estimate = float(found["error_estimate"][0])
    return table, True


def store_table(key: str, table: T.CellTable, cache_dir: str | None = None) -> None:
    P = table.pressures
    arrays = {"pressure": P, "error_estimate": np.array([table.error_estimate]),
              **{k: np.array([table.values[q][k] for q in P]) for k in T.KEYS}}
    cell_law.write_cached(key, arrays, TABLE_ARRAYS, TABLE_FORMAT, cache_dir)


def executor_map(response: Callable[[float], T.Response], pressures: Sequence[float]) -> list[T.Response]:
    """The cell solves of one table level as one batch of the run's executor (local processes or Dask)."""
    return executor.current().map(response, list(pressures), [f"p = {p:.9g}" for p in pressures],
                                  label="cell table level")


def couple(scene, problem, solve,
           map_tasks: Callable[[Callable[[float], T.Response], Sequence[float]], list[T.Response]] = executor_map,
           cache_dir: str | None = None, warm: bool = True):
    """Run the loop of ``scene.two_scale`` from ``problem``; returns ``(solution, results)``.

    ``solve(problem, start)``: the macro solve (warm-started from the
    vector ``start`` when it is not None); ``map_tasks``: runs the cell
    solves of one table level (:class:`~ngcontact.coupling.two_scale.CellTable`);
    ``warm = False`` cold-starts every macro solve (for comparisons).
    """
    from ngcontact.drivers.build import cell_scene_of
    spec = scene.two_scale
    path = resolve(scene, spec.cell)
    overrides = cell_links.overrides(scene.interface)
    cell_scene = cell_scene_of(path, key="two_scale.cell", overrides=overrides)
    task = PressureSolve(path, spec.cell_length_unit, overrides)
    key = table_key(cell_scene, spec.cell_length_unit, spec.table_tol)
    table, from_cache = cached_table(key, task, spec.table_tol, map_tasks, cache_dir)
    out = T.couple(problem, table, tol=spec.tol, max_iter=spec.max_iter, table_min=spec.table_min,
                   points_per_element=scene.output.points_per_element, solve=solve, warm=warm)
    if table.solves:
        store_table(key, table, cache_dir)
    p = interface_samples(out.solution, scene.output.points_per_element)["pressure"]
    coef = table(np.asarray(p))
    law = T.response_law(table)
    res = {"converged": out.converged, "iterations": len(out.history) - 1, "macro_solves": out.macro_solves,
           "cell_solves": table.solves, "tolerance": spec.tol, "history": out.history,
           "newton_per_solve": [h["newton_iterations"] for h in out.history if h["law_changed"]],
           "table": table.as_dict(),
           "cache": {"key": key, "table_from_cache": from_cache,
                     "directory": cache_dir or cell_law.cache_dir_default()},
           "law": {"type": "tabulated cell response p(c)", "closure": list(law.closure),
                   "pressure": list(law.pressure)},
           "cell": {"scene": path, "ndof": int(task.problem().ndof) if table.solves else None,
                    "overrides": overrides},
           "interface_coefficients": {"contact_fraction": coef["contact_fraction"], "k_n0": coef["k_n0"]}}
    return out.solution, res
