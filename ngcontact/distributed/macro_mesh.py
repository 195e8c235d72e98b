"""A macro mesh made on rank 0, distributed over the MPI ranks, and a solution gathered back to rank 0.

NGSolve distributes a Netgen mesh (``Mesh.Distribute``: METIS partitions
the elements; rank 0 keeps none), optionally refined uniformly on the
ranks; the spaces, forms and vectors built on the
distributed mesh are then assembled and solved in parallel (each rank its
elements, the interface law's energy included: a local law on a fixed
interface needs no search across ranks).  The geometry travels with the
mesh, so that every rank curves its elements as the whole mesh was curved.

For the strength check alone (which samples the whole stress field) rank 0
keeps its whole mesh and the solution comes back to it element by element:
every rank sends, per element, its vertices' coordinates and its dofs'
values; rank 0 finds each element of its own (whole, undistributed) copy by
those coordinates and puts the values on the same element's dofs.  Rank 0
then checks the strength on the whole mesh exactly as one process does.
"""
from __future__ import annotations

import pickle
from dataclasses import replace

import netgen.meshing
import ngsolve as ng
import numpy as np
from scipy.spatial import cKDTree

from ngcontact.distributed.boundary_numbers import Coarse, numbered
from ngcontact.distributed.world import World


def distribute(geometry, order: int, refinements: int, world: World, *, keep: bool = False):
    """``geometry`` (a ``MacroGeometry`` with straight elements on rank 0, ``None`` elsewhere) distributed,
    refined uniformly ``refinements`` times on the ranks and curved to ``order``.

    Rank 0 meshes with straight elements (a mesh curved before it is
    distributed does not distribute) and distributes a copy (the part a
    distributed original leaves on rank 0 does not refine); the caller lets
    the whole mesh go afterwards unless ``keep`` (the strength check gathers
    the solution onto it).  Every rank refines
    its part with Netgen's uniform refinement
    (:func:`ngcontact.drivers.macro_geometry.refined_uniformly`; NGSolve's
    bisection ``Mesh.Refine`` does not number the dofs of a distributed mesh
    consistently) and curves it to ``order`` from the geometry sent with the
    mesh, as one process refines and curves the whole mesh.

    Returns the distributed geometry and every rank's
    :class:`~ngcontact.distributed.boundary_numbers.BoundaryNumbers`.
    """
    comm = world.comm
    coarse = None
    if world.root:
        ngmesh = geometry.mesh.ngmesh
        shape, meta = ngmesh.GetGeometry(), replace(geometry, mesh=None)
        comm.bcast(pickle.dumps((shape, meta)))
        coarse = Coarse.of(geometry.mesh)
        part = ngmesh.Copy().Distribute(comm)
        del ngmesh
    else:
        shape, meta = pickle.loads(comm.bcast(None))
        part = netgen.meshing.Mesh.Receive(comm)
        if shape is not None:
            part.SetGeometry(shape)
    numbers = numbered(world, ng.Mesh(part), coarse)
    del coarse
    for _ in range(refinements):
        part.Refine()
        numbers = numbers.refined(part.dim, len(part.Elements2D() if part.dim == 3 else part.Elements1D()))
    mesh = ng.Mesh(part)
    if order > 1 and shape is not None:
        mesh.Curve(order)
    return replace(meta, mesh=mesh), numbers


def _elements(mesh: ng.Mesh, space, vec) -> tuple[np.ndarray, list[np.ndarray]]:
    """Per volume element: its vertices' coordinates (rows) and its dofs' values in ``vec``."""
    values = vec.FV().NumPy()
    points, dofs = [], []
    for el in mesh.Elements(ng.VOL):
        points.append(np.concatenate([mesh[v].point for v in el.vertices]))
        nrs = np.asarray([d for d in space.GetDofNrs(el)], dtype=int)
        dofs.append(nrs)
    data = [np.where(d >= 0, values[np.maximum(d, 0)], 0.0) for d in dofs]
    width = max((len(p) for p in points), default=0)
    coords = np.full((len(points), width), np.nan)
    for i, p in enumerate(points):
        coords[i, :len(p)] = p
    return coords, data


def gather(world: World, local: ng.GridFunction, whole: ng.GridFunction | None) -> None:
    """Copy the distributed ``local`` into ``whole``, the same space on rank 0's whole mesh.

    Raises ``ValueError`` on rank 0 where an element of a rank has no
    counterpart in the whole mesh, or where their dofs differ in number.
    """
    local.vec.Cumulate()
    coords, data = _elements(local.space.mesh, local.space, local.vec)
    parts = world.comm.gather((coords, data), root=0)
    if not world.root:
        return
    assert whole is not None
    space, mesh = whole.space, whole.space.mesh
    elements = list(mesh.Elements(ng.VOL))
    mine, _ = _elements(mesh, space, whole.vec)
    tree = cKDTree(np.nan_to_num(mine, nan=0.0))
    out = whole.vec.FV().NumPy()
    scale = float(np.nanmax(np.abs(mine))) if mine.size else 1.0
    for coords, data in parts:
        if not len(data):
            continue
        dist, at = tree.query(np.nan_to_num(coords, nan=0.0))
        if np.any(dist > 1e-9 * scale):
            raise ValueError("gathering the solution: an element of a rank is not in rank 0's mesh")
        for k, values in zip(at, data):
            nrs = np.asarray([d for d in space.GetDofNrs(elements[k])], dtype=int)
            if len(nrs) != len(values):
                raise ValueError("gathering the solution: an element's dofs differ between a rank and rank 0")
            keep = nrs >= 0
            out[nrs[keep]] = values[keep]
