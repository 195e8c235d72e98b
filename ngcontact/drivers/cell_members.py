"""The loads of a cell solved on their own: members of a batch of independent solves.

A load sweep normally solves each load from the previous one's solution
(continuation, :meth:`ngcontact.cell.cell_problem.CellProblem.sweep`): the
loads are then a chain, and so is a frictional load path.  With
``load.independent = true`` every load starts from the unloaded cell (FE:
a first load's start, rigid or spectral; spectral cell: no pressure), so the
answer of a load does not depend on the others and the loads of the sweep
are a batch (:mod:`ngcontact.parallel.executor`) that runs on as many workers
as there are.  A member receives the scene (a frozen description) and the
load's index, builds its own mesh or grid, and returns plain data: the
load's solution (numbers and arrays) and, for the last load of an FE sweep,
the displacement vector the driver writes to VTK.
"""
from __future__ import annotations

import numpy as np

from ngcontact.cell.cell_model import CellSolution
from ngcontact.cell.cell_problem import CellProblem
from ngcontact.cell.spectral_cell import SpectralSolution
from ngcontact.drivers.build import cell_loads, cell_problem, spectral_cell
from ngcontact.parallel import executor


def fe_problem(scene) -> CellProblem:
    """The FE cell problem of a cell scene (mesh, spaces, forms), before any load."""
    return cell_problem(scene)


def fe_load(job: tuple) -> tuple[CellSolution, np.ndarray | None]:
    """Member: load ``k`` of ``scene`` on a fresh FE cell; with ``state`` also the solution vector."""
    scene, k, state = job
    problem = fe_problem(scene)
    sol = problem.solve(cell_loads(scene)[k], first=True)
    return sol, (problem.gfu.vec.FV().NumPy().copy() if state else None)


def spectral_load(job: tuple) -> SpectralSolution:
    """Member: load ``k`` of ``scene`` on a fresh spectral cell, from zero pressure."""
    scene, k = job
    return spectral_cell(scene).solve(cell_loads(scene)[k])


def names(n: int) -> list[str]:
    return [f"load {k}" for k in range(n)]


def solve_fe(scene, problem: CellProblem) -> list[CellSolution]:
    """Every load of the scene independently; ``problem`` (the driver's own) receives the last load's state."""
    n = len(cell_loads(scene))
    out = executor.current().map(fe_load, [(scene, k, k == n - 1) for k in range(n)], names(n), label="loads")
    state = out[-1][1]
    vec = problem.gfu.vec.FV().NumPy()
    if state is None or len(state) != len(vec):
        raise RuntimeError(f"a worker's cell has {0 if state is None else len(state)} dofs, this one {len(vec)}: "
                           "the mesh was not rebuilt identically")
    vec[:] = state
    return [sol for sol, _ in out]


def solve_spectral(scene) -> list[SpectralSolution]:
    """Every load of the scene independently on the spectral cell."""
    n = len(cell_loads(scene))
    return executor.current().map(spectral_load, [(scene, k) for k in range(n)], names(n), label="loads")
