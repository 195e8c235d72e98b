"""The faces of a two-body model read from a file: what each is, where it lies, which body it bounds.

A :class:`ModelFace` is known by samples of its surface (the triangles of a
coarse surface mesh, vertices on the exact surface) together with the exact
area and centroid where the source has them.  Its :class:`SurfaceForm` is
recognised from the samples, so that a user can pick faces by geometry
(:mod:`ngcontact.geometry.face_selectors`) and ``ngcontact check`` can list
them:

* a **plane** when every sample lies within the tolerance of the least-squares
  plane through them (normal: the singular vector of the smallest singular
  value of the centred samples);
* a **cylinder** when every sample lies within the tolerance of a circular
  cylinder ``| (x - p) - ((x - p) . d) d | = R``, fitted by least squares from
  a start whose axis ``d`` is the direction most nearly orthogonal to the
  triangles' normals (the eigenvector of the smallest eigenvalue of
  ``sum n n^T``) and whose centre and radius are the algebraic circle fit of
  the samples projected on the plane orthogonal to ``d``;
* **other** otherwise.

Lengths are in the file's own units throughout.
"""
from __future__ import annotations

from abc import ABC, abstractmethod

from dataclasses import dataclass
from typing import ClassVar

import numpy as np


@dataclass(frozen=True)
class SurfaceForm:
    """What a face is: ``kind`` ``plane`` (with ``normal``), ``cylinder`` (``point``, ``axis``, ``radius``)
    or ``other``; of a planar model's boundary curve: ``line`` (``normal`` in the plane), ``arc``
    (``point`` its centre, ``axis`` ``z``, ``radius``) or ``other curve``."""

    kind: str
    normal: tuple[float, ...] | None = None
    point: tuple[float, ...] | None = None
    axis: tuple[float, ...] | None = None
    radius: float | None = None

    def describe(self) -> str:
        if self.kind in ("plane", "line"):
            return f"{self.kind}, normal " + _vec(self.normal)
        if self.kind == "cylinder":
            return f"cylinder, axis {_vec(self.axis)} through {_vec(self.point)}, radius {self.radius:.6g}"
        if self.kind == "arc":
            return f"circular arc, centre {_vec(self.point)}, radius {self.radius:.6g}"
        return "other " + ("curve" if self.kind == "other curve" else "surface")


@dataclass(frozen=True)
class ModelFace:
    """One face of the model.

    ``index``: its number in the model (0-based, as ``ngcontact check``
    lists it); ``label``: the name the file gives it, or None; ``bodies``:
    indices of the bodies it bounds (two for a face they share);
    ``triangles``: samples of the surface, shape ``(n, 3, 3)`` (of a planar
    model's boundary curve: segments as degenerate triangles, and ``area``
    is its length, ``measure`` says which).
    """

    index: int
    label: str | None
    bodies: tuple[int, ...]
    area: float
    centroid: tuple[float, ...]
    triangles: np.ndarray
    form: SurfaceForm
    measure: str = "area"

    @property
    def points(self) -> np.ndarray:
        return self.triangles.reshape(-1, 3)

    def distance(self, point) -> float:
        """Distance from ``point`` to the sampled surface (exact for planar faces)."""
        return float(point_triangle_distance(np.asarray(point, dtype=float), self.triangles).min())

    def describe(self, body_names: dict[int, str]) -> str:
        owner = " and ".join(body_names.get(b, f"body {b}") for b in self.bodies)
        name = f"{self.label!r}" if self.label else "(no name)"
        return (f"face {self.index}: {name}, {owner}, {self.measure} {self.area:.6g}, centroid {_vec(self.centroid)}, "
                f"{self.form.describe()}")


def _vec(v) -> str:
    """Components shown to 6 digits, those below ``1e-9`` of the largest shown as 0."""
    floor = 1e-9 * max(1.0, max(abs(x) for x in v))
    return "(" + ", ".join(f"{0.0 if abs(x) < floor else x:.6g}" for x in v) + ")"


def _unit(v: np.ndarray) -> np.ndarray:
    v = v / np.linalg.norm(v)
    k = int(np.argmax(np.abs(v) > 1e-9))   # first clearly nonzero component positive: one sign per direction
    return -v if v[k] < 0 else v


def surface_form(triangles: np.ndarray, tolerance: float) -> SurfaceForm:
    """The :class:`SurfaceForm` of the surface sampled by ``triangles`` (module docstring)."""
    pts = triangles.reshape(-1, 3)
    centred = pts - pts.mean(axis=0)
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]
    if np.abs(centred @ normal).max() <= tolerance:
        return SurfaceForm("plane", normal=tuple(_unit(normal)))
    cylinder = _fit_cylinder(triangles)
    if cylinder is not None:
        p, d, r = cylinder
        if np.abs(_axis_distance(pts, p, d) - r).max() <= tolerance:
            return SurfaceForm("cylinder", point=tuple(p), axis=tuple(_unit(d)), radius=float(r))
    return SurfaceForm("other")


def curve_form(segments: np.ndarray, tolerance: float) -> SurfaceForm:
    """The form of a boundary curve in the plane ``z = 0`` sampled by ``segments``: a ``line`` when every
    sample lies within the tolerance of the least-squares line, an ``arc`` when within it of the algebraic
    circle fit ``u^2 + v^2 = a u + b v + c``, else ``other curve``."""
    pts = segments.reshape(-1, 3)[:, :2]
    centred = pts - pts.mean(axis=0)
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]
    if np.abs(centred @ normal).max() <= tolerance:
        return SurfaceForm("line", normal=tuple(_unit(np.array([normal[0], normal[1], 0.0]))))
    A = np.column_stack([pts, np.ones(len(pts))])
    (a, b, c), *_ = np.linalg.lstsq(A, (pts ** 2).sum(axis=1), rcond=None)
    centre = np.array([a / 2, b / 2])
    r2 = c + centre @ centre
    if r2 > 0 and np.abs(np.linalg.norm(pts - centre, axis=1) - np.sqrt(r2)).max() <= tolerance:
        return SurfaceForm("arc", point=(float(centre[0]), float(centre[1]), 0.0), axis=(0.0, 0.0, 1.0),
                           radius=float(np.sqrt(r2)))
    return SurfaceForm("other curve")


def _axis_distance(pts: np.ndarray, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    rel = pts - p
    return np.linalg.norm(rel - np.outer(rel @ d, d), axis=1)


def _fit_cylinder(triangles: np.ndarray):
    """``(point on the axis closest to the origin, axis, radius)`` fitted to the samples, or None."""
    from scipy.optimize import least_squares

    pts = triangles.reshape(-1, 3)
    n = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    n = n[np.linalg.norm(n, axis=1) > 0]
    if len(n) < 2:
        return None
    n /= np.linalg.norm(n, axis=1)[:, None]
    d = np.linalg.eigh(n.T @ n)[1][:, 0]
    e1 = np.linalg.svd(np.eye(3) - np.outer(d, d))[0][:, 0]
    e2 = np.cross(d, e1)
    u, v = pts @ e1, pts @ e2
    A = np.column_stack([u, v, np.ones_like(u)])
    (cu, cv, k), *_ = np.linalg.lstsq(A, u * u + v * v, rcond=None)
    r2 = k + (cu * cu + cv * cv) / 4
    if not r2 > 0:
        return None
    start = np.concatenate([cu / 2 * e1 + cv / 2 * e2, d, [np.sqrt(r2)]])

    def residual(z):
        axis = z[3:6] / np.linalg.norm(z[3:6])
        return _axis_distance(pts, z[:3], axis) - z[6]

    z = least_squares(residual, start).x
    axis = z[3:6] / np.linalg.norm(z[3:6])
    foot = z[:3] - (z[:3] @ axis) * axis
    return foot, axis, abs(z[6])


def point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distances from the point ``p`` to each triangle of ``tri`` (shape ``(n, 3, 3)``).

    The foot of the perpendicular when it falls inside the triangle (its
    barycentric coordinates all >= 0), else the nearest of the three edges.
    """
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    e0, e1 = b - a, c - a
    normal = np.cross(e0, e1)
    area2 = np.einsum("ij,ij->i", normal, normal)
    ok = area2 > 0
    w = p - a
    safe = np.where(ok, area2, 1.0)
    beta = np.einsum("ij,ij->i", np.cross(w, e1), normal) / safe
    gamma = np.einsum("ij,ij->i", np.cross(e0, w), normal) / safe
    inside = ok & (beta >= 0) & (gamma >= 0) & (beta + gamma <= 1)
    plane = np.abs(np.einsum("ij,ij->i", w, normal)) / np.sqrt(safe)
    edges = np.min([_segment_distance(p, s, t) for s, t in ((a, b), (b, c), (c, a))], axis=0)
    return np.where(inside, plane, edges)


def _segment_distance(p: np.ndarray, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    d = t - s
    length2 = np.einsum("ij,ij->i", d, d)
    lam = np.clip(np.einsum("ij,ij->i", p - s, d) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    return np.linalg.norm(p - (s + lam[:, None] * d), axis=1)


#: the region names of the two bodies in a model's mesh, and the label of faces nothing names
MODEL_ROUGH, MODEL_COUNTER, MODEL_UNNAMED = "rough", "counter", "free"


@dataclass
class TwoBodyModel(ABC):
    """Two bodies read from a file and their faces, before meshing (in the file's units as read).

    Subclasses (a CAD file, :mod:`ngcontact.geometry.cad_model`; a mesh
    file, :mod:`ngcontact.geometry.mesh_model`) say which bodies contain a
    point and produce the :class:`~ngcontact.geometry.bodies.MacroGeometry`.
    """

    path: str
    faces: list[ModelFace]
    solid_names: list[str | None]
    volumes: list[float]
    size: float
    #: whether :meth:`mesh` meshes the model (with the scene's sizes) or uses a mesh the file holds
    meshed_here: ClassVar[bool] = True

    @property
    def tolerance(self) -> float:
        """Default tolerance of the geometric selectors: ``1e-4`` of the bounding-box diagonal."""
        return 1e-4 * self.size

    def body_names(self, rough: int, counter: int) -> dict[int, str]:
        return {rough: f"rough (body {rough})", counter: f"counter (body {counter})"}

    #: what ``volumes`` measure (a planar model's bodies have areas)
    body_measure: ClassVar[str] = "volume"

    def bodies_listing(self) -> str:
        return "\n".join(f"  body {i}: {repr(self.solid_names[i]) if self.solid_names[i] else '(no name)'}, "
                         f"{self.body_measure} {v:.6g}" for i, v in enumerate(self.volumes))

    def interface_faces(self) -> list[ModelFace]:
        return [f for f in self.faces if len(f.bodies) == 2]

    @abstractmethod
    def containing(self, point) -> list[int]:
        """The bodies ``point`` lies in (within the tolerance)."""

    @abstractmethod
    def mesh(self, rough: int, counter: int, labels: dict[int, str], *, length_unit: float, maxh: float,
             interface_maxh: float, order: int):
        """The :class:`~ngcontact.geometry.bodies.MacroGeometry` in metres: regions ``rough``, ``counter``,
        boundary ``interface`` on the shared faces, ``labels`` (face index -> name) on the selected ones,
        the file's names on the others, :data:`MODEL_UNNAMED` where it has none."""


def body_index(model: TwoBodyModel, key: str, *, name: str | None = None, index: int | None = None,
               point: tuple[float, ...] | None = None) -> int:
    """The body a scene means by its ``name`` in the file, its ``index`` or a ``point`` inside it."""
    from ngcontact.errors import GeometryError

    what: object
    if name is not None:
        found, what = [i for i, n in enumerate(model.solid_names) if n == name], name
    elif index is not None:
        found, what = ([index] if 0 <= index < len(model.volumes) else []), index
    else:
        assert point is not None
        found, what = model.containing(point), list(point)
    if len(found) != 1:
        raise GeometryError(key, what, ("names no body" if not found else "lies in both bodies (on the interface)")
                            + " of the model; the bodies are\n" + model.bodies_listing())
    return found[0]
