"""The keys of a macro geometry read from a file (``geometry.shape = "file"``): which solid is which body,
and faces named by the file or picked by where they lie.

Coordinates, radii and tolerances of the selectors are in the units of the
file as read (millimetres for STEP and IGES, see
:mod:`ngcontact.geometry.cad_model`); ``geometry.length_unit`` scales the
model to metres.  Each table here builds the geometry room's selector
(:mod:`ngcontact.geometry.face_selectors`), which the model check applies
before meshing.
"""
from __future__ import annotations

from dataclasses import dataclass

from ngcontact.errors import MISSING, SceneError
from ngcontact.geometry import face_selectors as fs
from ngcontact.scene.schema import positive, param

#: Boundary labels of a file geometry, for the README reference.
FILE_BOUNDARY_DOCS = {
    "interface": "the faces (planar model: curves) the two bodies share, found by gluing them; carries the law",
    "NAME": "every table geometry.boundaries.NAME: the faces its selector picks",
    "(file names)": "the names the file gives faces no selector picks; the others are `free`",
}


def _unit_vector(v) -> str | None:
    return None if any(x != 0 for x in v) else "must not be the zero vector"


@dataclass(frozen=True, kw_only=True)
class BodySpec:
    """Which solid of the file a body is: exactly one of name, index, point."""

    name: str | None = param(None, doc="the solid's name in the file (a mesh: its region's)")
    index: int | None = param(None, doc="the solid's index as `ngcontact check` lists it (0 or 1)")
    point: tuple[float, float, float] | None = param(None, doc="a point inside the solid (planar model: "
                                                     "(x, y, 0) inside the face)", units="file units")

    def check(self, path: str) -> None:
        given = [k for k in ("name", "index", "point") if getattr(self, k) is not None]
        if len(given) != 1:
            raise SceneError(path, {k: getattr(self, k) for k in given} or MISSING,
                             "give exactly one of name, index, point")


@dataclass(frozen=True, kw_only=True)
class PlaneSpec:
    """A plane through a point with a normal."""

    point: tuple[float, float, float] = param(doc="a point of the plane", units="file units")
    normal: tuple[float, float, float] = param(doc="its normal (any length, not zero)", check=_unit_vector)


@dataclass(frozen=True, kw_only=True)
class CylinderSpec:
    """A circular cylinder by its axis and radius."""

    point: tuple[float, float, float] = param(doc="a point of the axis", units="file units")
    axis: tuple[float, float, float] = param(doc="direction of the axis (not zero)", check=_unit_vector)
    radius: float = param(doc="radius", units="file units", check=positive())


@dataclass(frozen=True, kw_only=True)
class BoxSpec:
    """An axis-aligned box."""

    low: tuple[float, float, float] = param(doc="smallest x, y, z", units="file units")
    high: tuple[float, float, float] = param(doc="largest x, y, z", units="file units")

    def check(self, path: str) -> None:
        if any(h < lo for lo, h in zip(self.low, self.high)):
            raise SceneError(f"{path}.high", list(self.high), f"must be >= low = {list(self.low)} componentwise")


SELECTORS = ("name", "index", "plane", "cylinder", "box", "nearest")


@dataclass(frozen=True, kw_only=True)
class FaceSelectorSpec:
    """Faces of the file's model: exactly one selector (the faces picked whole, every sample within tolerance)."""

    name: str | None = param(None, doc="the faces the file names so (a STEP face name, a mesh's boundary "
                             "region, a Gmsh physical surface)")
    index: tuple[int, ...] | None = param(None, doc="faces by their index in `ngcontact check`'s list")
    plane: PlaneSpec | None = param(None, doc="the faces lying on a plane")
    cylinder: CylinderSpec | None = param(None, doc="the faces lying on a cylinder")
    box: BoxSpec | None = param(None, doc="the faces lying inside a box")
    nearest: tuple[float, float, float] | None = param(None, doc="the one face nearest this point",
                                                       units="file units")
    tolerance: float | None = param(None, doc="distance within which a face lies on the plane, cylinder or "
                                    "box, or two faces are equally near (default 1e-4 of the model's "
                                    "bounding-box diagonal)", units="file units", check=positive())

    def check(self, path: str) -> None:
        given = [k for k in SELECTORS if getattr(self, k) is not None]
        if len(given) != 1:
            raise SceneError(path, given or MISSING, "give exactly one selector of " + ", ".join(SELECTORS))

    def selector(self, key: str) -> fs.FaceSelector:
        """The geometry room's selector; ``key`` is this table's place in the scene."""
        tol = self.tolerance
        if self.name is not None:
            return fs.ByName(key, self.name)
        if self.index is not None:
            return fs.ByIndex(key, self.index)
        if self.plane is not None:
            return fs.OnPlane(key, self.plane.point, self.plane.normal, tol)
        if self.cylinder is not None:
            c = self.cylinder
            return fs.OnCylinder(key, c.point, c.axis, c.radius, tol)
        if self.box is not None:
            return fs.InBox(key, self.box.low, self.box.high, tol)
        assert self.nearest is not None
        return fs.NearestTo(key, self.nearest, tol)


def check_file_geometry(geometry, path: str) -> None:
    """The keys of ``shape = "file"``: the file, its unit, the two bodies, no dimensions; a mesh in 3D."""
    from ngcontact.geometry.cad_model import CAD_SUFFIXES
    from ngcontact.geometry.mesh_model import MESH_SUFFIXES

    if geometry.shape != "file":
        raise SceneError(f"{path}.file", geometry.file, "only used with shape = 'file'; remove it")
    if geometry.file is None:
        raise SceneError(f"{path}.file", MISSING, "required for shape = 'file': the CAD file of the two bodies")
    suffix = "." + geometry.file.rsplit(".", 1)[-1].lower() if "." in geometry.file else ""
    if suffix not in (*CAD_SUFFIXES, *MESH_SUFFIXES):
        raise SceneError(f"{path}.file", geometry.file, "must end in one of " + ", ".join((*CAD_SUFFIXES,
                                                                                            *MESH_SUFFIXES)))
    unit = CAD_SUFFIXES.get(suffix)
    if unit is not None and geometry.length_unit not in (None, unit):
        raise SceneError(f"{path}.length_unit", geometry.length_unit,
                         f"a {suffix} file is read in millimetres whatever unit it declares (the reader "
                         f"converts): the length unit is {unit:g}; omit it")
    if geometry.setting != "3d" and suffix not in CAD_SUFFIXES:
        raise SceneError(f"{path}.setting", geometry.setting, "a mesh file takes setting '3d' (a planar model "
                         "for plane strain or axisymmetry comes from a CAD file of two faces in z = 0)")
    if geometry.dimensions is not None:
        raise SceneError(f"{path}.dimensions", geometry.dimensions, "the file gives the dimensions; remove them")
    for key in ("rough", "counter"):
        if getattr(geometry, key) is None:
            raise SceneError(f"{path}.{key}", MISSING, "required for shape = 'file': which solid of the file "
                             "(a table with name, index or point)")
    if "interface" in (geometry.boundaries or {}):
        raise SceneError(f"{path}.boundaries.interface", "interface", "reserved: the interface is the faces "
                         "the two bodies share, found from the file; choose another name")


def file_length_unit(geometry) -> float:
    """Metres per unit of the file as read: ``geometry.length_unit``, else the format's."""
    from ngcontact.geometry.cad_model import CAD_SUFFIXES

    if geometry.length_unit is not None:
        return geometry.length_unit
    return CAD_SUFFIXES.get("." + geometry.file.rsplit(".", 1)[-1].lower()) or 1.0
