"""The loads of a cell solved on their own: members of a batch of independent solves.

A load sweep normally solves each load from the previous one's solution
(continuation, :meth:`ngcontact.cell.cell_solver.CellSolver.sweep`): the
loads are then a chain, and so is a frictional load path.  With
``load.independent = true`` every load starts from the unloaded cell (a
first load's start), so the answer of a load does not depend on the others
and the loads of the sweep are a batch (:mod:`ngcontact.parallel.executor`)
that runs on as many workers as there are.  A member receives the scene (a
frozen description), the load's index and whether to return its state; it
builds its own cell through the cell protocol (whichever method the scene
names) and returns plain data: the load's solution and, for the last load,
the cell's state (an FE cell's displacement vector, which the driver writes
to VTK).

The default accuracy (:func:`held`).  A scene that states no tolerance holds
its answer to :data:`ngcontact.cell.admissibility.DEFAULT_TOLERANCE`
(``discretization.estimate = "auto"`` or ``"estimate"``), whether its loads
are chained or independent: one scene, one accuracy and one verdict in the
report.  Independent loads are held to it one by one: each member holds its
own load as the method holds a sweep
(:meth:`~ngcontact.cell.cell_solver.CellSolver.default_accuracy` on that
load alone, where the method :meth:`~ngcontact.cell.cell_solver.CellSolver.holds_loads_alone`),
and the driver joins the members' refinements into the sweep's
(:func:`ngcontact.cell.cell_solver.joined`).  Why each member refines
itself rather than a discretization decided once for the scene and handed
to every member:

* it keeps the mode's promise: a load's answer does not depend on the other
  loads.  One discretization for the sweep is set by its worst load, so a
  load's answer would change with the loads posed beside it; a load refined
  on its own gives the same answer alone or in any sweep (the responses of a
  cell table are such loads);
* there is no one discretization to hand out where the refinement is each
  load's own: an FE cell's graded meshes follow the contact edges of their
  load, and its estimate (one order more on the same mesh) is the load's;
* deciding the discretization needs its estimate, hence the solves on every
  level: a decision before the batch would solve the whole refinement in one
  process (as the chained sweep does) and the batch would then repeat its
  finest level.  Members that refine themselves make the solves the chained
  refinement makes for their load (fewer where a load meets the tolerance on
  a coarser level than the sweep's worst load), on the run's workers; what
  they repeat is building the finer meshes and enriched spaces once per
  member instead of once per sweep.

Both modes thus reach the same default tolerance, and their answers agree
within their estimates (the chained sweep solves every load on the level of
its worst load, a member on its own load's).  The members of ``"estimate"``
keep the scene's discretization, so the last one returns its state as
without an estimate; under ``"auto"`` a load's refinement may leave the
scene's mesh, so the last load is held by the driver's own cell (its mesh,
fields and unknowns are the report's, as the chained refinement's last
level is).  ``discretization.estimate = "off"`` keeps the plain batch: one
solve per load.  The spectral cell holds a load alone too: its grid-doubling
estimate is per load already (:mod:`ngcontact.cell.spectral.refinement`), so
a member refines its own load's grids, and ``results.method`` gives the last
load's grid and levels with every load's under ``per_load``
(:func:`ngcontact.cell.cell_solver.joined`).  A method that cannot hold a load
alone (a spectral cell built without the recipe of finer grids) solves its
independent loads on the scene's discretization, not estimated.
"""
from __future__ import annotations

from typing import Any

from ngcontact.cell.cell_solution import CellSolution
from ngcontact.cell.cell_solver import CellSolver, Refinement, joined
from ngcontact.drivers.build import cell_loads, cell_solver
from ngcontact.parallel import executor


def load_member(job: tuple) -> tuple[CellSolution, Any]:
    """Member: load ``k`` of ``scene`` on a fresh cell; with ``state`` also the cell's state after it."""
    scene, k, state = job
    cell = cell_solver(scene)
    sol = cell.solve(cell_loads(scene)[k], first=True)
    return sol, (cell.state() if state else None)


def held_member(job: tuple) -> tuple[Refinement, Any]:
    """Member: load ``k`` of ``scene`` on a fresh cell held to ``tolerance`` on its own (module docstring);
    with ``state`` also the cell's state after it."""
    scene, k, state, tolerance = job
    cell = cell_solver(scene)
    return held_alone(cell, cell_loads(scene)[k], tolerance), (cell.state() if state else None)


def held_alone(cell: CellSolver, load, tolerance: float) -> Refinement:
    """``load`` alone on ``cell`` held to ``tolerance`` (a cell that :meth:`holds_loads_alone`)."""
    done = cell.default_accuracy(tolerance, [load])
    if done is None:
        raise RuntimeError("a cell that holds loads alone returned no refinement of its load")
    return done


def names(n: int) -> list[str]:
    return [f"load {k}" for k in range(n)]


def solve(scene, cell: CellSolver) -> list[CellSolution]:
    """Every load of the scene independently; ``cell`` (the driver's own) receives the last load's state."""
    n = len(cell_loads(scene))
    out = executor.current().map(load_member, [(scene, k, k == n - 1) for k in range(n)], names(n), label="loads")
    cell.set_state(out[-1][1])
    return [sol for sol, _ in out]


def held(scene, cell: CellSolver, tolerance: float) -> Refinement | None:
    """Every load of the scene independently, each held to the default ``tolerance`` on its own, joined into
    the sweep's refinement (module docstring); ``None`` where the method does not hold loads alone (then
    :func:`solve`).  ``cell`` (the driver's own) ends as the last load left it."""
    if not cell.holds_loads_alone():
        return None
    loads = cell_loads(scene)
    n = len(loads)
    own = cell.refines_by_default()       # the last load's refinement may leave the scene's mesh: solved here
    batch = n - 1 if own else n
    jobs = [(scene, k, k == n - 1, tolerance) for k in range(batch)]
    out = executor.current().map(held_member, jobs, names(batch), label="loads") if batch else []
    parts = [done for done, _ in out]
    if own:
        parts.append(held_alone(cell, loads[-1], tolerance))
    else:
        cell.set_state(out[-1][1])
    return joined(parts)
