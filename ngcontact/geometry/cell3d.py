"""Periodic two-body cells in 3D with Netgen's constructive solid geometry.

The cell is ``[0, P] x [0, P] x [-h_rough, h_counter]``; the macro normal
``n0`` is ``+e_z`` and the summits of the roughness lie at ``z = 0``.  The
faces ``x = 0, P`` and ``y = 0, P`` are identified periodically
(``CSGeometry.PeriodicSurfaces``).

Mirror-symmetric quarter
------------------------
A cell whose gap is even about its mid-lines ``x = P/2`` and ``y = P/2``
(a periodic function even about ``P/2`` is even about ``0`` too), under a
normal frictionless load, has a solution with the same mirror symmetry: the
in-plane displacement normal to each mirror plane vanishes on it, and so
does the shear traction on it.  :func:`flat_cell3d` and
:func:`ngcontact.cell.fe.contact_edge_mesh.edge_refined_cell` with
``symmetric=True`` mesh the quarter ``[0, P/2]^2`` instead; its lateral
faces are ``symmetry_x`` (``x = 0, P/2``) and ``symmetry_y``
(``y = 0, P/2``), where the cell problem holds ``u_x`` resp. ``u_y`` at zero
and leaves the shear traction natural.  Means over the quarter are the
means over the period (:attr:`~ngcontact.geometry.cell2d.Cell.area` is the
quarter's).

Shapes
------
* :func:`flat_cell3d` -- the plane interface ``z = 0``;
* :func:`square_hills_cell` -- the implant coating of paper Fig. 6: one
  square hill of side ``a`` and height ``t`` centred in the cell, its plane
  summit at ``z = 0``, on a base whose top lies at ``z = -t``.  With
  ``arrangement="summit"`` the counter body fills ``z > 0`` and touches only
  the summit (paper Example 26: ``|S_C_real| = a^2``); with ``"conforming"``
  it fills everything around the hill as well.

Faces are named after meshing from the domains on either side of each face
(Netgen's face descriptors): a face between ``rough`` and ``counter`` is
``contact``; a face between a body and a void inside the cell is ``free``.

Free-form surfaces
------------------
CSG composes solids from primitives with closed-form surfaces and cannot
express a bisinusoid or a sampled height map.  For those two shapes -- and
only those -- the cell is built with Netgen's OCC kernel instead
(:func:`surface_cell`): a B-spline surface interpolating the heights on a
periodic grid splits the box into the two bodies (``Glue``), the conforming
arrangement (the counter body fills the valleys, the whole surface is
``contact``), with the lateral faces identified periodically.  The summit
arrangement of a free-form surface is represented by the small-slope model:
the flat cell (:func:`flat_cell3d`) plus the initial gap ``g(x, y) >= 0``
between the summit plane and the rough surface (:func:`bisinusoid_gap`,
:func:`height_map_gap`).
"""
from __future__ import annotations

import logging
import math

import numpy as np
import ngsolve as ng
from netgen.csg import CSGeometry, OrthoBrick, Plane, Pnt, Vec

from ngcontact.errors import GeometryError
from ngcontact.geometry import mesher
from ngcontact.geometry.cell2d import Cell, periodic_maxh
from ngcontact.quiet import quiet

log = logging.getLogger(__name__)

ARRANGEMENTS = ("conforming", "summit")
#: the lateral faces of a symmetric quarter, holding ``u_x`` resp. ``u_y`` at zero
SYMMETRY_FACES = ("symmetry_x", "symmetry_y")
_KEEP = ("periodic", "top", "bottom") + SYMMETRY_FACES


def _positive(key, value):
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise GeometryError(key, value, "must be a finite number > 0")
    return float(value)


def _box_planes(P, h_rough, h_counter, symmetric: bool = False):
    """Lateral, bottom and top half-spaces of the cell (``symmetric``: of its quarter ``[0, P/2]^2``, the
    lateral planes named after the displacement component they hold, :data:`SYMMETRY_FACES`)."""
    side = 0.5 * P if symmetric else P
    bx, by = SYMMETRY_FACES if symmetric else ("periodic", "periodic")
    xm = Plane(Pnt(0, 0, 0), Vec(-1, 0, 0)).bc(bx)
    xp = Plane(Pnt(side, 0, 0), Vec(1, 0, 0)).bc(bx)
    ym = Plane(Pnt(0, 0, 0), Vec(0, -1, 0)).bc(by)
    yp = Plane(Pnt(0, side, 0), Vec(0, 1, 0)).bc(by)
    bottom = Plane(Pnt(0, 0, -h_rough), Vec(0, 0, -1)).bc("bottom")
    top = Plane(Pnt(0, 0, h_counter), Vec(0, 0, 1)).bc("top")
    return (xm, xp, ym, yp), bottom, top


def _identify_periodic(geo, lateral, symmetric: bool = False) -> None:
    """Identify the lateral planes ``x = 0, P`` and ``y = 0, P`` periodically (Netgen announces each
    identification on C++'s standard output: kept off the terminal); a symmetric quarter's are not."""
    if symmetric:
        return
    xm, xp, ym, yp = lateral
    with quiet("stdout"):
        geo.PeriodicSurfaces(xm, xp)
        geo.PeriodicSurfaces(ym, yp)


def _mesh(geo, maxh: float, P: float, h_rough: float, h_counter: float, symmetric: bool = False) -> Cell:
    ngmesh = mesher.generate(geo, maxh=periodic_maxh(maxh, P))
    _name_faces(ngmesh)
    mesh = ng.Mesh(ngmesh)
    log.debug("3D cell: %d elements, boundaries %s", mesh.ne, sorted(set(mesh.GetBoundaries())))
    return Cell(mesh=mesh, dim=3, period=(P, P), h_rough=float(h_rough),
                h_counter=float(h_counter), symmetric=symmetric)


def _name_faces(ngmesh) -> None:
    """Name interface faces ``contact`` / ``free`` from the domains on their two sides."""
    rough = counter = None
    for i in range(1, ngmesh.GetNDomains() + 1):
        name = ngmesh.GetMaterial(i)
        if name == "rough":
            rough = i
        elif name == "counter":
            counter = i
    wanted: dict[int, str] = {}
    for i in range(1, ngmesh.GetNFaceDescriptors() + 1):
        fd = ngmesh.FaceDescriptor(i)
        if fd.bcname in _KEEP:
            continue
        name = "contact" if {fd.domin, fd.domout} == {rough, counter} else "free"
        if wanted.setdefault(fd.bc, name) != name:
            raise RuntimeError(f"Netgen gave one boundary number {fd.bc} to contact and free faces")
    for bc, name in wanted.items():
        ngmesh.SetBCName(bc - 1, name)


def flat_cell3d(period: float = 1.0, h_rough: float = 1.0, h_counter: float = 1.0, *,
                maxh: float, interface_maxh: float | None = None, symmetric: bool = False) -> Cell:
    """Two bodies bonded along the plane ``z = 0`` of a periodic ``period x period`` cell (``symmetric``:
    its quarter ``[0, P/2]^2`` between mirror planes, module docstring).

    Parameters
    ----------
    period
        Cell side ``P`` in ``x`` and ``y`` (``|T| = P^2``).
    h_rough, h_counter
        Far faces ``bottom`` at ``z = -h_rough`` and ``top`` at ``z = h_counter``.
    maxh, interface_maxh
        Mesh sizes in the bodies and on the interface.
    """
    P = _positive("period", period)
    hr, hc = _positive("h_rough", h_rough), _positive("h_counter", h_counter)
    geo = flat_geometry(P, hr, hc, periodic_maxh(interface_maxh or maxh, P), symmetric)
    return _mesh(geo, maxh, P, hr, hc, symmetric)


def flat_geometry(P: float, h_rough: float, h_counter: float, interface_maxh: float,
                  symmetric: bool = False) -> CSGeometry:
    """The CSG geometry of :func:`flat_cell3d`: the two bodies of the box (or its symmetric quarter) split
    by the plane ``contact`` at ``z = 0`` meshed at ``interface_maxh``, the lateral faces identified (periodic)."""
    lat, bottom, top = _box_planes(P, h_rough, h_counter, symmetric)
    xm, xp, ym, yp = lat
    plane = Plane(Pnt(0, 0, 0), Vec(0, 0, 1)).bc("contact").maxh(interface_maxh)
    box = xm * xp * ym * yp
    geo = CSGeometry()
    geo.Add((box * bottom * plane).mat("rough"))
    geo.Add((box * top - plane).mat("counter"))
    _identify_periodic(geo, lat, symmetric)
    return geo


def square_hills_cell(side: float, height: float, *, period: float = 1.0,
                      arrangement: str = "summit", h_rough: float, h_counter: float,
                      maxh: float, interface_maxh: float | None = None) -> Cell:
    """The implant-coating cell of paper Fig. 6: one square hill with a plane summit.

    Parameters
    ----------
    side
        Hill side ``a < period``; the hill is centred in the cell.
    height
        Hill height ``t < h_rough``; summit at ``z = 0``, base top at ``z = -t``.
    period
        Cell side ``P``.
    arrangement
        ``"summit"`` (counter body flat on the summits, voids around the hill,
        ``contact`` = the summit square) or ``"conforming"`` (the counter body
        fills the space around the hill, ``contact`` = the whole rough surface).
    h_rough, h_counter
        Far faces at ``z = -h_rough`` and ``z = h_counter``.
    maxh, interface_maxh
        Mesh sizes in the bodies and on the rough surface.
    """
    P = _positive("period", period)
    a, t = _positive("side", side), _positive("height", height)
    hr, hc = _positive("h_rough", h_rough), _positive("h_counter", h_counter)
    if arrangement not in ARRANGEMENTS:
        raise GeometryError("arrangement", arrangement, f"must be one of {', '.join(ARRANGEMENTS)}")
    if not a < P:
        raise GeometryError("side", side, f"must be < period = {P} (hills must not touch)")
    if not t < hr:
        raise GeometryError("height", height, f"must be < h_rough = {hr} "
                         "(the hill base must lie inside the rough body)")
    hi = periodic_maxh(interface_maxh or maxh, P)
    lat, bottom, top = _box_planes(P, hr, hc)
    xm, xp, ym, yp = lat
    box = xm * xp * ym * yp
    c0, c1 = 0.5 * (P - a), 0.5 * (P + a)
    base_top = Plane(Pnt(0, 0, -t), Vec(0, 0, 1)).bc("interface").maxh(hi)
    hill = OrthoBrick(Pnt(c0, c0, -0.5 * (t + hr)), Pnt(c1, c1, 0.0)).bc("interface").maxh(hi)
    rough = box * bottom * base_top + hill
    if arrangement == "summit":
        summit = Plane(Pnt(0, 0, 0), Vec(0, 0, -1)).bc("interface").maxh(hi)
        counter = box * top * summit
    else:
        counter = box * top - base_top - hill
    geo = CSGeometry()
    geo.Add(rough.mat("rough"))
    geo.Add(counter.mat("counter"))
    _identify_periodic(geo, (xm, xp, ym, yp))
    return _mesh(geo, maxh, P, hr, hc)


# ------------------------------------------------ free-form surfaces (OCC)
def bisinusoid_heights(amplitude: float, period: float = 1.0, samples: int = 33) -> np.ndarray:
    """Heights ``A (cos(2 pi x/P) + cos(2 pi y/P) - 2)`` on a ``samples x samples`` periodic grid.

    Same layout as a height map: ``H[i, j]`` at ``x = j P/(n - 1)``,
    ``y = i P/(n - 1)``; the last row and column repeat the first.
    """
    A, P = _positive("geometry.amplitude", amplitude), _positive("geometry.period", period)
    t = np.linspace(0.0, P, int(samples))
    X, Y = np.meshgrid(t, t)
    k = 2 * math.pi / P
    return A * (np.cos(k * X) + np.cos(k * Y) - 2.0)


def surface_cell(heights, *, period: float = 1.0, h_rough: float, h_counter: float,
                 maxh: float, interface_maxh: float | None = None, order: int = 1) -> Cell:
    """Conforming cell whose bodies meet along a periodic free-form surface (OCC).

    Parameters
    ----------
    heights
        ``H[i, j]``, the height at ``x = j P/(n_x - 1)``, ``y = i P/(n_y - 1)``
        with the last row and column repeating the first (validated by
        :func:`ngcontact.geometry.tabulated.check_height_map`).  The surface is
        shifted so that its highest summit lies at ``z = 0``.
    period
        ``P``, the cell period in ``x`` and ``y``.
    h_rough, h_counter
        The far faces lie at ``z = -h_rough`` and ``z = h_counter``; the
        surface must stay strictly between them.
    maxh, interface_maxh
        Mesh sizes in the bodies and on the surface.
    order
        Geometry order of the curved elements.

    Notes
    -----
    The surface is the B-spline interpolating the grid points
    (``netgen.occ.SplineSurfaceInterpolation``).  Its boundary curves on
    ``x = 0`` and ``x = P`` interpolate identical data and therefore coincide
    after the shift by ``P``, which makes the periodic identification of the
    lateral faces exact.
    """
    import netgen.occ as occ
    from ngcontact.geometry.tabulated import check_height_map

    P = _positive("geometry.period", period)
    hr, hc = _positive("h_rough", h_rough), _positive("geometry.h_counter", h_counter)
    H = check_height_map(heights, path="geometry.heights")
    H = H - H.max()
    if -H.min() >= hr:
        raise GeometryError("h_rough", hr, f"must exceed the roughness depth {float(-H.min())!r}")
    ny, nx = H.shape
    xs, ys = np.linspace(0.0, P, nx), np.linspace(0.0, P, ny)
    X, Y = np.meshgrid(xs, ys)
    # first surface parameter along x, second along y
    pts = np.ascontiguousarray(np.stack([X.T, Y.T, H.T], axis=-1))
    surface = occ.SplineSurfaceInterpolation(pts)
    if interface_maxh:
        surface.maxh = periodic_maxh(_positive("discretization.interface_maxh", interface_maxh), P)
    box = occ.Box(occ.Pnt(0, 0, -hr), occ.Pnt(P, P, hc))
    box.faces.Min(occ.X).Identify(box.faces.Max(occ.X), "periodic_x", occ.IdentificationType.PERIODIC)
    box.faces.Min(occ.Y).Identify(box.faces.Max(occ.Y), "periodic_y", occ.IdentificationType.PERIODIC)
    shape = occ.Glue([box, surface])
    solids = sorted(shape.solids, key=lambda sol: sol.center.z)
    if len(solids) != 2:
        raise ValueError(f"the surface split the cell into {len(solids)} solids, expected 2")
    solids[0].mat("rough")
    solids[1].mat("counter")
    for f in shape.faces:
        c = f.center
        if abs(c.z + hr) < 1e-9 * max(1.0, hr):
            f.name = "bottom"
        elif abs(c.z - hc) < 1e-9 * max(1.0, hc):
            f.name = "top"
        elif min(abs(c.x), abs(c.x - P), abs(c.y), abs(c.y - P)) < 1e-12 * max(1.0, P):
            f.name = "periodic"
        else:
            f.name = "contact"
    size = periodic_maxh(_positive("discretization.maxh", maxh), P)
    mesh = ng.Mesh(mesher.generate(occ.OCCGeometry(shape), maxh=size))
    if order > 1:
        mesh.Curve(order)
    log.debug("OCC surface cell: %d elements", mesh.ne)
    return Cell(mesh=mesh, dim=3, period=(P, P), h_rough=hr, h_counter=hc)


# ----------------------------------------------------- small-slope models
def bisinusoid_gap(amplitude: float, period: float = 1.0, xy=None):
    """Initial gap of the bisinusoid ``z = A (cos(2 pi x/P) + cos(2 pi y/P) - 2)`` below its summit.

    Small-slope model on :func:`flat_cell3d`: ``g(x, y) = A (2 - cos(2 pi x/P)
    - cos(2 pi y/P)) >= 0``, zero at the summit ``(0, 0)``.  A
    CoefficientFunction, or with ``xy = (x, y)`` (arrays) its values there.
    """
    A, P = _positive("amplitude", amplitude), _positive("period", period)
    k = 2 * math.pi / P
    x, y, m = (ng.x, ng.y, ng) if xy is None else (xy[0], xy[1], np)
    return A * (2 - m.cos(k * x) - m.cos(k * y))


def height_map_gap(heights, period: float = 1.0):
    """Initial gap ``max(H) - H(x, y)`` of a periodic height map, bilinear between samples.

    Small-slope model on :func:`flat_cell3d`.  ``heights[i, j]`` is the
    height at ``x = j P / (n_x - 1)``, ``y = i P / (n_y - 1)``: the last row
    and column repeat the first (see
    :func:`ngcontact.geometry.tabulated.read_height_map`, which validates
    such arrays).
    """
    P = _positive("period", period)
    H = np.asarray(heights, dtype=float)
    g = np.ascontiguousarray(H.max() - H)
    return ng.VoxelCoefficient((0.0, 0.0), (P, P), g, linear=True)


def bilinear_samples(values, period: float, grid: int) -> np.ndarray:
    """A periodic map (layout of :func:`height_map_gap`) at the points ``(j, i) P / grid`` of a uniform grid.

    Bilinear between the map's samples, as the voxel coefficient the FE cell
    uses; returns shape ``(grid, grid)`` indexed ``[i (y), j (x)]``.
    """
    V = np.asarray(values, dtype=float)
    ny, nx = V.shape[0] - 1, V.shape[1] - 1
    if ny == nx == grid:
        return V[:-1, :-1].copy()
    s = np.arange(grid) / grid

    def weights(n):
        t = s * n
        i = np.minimum(np.floor(t).astype(int), n - 1)
        return i, t - i
    iy, wy = weights(ny)
    ix, wx = weights(nx)
    lo = V[iy][:, ix] * (1 - wx) + V[iy][:, ix + 1] * wx
    hi = V[iy + 1][:, ix] * (1 - wx) + V[iy + 1][:, ix + 1] * wx
    return lo * (1 - wy)[:, None] + hi * wy[:, None]
