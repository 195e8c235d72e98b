"""Two solids read from a CAD file (STEP, IGES, BREP) through Netgen's OCC kernel, meshed as a macro geometry.

:func:`read_cad` loads the file (``netgen.occ.OCCGeometry``), requires two
solids and glues them (``netgen.occ.Glue``): where they touch, the two
coincident faces become one face both solids bound, so the mesh is conforming
there.  Those shared faces are the macro interface ``S_0`` (boundary
``interface``); each body keeps its own region (``rough``, ``counter``), so the
two sides of ``S_0`` stay apart in the displacement spaces as for the
built-in shapes (:mod:`ngcontact.geometry.bodies`).

A planar model (plane strain; axisymmetry with ``x = r``, ``y = z``) is two
faces in ``z = 0``, read with ``dim = 2``: the same holds one dimension
lower, its "faces" are the boundary curves (edges), sampled along their
parameter and recognised as lines or circular arcs
(:func:`~ngcontact.geometry.model_faces.curve_form`).

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
                                            curve_form, surface_form)

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
    dim: int = 3

    def bodies_listing(self) -> str:
        text = super().bodies_listing()
        return text.replace(", volume ", ", area ") if self.dim == 2 else text

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


def read_cad(path: str, key: str = "geometry.file", dim: int = 3) -> CadModel:
    """Read, glue and list the two bodies of ``path``: solids (``dim = 3``) or planar faces in ``z = 0``
    (``dim = 2``, whose "faces" are then their edges; module docstring)."""
    from netgen.occ import Glue, OCCGeometry

    what = "solids" if dim == 3 else "planar faces"
    try:
        shape = OCCGeometry(path, dim=dim).shape
    except Exception as exc:  # the kernel's own message says what it could not read
        raise GeometryError(key, path, f"not readable as CAD ({exc})") from None
    bodies = list(shape.solids if dim == 3 else shape.faces)
    if len(bodies) != 2 or (dim == 2 and len(shape.solids) > 0):
        raise GeometryError(key, path, f"holds {len(shape.solids)} solids and {len(shape.faces)} faces; a "
                            f"{dim}D macro model needs exactly two {what} (the rough and the counter body)")
    glued = Glue(bodies)
    parts = list(glued.solids if dim == 3 else glued.faces)
    if len(parts) != 2:
        raise GeometryError(key, path, f"the two {what} overlap (gluing them gives {len(parts)}); model them "
                            "touching along the interface, with the interference as a negative interface.gap")
    entities = _distinct(glued.faces if dim == 3 else glued.edges)
    lo, hi = (np.array(p) for p in glued.bounding_box)
    size = float(np.linalg.norm(hi - lo))
    samples = _surface_triangles(glued, len(entities), size) if dim == 3 else [_edge_samples(e) for e in entities]
    faces = []
    for i, f in enumerate(entities):
        owners = tuple(k for k, s in enumerate(parts) if any(f == g for g in (s.faces if dim == 3 else s.edges)))
        form = surface_form(samples[i], FORM_TOLERANCE * size) if dim == 3 else \
            curve_form(samples[i], FORM_TOLERANCE * size)
        faces.append(ModelFace(index=i, label=f.name, bodies=owners, area=float(f.mass),
                               centroid=tuple(float(c) for c in f.center), triangles=samples[i], form=form,
                               measure="area" if dim == 3 else "length"))
    model = CadModel(path=path, shape=glued, solids=parts, occ_faces=entities, faces=faces, dim=dim,
                     solid_names=[s.name for s in parts], size=size, volumes=[float(s.mass) for s in parts])
    if not model.interface_faces():
        raise GeometryError(key, path, f"the two {what} share no boundary: they must touch along the interface "
                            "(the interference, if any, is a negative interface.gap); the bodies are\n"
                            + model.bodies_listing())
    return model


def _edge_samples(edge, n: int = 16) -> np.ndarray:
    """Points along ``edge`` as degenerate triangles ``(p_i, p_i+1, p_i+1)``, shape ``(n, 3, 3)``."""
    t0, t1 = edge.parameter_interval
    pts = np.array([tuple(edge.Value(t)) for t in np.linspace(t0, t1, n + 1)])
    return np.stack([pts[:-1], pts[1:], pts[1:]], axis=1)


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
        if model.dim == 3:
            solid.mat(name)
        else:   # a planar face's name is its region's
            solid.name = name
    for f, face in zip(model.occ_faces, model.faces):
        if len(face.bodies) == 2:
            f.name = "interface"
            f.maxh = interface_maxh / length_unit
        else:
            f.name = labels.get(face.index, face.label or UNNAMED)
    shape = model.shape.Scale(Pnt(0, 0, 0), length_unit) if length_unit != 1.0 else model.shape
    mesh = ng.Mesh(OCCGeometry(shape, dim=model.dim).GenerateMesh(maxh=maxh))
    if order > 1:
        mesh.Curve(order)
    names = sorted(set(mesh.GetBoundaries()))
    return MacroGeometry(mesh=mesh, rough=ROUGH, counter=COUNTER,
                         boundaries={n: "selected in the scene" if n in labels.values() else
                                     "the faces the bodies share" if n == "interface" else "named in the file"
                                     for n in names},
                         dims={"length_unit": length_unit})
