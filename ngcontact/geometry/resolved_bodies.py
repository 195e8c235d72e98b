"""Two bodies meeting along a resolved periodic rough interface (plane strain or axisymmetric).

The interface is ``N`` copies of one period of a profile of
:mod:`ngcontact.geometry.profiles`, scaled by ``s = eps / P`` in both
directions, ``eps = L / N`` the period of the resolved roughness, ``P`` the
period of the profile (the cell's period).  Summits lie at ``y = 0``; the
valleys reach down to ``y = -s * depth``.  In the conforming arrangement the
``counter`` body (above) fills the valleys of the ``rough`` body (below),
and the whole chain is the potential contact surface ``contact``.

The mesh is graded towards the interface: the interface segments carry
``interface_maxh`` (a fraction of ``eps``), the far field ``maxh``; Netgen's
grading spreads the transition over a layer whose width scales with the
interface size, so the number of elements grows like ``N`` (times
``log N`` for the transition), not like ``N^2``.

Regions ``rough`` (``-h_rough < y < profile``) and ``counter``
(``profile < y < h_counter``), ``0 < x < L``.  Boundaries: ``contact`` (the
resolved interface, or ``interface`` for the flat macro interface ``S_0``
of :func:`flat_blocks`), ``bottom`` (``y = -h_rough``), ``top``
(``y = h_counter``), ``rough_sides`` and ``counter_sides`` (``x = 0, L``),
or ``periodic`` when the lateral faces are identified (a strip of ``N``
cells, for comparison with the cell problem).  The blocks may be shifted to
``x0 <= x <= x0 + L`` (in axisymmetry ``x`` is the radius ``r``: an annular
disk whose face carries concentric ring grooves).

The femur with a grooved stem is built by
:func:`ngcontact.geometry.femur.femur_stem`, which lays the same
:func:`profile_chain` along the stem-bone interface.
"""
from __future__ import annotations

from dataclasses import dataclass


import ngsolve as ng
from netgen.geom2d import SplineGeometry

from ngcontact.geometry.profiles import Arc, Curve, Line, Profile, interface_segments

ROUGH, COUNTER = 1, 2


@dataclass(frozen=True)
class ResolvedGeometry:
    """A meshed two-body geometry with a resolved or flat interface (no physics).

    Attributes
    ----------
    mesh
        The NGSolve mesh (regions ``rough``, ``counter``).
    interface
        Boundary label of the interface (``contact`` resolved, ``interface`` flat).
    periods
        Number of periods ``N`` resolved (0 for a flat interface).
    eps
        Period of the resolved roughness ``L / N`` (the length ``L`` when flat).
    length
        Arc length of the macro interface (the block width ``L``).
    h_rough, h_counter
        Heights of the blocks (0 for the femur).
    segments
        Per straight interface segment ``(N_i, eps_i)`` (femur; empty for blocks).
    """

    mesh: ng.Mesh
    interface: str
    periods: int
    eps: float
    length: float
    h_rough: float = 0.0
    h_counter: float = 0.0
    segments: tuple[tuple[int, float], ...] = ()
    x0: float = 0.0


def scaled_profile(profile: Profile, eps: float) -> Profile:
    """``profile`` scaled by ``eps / profile.period`` in both directions."""
    s = eps / profile.period

    def sc(p):
        return (p[0] * s, p[1] * s)

    pieces: list[Line | Arc | Curve] = []
    for p in profile.pieces:
        if isinstance(p, Line):
            pieces.append(Line(sc(p.start), sc(p.end)))
        elif isinstance(p, Arc):
            pieces.append(Arc(sc(p.center), p.radius * s, p.t0, p.t1))
        elif isinstance(p, Curve):
            pieces.append(Curve(sc(p.start), sc(p.control), sc(p.end)))
        else:
            raise TypeError(f"unknown profile piece {type(p).__name__}")
    return Profile(profile.name, eps, tuple(pieces))


def profile_chain(profile: Profile, periods: int, eps: float) -> list:
    """Interface segments of ``periods`` scaled copies, left to right."""
    one = interface_segments(scaled_profile(profile, eps), "conforming")
    out = []
    for k in range(periods):
        dx = k * eps
        for seg in one:
            pts = tuple((p[0] + dx, p[1]) for p in seg.points)
            out.append((seg.kind, pts))
    return out


def resolved_blocks(profile: Profile, periods: int, length: float, h_rough: float, h_counter: float, *,
                    maxh: float, interface_maxh: float, order: int = 1,
                    periodic: bool = False, grading: float = 0.3, x0: float = 0.0) -> ResolvedGeometry:
    """Mesh two blocks meeting along ``periods`` scaled copies of ``profile``.

    Parameters
    ----------
    profile
        One period of the roughness (summits at ``y = 0``), any period ``P``.
    periods
        ``N >= 1``; the resolved period is ``eps = length / N``.
    length, h_rough, h_counter
        Block width and the far faces ``y = -h_rough``, ``y = h_counter``.
    maxh, interface_maxh
        Mesh size in the far field and on the interface.
    order
        Geometry order (curved elements on arcs).
    periodic
        Identify ``x = 0`` with ``x = length`` (boundary ``periodic``).
    grading
        Netgen's grading factor (smaller: slower growth away from the interface).
    x0
        Position of the left faces (the inner radius in axisymmetry), ``>= 0``.
    """
    if x0 < 0:
        raise ValueError(f"x0 = {x0!r}: must be >= 0")
    if not (isinstance(periods, int) and periods >= 1):
        raise ValueError(f"periods = {periods!r}: must be an integer >= 1")
    if min(length, h_rough, h_counter, maxh, interface_maxh) <= 0:
        raise ValueError("length, heights and mesh sizes must be > 0")
    eps = length / periods
    lo, hi = profile.bounds
    s = eps / profile.period
    if not (-h_rough < s * lo and s * hi < h_counter):
        raise ValueError(f"the scaled roughness spans y in [{s * lo}, {s * hi}]: it must lie inside "
                         f"(-h_rough, h_counter) = ({-h_rough}, {h_counter})")
    chain = [(kind, tuple((p[0] + x0, p[1]) for p in pts)) for kind, pts in profile_chain(profile, periods, eps)]
    geo = SplineGeometry()
    cache = {}
    tol = 1e-12 * length

    def point(p, h=None):
        key = (round(p[0] / tol), round(p[1] / tol))
        if key not in cache:
            cache[key] = geo.AppendPoint(*p, maxh=h) if h else geo.AppendPoint(*p)
        return cache[key]

    y0 = chain[0][1][0][1]
    x1 = x0 + length
    bl, br = point((x0, -h_rough)), point((x1, -h_rough))
    tl, tr = point((x0, h_counter)), point((x1, h_counter))
    il, ir = point((x0, y0), interface_maxh), point((x1, y0), interface_maxh)
    geo.Append(["line", bl, br], leftdomain=ROUGH, rightdomain=0, bc="bottom")
    geo.Append(["line", tr, tl], leftdomain=COUNTER, rightdomain=0, bc="top")
    if periodic:
        right = geo.Append(["line", br, ir], leftdomain=ROUGH, rightdomain=0, bc="periodic")
        geo.Append(["line", bl, il], leftdomain=0, rightdomain=ROUGH, bc="periodic", copy=right)
        right = geo.Append(["line", ir, tr], leftdomain=COUNTER, rightdomain=0, bc="periodic")
        geo.Append(["line", il, tl], leftdomain=0, rightdomain=COUNTER, bc="periodic", copy=right)
    else:
        geo.Append(["line", br, ir], leftdomain=ROUGH, rightdomain=0, bc="rough_sides")
        geo.Append(["line", il, bl], leftdomain=ROUGH, rightdomain=0, bc="rough_sides")
        geo.Append(["line", ir, tr], leftdomain=COUNTER, rightdomain=0, bc="counter_sides")
        geo.Append(["line", tl, il], leftdomain=COUNTER, rightdomain=0, bc="counter_sides")
    # run left to right: rough (below) on the right-hand side of the direction of travel
    for kind, pts in chain:
        ids = [point(p) for p in pts]
        geo.Append([kind, *ids], leftdomain=COUNTER, rightdomain=ROUGH, bc="contact", maxh=interface_maxh)
    geo.SetMaterial(ROUGH, "rough")
    geo.SetMaterial(COUNTER, "counter")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh, grading=grading))
    if order > 1:
        mesh.Curve(order)
    return ResolvedGeometry(mesh=mesh, interface="contact", periods=periods, eps=eps, length=length,
                            h_rough=h_rough, h_counter=h_counter, x0=x0)


def flat_blocks(length: float, h_rough: float, h_counter: float, *, maxh: float,
                interface_maxh: float | None = None, grading: float = 0.3, x0: float = 0.0) -> ResolvedGeometry:
    """The same two blocks bonded along the flat macro interface ``S_0`` (``y = 0``).

    Boundary ``interface`` instead of ``contact``; all other labels as in
    :func:`resolved_blocks`, so the same supports and loads apply.
    """
    if min(length, h_rough, h_counter, maxh) <= 0:
        raise ValueError("length, heights and mesh sizes must be > 0")
    hint = interface_maxh or maxh
    geo = SplineGeometry()
    x1 = x0 + length
    P = [geo.AppendPoint(x, y) for x, y in ((x0, -h_rough), (x1, -h_rough), (x1, 0.0),
                                             (x1, h_counter), (x0, h_counter), (x0, 0.0))]
    geo.Append(["line", P[0], P[1]], leftdomain=ROUGH, rightdomain=0, bc="bottom")
    geo.Append(["line", P[1], P[2]], leftdomain=ROUGH, rightdomain=0, bc="rough_sides")
    geo.Append(["line", P[2], P[3]], leftdomain=COUNTER, rightdomain=0, bc="counter_sides")
    geo.Append(["line", P[3], P[4]], leftdomain=COUNTER, rightdomain=0, bc="top")
    geo.Append(["line", P[4], P[5]], leftdomain=COUNTER, rightdomain=0, bc="counter_sides")
    geo.Append(["line", P[5], P[0]], leftdomain=ROUGH, rightdomain=0, bc="rough_sides")
    geo.Append(["line", P[2], P[5]], leftdomain=ROUGH, rightdomain=COUNTER, bc="interface", maxh=hint)
    geo.SetMaterial(ROUGH, "rough")
    geo.SetMaterial(COUNTER, "counter")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh, grading=grading))
    return ResolvedGeometry(mesh=mesh, interface="interface", periods=0, eps=length, length=length,
                            h_rough=h_rough, h_counter=h_counter, x0=x0)
