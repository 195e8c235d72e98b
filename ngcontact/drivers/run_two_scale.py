"""Driver part of ``[two_scale]`` (macro kind): the coupling loop of :mod:`ngcontact.coupling.two_scale`.

No file I/O here except the cell-table cache of :mod:`ngcontact.coupling.cell_law`
(``$NGCONTACT_CACHE``): the table of cell responses is stored under the
SHA-256 of the validated cell scene with its overrides, the data files it
names, the cell length unit and the table tolerance, so a second run of the
same scene solves no cell problem; an edited cell scene or data file gives
another key.  A table that grows during the run (the loop, a mesh level of
the macro refinement, the refinement towards ``discretization.tolerance`` of
:mod:`ngcontact.coupling.table_share`) is written back at once (atomically),
with the responses its share's estimate solved (``held``), so the next run
starts from it.

The cell solves of one table level go through ``map_tasks`` (default:
:func:`executor_map`, one batch of the run's executor, ``--workers`` local
processes or a Dask cluster): each task is a :class:`PressureSolve`, a
picklable callable that builds its cell problem once per process.  The
workers change no result (the same safety factor to round-off), only the
wall time of a cold table (``scripts/two_scale_benchmark.py``:
docs/benchmarks.md, section two_scale_benchmark).

A cell with micro friction under ``interface.friction = "from_cell"`` also
gets its shear table (:mod:`ngcontact.coupling.shear_table`): the macro
law's tangential part is then the cell's tabulated shear instead of the
``mu0`` of eqs. 42-43 (which only starts the loop); its cell solves go
through the same executor (:class:`ShearSolve` tasks) and it is cached the
same way under its own key, with the loads its share's estimate solved
(``held``, format ``cell-shear-table-2``).

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
tabulated response and its interpolation, the monotone cubic), ``cell`` (scene, method, its ``ndof`` (FE) or
``grid_points`` (spectral) when it was solved, overrides and, where the section sets any, the
``discretization`` keys it replaces: ``two_scale.cell_grid``, ...) and the coefficients
at the interface samples (``contact_fraction``, ``k_n0``; along the profile
in 2D and axisymmetry, on the interface surface in 3D); with a shear
table also ``shear_table`` (rows, nodes, cell solves, the error estimates
in the jump and in the pressure, the rows themselves: far-face jump [cell
units], interface jump [m], shear [Pa]) and its ``cache`` entry, and
``cell_solves`` counts both tables' solves.
"""
from __future__ import annotations

import hashlib
import logging
import threading
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ngcontact.coupling import cell_law
from ngcontact.coupling import shear_table as S
from ngcontact.coupling import pressure_table as PT
from ngcontact.coupling import table_share as TS
from ngcontact.coupling import two_scale as T
from ngcontact.macro import away_maxima as AM
from ngcontact.macro import discretization_error as DE
from ngcontact.macro.macro_measures import interface_samples
from ngcontact.scene import cell_links
from ngcontact.scene.sections import resolve
from ngcontact.scene.two_scale_section import cell_discretization, load_cell
from ngcontact.parallel import executor

log = logging.getLogger(__name__)

TABLE_FORMAT = "cell-table-3"
#: ``held``: 1 at a pressure solved for the estimate of the table's share but not a node of its law
TABLE_ARRAYS = ("pressure",) + PT.KEYS + ("error_estimate", "held")


#: cell problems built by unpickled tasks in this process (a worker), by task kind, content key and thread
_BUILT: dict[tuple, Any] = {}
#: how many of them a worker keeps (a long-lived Dask worker serves many runs)
KEEP_BUILT = 4


class PressureSolve:
    """``p -> cell response`` of one cell scene; picklable (the cell problem is rebuilt per process).

    A batch member arrives in a worker as a pickled copy of the task.  The
    copies of one worker share the cell problem they build (its mesh, spaces
    and forms), found by the content key of the cell scene (scene, contact
    overrides, data files: :func:`~ngcontact.drivers.build.cell_key`) and the
    worker thread: a worker builds the cell once per run, not once per
    pressure, as the run's own process does with its one task.  Every
    response is solved afresh from a first load's start (``first=True``), so a
    shared problem gives the numbers of a fresh one.

    ``method``: ``"fe"`` or ``"spectral"`` instead of the cell scene's own
    ``discretization.method`` (``two_scale.cell_method``); ``discretization``: other keys of the cell's
    ``[discretization]`` replaced (``two_scale.cell_grid``, ``cell_maxh``, ...).  The cell is
    reached through the cell protocol
    (:meth:`~ngcontact.cell.cell_solver.CellSolver.response`), each pressure
    from a first load's start, whichever method solves it.
    """

    def __init__(self, path: str, length_unit: float, overrides: dict | None = None, method: str | None = None,
                 discretization: dict | None = None):
        from ngcontact.drivers.build import cell_key, cell_scene_of
        self.path, self.length_unit, self.overrides = path, length_unit, dict(overrides or {})
        self.discretization = dict(discretization or {})
        scene = cell_scene_of(path, key="two_scale.cell", overrides=self.overrides, method=method,
                              discretization=self.discretization)
        self.method = scene.discretization.method
        self.key = cell_key(scene)
        self._problem = None
        self._shared = False

    def __getstate__(self):
        return {"path": self.path, "length_unit": self.length_unit, "overrides": self.overrides, "key": self.key,
                "method": self.method, "discretization": self.discretization, "_problem": None, "_shared": False}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._shared = True  # a copy in a worker: share the worker's cell problem

    def build(self):
        """The cell this task solves: the scene's cell behind the cell protocol."""
        from ngcontact.drivers.build import cell_scene_of, cell_solver
        return cell_solver(cell_scene_of(self.path, key="two_scale.cell", overrides=self.overrides,
                                         method=self.method, discretization=self.discretization))

    def problem(self):
        """The cell of :meth:`build`, built once per process and worker thread."""
        if self._problem is None:
            slot = (type(self).__name__, self.key, threading.get_ident())
            if self._shared and slot in _BUILT:
                self._problem = _BUILT[slot]
                return self._problem
            self._problem = self.build()
            if self._shared:
                while len(_BUILT) >= KEEP_BUILT:
                    _BUILT.pop(next(iter(_BUILT)))
                _BUILT[slot] = self._problem
        return self._problem

    def __call__(self, pressure: float) -> PT.Response:
        return self.problem().response(pressure, self.length_unit)

    def size(self) -> dict:
        """The cell's discretization for the report: ``{"method", "ndof"}`` (FE) or ``{"method", "grid_points"}``."""
        return self.problem().size()


class ShearSolve(PressureSolve):
    """``(p, Delta) -> cell shear response`` of one cell scene; picklable like :class:`PressureSolve`.

    The shear response is the FE cell's (its far-face jump under a shear load,
    :func:`~ngcontact.coupling.shear_table.cell_shear_response`)."""

    def build(self):
        from ngcontact.drivers.build import recovery_cell_problem
        return recovery_cell_problem(self.path, key="two_scale.cell", overrides=self.overrides,
                                     method=self.method, discretization=self.discretization)[1]

    def __call__(self, load) -> S.ShearResponse:  # type: ignore[override]
        return S.cell_shear_response(self.problem(), load[0], load[1], self.length_unit)


SHEAR_FORMAT = "cell-shear-table-2"
#: ``held``: 1 at a load solved for the estimate of the tables' share but not a node of the law
SHEAR_ARRAYS = ("row_pressure", "far_face_jump", "jump", "shear", "errors", "checked", "held")


def shear_key(cell_scene, length_unit: float, tol: float) -> str:
    """Cache key of a cell's shear table (another format than the pressure table's, same inputs)."""
    from ngcontact.drivers.build import cell_key
    return hashlib.sha256(f"{SHEAR_FORMAT}|{cell_key(cell_scene)}|{length_unit!r}|{tol!r}".encode()).hexdigest()


def _shear_shapes(arrays: dict) -> str | None:
    n = arrays["row_pressure"].shape
    if len(n) != 1 or any(arrays[k].shape != n for k in ("far_face_jump", "jump", "shear", "held")) or \
            arrays["errors"].shape != (3,) or arrays["checked"].ndim != 2 or arrays["checked"].shape[1] != 3:
        return "arrays of shapes " + ", ".join(str(arrays[k].shape) for k in SHEAR_ARRAYS)
    return None


def cached_shear(key: str, response, tol: float, length_unit: float, map_tasks, cache_dir: str | None = None,
                 max_solves: int = S.ShearTable.max_solves) -> tuple[S.ShearTable, bool]:
    """A :class:`~ngcontact.coupling.shear_table.ShearTable` filled from the cache when it holds ``key``; at most
    ``max_solves`` cell solves in this run (``two_scale.max_cell_solves``)."""
    found = cell_law.read_cached(key, SHEAR_ARRAYS, SHEAR_FORMAT, cache_dir, _shear_shapes)
    table = S.ShearTable(response, tol=tol, length_unit=length_unit, map_tasks=map_tasks, max_solves=max_solves)
    if found is None:
        return table, False
    for p, d, s, t, h in zip(*(found[k] for k in ("row_pressure", "far_face_jump", "jump", "shear", "held"))):
        if h:
            table.held[(float(p), float(d))] = (float(s), float(t))
        else:
            table.rows.setdefault(float(p), {})[float(d)] = (float(s), float(t))
    table.jump_error, table.pressure_error, table.covered_jump = (float(x) for x in found["errors"])
    table.checked = [(float(a), float(b), float(c)) for a, b, c in found["checked"]]
    return table, True


def store_shear(key: str, table: S.ShearTable, cache_dir: str | None = None) -> None:
    flat = [(p, d, s, t, 0.0) for p in table.pressures for d, (s, t) in sorted(table.rows[p].items())]
    flat += [(p, d, s, t, 1.0) for (p, d), (s, t) in sorted(table.held.items())]
    cols = np.array(flat, float).reshape(-1, 5)
    arrays = {"row_pressure": cols[:, 0], "far_face_jump": cols[:, 1], "jump": cols[:, 2], "shear": cols[:, 3],
              "held": cols[:, 4],
              "errors": np.array([table.jump_error, table.pressure_error, table.covered_jump]),
              "checked": np.array(table.checked, float).reshape(-1, 3)}
    cell_law.write_cached(key, arrays, SHEAR_ARRAYS, SHEAR_FORMAT, cache_dir)


def table_key(cell_scene, length_unit: float, tol: float) -> str:
    """Cache key of a cell table: the cell (scene, overrides, data files), its length unit and tolerance."""
    from ngcontact.drivers.build import cell_key
    h = hashlib.sha256()
    h.update(f"{TABLE_FORMAT}|{cell_key(cell_scene)}|{length_unit!r}|{tol!r}".encode())
    return h.hexdigest()


def _table_shapes(arrays: dict) -> str | None:
    n = arrays["pressure"].shape
    if len(n) != 1 or any(arrays[k].shape != n for k in PT.KEYS + ("held",)) or \
            arrays["error_estimate"].shape != (1,) or np.count_nonzero(arrays["held"] == 0) < 2:
        return "arrays of shapes " + ", ".join(str(arrays[k].shape) for k in TABLE_ARRAYS)
    if np.any(np.diff(arrays["pressure"]) <= 0):
        return "pressures not increasing"
    return None


def cached_table(key: str, response, tol: float, map_tasks, cache_dir: str | None = None,
                 max_solves: int = PT.CellTable.max_solves) -> tuple[PT.CellTable, bool]:
    """A :class:`~ngcontact.coupling.pressure_table.CellTable` filled from the cache when it holds ``key``; at most
    ``max_solves`` cell solves in this run (``two_scale.max_cell_solves``)."""
    found = cell_law.read_cached(key, TABLE_ARRAYS, TABLE_FORMAT, cache_dir, _table_shapes)
    table = PT.CellTable(response, tol=tol, map_tasks=map_tasks, max_solves=max_solves)
    if found is None:
        return table, False
    for i, p in enumerate(found["pressure"]):
        (table.held if found["held"][i] else table.values)[float(p)] = {k: float(found[k][i]) for k in PT.KEYS}
    table.error_estimate = float(found["error_estimate"][0])
    return table, True


def store_table(key: str, table: PT.CellTable, cache_dir: str | None = None) -> None:
    """Write ``table`` (its nodes and the responses it holds) under ``key``, atomically: a run that grew the
    table leaves it for the next."""
    known = {**table.held, **table.values}
    P = np.array(sorted(known))
    arrays = {"pressure": P, "error_estimate": np.array([table.error_estimate]),
              "held": np.array([float(q not in table.values) for q in P]),
              **{k: np.array([known[q][k] for q in P]) for k in PT.KEYS}}
    cell_law.write_cached(key, arrays, TABLE_ARRAYS, TABLE_FORMAT, cache_dir)


def executor_map(response: Callable[[float], PT.Response], pressures: Sequence[float]) -> list[PT.Response]:
    """The cell solves of one table level as one batch of the run's executor (local processes or Dask)."""
    return executor.current().map(response, list(pressures), [f"p = {p:.9g}" for p in pressures],
                                  label="cell table level")


def shear_executor_map(response: Callable[[S.ShearLoad], S.ShearResponse], loads: Sequence[S.ShearLoad]
                       ) -> list[S.ShearResponse]:
    """The cell solves of one shear-table level as one batch of the run's executor."""
    return executor.current().map(response, list(loads), [f"p = {p!r}, jump = {d!r}" for p, d in loads],
                                  label="shear table level")


class Relevel:
    """The loop of a two-scale scene run again on another macro mesh (a mesh level of
    :mod:`ngcontact.drivers.macro_refinement`) from the tables the scene's loop made: the cell's law does not
    change with the macro mesh, so a table that covers the level's pressures (and, with a shear table, its
    jumps) is its law as it stands, and one that does not grows by the cell solves the new range needs.
    ``__call__(problem, start)`` has the macro solve's signature; ``loops`` lists each level's loop.
    ``write_back()`` stores the tables in the cell-law cache (after every growth: the next run starts from
    them); :meth:`table_share` estimates the table's share of the run's error and refines the table for it.
    """

    def __init__(self, scene, table: PT.CellTable, shear: S.ShearTable | None, solve,
                 write_back: Callable[[], None] = lambda: None):
        self.spec, self.output, self.table, self.shear, self.solve = scene.two_scale, scene.output, table, shear, solve
        self.loops: list[dict[str, Any]] = []
        self.write_back = write_back
        self.share: TS.TableShare | None = None
        self.safety = None   # the strength check's safety factor, a quantity of the share (table_share)
        self.radius = getattr(scene.discretization, "exclusion_radius", None)
        self.exclusion: AM.Exclusion | None | bool = False   # the balls of the maxima away (table_share)
        self.shared_at = 0   # the mesh levels run when the share was estimated

    def __call__(self, problem, start=None):
        spec = self.spec
        solves = self.table.solves + (self.shear.solves if self.shear is not None else 0)
        out = T.couple(problem, self.table, tol=spec.tol, max_iter=spec.max_iter, table_min=spec.table_min,
                       points_per_element=self.output.points_per_element, solve=self.solve, shear=self.shear)
        added = self.table.solves + (self.shear.solves if self.shear is not None else 0) - solves
        self.loops.append({"elements": problem.mesh.ne, "iterations": len(out.history) - 1, "cell_solves": added,
                           "max_change": out.history[-1]["max_change"]})
        if added:
            self.write_back()
        return out.solution

    def table_share(self, sol, tolerance: float, refine: bool = True, safety=None):
        """The tables' share of the headline quantities of ``sol`` (:mod:`ngcontact.coupling.table_share`: the
        pressure table's and, with one, the shear table's), with ``refine`` the tables refined until it is below
        its fraction of ``tolerance``; the tables are written back to the cache either way.  ``safety``: the
        strength check's :class:`~ngcontact.drivers.macro_accuracy.SafetyFactor`, whose ``safety_factor`` is
        then a quantity of the share too (kept from the first call).  Where the bodies have singular points, the
        maxima away from them (``*_away``, :mod:`ngcontact.macro.away_maxima`, and the safety factor away) are
        quantities of the share as well, outside the balls of the first call's solution (the same set at every
        level; the points a macro refinement finds later are not among them).  Returns the answer's solution."""
        component = next(n for n in DE.headlines(sol, self.output.points_per_element)
                         if n.startswith("resultant_")).removeprefix("resultant_")
        self.safety = safety if safety is not None else self.safety
        if self.exclusion is False:
            self.exclusion = AM.exclusion_of(sol, self.radius)
        exclusion = self.exclusion if isinstance(self.exclusion, AM.Exclusion) else None

        def measure(s):
            out = DE.headlines(s, self.output.points_per_element, component)
            if exclusion is not None:
                out.update(AM.away_maxima(s, exclusion))
            if self.safety is not None:
                out.update(self.safety.samples(s, None if exclusion is None else exclusion.outside))
            return out
        parts: list = [TS.PressurePart(self.table)]
        if self.shear is not None and self.shear.rows:
            parts += [TS.ShearPart(self.shear, "pressure"), TS.ShearPart(self.shear, "jump")]
        try:
            self.share = TS.estimate(sol, parts, self.solve, measure, tolerance, self.output.points_per_element,
                                     refine)
        finally:
            self.write_back()
        self.shared_at = len(self.loops)
        return self.share.solution

    def record(self, results: dict, sol) -> dict:
        """``results`` (``results["two_scale"]``) of the refined solution ``sol``, updated where mesh levels ran:
        its interface coefficients, the table as it grew, the cell solves and the levels' loops
        (``mesh_levels``), and the table's share of the error (``table_share``, :meth:`table_share`): estimated
        again on ``sol`` where mesh levels extended the table since (not refined: that would change the answer
        the macro refinement's estimates were made on)."""
        if self.share is not None and any(lv["cell_solves"] for lv in self.loops[self.shared_at:]):
            self.table_share(sol, self.share.tolerance, refine=False)
        if self.share is not None:
            results["table_share"] = self.share.quantity()
        if not self.loops and self.share is None:
            return results
        p = interface_samples(sol, self.output.points_per_element)["pressure"]
        coef = self.table(np.asarray(p))
        results["interface_coefficients"] = {"contact_fraction": coef["contact_fraction"], "k_n0": coef["k_n0"]}
        results["table"] = self.table.as_dict()
        results["cell_solves"] = self.table.solves + (self.shear.solves if self.shear is not None else 0)
        if self.loops:
            results["mesh_levels"] = self.loops
        results["law"].update(law_record(PT.response_law(self.table)))
        return results


def couple(scene, problem, solve, **kw):
    """Run the loop of ``scene.two_scale`` from ``problem``; returns ``(solution, results)``
    (:func:`couple_loop` without its :class:`Relevel`)."""
    sol, res, _ = couple_loop(scene, problem, solve, **kw)
    return sol, res


#: how the cell solves of one table level run (:func:`executor_map`, or serially in tests)
MapTasks = Callable[[Callable[[float], PT.Response], Sequence[float]], list[PT.Response]]


def couple_loop(scene, problem, solve, map_tasks: MapTasks = executor_map,
                cache_dir: str | None = None, warm: bool = True, shear_map=shear_executor_map, safety=None):
    """Run the loop of ``scene.two_scale`` from ``problem``; returns ``(solution, results, relevel)``,
    ``relevel`` the loop on another macro mesh from the same tables (:class:`Relevel`).

    ``solve(problem, start)``: the macro solve (warm-started from the
    vector ``start`` when it is not None); ``map_tasks``: runs the cell
    solves of one table level (:class:`~ngcontact.coupling.pressure_table.CellTable`);
    ``warm = False`` cold-starts every macro solve (for comparisons); ``safety``: the strength check's safety
    factor, counted in the tables' share (:meth:`Relevel.table_share`).
    """
    from ngcontact.drivers.build import cell_scene_of
    spec = scene.two_scale
    path = resolve(scene, spec.cell)
    overrides = cell_links.overrides(scene.interface)
    keys = cell_discretization(spec)

    def of(p, o, m=None, d=None):
        return cell_scene_of(p, key="two_scale.cell", overrides=o, method=m, discretization=d)
    # the cell as the loop solves it, its method resolved once (an "auto" cell by fe where the shear table needs it)
    cell_scene = load_cell(of, path, spec.cell, overrides, spec, scene.interface.friction == "from_cell")
    method = cell_scene.discretization.method
    task = PressureSolve(path, spec.cell_length_unit, overrides, method, keys)
    key = table_key(cell_scene, spec.cell_length_unit, spec.table_tol)
    table, from_cache = cached_table(key, task, spec.table_tol, map_tasks, cache_dir, spec.max_cell_solves)
    shear, skey, shear_cached = None, None, False
    if scene.interface.friction == "from_cell" and cell_scene.contact.friction != "none":
        skey = shear_key(cell_scene, spec.cell_length_unit, spec.table_tol)
        shear_task = ShearSolve(path, spec.cell_length_unit, overrides, method, discretization=keys)
        shear, shear_cached = cached_shear(skey, shear_task, spec.table_tol, spec.cell_length_unit, shear_map,
                                           cache_dir, spec.max_cell_solves)
    out = T.couple(problem, table, tol=spec.tol, max_iter=spec.max_iter, table_min=spec.table_min,
                   points_per_element=scene.output.points_per_element, solve=solve, warm=warm, shear=shear)
    def write_back() -> None:
        if table.solves:
            store_table(key, table, cache_dir)
        if shear is not None and shear.solves and skey is not None:
            store_shear(skey, shear, cache_dir)
    write_back()
    p = interface_samples(out.solution, scene.output.points_per_element)["pressure"]
    coef = table(np.asarray(p))
    law = PT.response_law(table)
    res = {"converged": out.converged, "iterations": len(out.history) - 1, "macro_solves": out.macro_solves,
           "cell_solves": table.solves, "tolerance": spec.tol, "history": out.history,
           "newton_per_solve": [h["newton_iterations"] for h in out.history if h["law_changed"]],
           "table": table.as_dict(),
           "cache": {"key": key, "table_from_cache": from_cache,
                     "directory": cache_dir or cell_law.cache_dir_default()},
           "law": {"type": "tabulated cell response p(c)", **law_record(law)},
           "cell": {"scene": path, "method": task.method, **(task.size() if table.solves else {}),
                    "method_choice": cell_scene.method_choice.statement if cell_scene.method_choice else task.method,
                    "overrides": overrides, **({"discretization": keys} if keys else {})},
           "interface_coefficients": {"contact_fraction": coef["contact_fraction"], "k_n0": coef["k_n0"]}}
    if shear is not None:
        res["cell_solves"] += shear.solves
        res["shear_table"] = shear.as_dict()
        res["shear_table"]["cache"] = {"key": skey, "table_from_cache": shear_cached}
        res["law"]["tangential"] = "tabulated cell shear T(p, a_t) (the cell's own friction)"
    relevel = Relevel(scene, table, shear, solve, write_back)
    if scene.discretization.tolerance is None:
        return out.solution, res, relevel
    sol = relevel.table_share(out.solution, float(scene.discretization.tolerance), safety=safety)
    return sol, relevel.record(res, sol), relevel


def law_record(law) -> dict[str, Any]:
    """The report's record of the macro law ``p = P(c)`` of a cell table."""
    return {"interpolation": law.interpolation, "closure": list(law.closure), "pressure": list(law.pressure)}
