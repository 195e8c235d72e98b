"""The measures of a macro solution on a mesh distributed over MPI ranks, reduced over the ranks.

Every rank measures its own elements and the ranks combine their parts
(:class:`~ngcontact.macro.solution_measures.Measures`), so that no rank needs
the whole solution:

* integrals (resultant, mean pressure, contact area, reactions, the
  interface force of the equilibrium check): NGSolve sums them over the
  ranks of the mesh;
* the equilibrium check's tests of the residual with rigid translations
  (paper eq. 8): each rank's dot products of its part of the residual with
  the test field, summed (:func:`ngcontact.macro.macro_measures.equilibrium`);
* the largest and smallest stresses: each rank's candidates, the first best
  of all kept in the order of the ranks;
* the interface's samples (a surface: far fewer numbers than the solution):
  each rank's interface elements with their numbers in the whole mesh
  (:mod:`ngcontact.distributed.boundary_numbers`), gathered on rank 0, put
  into that order and sent to every rank, so that the table, the peaks and
  the states are those of one process;
* a figure's samples: gathered on rank 0 only, which draws.

The moment of a support fixing every component (plane strain) is taken
about the mid-point of its boundary's bounding box, the smallest and
largest coordinates of its vertices over the ranks.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.distributed.boundary_numbers import BoundaryNumbers
from ngcontact.distributed.world import World
from ngcontact.macro import macro_measures as MM
from ngcontact.macro.macro_problem import MacroSolution
from ngcontact.macro.solution_measures import Measures, Samples, reactions_of


def boundary_box(world: World, mesh, label: str) -> tuple[np.ndarray, np.ndarray]:
    """The smallest and largest coordinates of the vertices of boundary ``label`` over the ranks' parts."""
    pts = np.asarray([mesh[v].point for el in mesh.Elements(ng.BND) if el.mat == label for v in el.vertices],
                     dtype=float).reshape(-1, mesh.dim)
    lo = pts.min(axis=0) if len(pts) else np.full(mesh.dim, np.inf)
    hi = pts.max(axis=0) if len(pts) else np.full(mesh.dim, -np.inf)
    return (np.min(np.asarray(world.comm.allgather(lo)), axis=0),
            np.max(np.asarray(world.comm.allgather(hi)), axis=0))


def boundary_mid(world: World, mesh, label: str, axis: int) -> float:
    """Mid-point of boundary ``label``'s extent along axis ``axis`` over the ranks
    (:func:`ngcontact.fem.two_body.boundary_mid` of the whole mesh)."""
    lo, hi = boundary_box(world, mesh, label)
    return float(0.5 * (lo[axis] + hi[axis]))


class Reduced(Measures):
    """The measures over ``world``'s ranks; ``numbers``: this rank's boundary elements' numbers in the whole
    mesh."""

    def __init__(self, world: World, numbers: BoundaryNumbers):
        self.world = world
        self.numbers = numbers
        self.draws = world.root

    def _sum(self, value: float) -> float:
        return float(self.world.comm.allreduce(value))

    def equilibrium(self, sol: MacroSolution) -> dict:
        return MM.equilibrium(sol, total=self._sum)

    def extrema(self, sol: MacroSolution, fields: dict) -> dict:
        return MM.field_extrema(sol, fields, candidates=lambda mine: [
            c for part in self.world.comm.allgather(mine) for c in part])

    def reactions(self, sol: MacroSolution) -> dict:
        p = sol.problem
        centres = {}
        for s in p.supports:
            if p.setting == "plane_strain" and not s.components:
                lo, hi = boundary_box(self.world, p.mesh, s.label)
                centres[s.label] = tuple(float(0.5 * (a + b)) for a, b in zip(lo, hi))
        return reactions_of(sol, centres)

    def _ordered(self, sol: MacroSolution, rows: np.ndarray) -> np.ndarray:
        """Every rank's interface samples ``rows`` (one block per element) in the whole mesh's element order,
        on every rank."""
        label = sol.problem.interface
        numbers = self.numbers.of(sol.problem.mesh, label)
        if len(rows) != len(numbers):
            raise ValueError(f"interface samples of {len(rows)} elements for {len(numbers)} interface elements")
        parts = self.world.comm.gather((numbers, rows), root=0)
        whole = None
        if self.world.root:
            assert parts is not None
            every = np.unique(np.concatenate([n for n, _ in parts]))
            if len(every) != self.numbers.labels.get(label, 0):
                raise ValueError(f"{len(every)} of the whole mesh's {self.numbers.labels.get(label, 0)} interface "
                                 "elements are on the ranks")
            whole = np.full((len(every),) + rows.shape[1:], np.nan)
            for numbers_r, rows_r in parts:
                whole[np.searchsorted(every, numbers_r)] = rows_r
        return self.world.comm.bcast(whole)

    def surface(self, sol: MacroSolution) -> dict:
        n = len(MM.SURFACE_POINTS)
        rows = MM.surface_rows(sol)
        ordered = self._ordered(sol, rows.reshape(-1, n, rows.shape[1]))
        return MM.surface_of(sol, ordered.reshape(-1, rows.shape[1]))

    def profile(self, sol: MacroSolution, points_per_element: int) -> dict:
        return MM.profile_of(sol, self._ordered(sol, MM.profile_rows(sol, points_per_element)))

    def samples(self, sample: Samples, sol: MacroSolution, fields: dict) -> dict:
        mine = sample(sol, fields) if sol.problem.mesh.ne else None
        parts = [p for p in (self.world.comm.gather(mine, root=0) or []) if p is not None]
        if not parts:
            return {"x": np.zeros(0), "y": np.zeros(0), "triangles": np.zeros((0, 3), dtype=int), "values": {},
                    "axisymmetric": False}
        x = np.concatenate([p["x"] for p in parts])
        return {"x": x, "y": np.concatenate([p["y"] for p in parts]),
                "triangles": np.arange(len(x)).reshape(-1, 3),
                "values": {n: np.concatenate([p["values"][n] for p in parts]) for n in parts[0]["values"]},
                "axisymmetric": parts[0]["axisymmetric"]}
