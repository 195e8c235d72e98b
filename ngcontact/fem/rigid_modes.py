"""Rigid motions that the supports and the interface leave free.

The energy of the two bodies (paper eq. 8) is positive definite on the
displacements that vanish on the Dirichlet boundary ``Gamma_D`` (eq. 5) only
when no rigid motion survives the constraints: otherwise the system is
singular and a solver either fails or drifts to an answer that means
nothing.  The rigid motions of one body are

    u(x) = c + omega x (x - x_c)         (3D: 3 translations, 3 rotations)
    u(x) = c + omega e_z x (x - x_c)     (plane strain: 2 translations, 1 rotation)
    u(r, z) = c e_z                      (axisymmetric: the axial translation only)

and the constraints are linear in their coefficients (each group, one
support component or the interface tie, weighted by one over the root of
its number of rows, so that a finer mesh does not outweigh a shorter
boundary): a support fixing
component ``i`` on a boundary demands ``u_i(x) = 0`` at its points, and the
interface ties the two bodies by ``n0 . (u_rough - u_counter) = 0`` (every
closed unilateral or linear law) and, when the law holds tangentially (an
elastic ``k_t0`` or friction), by the whole jump.  The free modes are the
null space of that small matrix (one column per rigid coefficient of each
body), evaluated at the support and interface vertices; independent of
the load.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.errors import ModelError
from ngcontact.fem.elasticity import COMPONENTS

#: a singular value of the (group-normalized) constraint matrix below this
#: fraction of the largest is a free mode.  A curved bore meshed at order 2
#: holds a frictionless ring's rotation with about 2e-3 (its normal is
#: radial to 4e-3), a support at an O(1) lever with about 0.3: "nearly free"
#: is singular in practice (the solve drifts or fails), so it is refused.
NULL_RTOL = 1e-2


def _modes(setting: str) -> list[str]:
    if setting == "axisymmetric":
        return ["translation in z"]
    if setting == "plane_strain":
        return ["translation in x", "translation in y", "rotation in the x-y plane"]
    return ["translation in x", "translation in y", "translation in z",
            "rotation about x", "rotation about y", "rotation about z"]


def _values(setting: str, pts: np.ndarray, centre: np.ndarray, size: float) -> np.ndarray:
    """``(n_points, n_components, n_modes)``: each rigid mode at the points."""
    n = len(pts)
    if setting == "axisymmetric":
        out = np.zeros((n, 2, 1))
        out[:, 1, 0] = 1.0
        return out
    d = (pts - centre) / size
    if setting == "plane_strain":
        out = np.zeros((n, 2, 3))
        out[:, 0, 0] = out[:, 1, 1] = 1.0
        out[:, 0, 2], out[:, 1, 2] = -d[:, 1], d[:, 0]
        return out
    out = np.zeros((n, 3, 6))
    for i in range(3):
        out[:, i, i] = 1.0
    for k in range(3):  # rotation about axis k: e_k x d
        e = np.zeros(3)
        e[k] = 1.0
        out[:, :, 3 + k] = np.cross(e, d)
    return out


def _vertex_sets(mesh, regions) -> list[set[int]]:
    sets: list[set[int]] = [set() for _ in regions]
    index = {name: i for i, name in enumerate(regions)}
    for el in mesh.Elements(ng.VOL):
        i = index.get(el.mat)
        if i is not None:
            sets[i].update(v.nr for v in el.vertices)
    return sets


def _interface_rows(mesh, label: str, normal_only: bool):
    """Points of the interface and the directions the tie constrains there.

    The points are the interface vertices.  The normal at a vertex is the
    principal direction of the normals of the elements meeting there (the
    mesh's own, curved elements included, signs irrelevant): on a circle
    meshed with straight chords it is exactly radial, so a frictionless ring
    whose rotation only the chords' corners would hold is still found free.
    """
    dim = mesh.dim
    corners = [(0.0,), (1.0,)] if dim == 2 else [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
    rule = ng.IntegrationRule(corners, [0.0] * len(corners))
    mips = mesh.MapToAllElements(rule, mesh.Boundaries(label))
    xyz = np.asarray(ng.CF((ng.x, ng.y, ng.z)[:dim])(mips)).reshape(-1, dim)
    if not len(xyz):
        return xyz, xyz
    size = float(np.max(np.ptp(xyz, axis=0))) or 1.0
    keys, which = np.unique(np.round(xyz / (1e-9 * size)).astype(np.int64), axis=0, return_inverse=True)
    which = which.ravel()
    points = np.zeros((len(keys), dim))
    np.add.at(points, which, xyz)
    points /= np.bincount(which)[:, None]
    if not normal_only:
        return np.repeat(points, dim, axis=0), np.tile(np.eye(dim), (len(points), 1))
    n = np.asarray(ng.specialcf.normal(dim)(mips)).reshape(-1, dim)
    # weights: one over the element's size, which makes the vertex normal of
    # points on a circle radial for chords of any lengths
    span = xyz.reshape(-1, len(corners), dim)
    size_el = np.linalg.norm(span[:, 1] - span[:, 0], axis=1) if dim == 2 else \
        np.linalg.norm(np.cross(span[:, 1] - span[:, 0], span[:, 2] - span[:, 0]), axis=1)
    weight = np.repeat(1.0 / np.maximum(size_el, 1e-300), len(corners))
    scatter = np.zeros((len(keys), dim, dim))
    np.add.at(scatter, which, weight[:, None, None] * n[:, :, None] * n[:, None, :])
    _, vecs = np.linalg.eigh(scatter)
    return points, vecs[:, :, -1]


def free_rigid_modes(mesh, setting: str, regions: tuple[str, str], supports, interface: str,
                     holds_tangentially: bool) -> list[str]:
    """Descriptions of the rigid motions no support or interface tie removes.

    Parameters
    ----------
    mesh, setting
        The mesh and its setting.
    regions
        The two bodies' region names (rough, counter).
    supports
        :class:`ngcontact.fem.two_body.Support` items (label, components).
    interface
        The interface label.
    holds_tangentially
        Whether the interface law resists a tangential jump.

    Returns
    -------
    list of str
        Empty when the model is fixed; otherwise one phrase per free mode,
        e.g. ``"body 'block': rotation in the x-y plane"``.
    """
    comps = COMPONENTS[setting]
    names = _modes(setting)
    m = len(names)
    pts = np.array([v.point for v in mesh.vertices], dtype=float)[:, :mesh.dim]
    owned = _vertex_sets(mesh, regions)
    size = float(np.max(np.ptp(pts, axis=0))) or 1.0
    centres = [pts[sorted(s)].mean(axis=0) if s else np.zeros(mesh.dim) for s in owned]
    rows = []
    labelled: dict[str, set[int]] = {}
    for el in mesh.Elements(ng.BND):
        labelled.setdefault(el.mat, set()).update(v.nr for v in el.vertices)
    for s in supports:
        on = labelled.get(s.label, set())
        for b, body in enumerate(owned):
            idx = sorted(on & body)
            if not idx:
                continue
            vals = _values(setting, pts[idx], centres[b], size)
            for c in (s.components or comps):
                block = np.zeros((len(idx), 2 * m))
                block[:, b * m:(b + 1) * m] = vals[:, comps.index(c), :]
                rows.append(block / np.sqrt(len(idx)))
    where, dirs = _interface_rows(mesh, interface, normal_only=not holds_tangentially)
    if len(where):
        a = np.einsum("pc,pcm->pm", dirs, _values(setting, where, centres[0], size))
        b = np.einsum("pc,pcm->pm", dirs, _values(setting, where, centres[1], size))
        rows.append(np.hstack([a, -b]) / np.sqrt(len(where) / (1 if not holds_tangentially else mesh.dim)))
    A = np.vstack(rows) if rows else np.zeros((1, 2 * m))
    _, sv, vt = np.linalg.svd(A.T @ A)
    top = max(float(sv[0]), 1e-300)
    out = []
    for k in np.flatnonzero(sv <= NULL_RTOL ** 2 * top):  # sv: squares of A's singular values
        vec = vt[k]
        j = int(np.argmax(np.abs(vec)))
        both = np.abs(vec[(1 - j // m) * m + j % m]) > 0.5 * np.abs(vec[j])
        who = "both bodies together" if both else f"body {regions[j // m]!r}"
        out.append(f"{who}: {names[j % m]}")
    return out


def check_rigid_modes(mesh, setting: str, regions: tuple[str, str], supports, interface: str,
                      holds_tangentially: bool) -> None:
    """Raise :class:`ModelError` naming every rigid motion the model leaves free."""
    free = free_rigid_modes(mesh, setting, regions, supports, interface, holds_tangentially)
    if free:
        held = "; ".join(f"{s.label} {list(s.components or COMPONENTS[setting])}" for s in supports) or "none"
        raise ModelError(f"the supports ({held}) leave a rigid-body motion free: {', '.join(free)}; "
                         "the system would be singular: fix more components or boundaries")
