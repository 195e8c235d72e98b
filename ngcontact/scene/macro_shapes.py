"""The built-in macro shapes: their settings, dimensions, regions, boundary labels and extent.

What a macro scene may name without meshing: the femur with its hip stem
(:mod:`ngcontact.geometry.femur`, axisymmetric or a 3D quarter,
:mod:`ngcontact.geometry.femur3d`), two coaxial tubes and a block on a base
(:mod:`ngcontact.geometry.bodies`); ``file`` names two bodies read from a
file, whose regions are ``rough`` and ``counter`` and whose labels the scene
selects (:mod:`ngcontact.scene.file_geometry`), so it has no entry in the
label tables here.  ``tests/scene/test_bad_input.py`` checks
that the labels listed here are exactly those the meshers create; the scene
layer validates supports and loads against them before any mesh exists.
"""
from __future__ import annotations

import dataclasses
import math

from ngcontact.errors import MISSING, SceneError
from ngcontact.geometry.femur import FemurStemDims, femur_interface_length

SHAPES = ("femur_stem", "coaxial", "block", "file")
SETTINGS = {"femur_stem": ("axisymmetric", "3d"), "coaxial": ("plane_strain", "axisymmetric", "3d"),
            "block": ("plane_strain",), "file": ("plane_strain", "axisymmetric", "3d")}
DIMENSIONS = {"femur_stem": tuple(f.name for f in dataclasses.fields(FemurStemDims)),
              "coaxial": ("a", "b", "c", "height"), "block": ("length", "h_block", "h_base"), "file": ()}
REQUIRED = {"femur_stem": (), "coaxial": ("a", "b", "c"), "block": ("length", "h_block", "h_base"), "file": ()}
#: dimensions that may be 0, with what that means
MAY_BE_ZERO = {("coaxial", "a"): "must be >= 0 (a > 0: the inner body is a tube; a = 0: a solid shaft)"}


def check_dimensions(dims: dict, path: str, shape: str, required) -> None:
    """A ``dimensions`` table: positive (``coaxial``'s inner radius ``a`` may be 0: a solid shaft), known for
    ``shape``, the ``required`` ones present.

    For ``femur_stem`` the completed dimensions must also describe a valid
    femur and stem (:class:`ngcontact.geometry.femur.FemurStemDims`).
    """
    for key in dims:
        if (shape, key) in MAY_BE_ZERO:
            if not dims[key] >= 0:
                raise SceneError(f"{path}.{key}", dims[key], MAY_BE_ZERO[shape, key])
        elif not dims[key] > 0:
            raise SceneError(f"{path}.{key}", dims[key], "must be > 0")
        if key not in DIMENSIONS[shape]:
            raise SceneError(f"{path}.{key}", dims[key],
                             f"unknown dimension of {shape!r}; known: " + ", ".join(DIMENSIONS[shape]))
    for key in required:
        if key not in dims:
            raise SceneError(f"{path}.{key}", MISSING, f"required for shape {shape!r}")
    if shape == "femur_stem":
        try:
            FemurStemDims(**dims).check()
        except ValueError as exc:
            raise SceneError(path, dims, str(exc)) from None


REGIONS = {"femur_stem": ("stem", "bone"), "coaxial": ("inner", "outer"), "block": ("block", "base"),
           "file": ("rough", "counter")}
#: Boundary labels of the meshed geometries (:mod:`ngcontact.geometry.bodies`) by (shape, setting),
#: so that supports and loads are checked without meshing.
FEMUR_BOUNDARIES = {
    "interface": "stem-bone interface S_0 (cone and cylinder); carries the law",
    "axis": "symmetry axis r = 0 of the stem: fix r there (components = [\"r\"])",
    "stem_top": "top face of the stem (where the joint load acts)",
    "stem_side": "stem surface above the bone",
    "stem_tip": "bottom face of the stem",
    "bone_top": "top face of the bone",
    "bone_outer": "outer surface of the femur",
    "canal": "empty canal below the stem tip",
    "base": "base of the femur (clamp it)",
}
_COAXIAL = {"interface": "r = b between the tubes; carries the law", "bore": "inner surface r = a of the inner "
            "tube (a > 0: the inner body is a tube; with a = 0 it is a solid shaft and has no bore; in "
            "axisymmetry its edge r = 0 is then the boundary axis, where r must be fixed: components = [\"r\"])",
            "mantle": "outer surface r = c of the outer tube"}
_QUARTER = {"sym_x": "the cut on the plane x = 0, a symmetry plane: fix x there (components = [\"x\"])",
            "sym_y": "the cut on the plane y = 0, a symmetry plane: fix y there (components = [\"y\"])"}
_ENDS = {"bottom": "end face z = 0 of both tubes", "top": "end face z = height of both tubes"}
#: Boundary labels of each (shape, setting) with what each is and what its supports mean.
BOUNDARY_DOCS: dict[tuple[str, str], dict[str, str]] = {
    ("femur_stem", "axisymmetric"): FEMUR_BOUNDARIES,
    ("femur_stem", "3d"): {**{k: v for k, v in FEMUR_BOUNDARIES.items() if k != "axis"}, **_QUARTER,
                           "stem_inner": "internal faces of the stem where its cone and cylinders meet (no "
                                         "support or load belongs there)"},
    ("coaxial", "plane_strain"): {**_COAXIAL, **_QUARTER},
    ("coaxial", "axisymmetric"): {**_COAXIAL, **_ENDS},
    ("coaxial", "3d"): {**_COAXIAL, **_QUARTER, **_ENDS},
    ("block", "plane_strain"): {
        "interface": "y = 0 between block and base; carries the law",
        "top": "top face of the block (the rough body, above the interface here; in the direct kind the rough "
               "block lies below)",
        "block_sides": "left and right faces of the block", "bottom": "bottom face of the base (the counter body)",
        "base_sides": "left and right faces of the base"},
}
BOUNDARIES = {key: tuple(sorted(labels)) for key, labels in BOUNDARY_DOCS.items()}
#: the boundary of a solid coaxial shaft (a = 0) on the axis r = 0 in axisymmetry
SHAFT_AXIS = "axis"


def boundaries_of(shape: str, setting: str, dims: dict) -> tuple[str, ...]:
    """The boundary labels the mesh of ``shape`` in ``setting`` with ``dims`` has.

    Those of :data:`BOUNDARIES`, except a solid coaxial shaft (``a = 0``):
    no ``bore``, and in axisymmetry its edge on the axis, ``axis``.
    """
    labels = BOUNDARIES[shape, setting]
    if shape == "coaxial" and dims.get("a") == 0:
        labels = tuple(sorted({*labels} - {"bore"} | ({SHAFT_AXIS} if setting == "axisymmetric" else set())))
    return labels


def check_shaft_axis(supports, shape: str, setting: str, dims: dict) -> None:
    """An axisymmetric solid shaft has ``u_r = 0`` on its axis: a support on ``axis`` must fix ``r``.

    The hoop strain ``u_r / r`` of the axisymmetric energy is finite at
    ``r = 0`` only when ``u_r`` vanishes there.
    """
    if not (shape == "coaxial" and setting == "axisymmetric" and dims.get("a") == 0):
        return
    if not any(s.boundary == SHAFT_AXIS and (s.symmetry or not s.components or "r" in s.components)
               and not any(s.displacement) and not s.affine() for s in supports):
        raise SceneError("supports", [s.boundary for s in supports], "a solid shaft (coaxial with a = 0) in "
                         "axisymmetry needs u_r = 0 on its axis: add [[supports]] boundary = \"axis\", "
                         "components = [\"r\"]")
#: A symmetry plane and the one component its support fixes.
SYMMETRY_PLANES = {"sym_x": "x", "sym_y": "y"}


def check_support_meaning(supports, comps: tuple[str, ...], setting: str) -> None:
    """A symmetry plane fixes its normal component only, and every translation is fixed somewhere.

    A support with ``symmetry = true`` fixes its plane's normal component;
    on a boundary whose plane is not known before meshing the translation
    check is left to the rigid-motion check on the mesh
    (:func:`ngcontact.fem.rigid_modes.check_rigid_modes`).

    Swapping the components of the two symmetry supports of a quarter ran
    without complaint and gave a mean pressure 10 % off; a base held only
    in x left the bodies free to translate in y (a singular system).  In
    axisymmetry the radial translation is no rigid motion (the axis or the
    rings hold it), so only z must be fixed.
    """
    for i, s in enumerate(supports):
        normal = SYMMETRY_PLANES.get(s.boundary)
        if normal is not None and tuple(s.components) != (normal,) and not s.symmetry:
            raise SceneError(f"supports[{i}].components", list(s.components) or list(comps),
                             f"{s.boundary!r} is the symmetry plane {normal} = 0: fix only its normal component "
                             f"[{normal!r}] there")
    if any(s.symmetry and s.boundary not in SYMMETRY_PLANES for s in supports):
        return   # a plane's normal is known from the mesh only: the rigid-motion check of the solve has it
    fixed = {c for s in supports
             for c in ((SYMMETRY_PLANES[s.boundary],) if s.symmetry else (s.components or comps))}
    needed = ("z",) if setting == "axisymmetric" else comps
    for c in needed:
        if c not in fixed:
            raise SceneError("supports", [s.boundary for s in supports], f"no support fixes component {c!r}: "
                             f"the bodies could translate freely in {c} (a singular system); fix {c} on some "
                             "boundary")


def macro_extent(shape: str, setting: str, dims: dict) -> tuple[int, float, float, float]:
    """``(dim, area or volume, interface length or area, smallest width)`` of a macro geometry."""
    if shape == "femur_stem":
        d = FemurStemDims(**dims)
        if setting == "3d":
            return 3, math.pi / 4 * d.r_bone ** 2 * d.z_stem_top, math.pi / 2 * d.r_stem * femur_interface_length(d), \
                d.r_bone - d.r_stem
        return 2, d.r_bone * d.z_stem_top, femur_interface_length(d), d.r_bone - d.r_stem
    if shape == "block":
        return 2, dims["length"] * (dims["h_block"] + dims["h_base"]), dims["length"], \
            min(dims["h_block"], dims["h_base"])
    a, b, c = dims["a"], dims["b"], dims["c"]
    width = min(b - a, c - b)
    if setting == "plane_strain":
        return 2, math.pi / 4 * (c * c - a * a), math.pi / 2 * b, width
    if setting == "axisymmetric":
        return 2, (c - a) * dims["height"], dims["height"], width
    return 3, math.pi / 4 * (c * c - a * a) * dims["height"], math.pi / 2 * b * dims["height"], width
