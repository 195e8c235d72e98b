"""Where each boundary element of a rank's part stands in the whole mesh that one process makes.

Rank 0 lists the mid-points of the boundary elements of the whole mesh
before it is distributed (a surface's worth of numbers, not the mesh);
after the distribution every rank finds its own boundary elements among
them by their mid-points (the vertices travel unchanged), and rank 0 lets
the list go.  These serial numbers put the interface's samples, gathered
from the ranks, into the order of one process
(:mod:`ngcontact.distributed.reduced_measures`).

A uniform refinement of the parts (Netgen's ``Mesh.Refine``, see
:func:`ngcontact.drivers.macro_geometry.refined_uniformly`) numbers its
children as it does in one process: boundary element ``i`` of ``n`` keeps
its first child at ``i`` and puts its other ``c - 1`` children (``c = 4``
triangles of a triangle, ``c = 2`` segments of a segment) at
``n + (c - 1) i + j``, ``j = 0 .. c - 2``.  The same map applied to a
rank's local numbers and to the serial numbers carries the serial numbers
through the refinements, so that a mesh refined on the ranks reports its
interface in the order of the same mesh refined in one process, although no
rank ever holds it whole.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import ngsolve as ng
import numpy as np
from scipy.spatial import cKDTree

from ngcontact.distributed.world import World


def midpoints(mesh: ng.Mesh) -> np.ndarray:
    """The mid-point of the vertices of every boundary element of ``mesh`` (this rank's part), in its order."""
    rows = [np.mean([mesh[v].point for v in el.vertices], axis=0) for el in mesh.Elements(ng.BND)]
    return np.asarray(rows, dtype=float).reshape(-1, mesh.dim)


@dataclass(frozen=True)
class Coarse:
    """What rank 0 keeps of the whole mesh before distributing it: its boundary elements' mid-points and the
    number of boundary elements of every label."""

    points: np.ndarray
    labels: dict[str, int]

    @staticmethod
    def of(mesh: ng.Mesh) -> "Coarse":
        return Coarse(points=midpoints(mesh), labels=dict(Counter(el.mat for el in mesh.Elements(ng.BND))))


@dataclass(frozen=True)
class BoundaryNumbers:
    """``serial``: for each boundary element of this rank's part (in its order) its number in the whole mesh;
    ``labels``: the whole mesh's number of boundary elements of every label."""

    serial: np.ndarray
    labels: dict[str, int]

    def of(self, mesh: ng.Mesh, label: str) -> np.ndarray:
        """The serial numbers of this rank's boundary elements ``label``, in the order of its part."""
        mine = np.array([el.mat == label for el in mesh.Elements(ng.BND)], dtype=bool)
        return self.serial[mine] if len(mine) else self.serial[:0]

    def refined(self, dim: int, count: int) -> "BoundaryNumbers":
        """The numbers after one uniform refinement of a mesh of dimension ``dim`` (module docstring); ``count``:
        this rank's boundary elements after it."""
        c = 4 if dim == 3 else 2
        n = len(self.serial)
        if count != c * n:
            raise ValueError(f"a uniform refinement made {count} boundary elements of {n}, not {c * n}")
        total = sum(self.labels.values())
        parent, j = np.divmod(np.arange(n * (c - 1)), c - 1)
        serial = np.concatenate([self.serial, total + (c - 1) * self.serial[parent] + j])
        return BoundaryNumbers(serial=serial, labels={k: c * v for k, v in self.labels.items()})


def numbered(world: World, mesh: ng.Mesh, coarse: Coarse | None) -> BoundaryNumbers:
    """Every rank's serial numbers of its part ``mesh`` of the distributed mesh, found by mid-point in rank 0's
    ``coarse`` (``None`` on the other ranks).

    Raises ``ValueError`` on every rank where a rank's boundary element is not in the whole mesh.
    """
    parts = world.comm.gather(midpoints(mesh), root=0)
    answers = head = None
    if world.root:
        assert coarse is not None and parts is not None
        tree = cKDTree(coarse.points)
        scale = float(np.max(np.abs(coarse.points))) if coarse.points.size else 1.0
        answers, lost = [], 0
        for points in parts:
            dist, at = tree.query(points) if len(points) else (np.zeros(0), np.zeros(0, dtype=int))
            lost += int(np.count_nonzero(dist > 1e-9 * scale))
            answers.append(np.asarray(at, dtype=np.int64))
        head = (coarse.labels, lost)
    serial = world.comm.scatter(answers, root=0)
    labels, lost = world.comm.bcast(head, root=0)
    if lost:       # raised on every rank alike
        raise ValueError(f"numbering the boundary: {lost} boundary elements of the ranks are not in rank 0's mesh")
    return BoundaryNumbers(serial=serial, labels=labels)
