"""The singular edges of a 3D macro solution's bodies: the 2D singular points' cases along edges.

Along an edge of a body's boundary the stress of linear elasticity near the edge is, to leading order,
the 2D wedge's in the plane normal to the edge (Grisvard 1985, the edge singularities of a polyhedron):
``d^(lambda - 1)`` or ``log d`` in the distance ``d`` to the edge, with ``lambda`` the eigenvalue of the
wedge of the two faces meeting there with their conditions.  So the cases of the singular points of a 2D
body (:mod:`ngcontact.macro.away_maxima`) carry over to edges of the mesh's boundary, found the same way
from the boundary labels, the supports, the loads and the solution, edge by edge of the boundary mesh:

* an edge where the interface meets a boundary without support while the interface is closed at the
  edge's middle (pressure above :data:`ngcontact.macro.singular_maxima.CLOSED` of its peak, at the
  nearest sample of :func:`ngcontact.macro.macro_measures.interface_surface`): the traction jumps there
  from the law's to none;
* an edge where a clamped boundary (a support of every component) meets a boundary without support or
  the interface (a clamped-free wedge of more than about 63 degrees has ``lambda < 1``);
* a re-entrant edge of a body: its interior dihedral angle there (the sum of its elements' dihedral
  angles at the edge, :func:`dihedral_angles`) exceeds ``pi`` by more than
  :data:`~ngcontact.macro.discretization_error.CORNER_ANGLE` where two boundary labels meet, by more than
  :data:`~ngcontact.macro.singular_maxima.SHARP` within one (the facets of a coarse mesh of a concave
  surface turn by less);
* an edge where a load with a traction (a tangential part) meets another boundary.

An edge on a face held normal to itself (a symmetry plane) and another face is a mirror, not an end, as
in 2D.  Vertices where singular edges meet are on those edges and so within their tubes; a conical
vertex not on any such edge is not detected.
"""
from __future__ import annotations

import math

import ngsolve as ng
import numpy as np

from ngcontact.fem.elasticity import COMPONENTS
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import singular_maxima as SM
from ngcontact.macro.macro_problem import MacroSolution
from ngcontact.macro.singular_set import SingularSet

#: the reasons, as the report says them
CLOSED_END = "the interface ends there closed"
CLAMPED = "a clamped boundary meets an unsupported one"
REENTRANT = "a re-entrant edge"
SHEAR_END = "a load with a traction ends there"

#: the local vertex pairs of a tetrahedron's six edges and the two vertices opposite each
TET_EDGES = ((0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2), (1, 2, 0, 3), (1, 3, 0, 2), (2, 3, 0, 1))


def boundary_edges(mesh: ng.Mesh) -> tuple[dict[tuple[int, int], set[str]], np.ndarray]:
    """Per edge of the boundary mesh (its two vertex numbers, the smaller first) the labels of the boundary
    elements that hold it (not those on faces inside one body,
    :func:`ngcontact.macro.discretization_error.internal_faces`), and every vertex's
    point."""
    labels: dict[tuple[int, int], set[str]] = {}
    inner = DE.internal_faces(mesh)
    for el in mesh.Elements(ng.BND):
        vs = [v.nr for v in el.vertices]
        if tuple(sorted(vs)) in inner:
            continue
        for k in range(len(vs)):
            a, b = vs[k - 1], vs[k]
            labels.setdefault((min(a, b), max(a, b)), set()).add(el.mat)
    return labels, np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])


def dihedral_angles(mesh: ng.Mesh, region: str, edges: set[tuple[int, int]]) -> dict[tuple[int, int], float]:
    """Per edge of ``edges`` the interior dihedral angle of body ``region`` there: the sum of the dihedral
    angles at that edge of the body's tetrahedra that hold it (``2 pi`` inside the body)."""
    pts = np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])
    tets = np.array([[v.nr for v in el.vertices] for el in mesh.Elements(ng.VOL)
                     if el.mat == region and len(el.vertices) == 4], dtype=int).reshape(-1, 4)
    out: dict[tuple[int, int], float] = {}
    for i, j, k, m in TET_EDGES:
        a, b = tets[:, i], tets[:, j]
        axis = pts[b] - pts[a]
        axis /= np.linalg.norm(axis, axis=1)[:, None]
        u, v = pts[tets[:, k]] - pts[a], pts[tets[:, m]] - pts[a]
        u -= (u * axis).sum(axis=1)[:, None] * axis
        v -= (v * axis).sum(axis=1)[:, None] * axis
        cos = (u * v).sum(axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        angle = np.arccos(np.clip(cos, -1.0, 1.0))
        for n in range(len(tets)):
            key = (int(min(a[n], b[n])), int(max(a[n], b[n])))
            if key in edges:
                out[key] = out.get(key, 0.0) + float(angle[n])
    return out


def closed_interface(sol: MacroSolution, labels: dict[tuple[int, int], set[str]], pts: np.ndarray
                     ) -> list[tuple[int, int]]:
    """The boundary edges where the interface meets a boundary without support and is closed at their
    middle (module docstring)."""
    p = sol.problem
    supported = {s.label for s in p.supports}
    ends = [e for e, names in labels.items()
            if p.interface in names and len(names) > 1 and not (names - {p.interface}) & supported]
    if not ends:
        return []
    surf = MM.interface_surface(sol)
    xyz = np.column_stack([surf["x"], surf["y"], surf["z"]])
    pressure = np.asarray(surf["pressure"], dtype=float)
    peak = float(pressure.max(initial=0.0))
    mids = np.array([(pts[a] + pts[b]) / 2.0 for a, b in ends])
    nearest = np.argmin(np.linalg.norm(xyz[None, :, :] - mids[:, None, :], axis=2), axis=1)
    return [e for e, k in zip(ends, nearest) if peak > 0 and pressure[k] > SM.CLOSED * peak]


def clamped(sol: MacroSolution, labels: dict[tuple[int, int], set[str]]) -> list[tuple[int, int]]:
    """The boundary edges where a clamped boundary meets a boundary without support or the interface."""
    p = sol.problem
    every = set(COMPONENTS[p.setting])
    held = {s.label for s in p.supports if not s.components or set(s.components) >= every}
    supported = {s.label for s in p.supports}
    return [e for e, names in labels.items() if names & held and names - supported]


def sheared(sol: MacroSolution, labels: dict[tuple[int, int], set[str]]) -> list[tuple[int, int]]:
    """The boundary edges where a load with a traction meets another boundary."""
    loaded = {load.label for load in sol.problem.loads if any(t != 0 for t in load.traction)}
    return [e for e, names in labels.items() if names & loaded and len(names) > 1]


def reentrant(sol: MacroSolution, labels: dict[tuple[int, int], set[str]]) -> list[tuple[int, int]]:
    """The boundary edges where a body's interior dihedral angle exceeds ``pi + CORNER_ANGLE`` between two
    labels, ``pi + SHARP`` within one."""
    p = sol.problem
    out = []
    for region in (p.rough, p.counter):
        angles = dihedral_angles(p.mesh, region, set(labels))
        out += [e for e, names in labels.items()
                if angles.get(e, 0.0) > math.pi + (DE.CORNER_ANGLE if len(names) > 1 else SM.SHARP)]
    return out


def singular_edges(sol: MacroSolution) -> SingularSet:
    """The singular edges of the module docstring (each segment once, with the first reason found)."""
    labels, pts = boundary_edges(sol.problem.mesh)
    found = [(e, CLOSED_END) for e in closed_interface(sol, labels, pts)]
    found += [(e, CLAMPED) for e in clamped(sol, labels)]
    found += [(e, REENTRANT) for e in reentrant(sol, labels)]
    found += [(e, SHEAR_END) for e in sheared(sol, labels)]
    seen: dict[tuple[int, int], str] = {}
    for e, reason in found:
        seen.setdefault(e, reason)
    edges = np.array([[pts[a], pts[b]] for a, b in seen]).reshape(-1, 2, 3)
    return SingularSet(np.zeros((0, 3)), (), edges, tuple(seen.values()))
