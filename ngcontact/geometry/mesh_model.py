"""Two regions of a volume mesh read from a file (Netgen ``.vol``, Gmsh ``.msh``), used as a macro geometry.

The mesh must be of tetrahedra (surface triangles) in exactly two regions
(Netgen materials, Gmsh physical volumes), the two bodies; which bodies a
boundary region bounds is found from the tetrahedra on either side of its
triangles (a Gmsh file does not say).  Its faces are its boundary regions (Netgen face
descriptors; Gmsh physical surfaces, read by ``netgen.read_gmsh.ReadGmsh``),
each a :class:`~ngcontact.geometry.model_faces.ModelFace` sampled by its own
triangles, with the area and area-weighted
centroid of those triangles.  A boundary region with a body on both sides is
the macro interface ``S_0``: the mesh is conforming there by construction, and
each body keeps its own region, so the two sides stay apart in the
displacement spaces as for the built-in shapes.

The mesh is used as it is: the element size of the scene does not apply, and
the elements stay straight (a mesh file carries no geometry to curve them
on).  Lengths are the file's; ``length_unit`` scales them to metres.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import ngsolve as ng

from ngcontact.errors import GeometryError
from ngcontact.geometry.bodies import MacroGeometry
from ngcontact.geometry.model_faces import (MODEL_COUNTER, MODEL_ROUGH, MODEL_UNNAMED, ModelFace, TwoBodyModel,
                                            surface_form)

#: file suffixes read as meshes
MESH_SUFFIXES = (".vol", ".msh")
#: relative tolerance (of the bounding-box diagonal) of recognising planes and cylinders
FORM_TOLERANCE = 1e-5


@dataclass
class MeshModel(TwoBodyModel):
    """A volume mesh of two regions and its boundary regions (in the file's units)."""

    meshed_here: ClassVar[bool] = False

    ngmesh: Any = None
    tets: Any = None          # (n, 4, 3) vertex coordinates of the volume elements
    tet_body: Any = None      # (n,) body index of each
    descriptors: Any = None   # the face descriptor number (1-based) of each face

    def containing(self, point) -> list[int]:
        p = np.asarray(point, dtype=float)
        a = self.tets[:, 0]
        T = np.stack([self.tets[:, k] - a for k in (1, 2, 3)], axis=2)
        ok = np.abs(np.linalg.det(T)) > 0
        lam = np.linalg.solve(np.where(ok[:, None, None], T, np.eye(3)), (p - a)[:, :, None])[:, :, 0]
        slack = self.tolerance / self.size
        inside = ok & np.all(lam >= -slack, axis=1) & (lam.sum(axis=1) <= 1 + slack)
        return sorted({int(b) for b in self.tet_body[inside]})

    def mesh(self, rough: int, counter: int, labels: dict[int, str], *, length_unit: float, maxh: float,
             interface_maxh: float, order: int) -> MacroGeometry:
        m = self.ngmesh
        m.SetMaterial(rough + 1, MODEL_ROUGH)
        m.SetMaterial(counter + 1, MODEL_COUNTER)
        for face in self.faces:
            name = "interface" if len(face.bodies) == 2 else labels.get(face.index, face.label or MODEL_UNNAMED)
            m.FaceDescriptor(self.descriptors[face.index]).bcname = name
        if length_unit != 1.0:
            m.Scale(length_unit)
        mesh = ng.Mesh(m)
        names = sorted(set(mesh.GetBoundaries()))
        return MacroGeometry(mesh=mesh, rough=MODEL_ROUGH, counter=MODEL_COUNTER,
                             boundaries={n: "selected in the scene" if n in labels.values() else
                                         "the faces the bodies share" if n == "interface" else "named in the file"
                                         for n in names},
                             dims={"length_unit": length_unit})


def _load(path: str, key: str):
    import netgen.meshing as nm

    try:
        if path.lower().endswith(".msh"):
            from netgen.read_gmsh import ReadGmsh
            return ReadGmsh(path)
        m = nm.Mesh()
        m.Load(path)
        return m
    except Exception as exc:  # the reader's own message says what it could not read
        raise GeometryError(key, path, f"not readable as a mesh ({type(exc).__name__}: {exc})") from None


def _face_bodies(tets: np.ndarray, tet_body: np.ndarray) -> dict[tuple, set]:
    """The bodies on either side of every triangle of the tetrahedra (sorted vertex numbers -> bodies)."""
    out: dict[tuple, set] = {}
    for corners in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
        for key, body in zip(map(tuple, np.sort(tets[:, corners], axis=1).tolist()), tet_body.tolist()):
            out.setdefault(key, set()).add(body)
    return out


def read_mesh(path: str, key: str = "geometry.file") -> MeshModel:
    """Read ``path`` and list its two regions and its boundary regions (module docstring)."""
    m = _load(path, key)
    tet_body = np.array([el.index - 1 for el in m.Elements3D()], dtype=int)
    regions = len(set(tet_body.tolist()))
    if m.dim != 3 or regions != 2 or any(len(el.vertices) != 4 for el in m.Elements3D()):
        raise GeometryError(key, path, f"a {m.dim}D mesh of {regions} regions; a macro model needs a 3D mesh of "
                            "tetrahedra in exactly two regions (the rough and the counter body)")
    pts = m.Coordinates()
    tets = np.array([[v.nr - 1 for v in el.vertices] for el in m.Elements3D()])
    adjacent = _face_bodies(tets, tet_body)
    volumes = np.abs(np.linalg.det(np.stack([pts[tets[:, k]] - pts[tets[:, 0]] for k in (1, 2, 3)], axis=2))) / 6
    size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    flat = int(np.count_nonzero(~(volumes > 1e-12 * size ** 3)))   # NaN counts: a point the reader left unset
    if flat or not np.isfinite(pts).all():
        raise GeometryError(key, path, f"holds {flat} of its {len(tets)} tetrahedra of zero volume (or points that "
                            "are not finite): the file is damaged or truncated; write it again")
    by_face: list[list] = [[] for _ in range(m.GetNFaceDescriptors())]
    owners: list[set] = [set() for _ in by_face]
    for el in m.Elements2D():
        v = [p.nr - 1 for p in el.vertices]
        by_face[el.index - 1].append(v)
        owners[el.index - 1] |= adjacent.get(tuple(sorted(v)), set())
    faces: list[ModelFace] = []
    numbers: list[int] = []
    for k, tris in enumerate(by_face):
        if not tris:        # a face descriptor without elements (a reader's placeholder)
            continue
        i, fd = len(faces), m.FaceDescriptor(k + 1)
        numbers.append(k + 1)
        owners[i] = owners[k]
        tri = pts[np.asarray(tris, dtype=int)].reshape(-1, 3, 3)
        areas = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        bodies = tuple(sorted(owners[i]))
        fd.domin, fd.domout = (bodies[0] + 1 if bodies else 0), (bodies[1] + 1 if len(bodies) == 2 else 0)
        label = fd.bcname if fd.bcname not in ("", "default") else None
        faces.append(ModelFace(index=i, label=label, bodies=bodies, area=float(areas.sum()),
                               centroid=tuple(areas @ tri.mean(axis=1) / areas.sum()), triangles=tri,
                               form=surface_form(tri, FORM_TOLERANCE * size)))
    model = MeshModel(path=path, faces=faces, solid_names=[m.GetMaterial(k) for k in (1, 2)],
                      volumes=[float(volumes[tet_body == b].sum()) for b in (0, 1)], size=size, ngmesh=m,
                      tets=pts[tets], tet_body=tet_body, descriptors=numbers)
    if not model.interface_faces():
        raise GeometryError(key, path, "no boundary region lies between the two regions: the bodies must share "
                            "the faces of their interface; the bodies are\n" + model.bodies_listing())
    return model
