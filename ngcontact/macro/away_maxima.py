"""The largest stress of each body away from its singular points (edges in 3D): a maximum that converges.

Where the stress of linear elasticity is unbounded at a point of a body's boundary (Williams 1952; the
cases of :mod:`ngcontact.macro.singular_maxima`), the body's largest stress has no limit: its value is set
by the element size there, and it is reported as mesh dependent.  What a design is judged by is the stress
away from such a point.  For a body ``B`` with the singular points ``x_1 .. x_k`` and a radius ``r``

    M_B(r) = max { sigma_eq(x) : x in B, |x - x_i| > r for every i },

``sigma_eq`` the von Mises or the Tresca stress (paper eq. 77).  On that set the exact stress is bounded
and continuous: the solution is smooth inside the body and up to the smooth parts of its boundary with
smooth data, and the unbounded terms ``|x - x_i|^(lambda - 1)`` and ``log |x - x_i|`` are bounded by
their values at distance ``r``.  So ``M_B(r)`` is a converging quantity of the discretization, and its
error is estimated as every other headline quantity's: the order ladder
(:mod:`ngcontact.macro.discretization_error`) on the sample points outside the balls, plus the sampling
error of a denser lattice outside them, and in a refinement the sequence of mesh levels
(:mod:`ngcontact.macro.mesh_sequence`); besides, by two local refinements at the singular points, which
see the error the singular points spread over the mesh (:mod:`ngcontact.macro.away_sequence`).  Its name
is the global maximum's with :data:`AWAY` (``von_mises_bone_away``), and its entry says where it is
attained (``location``).  The safety factor of
eq. 78 is offered the same way: ``safety_factor_away``, the smallest ``sigma_u / sigma_eq`` of the micro
stresses (eq. 75) over the interface points outside the balls.

The singular points (:func:`singular_points`), from the geometry, the supports and the solution:

* an end of the interface on a boundary without support where the interface is closed
  (:func:`ngcontact.macro.singular_maxima.closed_ends`): the traction jumps there from the law's to none;
* a vertex where a clamped boundary (a support of every component) meets a boundary without support or
  the interface: a clamped-free wedge of more than about 63 degrees has ``lambda < 1`` (Williams 1952;
  ``lambda ~ 0.71`` at 90 degrees and ``nu = 0.3``);
* a re-entrant corner of a body, whose interior angle exceeds ``pi`` by more than
  :data:`~ngcontact.macro.discretization_error.CORNER_ANGLE` where two boundary labels meet, by more than
  :data:`~ngcontact.macro.singular_maxima.SHARP` within one (:func:`reentrant_corners`): a free wedge
  wider than ``pi`` has ``lambda < 1`` (0.544 at 270 degrees).

* an end of a load with a traction (a tangential part): the shear stress jumps there, ``(2 tau / pi) log r``
  on a straight edge, and at a corner the two faces' shears disagree.

And, found by the solution's local levels in 2D (:mod:`ngcontact.macro.away_sequence`): a point where a
maximum away grows with every halving of the elements holding it, as a stiff closed interface makes a kink
of its gap one (:func:`ngcontact.macro.away_sequence.grown`); the maxima away are then taken outside its
ball too (:func:`ngcontact.drivers.macro_accuracy.judged`).

A face meeting a symmetry plane (a support of its normal component) is a mirror of a straight face, no
singular point.  A maximum found singular at a point outside every ball (by the order ladder or the corner
check) makes the maximum away of that body mesh dependent there too (:func:`settle`): it lies in the set
``M_B(r)`` is taken over.

The radius
    The singular terms have no length of their own, so ``r`` says what "at the singular point" means:
    by default :data:`RADIUS_SHARE` = 1/4 of the smallest extent of the two bodies' bounding boxes
    (:func:`default_radius`; the femur's stem and bone are each 11 mm wide, so ``r = 2.75 mm``, about half
    the bone's wall at its top), else ``discretization.exclusion_radius`` [m], positive and below that
    smallest extent.  A smaller radius gives a larger maximum, nearer the point, which converges more
    slowly: the stress's gradient on the circle grows like ``r^(lambda - 2)``, and a circle inside the
    elements that touch the singular point is resolved only once they are refined.  Because the maximum
    of a stress growing towards the point is attained on the circle, the circle is sampled as well
    (:func:`rim`, :data:`RIM` points each).

What the verdict counts (:func:`settle`)
    A global maximum (or the global safety factor) that is mesh dependent and has a counterpart away from
    the singular points is listed with its mesh-dependent value and ``counted = false``: the verdict
    (``accuracy.met``) and a refinement's target are the counterpart's.  A mesh-dependent maximum without
    one is counted (not met), as before.  A maximum away found singular outside every ball makes its
    body's maximum singular there too, as a body's does its counterpart's: the body holds the set.

On one mesh
    The set away from the singular points is part of the body, so on every mesh a body's maximum is at
    least its maximum away, and the safety factor over the interface at most its counterpart away
    (:func:`bounded`: where the rim's points, which are not among the body's sample points, find a larger
    stress, the body's maximum is that sample).

In 3D
    The singular points are edges (:mod:`ngcontact.macro.singular_edges`: the same four cases, found edge by
    edge of the boundary mesh), the balls are tubes of radius ``r`` around them
    (:class:`ngcontact.macro.singular_set.SingularSet` gives the distance to points and edges alike), and
    the rim is sampled on rings of :data:`RING` points around each edge segment.  The maxima away and the
    safety factor away are estimated as in 2D: the order ladder outside the tubes and the local refinements
    at the edges (:mod:`ngcontact.macro.away_sequence`).  The corner check of 2D (local refinements telling
    a growing corner from a bounded one, :mod:`ngcontact.macro.singular_maxima`) is not taken in 3D: a
    maximum over a whole body or the safety factor attained within the tubes is mesh dependent there
    (:func:`inside_tubes`), since a clamped, closed or re-entrant edge has ``lambda < 1`` or a logarithm;
    one attained outside them is the maximum away as well and keeps the ladder's estimate.  Where the
    interface ends closed, every maximum over a whole body is mesh dependent as in 2D
    (:func:`ngcontact.macro.singular_maxima.at_closed_ends`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import ngsolve as ng
import numpy as np

from ngcontact.fem.elasticity import COMPONENTS
from ngcontact.fem.materials import tresca, von_mises
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import singular_maxima as SM
from ngcontact.macro.macro_problem import MacroSolution
from ngcontact.macro.singular_edges import singular_edges
from ngcontact.macro.singular_set import SingularSet

#: the suffix of a quantity taken away from the singular points
AWAY = SM.AWAY
#: the default radius as a share of the smallest extent of the two bodies' bounding boxes
RADIUS_SHARE = 0.25
#: points on each ball's circle where the stress is sampled (:func:`rim`)
RIM = 256
#: points on each ring around a singular edge where the stress is sampled (3D, :func:`rim`)
RING = 24
#: the global quantities that have a counterpart away from the singular points
GLOBAL = ("von_mises_", "tresca_", "safety_factor")


@dataclass(frozen=True)
class Exclusion:
    """The region within ``radius`` of the singular ``points`` (one row each, with why each is one) and, in
    3D, of the singular ``edges`` (``m x 2 x 3`` segments, with ``edge_why``): balls in 2D, tubes in 3D
    (:class:`ngcontact.macro.singular_set.SingularSet` answers for both)."""

    points: np.ndarray
    radius: float
    why: tuple[str, ...]
    radius_from: str = "default"
    edges: np.ndarray | None = None
    edge_why: tuple[str, ...] = ()

    @property
    def singular(self) -> SingularSet:
        """The singular set the region is around."""
        dim = self.points.shape[1] if np.ndim(self.points) == 2 else 2
        edges = np.zeros((0, 2, dim)) if self.edges is None else self.edges
        return SingularSet(np.asarray(self.points, dtype=float).reshape(-1, dim), tuple(self.why), edges,
                           tuple(self.edge_why))

    def outside(self, xyz: np.ndarray) -> np.ndarray:
        """Which of the points ``xyz`` (one row each) lie outside the region."""
        return self.singular.distance(xyz, self.radius) > self.radius

    def joined(self, points: list[tuple[float, ...]], why: str) -> Exclusion:
        """The region with ``points`` (one reason ``why`` for all) among its singular points."""
        rows = np.vstack([np.asarray(self.points, dtype=float).reshape(-1, len(points[0])), np.asarray(points)])
        return replace(self, points=rows, why=self.why + (why,) * len(points))

    def covers(self, point: tuple[float, ...]) -> bool:
        """``point`` lies within the region."""
        return not bool(self.outside(np.asarray(point))[0])

    def record(self) -> dict:
        """``results.accuracy.exclusion``: the radius, where it comes from, the points and why each is one and,
        in 3D, the singular edges as connected curves (reason, length, segments, ends)."""
        out = {"radius": self.radius, "radius_from": self.radius_from,
               "points": [[float(c) for c in p] for p in self.points], "why": list(self.why),
               "how": f"the maxima named *{AWAY} are taken outside a ball of this radius around each point "
                      "(ngcontact.macro.away_maxima)"}
        if self.edges is not None and len(self.edges):
            out["edges"] = self.singular.curves()
            out["how"] = (f"the maxima named *{AWAY} are taken outside a tube of this radius around each singular "
                          "edge (ngcontact.macro.away_maxima, ngcontact.macro.singular_edges)")
        return out


def body_extents(mesh: ng.Mesh, regions: tuple[str, ...]) -> dict[str, float]:
    """Per region the smallest extent of its vertices' bounding box."""
    pts = np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])
    out = {}
    for region in regions:
        used = sorted({v.nr for el in mesh.Elements(ng.VOL) if el.mat == region for v in el.vertices})
        span = np.ptp(pts[used], axis=0)
        out[region] = float(span.min())
    return out


def default_radius(mesh: ng.Mesh, regions: tuple[str, ...]) -> float:
    """:data:`RADIUS_SHARE` of the smallest extent of the bodies' bounding boxes (module docstring)."""
    return RADIUS_SHARE * min(body_extents(mesh, regions).values())


def clamped_corners(sol: MacroSolution) -> list[tuple[float, ...]]:
    """The boundary vertices where a clamped boundary meets a boundary without support or the interface."""
    p = sol.problem
    every = set(COMPONENTS[p.setting])
    clamped = {s.label for s in p.supports if not s.components or set(s.components) >= every}
    supported = {s.label for s in p.supports}
    labels, _, pts = DE.boundary_vertices(p.mesh)
    return [tuple(float(c) for c in pts[v]) for v, names in labels.items()
            if names & clamped and (names - supported)]


def shear_load_ends(sol: MacroSolution) -> list[tuple[float, ...]]:
    """The boundary vertices where a load with a traction (a tangential part) meets another boundary."""
    p = sol.problem
    sheared = {load.label for load in p.loads if any(t != 0 for t in load.traction)}
    labels, _, pts = DE.boundary_vertices(p.mesh)
    return [tuple(float(c) for c in pts[v]) for v, names in labels.items() if names & sheared and len(names) > 1]


def interior_angles(mesh: ng.Mesh, region: str) -> dict[int, float]:
    """Per vertex of body ``region`` the sum of its elements' angles there (2D; ``2 pi`` inside the body)."""
    pts = np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])[:, :2]
    out: dict[int, float] = {}
    for el in mesh.Elements(ng.VOL):
        if el.mat != region:
            continue
        vs = [v.nr for v in el.vertices]
        for k, v in enumerate(vs):
            a, b = pts[vs[k - 1]] - pts[v], pts[vs[(k + 1) % len(vs)]] - pts[v]
            cos = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
            out[v] = out.get(v, 0.0) + math.acos(max(-1.0, min(1.0, cos)))
    return out


def reentrant_corners(sol: MacroSolution) -> list[tuple[float, ...]]:
    """The boundary vertices where a body's interior angle exceeds ``pi + CORNER_ANGLE`` where two boundary
    labels meet, ``pi + SHARP`` (:data:`ngcontact.macro.singular_maxima.SHARP`) within one label (the
    vertices of a coarse polygon approximating a concave arc turn by less)."""
    p = sol.problem
    labels, _, pts = DE.boundary_vertices(p.mesh)
    out = []
    for region in (p.rough, p.counter):
        angles = interior_angles(p.mesh, region)
        out += [tuple(float(c) for c in pts[v]) for v, names in labels.items()
                if angles.get(v, 0.0) > math.pi + (DE.CORNER_ANGLE if len(names) > 1 else SM.SHARP)]
    return out


def singular_points(sol: MacroSolution) -> tuple[np.ndarray, tuple[str, ...]]:
    """The singular points of the module docstring (one row each, none twice) and why each is one."""
    found: list[tuple[tuple[float, ...], str]] = [(end, "the interface ends there closed")
                                                   for end, _ in SM.closed_ends(sol)]
    found += [(c, "a clamped boundary meets an unsupported one") for c in clamped_corners(sol)]
    found += [(c, "a re-entrant corner") for c in reentrant_corners(sol)]
    found += [(c, "a load with a traction ends there") for c in shear_load_ends(sol)]
    points: list[tuple[float, ...]] = []
    why: list[str] = []
    for point, reason in found:
        if not any(math.dist(point, q) <= 1e-12 * max(1.0, math.hypot(*q)) for q in points):
            points.append(point)
            why.append(reason)
    return np.array(points).reshape(-1, sol.problem.mesh.dim), tuple(why)


def smallest_extent(mesh: ng.Mesh, regions: tuple[str, ...]) -> float:
    """The smallest extent of the bounding boxes of the bodies ``regions``: the bound of the radius."""
    return min(body_extents(mesh, regions).values())


def exclusion_of(sol: MacroSolution, radius: float | None = None) -> Exclusion | None:
    """The region of the module docstring on ``sol`` (``radius``: the scene's, in ``(0, smallest extent)``,
    else the default): balls around the singular points in 2D, tubes around the singular edges in 3D
    (:func:`ngcontact.macro.singular_edges.singular_edges`); ``None`` where the bodies have none."""
    p = sol.problem
    found = SingularSet.of_points(*singular_points(sol)) if p.mesh.dim == 2 else singular_edges(sol)
    if not len(found):
        return None
    edges = found.edges if len(found.edges) else None
    if radius is None:
        return Exclusion(found.points, default_radius(p.mesh, (p.rough, p.counter)), found.why, edges=edges,
                         edge_why=found.edge_why)
    return Exclusion(found.points, float(radius), found.why, "scene", edges, found.edge_why)


def circles(exclusion: Exclusion, count: int = RIM) -> np.ndarray:
    """``count`` points on each ball's circle (2D) or on each ring around a singular edge's segment (3D),
    offset by half a step, those outside the rest of the region
    (:meth:`ngcontact.macro.singular_set.SingularSet.rim`)."""
    return exclusion.singular.rim(exclusion.radius, count)


def rim(sol: MacroSolution, exclusion: Exclusion, region: str) -> tuple[np.ndarray, np.ndarray]:
    """The stress tensors (``n x 3 x 3``) and points of body ``region`` on the region's boundary:
    :data:`RIM` points on each ball's circle in 2D, :data:`RING` on each ring around a singular edge in 3D
    (offset by half a step, so none falls on a straight boundary or a symmetry plane through the set),
    those outside the rest of the region."""
    mesh = sol.problem.mesh
    pts = circles(exclusion, RIM if mesh.dim == 2 else RING)
    if not len(pts):
        return np.zeros((0, 3, 3)), np.zeros((0, mesh.dim))
    mips = mesh(*pts.T)
    found = mips["nr"] >= 0
    mips, pts = mips[found], pts[found]
    if not len(pts):
        return np.zeros((0, 3, 3)), np.zeros((0, mesh.dim))
    inside = np.asarray(mesh.MaterialCF({region: 1.0}, default=0.0)(mips)).ravel() > 0.5
    values = np.asarray(MM.stress(sol)(mips[inside])).reshape(-1, 3, 3)
    return values, pts[inside]


def away_maxima(sol: MacroSolution, exclusion: Exclusion, dense_inset: float = 1e-3) -> dict[str, DE.Sample]:
    """Per body the largest von Mises and Tresca stress outside the balls (``<name>_away``): the larger of
    :func:`ngcontact.macro.discretization_error.body_maxima` over the element samples outside and the
    maximum on the balls' circles (:func:`rim`), where a stress growing towards a singular point attains
    it; the sampling error the denser lattice's excess over that."""
    found = DE.body_maxima(sol, dense_inset, keep=exclusion.outside)
    out = {}
    for region in (sol.problem.rough, sol.problem.counter):
        s, xy = rim(sol, exclusion, region)
        for name, measure in (("von_mises", von_mises), ("tresca", tresca)):
            inner = found.get(f"{name}_{region}")
            if not len(s):
                if inner is not None:
                    out[f"{name}_{region}{AWAY}"] = inner
                continue
            values = measure(s)
            k = int(np.argmax(values))
            edge = DE.Sample(float(values[k]), tuple(float(c) for c in xy[k]))
            if inner is None or edge.value >= inner.value:
                dense = inner.value + inner.sampling if inner is not None else edge.value
                edge = DE.Sample(edge.value, edge.location, sampling=max(dense - edge.value, 0.0))
                out[f"{name}_{region}{AWAY}"] = edge
            else:
                out[f"{name}_{region}{AWAY}"] = inner
    return out


def bounded(samples: dict[str, DE.Sample]) -> dict[str, DE.Sample]:
    """``samples`` of one solution with each maximum over a whole body at least its counterpart's away and the
    safety factor at most its counterpart's away: the set away from the singular points is part of the body
    (part of the interface), so on one mesh a maximum over it cannot exceed the body's, nor a minimum over it
    fall below the interface's; where the rim's points (not among the body's sample points) find a larger
    stress, the body's maximum is that sample."""
    out = dict(samples)
    for name, away in samples.items():
        whole = _global(name) if name.endswith(AWAY) else None
        if whole is None or whole not in samples:
            continue
        smaller = whole.startswith(GLOBAL[2])
        if (away.value < samples[whole].value) if smaller else (away.value > samples[whole].value):
            out[whole] = away
    return out


def _global(name: str) -> str:
    return name[:-len(AWAY)]


def _body_of(name: str) -> str:
    """The body a stress maximum's name names (``safety_factor``: the interface, both bodies)."""
    return next((name[len(p):] for p in GLOBAL[:2] if name.startswith(p)), "interface")


def inside_tubes(found: list[DE.Estimate], exclusion: Exclusion | None) -> list[DE.Estimate]:
    """``found`` with each maximum over a whole body and the safety factor that a 3D run attains within the
    tubes around the singular edges made mesh dependent at the edge's nearest point (module docstring,
    "In 3D"); the others, and every estimate of a 2D run, as they are."""
    if exclusion is None or exclusion.edges is None or not len(exclusion.edges):
        return found
    out = []
    for e in found:
        if e.name.startswith(GLOBAL) and not e.name.endswith(AWAY) and e.singular_at is None \
                and e.location is not None and exclusion.covers(e.location):
            at = exclusion.singular.nearest(e.location)
            e = replace(e, error=None, singular_at=at,
                        how=f"{e.how}; attained at {DE._point(e.location)}, within {exclusion.radius:.3g} m of a "
                            "singular edge, where the stress grows like d^(lambda - 1) or log d in the distance d "
                            "to the edge (the 2D wedge's, Grisvard 1985), so its value is set by the mesh there: "
                            f"mesh dependent, singular at {DE._point(at)}")
        out.append(e)
    return out


def settle(found: list[DE.Estimate], exclusion: Exclusion | None) -> list[DE.Estimate]:
    """``found`` with what the verdict counts (module docstring): a mesh-dependent global maximum with a
    counterpart away is not counted; a counterpart whose body is singular outside every ball is mesh
    dependent there, and a body whose counterpart is singular outside every ball (found so by the local
    levels, :mod:`ngcontact.macro.away_sequence`) is mesh dependent there too."""
    if exclusion is None:
        return found
    names = {e.name for e in found}
    outside = {_body_of(e.name): e for e in found if e.name.startswith(GLOBAL) and not e.name.endswith(AWAY)
               and e.singular_at is not None and not exclusion.covers(e.singular_at)}
    away = {_body_of(_global(e.name)): e for e in found if e.name.endswith(AWAY) and e.singular_at is not None
            and not exclusion.covers(e.singular_at)}
    out = []
    for e in found:
        whole = e.name.startswith(GLOBAL) and not e.name.endswith(AWAY) and e.singular_at is None
        hit = away.get(_body_of(e.name)) if whole else None
        if hit is not None and hit.singular_at is not None:
            e = replace(e, error=None, singular_at=hit.singular_at,
                        how=f"{e.how}; {hit.name} is singular at {DE._point(hit.singular_at)}, outside the balls "
                            "around the singular points, and the body holds that set, so this maximum has no "
                            f"converged value either: mesh dependent, singular at {DE._point(hit.singular_at)}")
        if e.name.endswith(AWAY):
            hit = outside.get(_body_of(_global(e.name)))
            if hit is not None and hit.singular_at is not None and e.singular_at is None:
                e = replace(e, error=None, singular_at=hit.singular_at,
                            how=f"{e.how}; {hit.name} is singular at {DE._point(hit.singular_at)}, outside the balls "
                                "around the singular points, so this maximum has no converged value either: mesh "
                                f"dependent, singular at {DE._point(hit.singular_at)}")
        elif e.name.startswith(GLOBAL) and e.singular_at is not None and e.name + AWAY in names:
            e = replace(e, counted=False)
        out.append(e)
    return out
