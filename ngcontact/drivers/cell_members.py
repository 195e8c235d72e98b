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
"""
from __future__ import annotations

from typing import Any

from ngcontact.cell.cell_solution import CellSolution
from ngcontact.cell.cell_solver import CellSolver
from ngcontact.drivers.build import cell_loads, cell_solver
from ngcontact.parallel import executor


def load_member(job: tuple) -> tuple[CellSolution, Any]:
    """Member: load ``k`` of ``scene`` on a fresh cell; with ``state`` also the cell's state after it."""
    scene, k, state = job
    cell = cell_solver(scene)
    sol = cell.solve(cell_loads(scene)[k], first=True)
    return sol, (cell.state() if state else None)


def names(n: int) -> list[str]:
    return [f"load {k}" for k in range(n)]


def solve(scene, cell: CellSolver) -> list[CellSolution]:
    """Every load of the scene independently; ``cell`` (the driver's own) receives the last load's state."""
    n = len(cell_loads(scene))
    out = executor.current().map(load_member, [(scene, k, k == n - 1) for k in range(n)], names(n), label="loads")
    cell.set_state(out[-1][1])
    return [sol for sol, _ in out]
