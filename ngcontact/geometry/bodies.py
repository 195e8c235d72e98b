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
(The axisymmetric femur with a hip stem, flat or grooved, has its own
builder: :func:`ngcontact.geometry.femur.femur_stem`.)
:func:`coaxial_plane_strain`, :func:`coaxial_axisymmetric`
    Two long coaxial tubes (inner ``inner`` = rough, outer ``outer`` =
    counter) for Lame's press fit: a quarter annulus in plane strain, an
    ``(r, z)`` strip in axisymmetry.  With inner radius ``a = 0`` the inner
    body is a solid shaft: no ``bore``; in axisymmetry its edge on the axis
    ``r = 0`` is the boundary ``axis``.
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
    boundaries: dict[str, str]
    dims: dict[str, float]


def coaxial_axisymmetric(a: float, b: float, c: float, height: float, *, maxh: float,
                         order: int = 1) -> MacroGeometry:
    """Two coaxial tubes ``a < r < b`` (``inner``) and ``b < r < c`` (``outer``) in ``(r, z)``.

    Boundaries: ``interface`` (``r = b``), ``bore`` (``r = a``), ``mantle``
    (``r = c``), ``bottom`` (``z = 0``), ``top`` (``z = height``); with
    ``a = 0`` (a solid shaft) ``axis`` (``r = 0``) instead of ``bore``.
    """
    if not 0 <= a < b < c or height <= 0:
        raise ValueError("need 0 <= a < b < c and height > 0")
    inside = "bore" if a > 0 else "axis"
    geo = SplineGeometry()
    P = [geo.AppendPoint(x, y) for x, y in ((a, 0), (b, 0), (c, 0), (c, height), (b, height), (a, height))]
    geo.Append(["line", P[0], P[1]], leftdomain=ROUGH, rightdomain=0, bc="bottom")
    geo.Append(["line", P[1], P[2]], leftdomain=COUNTER, rightdomain=0, bc="bottom")
    geo.Append(["line", P[2], P[3]], leftdomain=COUNTER, rightdomain=0, bc="mantle")
    geo.Append(["line", P[3], P[4]], leftdomain=COUNTER, rightdomain=0, bc="top")
    geo.Append(["line", P[4], P[5]], leftdomain=ROUGH, rightdomain=0, bc="top")
    geo.Append(["line", P[5], P[0]], leftdomain=ROUGH, rightdomain=0, bc=inside)
    geo.Append(["line", P[1], P[4]], leftdomain=ROUGH, rightdomain=COUNTER, bc="interface")
    geo.SetMaterial(ROUGH, "inner")
    geo.SetMaterial(COUNTER, "outer")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    return MacroGeometry(mesh=mesh, rough="inner", counter="outer",
                         dims={"a": a, "b": b, "c": c, "height": height},
                         boundaries={"interface": "r = b", inside: f"r = {'a' if a > 0 else 0}", "mantle": "r = c",
                                     "bottom": "z = 0", "top": "z = height"})


def coaxial_plane_strain(a: float, b: float, c: float, *, maxh: float, order: int = 2) -> MacroGeometry:
    """Quarter cross-section of two coaxial tubes in plane strain (``x, y >= 0``).

    Circular arcs are exact rational splines; ``order`` curves the elements.
    Boundaries: ``interface`` (``r = b``), ``bore`` (``r = a``), ``mantle``
    (``r = c``), ``sym_x`` (the face on ``x = 0``), ``sym_y`` (on ``y = 0``);
    with ``a = 0`` the inner body is a quarter disk (no ``bore``).
    """
    if not 0 <= a < b < c:
        raise ValueError("need 0 <= a < b < c")
    geo = SplineGeometry()

    def pt(x, y):
        return geo.AppendPoint(x, y)

    B0, C0 = pt(b, 0), pt(c, 0)
    B1, C1 = pt(0, b), pt(0, c)
    Bc, Cc = pt(b, b), pt(c, c)   # spline3 control points of the quarter arcs
    if a > 0:
        A0, A1, Ac = pt(a, 0), pt(0, a), pt(a, a)
    else:
        A0 = A1 = pt(0, 0)
    geo.Append(["line", A0, B0], leftdomain=ROUGH, rightdomain=0, bc="sym_y")
    geo.Append(["line", B0, C0], leftdomain=COUNTER, rightdomain=0, bc="sym_y")
    geo.Append(["spline3", C0, Cc, C1], leftdomain=COUNTER, rightdomain=0, bc="mantle")
    geo.Append(["line", C1, B1], leftdomain=COUNTER, rightdomain=0, bc="sym_x")
    geo.Append(["line", B1, A1], leftdomain=ROUGH, rightdomain=0, bc="sym_x")
    if a > 0:
        geo.Append(["spline3", A1, Ac, A0], leftdomain=ROUGH, rightdomain=0, bc="bore")
    geo.Append(["spline3", B0, Bc, B1], leftdomain=ROUGH, rightdomain=COUNTER, bc="interface")
    geo.SetMaterial(ROUGH, "inner")
    geo.SetMaterial(COUNTER, "outer")
    mesh = ng.Mesh(geo.GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    labels = {"interface": "r = b", "bore": "r = a", "mantle": "r = c", "sym_x": "x = 0", "sym_y": "y = 0"}
    if a == 0:
        del labels["bore"]
    return MacroGeometry(mesh=mesh, rough="inner", counter="outer", dims={"a": a, "b": b, "c": c},
                         boundaries=labels)


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
    ``mantle``, ``bottom``, ``top``, ``sym_x`` (``x = 0``), ``sym_y`` (``y = 0``);
    with ``a = 0`` the inner body is a quarter of a solid shaft (no ``bore``).
    """
    from netgen.occ import Box, Cylinder, Glue, OCCGeometry, Pnt, X, Y, Z

    if not 0 <= a < b < c or height <= 0:
        raise ValueError("need 0 <= a < b < c and height > 0")
    quarter = Box(Pnt(0, 0, 0), Pnt(c, c, height))

    def cylinder(r, name):
        cyl = Cylinder(Pnt(0, 0, 0), Z, r=r, h=height)
        cyl.faces.name = name
        return cyl

    inner = (cylinder(b, "interface") - cylinder(a, "bore") if a > 0 else cylinder(b, "interface")) * quarter
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
                         boundaries={"interface": "r = b", **({"bore": "r = a"} if a > 0 else {}), "mantle": "r = c",
                                     "bottom": "z = 0", "top": "z = height", "sym_x": "x = 0",
                                     "sym_y": "y = 0"})
