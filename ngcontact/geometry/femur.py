"""The axisymmetric femur with a hip stem: one builder for the flat and the grooved interface.

Coordinates ``(r, z)`` = mesh ``(x, y)``.  The femur is a hollow cylinder
(outer radius ``r_bone``) from its clamped base ``z = 0`` up to
``z_bone_top``; the stem is a solid cylinder of radius ``r_stem`` from its
top ``z_stem_top`` down to the corner ``z_corner``, below which a conical
frustum narrows to ``r_tip`` at ``z_tip``.  The canal follows the stem (the
interface) and continues below the tip as an empty canal of radius ``r_tip``
down to the base (:class:`FemurStemDims`).

The interface (the cone from the tip to the corner, then the cylinder up to
the bone top) is either flat, the macro interface ``S_0`` (boundary
``interface``), or carries ``N`` resolved periods of a roughness profile
(boundary ``contact``): circumferential grooves in the stem, filled by the
bone.  Along a straight interface segment from ``a`` to ``b`` with unit
tangent ``t`` and the unit normal ``n`` on its left (pointing out of the
stem into the bone when travelled from the bone top down), a profile point
``(s, y)`` of a period starting at arc length ``s_k`` maps to
``a + (s_k + s) t + y n``: a rigid motion, so lines stay lines and the
rational ``spline3`` arcs stay exact.  Each segment ``i`` of arc length
``L_i`` gets ``N_i = max(1, round(L_i / eps))`` whole periods,
``eps = (sum L_i) / N`` (:func:`split_periods`), so its own period
``eps_i = L_i / N_i`` is within a factor ``[2/3, 2]`` of ``eps``.  The
profile starts and ends a period at the summit height ``y = 0``, so the
chains of the two segments meet at the corner.

Boundaries: ``interface`` or ``contact``, ``axis`` (``r = 0``), ``stem_top``
(loaded face), ``stem_side`` (stem above the bone), ``stem_tip`` (bottom
face of the stem), ``bone_top``, ``bone_outer``, ``canal`` (empty canal
below the tip), ``base`` (clamped).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import ngsolve as ng
import numpy as np
from netgen.geom2d import SplineGeometry

from ngcontact.geometry import mesher
from ngcontact.geometry.profiles import Profile
from ngcontact.geometry.resolved_bodies import profile_chain

STEM, BONE = 1, 2

#: Boundary labels of the femur with a short description each (the interface's own label aside).
BOUNDARIES = {
    "axis": "symmetry axis r = 0 of the stem",
    "stem_top": "top face of the stem (loaded)",
    "stem_side": "stem surface above the bone",
    "stem_tip": "bottom face of the stem",
    "bone_top": "top face of the bone",
    "bone_outer": "outer surface of the femur",
    "canal": "empty canal below the stem tip",
    "base": "base of the femur (clamped)",
}


@dataclass(frozen=True)
class FemurMesh:
    """A meshed femur with its stem (no physics).

    Attributes
    ----------
    mesh
        The NGSolve mesh; regions ``regions[0]`` (the stem) and ``regions[1]`` (the bone).
    interface
        ``interface`` (flat ``S_0``) or ``contact`` (resolved grooves).
    periods, eps
        ``N`` and ``eps = (interface length) / N`` (flat: 0 and the length).
    length
        Arc length of the interface segments (cone plus cylinder).
    segments
        ``((N_1, eps_1), (N_2, eps_2))`` of the cylinder and the cone (flat: empty).
    """

    mesh: ng.Mesh
    interface: str
    periods: int
    eps: float
    length: float
    segments: tuple[tuple[int, float], ...] = ()


@dataclass(frozen=True, kw_only=True)
class FemurStemDims:
    """Dimensions of the axisymmetric femur with a hip stem, in metres (see the module docstring)."""

    r_stem: float = 0.011
    r_tip: float = 0.005
    r_bone: float = 0.016
    z_tip: float = 0.04
    z_corner: float = 0.12
    z_bone_top: float = 0.17
    z_stem_top: float = 0.19

    def check(self) -> None:
        if not 0 < self.r_tip <= self.r_stem < self.r_bone:
            raise ValueError("need 0 < r_tip <= r_stem < r_bone")
        if not 0 < self.z_tip < self.z_corner < self.z_bone_top < self.z_stem_top:
            raise ValueError("need 0 < z_tip < z_corner < z_bone_top < z_stem_top")


def femur_stem_interface(dims) -> list:
    """The straight segments of the stem-bone interface, from the bone top down to the stem tip.

    Returns ``[(a, b), ...]`` in ``(r, z)``: the cylinder from
    ``(r_stem, z_bone_top)`` to the corner ``(r_stem, z_corner)``, then the
    cone down to the tip ``(r_tip, z_tip)``.  Travelled in this order, the
    left-hand normal points out of the stem into the bone.
    """
    d = dims
    top, corner, tip = (d.r_stem, d.z_bone_top), (d.r_stem, d.z_corner), (d.r_tip, d.z_tip)
    return [(top, corner), (corner, tip)]


def femur_interface_length(dims) -> float:
    """Arc length of the stem-bone interface: the cylinder and the cone of :func:`femur_stem_interface`."""
    return float(sum(math.dist(a, b) for a, b in femur_stem_interface(dims)))


def split_periods(lengths, periods: int) -> tuple[tuple[int, float], ...]:
    """``N_i = max(1, round(L_i / eps))`` whole periods per segment, ``eps = sum(L_i) / periods``.

    Returns ``((N_1, eps_1), ...)`` with ``eps_i = L_i / N_i``.
    """
    if not (isinstance(periods, int) and periods >= 1):
        raise ValueError(f"periods = {periods!r}: must be an integer >= 1")
    eps = float(sum(lengths)) / periods
    out: list[tuple[int, float]] = []
    for L in lengths:
        n = max(1, int(round(L / eps)))
        out.append((n, L / n))
    return tuple(out)


def _chain_along(profile: Profile, a, b, periods: int) -> list:
    """``periods`` scaled copies of ``profile`` along the segment ``a -> b``, normal on the left."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    L = float(np.linalg.norm(b - a))
    t = (b - a) / L
    n = np.array([-t[1], t[0]])
    eps = L / periods
    out = []
    for kind, pts in profile_chain(profile, periods, eps):
        out.append((kind, tuple(tuple(a + p[0] * t + p[1] * n) for p in pts)))
    return out


def femur_stem(dims: FemurStemDims, profile: Profile | None = None, periods: int = 0, *, maxh: float,
               interface_maxh: float | None = None, corner_maxh: float | None = None, order: int = 1,
               grading: float = 0.3, regions: tuple[str, str] = ("stem", "bone")) -> FemurMesh:
    """Mesh the femur (``regions[1]``) with its stem (``regions[0]``), flat or grooved.

    Parameters
    ----------
    dims
        The dimensions, :class:`FemurStemDims`.
    profile
        One period of the roughness (summits at ``y = 0``, valleys into the
        stem), or ``None`` for the flat macro interface ``S_0``.
    periods
        Total number ``N`` of periods along the interface (split between
        cone and cylinder by :func:`split_periods`); ignored when flat.
    maxh, interface_maxh
        Mesh size in the bodies and along the interface (resolved: a
        fraction of ``eps``; the grading keeps the element count growing
        like ``N``).
    corner_maxh
        Mesh size at the points where the interface ends or turns (stem tip,
        cone-cylinder corner, bone top); default ``interface_maxh``.
    order
        Geometry order (curved elements on arcs of the profile).
    grading
        Netgen's grading factor.
    regions
        Region names of the stem (the rough body) and the bone.

    Raises
    ------
    ValueError
        Invalid dimensions or sizes, or grooves so deep that they reach the axis.
    """
    dims.check()
    d = dims
    hint = interface_maxh or maxh
    hcorner = corner_maxh or hint
    if min(maxh, hint, hcorner) <= 0:
        raise ValueError("mesh sizes must be > 0")
    segs = femur_stem_interface(d)
    lengths = [math.dist(a, b) for a, b in segs]
    split: tuple[tuple[int, float], ...] = ()
    if profile is None:
        chain = [("line", (a, b)) for a, b in segs]
        label, eps = "interface", float(sum(lengths))
    else:
        split = split_periods(lengths, periods)
        chain = []
        for (a, b), (n, _) in zip(segs, split):
            chain += _chain_along(profile, a, b, n)
        label, eps = "contact", float(sum(lengths)) / periods
        r_min = min(p[0] for _, pts in chain for p in pts)
        if not r_min > 0:
            raise ValueError(f"periods = {periods}: the grooves (depth {profile.depth * eps / profile.period:.4g} m) "
                             f"reach the axis (r = {r_min:.4g} m); use more periods or a shallower profile")
    # travelled from the tip up, the stem on the left (the reversed chain: each piece's points reversed)
    chain = [(kind, tuple(reversed(pts))) for kind, pts in reversed(chain)]
    geo = SplineGeometry()
    cache: dict = {}
    tol = 1e-12 * d.z_stem_top

    def point(p, h=None):
        key = (round(p[0] / tol), round(p[1] / tol))
        if key not in cache:
            cache[key] = geo.AppendPoint(*p, maxh=h) if h else geo.AppendPoint(*p)
        return cache[key]

    for p, h in (((0.0, d.z_tip), None), ((0.0, d.z_stem_top), None), ((d.r_tip, d.z_tip), hcorner),
                 ((d.r_stem, d.z_corner), hcorner), ((d.r_stem, d.z_bone_top), hcorner),
                 ((d.r_stem, d.z_stem_top), None), ((d.r_tip, 0.0), None), ((d.r_bone, 0.0), None),
                 ((d.r_bone, d.z_bone_top), None)):
        point(p, h)

    def seg(a, b, left, right, bc):
        geo.Append(["line", point(a), point(b)], leftdomain=left, rightdomain=right, bc=bc)

    seg((0.0, d.z_tip), (d.r_tip, d.z_tip), STEM, 0, "stem_tip")
    for kind, pts in chain:
        geo.Append([kind, *[point(p) for p in pts]], leftdomain=STEM, rightdomain=BONE, bc=label, maxh=hint)
    seg((d.r_stem, d.z_bone_top), (d.r_stem, d.z_stem_top), STEM, 0, "stem_side")
    seg((d.r_stem, d.z_stem_top), (0.0, d.z_stem_top), STEM, 0, "stem_top")
    seg((0.0, d.z_stem_top), (0.0, d.z_tip), STEM, 0, "axis")
    seg((d.r_tip, 0.0), (d.r_bone, 0.0), BONE, 0, "base")
    seg((d.r_bone, 0.0), (d.r_bone, d.z_bone_top), BONE, 0, "bone_outer")
    seg((d.r_bone, d.z_bone_top), (d.r_stem, d.z_bone_top), BONE, 0, "bone_top")
    seg((d.r_tip, d.z_tip), (d.r_tip, 0.0), BONE, 0, "canal")
    geo.SetMaterial(STEM, regions[0])
    geo.SetMaterial(BONE, regions[1])
    mesh = ng.Mesh(mesher.generate(geo, maxh=maxh, grading=grading))
    if order > 1:
        mesh.Curve(order)
    return FemurMesh(mesh=mesh, interface=label, periods=0 if profile is None else periods, eps=eps,
                     length=float(sum(lengths)), segments=split)


def femur_stem_body(dims, points) -> np.ndarray:
    """Which body each point ``(r, z)`` lies in with the flat interface: 0 stem, 1 bone, -1 outside."""
    d = dims
    pts = np.asarray(points, float).reshape(-1, 2)
    r, z = pts[:, 0], pts[:, 1]
    slope = (d.r_stem - d.r_tip) / (d.z_corner - d.z_tip)
    r_int = np.where(z < d.z_tip, d.r_tip, np.where(z < d.z_corner, d.r_tip + slope * (z - d.z_tip), d.r_stem))
    stem = (z > d.z_tip) & (z < d.z_stem_top) & (r >= 0) & (r < r_int)
    bone = (z > 0) & (z < d.z_bone_top) & (r > r_int) & (r < d.r_bone)
    return np.where(stem, 0, np.where(bone, 1, -1))


def distance_to_polyline(segments, points) -> np.ndarray:
    """Euclidean distance of each point to the union of the segments ``[(a, b), ...]``."""
    pts = np.asarray(points, float).reshape(-1, 2)
    out = np.full(len(pts), np.inf)
    for a, b in segments:
        a, b = np.asarray(a, float), np.asarray(b, float)
        ab = b - a
        t = np.clip((pts - a) @ ab / (ab @ ab), 0.0, 1.0)
        out = np.minimum(out, np.linalg.norm(pts - (a + t[:, None] * ab), axis=1))
    return out
