"""Periodic two-body cells in 2D with Netgen's ``geom2d``.

The interface between ``rough`` (below) and ``counter`` (above) is a chain of
segments from ``(0, y0)`` to ``(period, y0)``: straight lines and rational
quadratic splines (``spline3``, exact circular arcs), so that curved
interfaces get curved high-order elements.  The lateral edges ``x = 0`` and
``x = period`` are identified (``copy=`` in geom2d), the far faces are
``bottom`` (``y = -h_rough``) and ``top`` (``y = h_counter``).

A segment list may also mark parts of the interface as free surfaces
bounding a void: a void is a closed region between two chains (the rough
profile below, the counter's face above) and belongs to neither body.  Each
segment names the domain on either side of its direction of travel
(``right`` / ``left``: ``"rough"``, ``"counter"`` or ``"void"``), so a void
may border both bodies (the summit arrangement of
:mod:`ngcontact.geometry.profiles`).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import ngsolve as ng
from netgen.geom2d import SplineGeometry

from ngcontact.errors import GeometryError

log = logging.getLogger(__name__)

#: Fewest elements across one period: an element reaching from one periodic
#: side to the other would carry a dof twice after the identification (NGSolve
#: refuses to assemble it), and Netgen's ``maxh`` is only a target size.
MIN_ELEMENTS_PER_PERIOD = 3


#: Largest ratio of the mesh size to the interface mesh size a message calls safe: Netgen's 2D grading failed
#: on a rectangular cell of height 1 at ratios 91 and 100 (and met 80 and 95), whatever the order.
SAFE_SIZE_RATIO = 50


def meshing_failure(exc: Exception, maxh: float, interface_maxh: float) -> GeometryError:
    """The error for Netgen's ``meshing failed`` on a cell meshed at ``maxh`` with the interface at ``interface_maxh``.

    Sizes :data:`SAFE_SIZE_RATIO` and more apart are named as the cause: the
    grading between them is what fails (a plain rectangular cell of height 1
    at interface_maxh = 0.002 has no feature below the mesh size).
    Otherwise both sizes are named with the usual causes.
    """
    ratio = maxh / interface_maxh
    if ratio >= SAFE_SIZE_RATIO:
        return GeometryError("discretization.interface_maxh", interface_maxh,
                             f"Netgen's mesher failed ({exc}) on the cell meshed at maxh = {maxh:g} with the "
                             f"interface at {interface_maxh:g}: sizes {ratio:.3g} times apart, which its grading "
                             "does not bridge reliably (failures seen from about 90); keep maxh / interface_maxh "
                             f"below {SAFE_SIZE_RATIO}: raise discretization.interface_maxh or lower "
                             "discretization.maxh")
    return GeometryError("discretization.maxh", maxh,
                         f"Netgen's mesher failed ({exc}) on the cell meshed at maxh = {maxh:g} with the interface "
                         f"at {interface_maxh:g}: a feature of the geometry smaller than these sizes is the usual "
                         "cause; change the geometry's sizes or the mesh sizes")


def periodic_maxh(maxh: float, period: float) -> float:
    """``maxh`` capped at ``period / MIN_ELEMENTS_PER_PERIOD`` (logged when capped)."""
    cap = period / MIN_ELEMENTS_PER_PERIOD
    if maxh > cap:
        log.info("mesh size %g capped at period / %d = %g for the periodic identification",
                 maxh, MIN_ELEMENTS_PER_PERIOD, cap)
        return cap
    return maxh


_DOMAINS = {"void": 0, "rough": 1, "counter": 2}


@dataclass(frozen=True)
class Segment:
    """One piece of the interface: ``kind`` is ``"line"`` or ``"spline3"``.

    ``points`` are 2 (line) or 3 (spline3: start, control, end) coordinates;
    ``label`` is ``"contact"`` or ``"free"``; ``right`` and ``left`` are the
    domains on the right- and left-hand side of the direction of travel
    (``"rough"``, ``"counter"`` or ``"void"``).  The defaults suit a chain
    run from ``x = 0`` to ``x = period``: ``rough`` below, ``counter`` above.
    """

    kind: str
    points: tuple[tuple[float, float], ...]
    label: str = "contact"
    right: str = "rough"
    left: str = "counter"


@dataclass(frozen=True)
class Cell:
    """A meshed periodic cell and its geometric data (no physics).

    ``symmetric``: the mesh covers one quarter ``[0, P/2]^2`` of a 3D period whose cell is even about its
    mid-lines, its lateral faces the mirror planes ``symmetry_x`` and ``symmetry_y`` (naming contract of
    :mod:`ngcontact.geometry`) instead of periodic faces.
    """

    mesh: ng.Mesh
    dim: int
    period: tuple[float, ...]          # period in each tangential direction
    h_rough: float         # depth of the rough body below y = 0
    h_counter: float       # height of the counter body above y = 0
    symmetric: bool = False

    @property
    def area(self) -> float:
        """Projected area (3D) or length (2D) of the meshed part of a period: ``|T|``, or on a symmetric
        cell the quarter's ``|T| / 4``, over which a mean over the period is the same mean."""
        a = 1.0
        for p in self.period:
            a *= 0.5 * p if self.symmetric else p
        return a


def _generate(geo, maxh: float, hint: float, grading: float) -> ng.Mesh:
    """Netgen's mesh of the cell's geometry; a meshing failure names its likely cause (:func:`meshing_failure`)."""
    try:
        return ng.Mesh(geo.GenerateMesh(maxh=maxh, grading=grading))
    except Exception as exc:  # netgen's NgException, which its Python package does not export by a stable name
        if type(exc).__name__ != "NgException" or "meshing" not in str(exc).lower():
            raise
        raise meshing_failure(exc, maxh, hint) from None


def interface_cell(segments, period: float, h_rough: float, h_counter: float, *,
                   maxh: float, interface_maxh: float | None = None, order: int = 1,
                   voids=(), grading: float = 0.3) -> Cell:
    """Mesh a 2D periodic cell whose bodies meet along ``segments``.

    Parameters
    ----------
    segments
        Interface segments, each a :class:`Segment`, forming the boundary
        between the bodies (and any voids) from ``x = 0`` to ``x = period``;
        exactly one point lies on each lateral edge and both at the same
        height.  With the default sides the rough body lies below and the
        counter body above.
    period
        Cell length ``|T|``.
    h_rough, h_counter
        Far faces at ``y = -h_rough`` and ``y = h_counter``.
    maxh, interface_maxh
        Mesh sizes in the bodies and on the interface.
    order
        Geometry order of the curved elements.
    voids
        Closed chains of :class:`Segment` (counter-clockwise) cut from the
        ``counter`` region: each void's boundary is labelled by its segments
        (``free`` or ``contact``).  A void's chain replaces the part of the
        interface it covers, which must then be omitted from ``segments``.
    grading
        Netgen's mesh grading: how fast elements may grow away from small
        ones (larger grows faster).
    """
    pts = [tuple(map(float, p)) for s in segments for p in s.points]
    ends = [tuple(map(float, p)) for s in segments for p in (s.points[0], s.points[-1])]
    tol = 1e-12 * period
    left_pts = {round(p[1], 12): p[1] for p in ends if abs(p[0]) <= tol}
    right_pts = {round(p[1], 12): p[1] for p in ends if abs(p[0] - period) <= tol}
    if len(left_pts) != 1 or len(right_pts) != 1:
        raise ValueError("the interface must run from x = 0 to x = period, meeting each "
                         f"lateral edge at exactly one point; it meets x = 0 at y in "
                         f"{sorted(left_pts.values())} and x = period at y in "
                         f"{sorted(right_pts.values())}")
    (y0,), (y1,) = left_pts.values(), right_pts.values()
    if abs(y0 - y1) > 1e-12 * max(1.0, abs(y0)):
        raise ValueError(f"the interface is not periodic: y(0) = {y0} but y(period) = {y1}")
    for s in segments:
        for side in (s.right, s.left):
            if side not in _DOMAINS:
                raise ValueError(f"segment side = {side!r}: must be one of {', '.join(_DOMAINS)}")
    lo = min(p[1] for p in pts)
    hi = max(p[1] for p in pts)
    if not (-h_rough < lo and hi < h_counter):
        raise ValueError(f"the interface spans y in [{lo}, {hi}]: it must lie strictly between "
                         f"-h_rough = {-h_rough} and h_counter = {h_counter}")
    maxh = periodic_maxh(maxh, period)
    hint = periodic_maxh(interface_maxh or maxh, period)
    geo = SplineGeometry()
    cache = {}

    def point(p):
        key = (round(p[0], 14), round(p[1], 14))
        if key not in cache:
            cache[key] = geo.AppendPoint(*p)
        return cache[key]

    ROUGH, COUNTER = _DOMAINS["rough"], _DOMAINS["counter"]
    bl, br = point((0.0, -h_rough)), point((period, -h_rough))
    tl, tr = point((0.0, h_counter)), point((period, h_counter))
    il, ir = point((0.0, y0)), point((period, y0))
    geo.Append(["line", bl, br], leftdomain=ROUGH, rightdomain=0, bc="bottom")
    right = geo.Append(["line", br, ir], leftdomain=ROUGH, rightdomain=0, bc="periodic")
    geo.Append(["line", bl, il], leftdomain=0, rightdomain=ROUGH, bc="periodic", copy=right)
    right = geo.Append(["line", ir, tr], leftdomain=COUNTER, rightdomain=0, bc="periodic")
    geo.Append(["line", il, tl], leftdomain=0, rightdomain=COUNTER, bc="periodic", copy=right)
    geo.Append(["line", tr, tl], leftdomain=COUNTER, rightdomain=0, bc="top")
    # interface: by default run left to right, rough (below) on the right-hand side
    for s in segments:
        ids = [point(p) for p in s.points]
        geo.Append([s.kind, *ids], leftdomain=_DOMAINS[s.left], rightdomain=_DOMAINS[s.right],
                   bc=s.label, maxh=hint)
    for chain in voids:
        for s in chain:
            ids = [point(p) for p in s.points]
            geo.Append([s.kind, *ids], leftdomain=0, rightdomain=COUNTER, bc=s.label, maxh=hint)
    geo.SetMaterial(ROUGH, "rough")
    geo.SetMaterial(COUNTER, "counter")
    mesh = _generate(geo, maxh, hint, grading)
    if order > 1:
        mesh.Curve(order)
    return Cell(mesh=mesh, dim=2, period=(float(period),), h_rough=float(h_rough),
                h_counter=float(h_counter))


def flat_cell(period: float = 1.0, h_rough: float = 1.0, h_counter: float = 1.0, *,
              maxh: float, interface_maxh: float | None = None, order: int = 1, vertices=(),
              grading: float = 0.3) -> Cell:
    """Two bodies bonded along the flat line ``y = 0`` (the small-slope model).

    ``vertices``: abscissae in ``(0, period)`` that become mesh vertices of
    the interface (a mesh graded towards the contact edges,
    :mod:`ngcontact.cell.fe.edge_grading`); ``grading`` as in
    :func:`interface_cell`.
    """
    tol = 1e-12 * period
    xs = [0.0] + sorted({float(v) for v in vertices if tol < v < period - tol}) + [float(period)]
    segs = [Segment("line", ((a, 0.0), (b, 0.0))) for a, b in zip(xs[:-1], xs[1:])]
    return interface_cell(segs, period, h_rough, h_counter, maxh=maxh,
                          interface_maxh=interface_maxh, order=order, grading=grading)
