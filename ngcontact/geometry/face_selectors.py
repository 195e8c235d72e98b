"""Faces of a model picked by the name the file gives them or by where they lie.

Each selector answers one question, :meth:`FaceSelector.pick`: which of the
model's :class:`~ngcontact.geometry.model_faces.ModelFace` it means.  The
geometric ones test every sample of a face against a tolerance (lengths in
the file's units), so a face is taken whole or not at all:

* :class:`ByName`: the faces the file names so (STEP names, Gmsh physical groups);
* :class:`ByIndex`: faces by their number in ``ngcontact check``'s list;
* :class:`OnPlane`: every sample within ``tolerance`` of the plane through
  ``point`` with normal ``normal``;
* :class:`OnCylinder`: every sample within ``tolerance`` of the cylinder of
  ``radius`` about the axis through ``point`` along ``axis``;
* :class:`InBox`: every sample inside the box ``[low, high]`` (widened by ``tolerance``);
* :class:`NearestTo`: the one face nearest ``point``, refused as ambiguous when
  another face is as near within ``tolerance``.

:func:`label_faces` applies a table of named selectors and refuses, with the
list of all faces, a selector that matches nothing, one that matches a face
both bodies share (the interface is not a boundary for supports or loads),
and a face two names claim.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ngcontact.errors import GeometryError
from ngcontact.geometry.model_faces import ModelFace


class FaceSelector(Protocol):
    """Picks faces of a model; ``key`` is where the scene states it (for messages)."""

    @property
    def key(self) -> str: ...

    def pick(self, faces: list[ModelFace], tolerance: float) -> list[ModelFace]: ...


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


@dataclass(frozen=True)
class ByName:
    key: str
    name: str

    def pick(self, faces, tolerance):
        return [f for f in faces if f.label == self.name]


@dataclass(frozen=True)
class ByIndex:
    key: str
    indices: tuple[int, ...]

    def pick(self, faces, tolerance):
        known = {f.index for f in faces}
        for i in self.indices:
            if i not in known:
                raise GeometryError(self.key, list(self.indices),
                                    f"face {i} does not exist; the model has faces 0 to {len(faces) - 1}")
        return [f for f in faces if f.index in self.indices]


@dataclass(frozen=True)
class OnPlane:
    key: str
    point: tuple[float, ...]
    normal: tuple[float, ...]
    tolerance: float | None = None

    def pick(self, faces, tolerance):
        tol = self.tolerance or tolerance
        n = _unit(self.normal)
        return [f for f in faces if np.abs((f.points - np.asarray(self.point)) @ n).max() <= tol]


@dataclass(frozen=True)
class OnCylinder:
    key: str
    point: tuple[float, ...]
    axis: tuple[float, ...]
    radius: float
    tolerance: float | None = None

    def pick(self, faces, tolerance):
        tol = self.tolerance or tolerance
        d = _unit(self.axis)
        out = []
        for f in faces:
            rel = f.points - np.asarray(self.point)
            r = np.linalg.norm(rel - np.outer(rel @ d, d), axis=1)
            if np.abs(r - self.radius).max() <= tol:
                out.append(f)
        return out


@dataclass(frozen=True)
class InBox:
    key: str
    low: tuple[float, ...]
    high: tuple[float, ...]
    tolerance: float | None = None

    def pick(self, faces, tolerance):
        tol = self.tolerance or tolerance
        lo, hi = np.asarray(self.low) - tol, np.asarray(self.high) + tol
        return [f for f in faces if np.all((f.points >= lo) & (f.points <= hi))]


@dataclass(frozen=True)
class NearestTo:
    key: str
    point: tuple[float, ...]
    tolerance: float | None = None

    def pick(self, faces, tolerance):
        tol = self.tolerance or tolerance
        dist = np.array([f.distance(self.point) for f in faces])
        best = np.flatnonzero(dist <= dist.min() + tol)
        if len(best) > 1:
            raise GeometryError(self.key, list(self.point),
                                "ambiguous: faces " + ", ".join(str(faces[k].index) for k in best)
                                + f" are all {dist.min():.6g} away (within the tolerance {tol:g}); move the point "
                                "into the face you mean, or select by plane, cylinder or box\n" + listing(faces))
        return [faces[int(best[0])]]


def listing(faces: list[ModelFace], body_names: dict[int, str] | None = None) -> str:
    """Every face on a line: index, name, bodies, area, centroid, form (``ngcontact check`` prints this)."""
    return "\n".join("  " + f.describe(body_names or {}) for f in faces)


def label_faces(faces: list[ModelFace], selectors: dict[str, FaceSelector], tolerance: float,
                body_names: dict[int, str] | None = None) -> dict[int, str]:
    """Face index -> boundary name for every face a selector picks (module docstring's refusals)."""
    owner: dict[int, str] = {}
    for name, selector in selectors.items():
        picked = selector.pick(faces, tolerance)
        if not picked:
            raise GeometryError(selector.key, name, "matches no face of the model; the faces are\n"
                                + listing(faces, body_names))
        for f in picked:
            if len(f.bodies) > 1:
                raise GeometryError(selector.key, name, f"matches face {f.index}, which both bodies share (the "
                                    "interface, which carries the law and takes no support or load); the faces are\n"
                                    + listing(faces, body_names))
            if f.index in owner:
                raise GeometryError(selector.key, name, f"ambiguous: face {f.index} is also selected as "
                                    f"{owner[f.index]!r}; a face belongs to one boundary; the faces are\n"
                                    + listing(faces, body_names))
            owner[f.index] = name
    return owner
