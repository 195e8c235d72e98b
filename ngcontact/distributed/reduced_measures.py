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
  each rank's interface elements with the mid-point of their vertices,
  gathered on rank 0, put into the order of rank 0's whole mesh (the same
  element has the same mid-point there) and sent to every rank, so that the
  table, the peaks and the states are those of one process;
* a figure's samples: gathered on rank 0 only, which draws.

The moment of a support fixing every component (plane strain) is taken
about the mid-point of its boundary, read off rank 0's whole mesh.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np
from scipy.spatial import cKDTree

from ngcontact.distributed.world import World
from ngcontact.fem.reaction import boundary_centre
from ngcontact.macro import macro_measures as MM
from ngcontact.macro.macro_problem import MacroSolution
from ngcontact.macro.solution_measures import Measures, Samples, reactions_of


def element_keys(mesh, label: str) -> np.ndarray:
    """The mid-point of the vertices of every boundary element ``label`` of ``mesh`` (this rank's), in order."""
    rows = [np.mean([mesh[v].point for v in el.vertices], axis=0)
            for el in mesh.Elements(ng.BND) if el.mat == label]
    return np.asarray(rows, dtype=float).reshape(-1, mesh.dim)


class Reduced(Measures):
    """The measures over ``world``'s ranks; ``whole``: rank 0's whole mesh (``None`` on the others)."""

    def __init__(self, world: World, whole: ng.Mesh | None):
        self.world = world
        self.whole = whole
        self.draws = world.root

    def _sum(self, value: float) -> float:
        return float(self.world.comm.allreduce(value))

    def equilibrium(self, sol: MacroSolution) -> dict:
        return MM.equilibrium(sol, total=self._sum)

    def extrema(self, sol: MacroSolution, fields: dict) -> dict:
        return MM.field_extrema(sol, fields, candidates=lambda mine: [
            c for part in self.world.comm.allgather(mine) for c in part])

    def reactions(self, sol: MacroSolution) -> dict:
        centres = None
        if self.world.root:
            assert self.whole is not None
            p = sol.problem
            centres = {s.label: boundary_centre(self.whole, s.label) for s in p.supports
                       if p.setting == "plane_strain" and not s.components}
        return reactions_of(sol, self.world.comm.bcast(centres))

    def _ordered(self, sol: MacroSolution, rows: np.ndarray) -> np.ndarray:
        """Every rank's interface samples ``rows`` (one block per element) in rank 0's element order, on
        every rank."""
        label = sol.problem.interface
        keys = element_keys(sol.problem.mesh, label)
        if len(rows) != len(keys):
            raise ValueError(f"interface samples of {len(rows)} elements for {len(keys)} interface elements")
        parts = self.world.comm.gather((keys, rows), root=0)
        whole = None
        if self.world.root:
            assert self.whole is not None and parts is not None
            mine = element_keys(self.whole, label)
            whole = np.full((len(mine),) + rows.shape[1:], np.nan)
            tree = cKDTree(mine)
            scale = float(np.max(np.abs(mine))) if mine.size else 1.0
            for keys_r, rows_r in parts:
                if not len(keys_r):
                    continue
                dist, at = tree.query(keys_r)
                if np.any(dist > 1e-9 * scale):
                    raise ValueError("an interface element of a rank is not in rank 0's mesh")
                whole[at] = rows_r
            if np.isnan(whole).any():
                raise ValueError("an interface element of rank 0's mesh is on no rank")
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
