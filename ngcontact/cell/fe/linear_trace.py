"""Order-2 bodies with a linear trace on ``S_C``: exact contact in 3D beyond order 1.

Exact non-penetration on a 3D cell holds the multiplier at the vertices
of the triangles of ``S_C``, each with a third of the area of the
triangles around it (:mod:`ngcontact.cell.fe.contact_multiplier`).  That
node-to-node problem is well posed where the displacements' trace on
``S_C`` is linear on each triangle: the vertices then determine the trace,
non-penetration at the vertices is non-penetration of the trace's
interpolant, and no node inside a patch is left hanging open.  On a
quadratic trace it is not (corner nodes of quadratic triangles carry no
consistent force under a uniform pressure), which is why order 2 was
refused there.

The bodies' stiffness is another matter.  Order-1 tetrahedra are too stiff
(the contact patch of a Hertz-like summit comes out too small) and
converge only linearly in their size below the patch, so that the contact
fraction of an order-1 cell stalls at several per cent unless the bodies
are meshed as finely as the contact edge.

This module keeps both: the displacements are of order ``p = 2`` in the
bodies and of order 1 on ``S_C``.  In Netgen's hierarchical ``H1`` basis
an edge of order 1 carries no edge bubble, so lowering the order of every
edge of ``S_C`` (:func:`lower_trace`) makes the trace on ``S_C`` exactly the
linear interpolant of its vertex values while each tetrahedron keeps its
quadratic bubbles on its other edges; the space stays conforming (an edge
has one order for all elements around it).  Non-penetration is the
order-1 node-to-node problem unchanged (the multiplier of order 1,
``ContactMultiplier(mesh, 1)``); the bodies' approximation is quadratic
but in the layer of tetrahedra that touch ``S_C``, where it is quadratic
across the surface and linear along it.
"""
from __future__ import annotations

import ngsolve as ng

#: the order of the trace on ``S_C`` with exact contact on triangles: the multiplier's vertex rule
TRACE_ORDER = 1


def lower_trace(space: ng.FESpace, mesh: ng.Mesh, label: str = "contact", order: int = TRACE_ORDER) -> None:
    """Set the order of every edge and face of the boundary ``label`` of ``space`` (an ``H1`` or ``VectorH1``
    before any ``Periodic`` wrapper) to ``order`` and update it (module docstring)."""
    edges: set[int] = set()
    faces: set[int] = set()
    for el in mesh.Boundaries(label).Elements():
        edges.update(e.nr for e in el.edges)
        faces.update(f.nr for f in el.faces)
    for nr in edges:
        space.SetOrder(ng.NodeId(ng.EDGE, nr), order)
    for nr in faces:
        space.SetOrder(ng.NodeId(ng.FACE, nr), order)
    space.Update()


def trace_order(model, dim: int) -> int:
    """The order of the displacements' trace on ``S_C``: :data:`TRACE_ORDER` with exact contact on the
    triangles of a 3D cell and ``model.linear_trace``, else the displacement order."""
    if dim == 3 and model.enforcement == "exact" and getattr(model, "linear_trace", False):
        return min(TRACE_ORDER, model.order)
    return model.order
