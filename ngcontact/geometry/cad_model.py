"""Two solids read from a CAD file (STEP, IGES, BREP) through Netgen's OCC kernel, meshed as a macro geometry.

:func:`read_cad` loads the file (``netgen.occ.OCCGeometry``), requires two
solids and glues them (``netgen.occ.Glue``): where they touch, the two
coincident faces become one face both solids bound, so the mesh is conforming
there.  Those shared faces are the macro interface ``S_0`` (boundary
``interface``); each body keeps its own region (``rough``, ``counter``), so the
two sides of ``S_0`` stay apart in the displacement spaces as for the
built-in shapes (:mod:`ngcontact.geometry.bodies`).

Every face is listed as a :class:`~ngcontact.geometry.model_faces.ModelFace`
sampled by a coarse surface mesh of the glued model (Netgen numbers its face
descriptors in the order of the shape's distinct faces, the order used here),
with the exact area and centroid from OCC.  Faces are named by the selectors
of :mod:`ngcontact.geometry.face_selectors` before the volume mesh exists.

Units: a STEP or IGES file is read in millimetres, whatever unit it declares
(the OCC reader converts), so its length unit is ``0.001`` m; a BREP file
has no unit.  Selection works in the units as read; the mesh is scaled to
metres by ``length_unit`` (the file's units per metre's inverse).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import ngsolve as ng

from ngcontact.errors import GeometryError
from ngcontact.geometry.bodies import MacroGeometry
from ngcontact.geometry.model_faces import (MODEL_COUNTER, MODEL_ROUGH, MODEL_UNNAMED, ModelFace, TwoBodyModel,
                                            surface_form)

#: file suffixes read through OCC, and the length unit [m] of the coordinates as read
CAD_SUFFIXES = {".step": 1e-3, ".stp": 1e-3, ".iges": 1e-3, ".igs": 1e-3, ".brep": None, ".brp": None}
ROUGH, COUNTER, UNNAMED = MODEL_ROUGH, MODEL_COUNTER, MODEL_UNNAMED
#: relative tolerance (of the model's bounding-box diagonal) of recognising planes and cylinders
FORM_TOLERANCE = 1e-5


@dataclass
class CadModel(TwoBodyModel):
    """The glued solids of a CAD file and their distinct faces (in the units as read)."""

    shape: Any = None
    solids: list = field(default_factory=list)
    occ_faces: list = field(default_factory=list)

    def containing(self, point) -> list[int]:
        from netgen.occ import Pnt, Vertex

        return [i for i, s in enumerate(self.solids) if s.Distance(Vertex(Pnt(*point))) <= self.tolerance]

    def mesh(self, rough: int, counter: int, labels: dict[int, str], *, length_unit: float, maxh: float,
             interface_maxh: float, order: int) -> MacroGeometry:
        return mesh_cad(self, rough, counter, labels, length_unit=length_unit, maxh=maxh,
                        interface_maxh=interface_maxh, order=order)


def _distinct(shapes) -> list:
    out: list = []
    for s in shapes:
        if not any(s == t for t in out):
            out.append(s)
    return out


def read_cad(path: str, key: str = "geometry.file") -> CadModel:
    """Read, glue and list the two solids of ``path`` (module docstring)."""
    from netgen.occ import Glue, OCCGeometry

    try:
        solids = list(OCCGeometry(path).shape.solids)
    except Exception as exc:  # the kernel's own message says what it could not read
        raise GeometryError(key, path, f"not readable as CAD ({exc})") from None
    if len(solids) != 2:
        raise GeometryError(key, path, f"holds {len(solids)} solids; a macro model needs exactly two bodies "
                            "(the rough and the counter body), each one solid")
    glued = Glue(solids)
    if len(glued.solids) != 2:
        raise GeometryError(key, path, "the two solids overlap (gluing them gives "
                            f"{len(glued.solids)} solids); model them touching along the interface, with the "
                            "interference as a negative interface.gap")
    parts = list(glued.solids)
    occ_faces = _distinct(glued.faces)
    lo, hi = (np.array(p) for p in glued.bounding_box)
    size = float(np.linalg.norm(hi - lo))
    triangles = _surface_triangles(glued, len(occ_faces), size)
    faces = []
    for i, f in enumerate(occ_faces):
        owners = tuple(k for k, s in enumerate(parts) if any(f == g for g in s.faces))
        faces.append(ModelFace(index=i, label=f.name, bodies=owners, area=float(f.mass),
                               centroid=tuple(float(c) for c in f.center), triangles=triangles[i],
                               form=surface_form(triangles[i], FORM_TOLERANCE * size)))
    model = CadModel(path=path, shape=glued, solids=parts, occ_faces=occ_faces, faces=faces,
                     solid_names=[s.name for s in parts], size=size, volumes=[float(s.mass) for s in parts])
    if not model.interface_faces():
        raise GeometryError(key, path, "the two solids share no face: they must touch along the interface "
                            "(the interference, if any, is a negative interface.gap); the bodies are\n"
                            + model.bodies_listing())
    return model


def _surface_triangles(shape, n_faces: int, size: float) -> list[np.ndarray]:
    """Triangles of a coarse surface mesh of ``shape``, one array per distinct face."""
    from netgen.meshing import MeshingStep
    from netgen.occ import OCCGeometry

    surface = OCCGeometry(shape).GenerateMesh(maxh=size / 8, perfstepsend=MeshingStep.MESHSURFACE)
    pts = np.array([p.p for p in surface.Points()])
    by_face: list[list] = [[] for _ in range(n_faces)]
    for el in surface.Elements2D():
        by_face[el.index - 1].append([v.nr - 1 for v in el.vertices])
    return [pts[np.asarray(t, dtype=int)] for t in by_face]


def mesh_cad(model: CadModel, rough: int, counter: int, labels: dict[int, str], *, length_unit: float,
             maxh: float, interface_maxh: float, order: int) -> MacroGeometry:
    """The volume mesh of ``model`` in metres: regions ``rough`` and ``counter``, boundary ``interface``
    on the shared faces, ``labels`` (face index -> name) on the selected ones, the file's own names on
    the others, :data:`UNNAMED` where it has none."""
    from netgen.occ import OCCGeometry, Pnt

    for solid, name in ((model.solids[rough], ROUGH), (model.solids[counter], COUNTER)):
        solid.mat(name)
    for f, face in zip(model.occ_faces, model.faces):
        if len(face.bodies) == 2:
            f.name = "interface"
            f.maxh = interface_maxh / length_unit
        else:
            f.name = labels.get(face.index, face.label or UNNAMED)
    shape = model.shape.Scale(Pnt(0, 0, 0), length_unit) if length_unit != 1.0 else model.shape
    mesh = ng.Mesh(OCCGeometry(shape).GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    names = sorted(set(mesh.GetBoundaries()))
    return MacroGeometry(mesh=mesh, rough=ROUGH, counter=COUNTER,
                         boundaries={n: "selected in the scene" if n in labels.values() else
                                     "the faces the bodies share" if n == "interface" else "named in the file"
                                     for n in names},
                         dims={"length_unit": length_unit})
