"""The femur with its hip stem in 3D: the axisymmetric section revolved, a quarter with two symmetry planes.

The solids of :mod:`ngcontact.geometry.femur` (same :class:`FemurStemDims`)
built with ``netgen.occ`` and cut to ``x, y >= 0``: the stem is a cone
from the tip ``(r_tip, z_tip)`` to the corner ``(r_stem, z_corner)`` and a
cylinder of radius ``r_stem`` up to ``z_stem_top``; the bone a cylinder of
radius ``r_bone`` from its base ``z = 0`` to ``z_bone_top``, hollowed by
the stem and, below the tip, by the empty canal of radius ``r_tip``.  The
stem's cylinder is two solids (in the bone and above it) so that its
surface is split where it leaves the bone: the part inside is the
interface, the part above ``stem_side``.

Boundaries: those of the axisymmetric femur (``interface``, ``stem_top``,
``stem_side``, ``stem_tip``, ``bone_top``, ``bone_outer``, ``canal``,
``base``) without ``axis``, plus the symmetry planes ``sym_x`` (``x = 0``)
and ``sym_y`` (``y = 0``).  The interface faces get ``interface_maxh``.
The same press fit solved in axisymmetry and in 3D must agree within the
discretization error (``tests/macro/test_femur_3d.py``).
"""
from __future__ import annotations

import math

import ngsolve as ng

from ngcontact.geometry.femur import FemurMesh, FemurStemDims, femur_interface_length

#: label of the two internal faces that split the stem into its cone and its two cylinders
INNER = "stem_inner"


def femur_stem_3d(dims: FemurStemDims, *, maxh: float, interface_maxh: float | None = None,
                  order: int = 2) -> FemurMesh:
    """Mesh the quarter femur with its stem (module docstring); curved to ``order``."""
    from netgen.occ import Box, Cone, Cylinder, Glue, OCCGeometry, Pnt, X, Y, Z, gp_Ax2

    d = dims
    d.check()
    quarter = Box(Pnt(0, 0, 0), Pnt(2 * d.r_bone, 2 * d.r_bone, 2 * d.z_stem_top))
    ih = interface_maxh or maxh

    def named(solid, side, top=None, bottom=None):
        solid.faces.name = side
        if top is not None:
            solid.faces.Max(Z).name = top
        if bottom is not None:
            solid.faces.Min(Z).name = bottom
        return solid

    cone = named(Cone(gp_Ax2(Pnt(0, 0, d.z_tip), Z), r1=d.r_tip, r2=d.r_stem, h=d.z_corner - d.z_tip,
                      angle=2 * math.pi),
                 "interface", top=INNER, bottom="stem_tip")
    seated = named(Cylinder(Pnt(0, 0, d.z_corner), Z, r=d.r_stem, h=d.z_bone_top - d.z_corner), "interface",
                   top=INNER, bottom=INNER)
    proud = named(Cylinder(Pnt(0, 0, d.z_bone_top), Z, r=d.r_stem, h=d.z_stem_top - d.z_bone_top),
                  "stem_side", top="stem_top", bottom=INNER)
    canal = named(Cylinder(Pnt(0, 0, 0), Z, r=d.r_tip, h=d.z_tip), "canal")
    bone = named(Cylinder(Pnt(0, 0, 0), Z, r=d.r_bone, h=d.z_bone_top), "bone_outer", top="bone_top",
                 bottom="base")
    bone = (bone - cone - seated - canal) * quarter
    stem = [s * quarter for s in (cone, seated, proud)]
    for solid, mat in [(bone, "bone")] + [(s, "stem") for s in stem]:
        solid.mat(mat)
        solid.faces.Min(X).name = "sym_x"
        solid.faces.Min(Y).name = "sym_y"
        for face in solid.faces:
            if face.name == "interface":
                face.maxh = ih
    mesh = ng.Mesh(OCCGeometry(Glue([bone, *stem])).GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    return FemurMesh(mesh=mesh, interface="interface", periods=0, eps=femur_interface_length(d),
                     length=femur_interface_length(d))
