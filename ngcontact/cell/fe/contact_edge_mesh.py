"""The 3D small-slope cell meshed finely along a predicted contact edge (Netgen's restricted local mesh size).

Why the edge.  On a small-slope 3D cell (the flat cell of
:func:`ngcontact.geometry.cell3d.flat_cell3d` with the initial gap ``g0``,
paper eqs. 49-51 with exact non-penetration) the contact set at light
loads is a few Hertz-like patches, a fraction of the cell wide.  A uniform
interface mesh spends nearly all of its elements on open surface: the
patch of the bisinusoid at a tenth of its full-contact pressure is about
ten interface elements across at ``interface_maxh = 0.02``.  What the
contact fraction needs is the edge resolved: the pressure is a square root
inside it and the opening a ``3/2`` power outside it (the Hertz edge), and
the node-based real contact set of exact enforcement
(:mod:`ngcontact.cell.fe.exact_contact_set`) places the edge inside the
element that straddles it from those two asymptotics, an error of a part
of the element size at the edge.

The prediction.  The spectral twin (the same layers and gap on a periodic
grid, whose solution's pressure field the caller passes in) gives the
contact set in a fraction of the FE solve: its edge points (:func:`edge_points`) are
the midpoints between a grid point carrying pressure and a neighbour that
does not, within half a grid spacing of the twin's own edge.

The mesh (:func:`edge_refined_cell`).  Netgen's mesh size is restricted to
``edge_maxh`` at each edge point on ``S_C`` (``MeshingParameters.RestrictH``)
and grows from there at Netgen's grading rate to ``interface_maxh`` on the
rest of ``S_C`` and ``maxh`` in the bodies, so the dofs go where the
contact fraction's error is made, and the bodies below the patch (depth of
the order of its radius, where the Hertz field decays) are refined with it.
The restriction is applied on both sides of the periodic faces alike (the
twin's grid is periodic), so the identified faces mesh the same.

The bodies below the patch (:class:`PatchBody`, :func:`patch_body`).  With
order-1 bodies the edge refinement alone leaves the bodies' stiffness
error: order-1 tetrahedra are too stiff, the patch comes out too small,
and that error falls with the body's element size below the patch, not
with the edge's (the Hertz field decays over a depth of the order of the
patch radius ``a``).  A :class:`PatchBody` restricts the mesh size to
``maxh`` at the twin's contact points (its grid points carrying pressure,
thinned to about one per ``maxh``) on ``S_C`` and at the same points in
layers ``LAYER_SPACING * maxh`` apart down into the rough body and up
into the counter body to ``depth``; Netgen's grading fills between the
layers.  The sizes scale with ``a``: the error of the contact fraction is
a function of ``edge_maxh / a``, ``maxh / a`` and ``depth / a`` (the
bisinusoid's figures: docs/benchmarks.md, section ``scaling_3d``).  Order-2
bodies on a linear trace on ``S_C`` (:mod:`ngcontact.cell.fe.linear_trace`)
are the other way to lower the bodies' error; what is left then is the
node-to-node contact set's own error, the contact edge placed within a
part of ``edge_maxh`` (:mod:`ngcontact.cell.fe.exact_contact_set`), which
falls with ``edge_maxh``.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import ngsolve as ng
from netgen.meshing import MeshingParameters

from ngcontact.errors import GeometryError
from ngcontact.geometry import cell3d
from ngcontact.geometry.cell2d import Cell, periodic_maxh

log = logging.getLogger(__name__)

#: distance of the layers of a :class:`PatchBody` restriction, in its element sizes
LAYER_SPACING = 3.0
#: Netgen's grading (its default): how fast the size may grow away from a restricted point
GRADING = 0.3
#: points of a restriction closer than this (relative to the period) to a periodic face are moved off it
FACE_CLEARANCE = 1e-6


def edge_points(pressure: np.ndarray, period: float) -> np.ndarray:
    """Points ``(x, y)`` on the contact edges of a periodic ``n_y x n_x`` pressure grid (module docstring).

    ``pressure[i, j]`` is the pressure at ``x = j P/n_x``, ``y = i P/n_y``.  An edge point is the midpoint
    between two neighbours along ``x`` or ``y`` (periodically) of which one carries pressure (``> 0``) and
    the other does not.  Returns an array of shape ``(m, 2)``, empty where the contact set has no edge.
    """
    p = np.asarray(pressure, float)
    if p.ndim != 2:
        raise ValueError(f"pressure has shape {p.shape}: a 2D grid of a 3D cell is needed")
    ny, nx = p.shape
    on = p > 0.0
    out = []
    for axis, n in ((1, nx), (0, ny)):
        cut = on != np.roll(on, -1, axis=axis)
        i, j = np.nonzero(cut)
        x = (j + (0.5 if axis == 1 else 0.0)) * period / nx
        y = (i + (0.5 if axis == 0 else 0.0)) * period / ny
        out.append(np.stack((x, y), axis=1))
    return np.concatenate(out) if out else np.empty((0, 2))


@dataclass(frozen=True)
class PatchBody:
    """The bodies below and above the contact patches meshed at ``maxh`` to ``depth`` (module docstring).

    ``points``: ``(m, 2)`` points ``(x, y)`` of the patches on ``S_C``.  ``growth``: the size at depth ``|z|``
    is ``maxh + growth |z|`` (``0``: ``maxh`` at every depth), graded like the Hertz field's gradient, which
    falls with the distance from the patch.
    """

    points: np.ndarray
    maxh: float
    depth: float
    growth: float = 0.0

    def __post_init__(self):
        if not (np.isfinite(self.maxh) and self.maxh > 0):
            raise GeometryError("body maxh", self.maxh, "must be > 0")
        if not (np.isfinite(self.depth) and self.depth >= 0):
            raise GeometryError("body depth", self.depth, "must be >= 0")
        if not (np.isfinite(self.growth) and self.growth >= 0):
            raise GeometryError("body growth", self.growth, "must be >= 0")

    def size(self, z) -> np.ndarray:
        """The element size at height ``z``: ``maxh + growth |z|``."""
        return self.maxh + self.growth * np.abs(np.asarray(z, float))

    def heights(self) -> np.ndarray:
        """The ``z`` of the layers: ``0`` and ``+-z_k`` up to ``depth``, ``z_(k+1) = z_k + LAYER_SPACING
        size(z_k)`` (:meth:`size`; evenly ``LAYER_SPACING maxh`` apart without growth)."""
        z: list[float] = []
        at = LAYER_SPACING * self.maxh
        while at <= self.depth * (1.0 + 1e-9):
            z.append(at)
            at += LAYER_SPACING * float(self.size(at))
        zz = np.array(z)
        return np.concatenate(([0.0], -zz, zz))


def patch_body(pressure: np.ndarray, period: float, *, maxh: float, depth: float,
               growth: float = 0.0) -> PatchBody:
    """A :class:`PatchBody` on the contact points of a periodic ``n_y x n_x`` pressure grid (as for
    :func:`edge_points`): the grid points carrying pressure, every ``s``-th along each axis with ``s`` the
    grid steps in ``maxh`` (at least 1); ``growth`` as for :class:`PatchBody`."""
    p = np.asarray(pressure, float)
    if p.ndim != 2:
        raise ValueError(f"pressure has shape {p.shape}: a 2D grid of a 3D cell is needed")
    ny, nx = p.shape
    stride = max(1, int(maxh * min(nx, ny) / period))
    i, j = np.nonzero(p > 0.0)
    keep = (i % stride == 0) & (j % stride == 0)
    pts = np.stack((j[keep] * period / nx, i[keep] * period / ny), axis=1)
    return PatchBody(points=pts, maxh=float(maxh), depth=float(depth), growth=float(growth))


def patch_radius(pressure: np.ndarray, period: float) -> float:
    """``a = P sqrt(f / pi)``: the radius of one round patch of the grid's contact fraction ``f`` (the
    length the sizes of :func:`edge_refined_cell` scale with on a cell of one patch, module docstring)."""
    return float(period) * float(np.sqrt(np.mean(np.asarray(pressure) > 0.0) / np.pi))


def patch_length(pressure: np.ndarray, period: float) -> float | None:
    """``l = 2 A / L``: the length the contact set of a periodic ``n x n`` pressure grid is wide, from its area
    ``A`` (the grid points carrying pressure) and its edges' length ``L`` (``None`` without an edge).

    ``l`` is the radius of a round patch (``2 pi a^2 / 2 pi a``) and the width of a strip, and a set of many
    patches has the ``l`` of their sizes weighted by their edges.  An edge displaced by ``delta`` moves the
    contact fraction by ``L delta / P^2``, its relative error is ``delta L / A = 2 delta / l``: an element
    size at the edge that is a fixed part of ``l`` gives a contact fraction of a fixed relative accuracy,
    whatever the load.  ``L`` is counted from the edge points (:func:`edge_points`): a curve of length ``L``
    crosses the grid lines ``L (|n_x| + |n_y|) / Delta`` times, and ``|n_x| + |n_y|`` has the mean ``4 / pi``
    over the directions of a closed convex curve, so ``L = (pi / 4) m Delta`` from ``m`` crossings."""
    p = np.asarray(pressure, float)
    crossings = len(edge_points(p, period))
    if crossings == 0:
        return None
    area = float(np.mean(p > 0.0)) * period ** 2
    return 2.0 * area / (0.25 * np.pi * crossings * period / p.shape[1])


def edge_refined_cell(points: np.ndarray, *, edge_maxh: float, period: float = 1.0, h_rough: float = 1.0,
                      h_counter: float = 1.0, maxh: float, interface_maxh: float,
                      body: PatchBody | None = None, symmetric: bool = False, grading: float = GRADING) -> Cell:
    """The flat periodic 3D cell (:func:`~ngcontact.geometry.cell3d.flat_cell3d`) with its mesh size
    restricted to ``edge_maxh`` at ``points`` on ``S_C`` (module docstring).

    Parameters
    ----------
    points
        ``(m, 2)`` edge points ``(x, y)`` in ``[0, P)^2`` (:func:`edge_points`); none: the uniform cell.
    edge_maxh
        Element size at the edge points (``<= interface_maxh``).
    period, h_rough, h_counter, maxh, interface_maxh
        As for :func:`~ngcontact.geometry.cell3d.flat_cell3d`.
    body
        The bodies below and above the patches refined too (:class:`PatchBody`), or ``None``.
    symmetric
        Mesh the quarter ``[0, P/2]^2`` between mirror planes (:mod:`ngcontact.geometry.cell3d`): the points
        of the period are folded into it (:func:`fold_quarter`).
    grading
        Netgen's grading ``gamma``: the size grows at most like ``edge_maxh + gamma r`` with the distance ``r``
        from the edge points (in ``(0, 1]``; :data:`GRADING`, Netgen's default, where not given).
    """
    if not (np.isfinite(grading) and 0 < grading <= 1):
        raise GeometryError("grading", grading, "must be in (0, 1]")
    if not (np.isfinite(edge_maxh) and 0 < edge_maxh <= interface_maxh):
        raise GeometryError("edge_maxh", edge_maxh, f"must be > 0 and <= interface_maxh = {interface_maxh}")
    P = float(period)
    geo = cell3d.flat_geometry(P, float(h_rough), float(h_counter), periodic_maxh(interface_maxh, P), symmetric)
    mp = MeshingParameters(maxh=periodic_maxh(maxh, P), grading=float(grading))
    pts = _inside(points, P, symmetric)
    for x, y in pts:
        mp.RestrictH(x=float(x), y=float(y), z=0.0, h=float(edge_maxh))
    if body is not None:
        below = _inside(body.points, P, symmetric)
        for z in body.heights():
            h = float(body.size(z))
            for x, y in below:
                mp.RestrictH(x=float(x), y=float(y), z=float(z), h=h)
    ngmesh = geo.GenerateMesh(mp=mp)
    cell3d._name_faces(ngmesh)
    mesh = ng.Mesh(ngmesh)
    log.info("edge-refined 3D cell%s: %d edge points at size %g, %d elements", " (symmetric quarter)" if symmetric
             else "", len(pts), edge_maxh, mesh.ne)
    return Cell(mesh=mesh, dim=3, period=(P, P), h_rough=float(h_rough), h_counter=float(h_counter),
                symmetric=symmetric)


def fold_quarter(points: np.ndarray, period: float) -> np.ndarray:
    """Points ``(x, y)`` of the period mirrored into the quarter ``[0, P/2]^2``: ``x -> min(x, P - x)``
    (``x`` taken modulo ``P``), the same in ``y``, duplicates (to a millionth of the period) dropped.  On a
    cell even about its mid-lines a point and its mirror images carry the same solution."""
    P = float(period)
    q = np.asarray(points, float).reshape(-1, 2) % P
    q = np.minimum(q, P - q)
    if not len(q):
        return q
    _, keep = np.unique(np.round(q / (FACE_CLEARANCE * P)).astype(np.int64), axis=0, return_index=True)
    return q[np.sort(keep)]


def _inside(points: np.ndarray, P: float, symmetric: bool) -> np.ndarray:
    """The restriction's points inside the meshed box, moved :data:`FACE_CLEARANCE` off its lateral faces."""
    side = 0.5 * P if symmetric else P
    pts = fold_quarter(points, P) if symmetric else np.asarray(points, float).reshape(-1, 2) % P
    return np.clip(pts, FACE_CLEARANCE * P, side - FACE_CLEARANCE * P)

