"""Macro bodies meeting along a conforming interface, built with Netgen.

Geometry knows no physics.  Every builder returns a :class:`MacroGeometry`
whose mesh has two regions, the ``rough`` body (paper ``D``, the one carrying
the roughness) and the ``counter`` body (paper ``Omega``), under the region
names listed in ``rough`` and ``counter``, and a boundary ``interface`` (the
macro interface ``S_0``) that both bodies share node for node, so that each
body may carry its own displacement space and the jump across ``S_0`` is
well defined.  The orientation of the mesh's boundary normal on ``interface``
is *not* part of the contract; :mod:`ngcontact.macro.macro_problem` determines ``n0``
(from ``rough`` into ``counter``) itself.

Builders
--------
:func:`femur_stem`
    Axisymmetric hip stem in a femur, coordinates ``(r, z)`` = mesh
    ``(x, y)``; regions ``stem`` (rough: the porous implant coating is on the
    stem) and ``bone`` (counter).
:func:`coaxial_plane_strain`, :func:`coaxial_axisymmetric`
    Two long coaxial tubes (inner ``inner`` = rough, outer ``outer`` =
    counter) for Lame's press fit: a quarter annulus in plane strain, an
    ``(r, z)`` strip in axisymmetry.
:func:`block_on_plane`
    A block (rough) on a base (counter) of the same width, plane strain.
:func:`coaxial_3d`
    Quarter of two coaxial tubes in 3D (``netgen.occ``), the revolved
    counterpart of :func:`coaxial_axisymmetric`.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ng
from netgen.geom2d import SplineGeometry

ROUGH, COUNTER = 1, 2


@dataclass(frozen=True)
class MacroGeometry:
    """A meshed two-body macro geometry (no physics).

    Attributes
    ----------
    mesh
        The NGSolve mesh.
    rough, counter
        Region names of the rough body (paper ``D``) and the counter body.
    boundaries
        Boundary labels with a short description each.
    dims
        The dimensions used (name -> value), for reports.
    """

    mesh: ng.Mesh
    rough: str
    counter: str
    boundaries: dict
    dims: dict


@dataclass(frozen=True, kw_only=True)
class FemurStemDims:
    """Dimensions of the axisymmetric femur with a hip stem, in metres.

    The femur is a hollow cylinder (outer radius ``r_bone``) from its clamped
    base ``z = 0`` up to ``z_bone_top``.  The stem is a solid cylinder of
    radius ``r_stem`` from its top ``z_stem_top`` down to ``z_corner``, below
    which a conical frustum narrows to ``r_tip`` at ``z_tip``.  The canal
    follows the stem (the interface) and continues below the tip as an empty
    canal of radius ``r_tip`` down to the base.
    """

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


def femur_stem(dims: FemurStemDims = FemurStemDims(), *, maxh: float, interface_maxh: float | None = None,
               corner_maxh: float | None = None, order: int = 1) -> MacroGeometry:
    """Mesh the axisymmetric femur (``bone``) with a hip stem (``stem``) in ``(r, z)``.

    Parameters
    ----------
    dims
        The dimensions, see :class:`FemurStemDims`.
    maxh, interface_maxh
        Mesh size in the bodies and along the interface.
    corner_maxh
        Mesh size at the points where the interface ends or turns (stem tip,
        cone-cylinder corner, bone top); default ``interface_maxh``.
    order
        Geometry order (the boundaries are straight, so 1 suffices).

    Boundaries: ``interface`` (stem-bone), ``axis`` (``r = 0``),
    ``stem_top`` (loaded face), ``stem_side`` (stem above the bone),
    ``stem_tip`` (bottom face of the stem), ``bone_top``, ``bone_outer``,
    ``canal`` (empty canal below the tip), ``base`` (clamped).
    """
    dims.check()
    d = dims
    hint = interface_maxh or maxh
    hcorner = corner_maxh or hint
    geo = SplineGeometry()
    pts = {}

    def p(name, x, y, h=None):
        pts[name] = geo.AppendPoint(x, y, maxh=h) if h else geo.AppendPoint(x, y)

    p("axis_tip", 0.0, d.z_tip)
    p("axis_top", 0.0, d.z_stem_top)
    p("tip", d.r_tip, d.z_tip, hcorner)
    p("corner", d.r_stem, d.z_corner, hcorner)
    p("bone_top_in", d.r_stem, d.z_bone_top, hcorner)
    p("stem_top_out", d.r_stem, d.z_stem_top)
    p("base_in", d.r_tip, 0.0)
    p("base_out", d.r_bone, 0.0)
    p("bone_top_out", d.r_bone, d.z_bone_top)

    def seg(a, b, left, right, bc, h=None):
        kw = {"maxh": h} if h else {}
        geo.Append(["line", pts[a], pts[b]], leftdomain=left, rightdomain=right, bc=bc, **kw)

    STEM, BONE = ROUGH, COUNTER
    seg("axis_tip", "tip", STEM, 0, "stem_tip")
    seg("tip", "corner", STEM, BONE, "interface", hint)
    seg("corner", "bone_top_in", STEM, BONE, "interface", hint)
    seg("bone_top_in", "stem_top_out", STEM, 0, "stem_side")
    seg("stem_top_out", "axis_top", STEM, 0, "stem_top")
    seg("axis_top", "axis_tip", STEM, 0, "axis")
    seg("base_in", "base_out", BONE, 0, "base")
    seg("base_out", "bone_top_out", BONE, 0, "bone_outer")
    seg("bone_top_out", "bone_top_in", BONE, 0, "bone_top")
    seg("tip", "base_in", BONE, 0, "canal")
    geo.SetMaterial(STEM, "stem")
    geo.SetMaterial(BONE, "bone")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    return MacroGeometry(mesh=mesh, rough="stem", counter="bone", dims=dict(vars(d)), boundaries={
        "interface": "stem-bone interface S_0 (cone and cylinder)",
        "axis": "symmetry axis r = 0 of the stem",
        "stem_top": "top face of the stem (loaded)",
        "stem_side": "stem surface above the bone",
        "stem_tip": "bottom face of the stem",
        "bone_top": "top face of the bone",
        "bone_outer": "outer surface of the femur",
        "canal": "empty canal below the stem tip",
        "base": "base of the femur (clamped)"})


def coaxial_axisymmetric(a: float, b: float, c: float, height: float, *, maxh: float,
                         order: int = 1) -> MacroGeometry:
    """Two coaxial tubes ``a < r < b`` (``inner``) and ``b < r < c`` (``outer``) in ``(r, z)``.

    Boundaries: ``interface`` (``r = b``), ``bore`` (``r = a``), ``mantle``
    (``r = c``), ``bottom`` (``z = 0``), ``top`` (``z = height``).
    """
    if not 0 < a < b < c or height <= 0:
        raise ValueError("need 0 < a < b < c and height > 0")
    geo = SplineGeometry()
    P = [geo.AppendPoint(x, y) for x, y in ((a, 0), (b, 0), (c, 0), (c, height), (b, height), (a, height))]
    geo.Append(["line", P[0], P[1]], leftdomain=ROUGH, rightdomain=0, bc="bottom")
    geo.Append(["line", P[1], P[2]], leftdomain=COUNTER, rightdomain=0, bc="bottom")
    geo.Append(["line", P[2], P[3]], leftdomain=COUNTER, rightdomain=0, bc="mantle")
    geo.Append(["line", P[3], P[4]], leftdomain=COUNTER, rightdomain=0, bc="top")
    geo.Append(["line", P[4], P[5]], leftdomain=ROUGH, rightdomain=0, bc="top")
    geo.Append(["line", P[5], P[0]], leftdomain=ROUGH, rightdomain=0, bc="bore")
    geo.Append(["line", P[1], P[4]], leftdomain=ROUGH, rightdomain=COUNTER, bc="interface")
    geo.SetMaterial(ROUGH, "inner")
    geo.SetMaterial(COUNTER, "outer")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    return MacroGeometry(mesh=mesh, rough="inner", counter="outer",
                         dims={"a": a, "b": b, "c": c, "height": height},
                         boundaries={"interface": "r = b", "bore": "r = a", "mantle": "r = c",
                                     "bottom": "z = 0", "top": "z = height"})


def coaxial_plane_strain(a: float, b: float, c: float, *, maxh: float, order: int = 2) -> MacroGeometry:
    """Quarter cross-section of two coaxial tubes in plane strain (``x, y >= 0``).

    Circular arcs are exact rational splines; ``order`` curves the elements.
    Boundaries: ``interface`` (``r = b``), ``bore`` (``r = a``), ``mantle``
    (``r = c``), ``sym_x`` (the face on ``x = 0``), ``sym_y`` (on ``y = 0``).
    """
    if not 0 < a < b < c:
        raise ValueError("need 0 < a < b < c")
    geo = SplineGeometry()

    def pt(x, y):
        return geo.AppendPoint(x, y)

    A0, B0, C0 = pt(a, 0), pt(b, 0), pt(c, 0)
    A1, B1, C1 = pt(0, a), pt(0, b), pt(0, c)
    Ac, Bc, Cc = pt(a, a), pt(b, b), pt(c, c)   # spline3 control points of the quarter arcs
    geo.Append(["line", A0, B0], leftdomain=ROUGH, rightdomain=0, bc="sym_y")
    geo.Append(["line", B0, C0], leftdomain=COUNTER, rightdomain=0, bc="sym_y")
    geo.Append(["spline3", C0, Cc, C1], leftdomain=COUNTER, rightdomain=0, bc="mantle")
    geo.Append(["line", C1, B1], leftdomain=COUNTER, rightdomain=0, bc="sym_x")
    geo.Append(["line", B1, A1], leftdomain=ROUGH, rightdomain=0, bc="sym_x")
    geo.Append(["spline3", A1, Ac, A0], leftdomain=ROUGH, rightdomain=0, bc="bore")
    geo.Append(["spline3", B0, Bc, B1], leftdomain=ROUGH, rightdomain=COUNTER, bc="interface")
    geo.SetMaterial(ROUGH, "inner")
    geo.SetMaterial(COUNTER, "outer")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    return MacroGeometry(mesh=mesh, rough="inner", counter="outer", dims={"a": a, "b": b, "c": c},
                         boundaries={"interface": "r = b", "bore": "r = a", "mantle": "r = c",
                                     "sym_x": "x = 0", "sym_y": "y = 0"})


def block_on_plane(length: float, h_block: float, h_base: float, *, maxh: float) -> MacroGeometry:
    """A block ``[0, length] x [0, h_block]`` (``block``, rough) on a base below (``base``, counter).

    Boundaries: ``interface`` (``y = 0``), ``top`` (top of the block),
    ``bottom`` (bottom of the base), ``block_sides``, ``base_sides``.
    """
    if min(length, h_block, h_base) <= 0:
        raise ValueError("dimensions must be > 0")
    geo = SplineGeometry()
    P = [geo.AppendPoint(x, y) for x, y in ((0, -h_base), (length, -h_base), (length, 0),
                                             (length, h_block), (0, h_block), (0, 0))]
    geo.Append(["line", P[0], P[1]], leftdomain=COUNTER, rightdomain=0, bc="bottom")
    geo.Append(["line", P[1], P[2]], leftdomain=COUNTER, rightdomain=0, bc="base_sides")
    geo.Append(["line", P[2], P[3]], leftdomain=ROUGH, rightdomain=0, bc="block_sides")
    geo.Append(["line", P[3], P[4]], leftdomain=ROUGH, rightdomain=0, bc="top")
    geo.Append(["line", P[4], P[5]], leftdomain=ROUGH, rightdomain=0, bc="block_sides")
    geo.Append(["line", P[5], P[0]], leftdomain=COUNTER, rightdomain=0, bc="base_sides")
    geo.Append(["line", P[5], P[2]], leftdomain=ROUGH, rightdomain=COUNTER, bc="interface")
    geo.SetMaterial(ROUGH, "block")
    geo.SetMaterial(COUNTER, "base")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh))
    return MacroGeometry(mesh=mesh, rough="block", counter="base",
                         dims={"length": length, "h_block": h_block, "h_base": h_base},
                         boundaries={"interface": "y = 0", "top": "top of the block",
                                     "bottom": "bottom of the base", "block_sides": "x = 0, length (block)",
                                     "base_sides": "x = 0, length (base)"})


def coaxial_3d(a: float, b: float, c: float, height: float, *, maxh: float, order: int = 2) -> MacroGeometry:
    """Quarter (``x, y >= 0``) of two coaxial tubes in 3D, axis ``z``, with ``netgen.occ``.

    Regions ``inner`` (rough, ``a < r < b``) and ``outer`` (counter,
    ``b < r < c``), ``0 < z < height``.  Boundaries: ``interface``, ``bore``,
    ``mantle``, ``bottom``, ``top``, ``sym_x`` (``x = 0``), ``sym_y`` (``y = 0``).
    """
    from netgen.occ import Box, Cylinder, Glue, OCCGeometry, Pnt, X, Y, Z

    if not 0 < a < b < c or height <= 0:
        raise ValueError("need 0 < a < b < c and height > 0")
    quarter = Box(Pnt(0, 0, 0), Pnt(c, c, height))

    def cylinder(r, name):
        cyl = Cylinder(Pnt(0, 0, 0), Z, r=r, h=height)
        cyl.faces.name = name
        return cyl

    inner = (cylinder(b, "interface") - cylinder(a, "bore")) * quarter
    outer = (cylinder(c, "mantle") - cylinder(b, "interface")) * quarter
    inner.mat("inner")
    outer.mat("outer")
    for solid in (inner, outer):
        solid.faces.Min(Z).name = "bottom"
        solid.faces.Max(Z).name = "top"
        solid.faces.Min(X).name = "sym_x"
        solid.faces.Min(Y).name = "sym_y"
    shape = Glue([inner, outer])
    mesh = ng.Mesh(OCCGeometry(shape).GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    return MacroGeometry(mesh=mesh, rough="inner", counter="outer",
                         dims={"a": a, "b": b, "c": c, "height": height},
                         boundaries={"interface": "r = b", "bore": "r = a", "mantle": "r = c",
                                     "bottom": "z = 0", "top": "z = height", "sym_x": "x = 0",
                                     "sym_y": "y = 0"})
