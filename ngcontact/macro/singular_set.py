"""The set a body's stress is singular on: points (2D) and edges (3D), with the distance to them.

In 2D the stress of linear elasticity is unbounded at isolated points of a body's boundary (Williams 1952:
``|x - x_i|^(lambda - 1)`` or ``log |x - x_i|``); in 3D at the same wedges run along edges of the
boundary, where the leading term is the 2D one of the wedge in the plane normal to the edge, in the
distance to the edge (Grisvard 1985, the edge singularities of a polyhedral domain).  So the 2D finders
(:mod:`ngcontact.macro.away_maxima`) answer with points and the 3D ones
(:mod:`ngcontact.macro.singular_edges`) with edges; both answer the questions the maxima away from the
singular set ask of it through :class:`SingularSet`:

* :meth:`SingularSet.distance`: the distance of points to the set, the smallest over its points and its
  straight segments (the chords of the mesh's boundary edges along a singular edge; on a curved edge a
  chord is within its sagitta of the edge, a share of the element size well inside the tubes it is used
  with);
* :meth:`SingularSet.rim`: points on the boundary of the region within ``r`` of the set (a circle around
  each point, rings around each segment at stations at most ``r`` apart), where a stress growing
  towards the set attains its maximum outside that region;
* :meth:`SingularSet.star`: the volume elements that touch the set, which a local refinement at the set
  halves (a vertex at a point; in 3D a vertex within a quarter of the element's shortest edge of a
  segment, so that the vertices a refinement puts on a curved edge, off its chords, still count);
* :meth:`SingularSet.record`: what the report says of it (per connected curve of segments its reason,
  length and ends).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import ngsolve as ng
import numpy as np

#: a vertex within this share of its element's shortest edge of a segment touches the set (module docstring)
TOUCH = 0.25


@dataclass(frozen=True)
class SingularSet:
    """Singular ``points`` (one row each) and ``edges`` (``m x 2 x dim``: straight segments), with why each is
    singular (``why`` per point, ``edge_why`` per segment)."""

    points: np.ndarray
    why: tuple[str, ...]
    edges: np.ndarray
    edge_why: tuple[str, ...] = ()

    @classmethod
    def of_points(cls, points: np.ndarray, why: tuple[str, ...]) -> SingularSet:
        points = np.asarray(points, dtype=float)
        dim = points.shape[1] if points.ndim == 2 else 2
        return cls(points.reshape(-1, dim), tuple(why), np.zeros((0, 2, dim)))

    @property
    def dim(self) -> int:
        return int(self.points.shape[1])

    def __len__(self) -> int:
        return len(self.points) + len(self.edges)

    def distance(self, xyz: np.ndarray, upto: float | None = None) -> np.ndarray:
        """The distance of each of the points ``xyz`` (one row each) to the set (``inf``: an empty set);
        with ``upto``, exact where it is at most ``upto`` and ``inf`` where it is larger (a search tree over
        the segments' middles finds the segments that can be that near)."""
        xyz = np.asarray(xyz, dtype=float).reshape(-1, self.dim)
        out = self.points_distance(xyz)
        if not len(self.edges):
            return out
        if upto is None:
            for a, b in _chunks(self.edges):
                out = np.minimum(out, segment_distance(xyz, a, b).min(axis=1))
            return out
        return np.minimum(out, self._near_edges(xyz, upto))

    def _near_edges(self, xyz: np.ndarray, upto: float) -> np.ndarray:
        """The distance to the segments where at most ``upto``, else ``inf``."""
        from scipy.spatial import cKDTree
        a, b = self.edges[:, 0], self.edges[:, 1]
        half = 0.5 * float(np.linalg.norm(b - a, axis=1).max())
        hits = cKDTree((a + b) / 2.0).query_ball_point(xyz, upto + half * (1.0 + 1e-9), return_sorted=False)
        counts = np.fromiter((len(h) for h in hits), dtype=int, count=len(xyz))
        out = np.full(len(xyz), math.inf)
        if not counts.sum():
            return out
        rows = np.repeat(np.arange(len(xyz)), counts)
        segs = np.concatenate([np.asarray(h, dtype=int) for h in hits if len(h)])
        ab = b[segs] - a[segs]
        rel = xyz[rows] - a[segs]
        t = np.clip((rel * ab).sum(axis=1) / np.maximum((ab * ab).sum(axis=1), 1e-300), 0.0, 1.0)
        d = np.linalg.norm(rel - t[:, None] * ab, axis=1)
        np.minimum.at(out, rows, d)
        return np.where(out <= upto, out, math.inf)

    def rim(self, radius: float, count: int) -> np.ndarray:
        """Points at distance ``radius`` from the set: ``count`` on a circle around each point (2D), ``count``
        on rings around each segment at stations at most ``radius`` apart (3D), each offset by half a step
        (none on a plane of symmetry through the set), those not nearer to another part of the set."""
        parts = [_circles(self.points, radius, count)] if len(self.points) and self.dim == 2 else []
        if len(self.edges):
            parts.append(_rings(self.edges, radius, count))
        if not parts:
            return np.zeros((0, self.dim))
        pts = np.vstack(parts)
        return pts[self.distance(pts, radius) >= radius * (1.0 - 1e-9)]

    def star(self, mesh: ng.Mesh) -> np.ndarray:
        """The volume elements that touch the set (module docstring), as a boolean array."""
        out = np.zeros(mesh.ne, dtype=bool)
        if not len(self):
            return out
        pts = np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])
        tol = 1e-9 * float(np.abs(pts).max())
        at_point = self.points_distance(pts) <= tol
        to_edge = np.full(len(pts), math.inf)
        for a, b in _chunks(self.edges):
            to_edge = np.minimum(to_edge, segment_distance(pts, a, b).min(axis=1))
        for el in mesh.Elements(ng.VOL):
            vs = [v.nr for v in el.vertices]
            reach = TOUCH * _shortest_edge(pts[vs]) + tol
            out[el.nr] = bool(at_point[vs].any() or (to_edge[vs] <= reach).any())
        return out

    def points_distance(self, xyz: np.ndarray) -> np.ndarray:
        """The distance of each of ``xyz`` to the set's points alone."""
        if not len(self.points):
            return np.full(len(xyz), math.inf)
        return np.linalg.norm(xyz[:, None, :] - self.points[None, :, :], axis=2).min(axis=1)

    def nearest(self, xyz: tuple[float, ...]) -> tuple[float, ...]:
        """The point of the set nearest to ``xyz``."""
        x = np.asarray(xyz, dtype=float)
        best, where = math.inf, x
        for p in self.points:
            if np.linalg.norm(p - x) < best:
                best, where = float(np.linalg.norm(p - x)), p
        for a, b in self.edges:
            t = float(np.clip(np.dot(x - a, b - a) / max(np.dot(b - a, b - a), 1e-300), 0.0, 1.0))
            q = a + t * (b - a)
            if np.linalg.norm(q - x) < best:
                best, where = float(np.linalg.norm(q - x)), q
        return tuple(float(c) for c in where)

    def curves(self) -> list[dict]:
        """The segments joined into connected curves of one reason each: reason, length, segments, ends."""
        out = []
        for reason in dict.fromkeys(self.edge_why):
            segs = self.edges[[k for k, w in enumerate(self.edge_why) if w == reason]]
            for group in _connected(segs):
                ends = _ends(segs[group])
                out.append({"why": reason, "segments": len(group),
                            "length": float(np.linalg.norm(segs[group, 1] - segs[group, 0], axis=1).sum()),
                            "ends": [[float(c) for c in p] for p in ends]})
        return out


def segment_distance(xyz: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The distance of each point ``xyz`` (n x dim) to each segment ``a[j] b[j]`` (n x m)."""
    ab = b - a
    length2 = np.maximum((ab * ab).sum(axis=1), 1e-300)
    rel = xyz[:, None, :] - a[None, :, :]
    t = np.clip((rel * ab[None, :, :]).sum(axis=2) / length2[None, :], 0.0, 1.0)
    return np.linalg.norm(rel - t[:, :, None] * ab[None, :, :], axis=2)


def _chunks(edges: np.ndarray, size: int = 256):
    """The segments in chunks (bounded memory for many points)."""
    for k in range(0, len(edges), size):
        yield edges[k:k + size, 0], edges[k:k + size, 1]


def _shortest_edge(vertices: np.ndarray) -> float:
    n = len(vertices)
    return min(float(np.linalg.norm(vertices[i] - vertices[j])) for i in range(n) for j in range(i + 1, n))


def _circles(points: np.ndarray, radius: float, count: int) -> np.ndarray:
    angle = 2.0 * math.pi * (np.arange(count) + 0.5) / count
    ring = np.column_stack([np.cos(angle), np.sin(angle)]) * radius
    return (np.repeat(points, count, axis=0) + np.tile(ring, (len(points), 1))).reshape(-1, 2)


def _rings(edges: np.ndarray, radius: float, count: int) -> np.ndarray:
    """Per segment rings of ``count`` points at distance ``radius``, in the planes normal to it at stations
    at most ``radius`` apart (the middles of equal parts)."""
    angle = 2.0 * math.pi * (np.arange(count) + 0.5) / count
    out = []
    for a, b in edges:
        axis = b - a
        length = float(np.linalg.norm(axis))
        if length == 0.0:
            continue
        axis = axis / length
        helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
        u = np.cross(axis, helper)
        u /= np.linalg.norm(u)
        v = np.cross(axis, u)
        ring = radius * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)
        stations = max(1, math.ceil(length / radius))
        for t in (np.arange(stations) + 0.5) / stations:
            out.append(a + t * (b - a) + ring)
    return np.vstack(out) if out else np.zeros((0, 3))


def _connected(segs: np.ndarray) -> list[list[int]]:
    """The indices of ``segs`` grouped by shared end points."""
    parent = list(range(len(segs)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    keys: dict[tuple, int] = {}
    for k, seg in enumerate(segs):
        for p in seg:
            key = tuple(np.round(p, 12))
            if key in keys:
                parent[root(k)] = root(keys[key])
            else:
                keys[key] = k
    groups: dict[int, list[int]] = {}
    for k in range(len(segs)):
        groups.setdefault(root(k), []).append(k)
    return list(groups.values())


def _ends(segs: np.ndarray) -> list[np.ndarray]:
    """The end points of a connected curve of segments (those used once; a closed curve: its first point)."""
    seen: dict[tuple, int] = {}
    at: dict[tuple, np.ndarray] = {}
    for seg in segs:
        for p in seg:
            key = tuple(np.round(p, 12))
            seen[key] = seen.get(key, 0) + 1
            at[key] = p
    ends = [at[k] for k, n in seen.items() if n == 1]
    return ends if ends else [segs[0, 0]]
