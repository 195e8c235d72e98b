"""The macro state at points of the interface ``S_0`` and the cell loads it makes (paper eqs. 49-51, 63, 72-75).

A cell at a point ``x`` of ``S_0`` is loaded by the macro stress through the
mean traction it transmits across the layer (the far-face condition of
eq. 51, the last term of eq. 65) and by the macro strain of the layer
tangential to ``S_0`` (the volume term ``du^0/dx`` of eq. 63).  Both are
read here from the macro solution; :func:`cell_loads` orders them into the
load vector ``l`` of :func:`ngcontact.coupling.strength.load_names`, whose
superposition gives the micro stress of eq. 75.

The traction is the homogenized law's ``tau = dW/da`` (eqs. 69-71) in the
local frame of :mod:`ngcontact.laws.local_frame`: pressure ``p = -tau_n``
(compression positive) and the shear along the tangents.  The strain is the
mean of the two bodies' strains next to ``x``, each evaluated inside its own
body at points moved off the interface along ``+-n0`` (a point exactly on
``S_0`` may be located in either body, and the strain jumps there).

Frames.  The cell's mesh axes are its tangents followed by its normal; they
are put on the macro frame as follows.

* 2D and axisymmetric macro problems, frame ``(n0, t0)``: a 2D cell's axes
  ``(x, y) = (t0, n0)``; a 3D cell's ``(x, y, z) = (t0, hoop, n0)``.  Loads
  ``shear_x = -tau`` (the counter's far face carries the opposite of what
  the rough body transmits), ``pressure = p``, ``E_xx = e_t0t0`` and for a
  3D cell ``E_yy = e_hoop`` (0 in plane strain), ``E_xy = 0``.
* 3D macro problems, frame ``(n0, t1, t2)``: the cell is 3D with axes
  ``(x, y, z) = (t1, t2, n0)``, the frame the interface law is written in
  (a bundle from a 3D cell takes its directions in the same axes).  Loads
  ``shear_x = -tau_1``, ``shear_y = -tau_2``, ``pressure = p``,
  ``E_xx = t1.E.t1``, ``E_yy = t2.E.t2``, ``E_xy = t1.E.t2`` (the tensor
  component, as in the cell's ``macro_strain``).  A 2D cell cannot take a
  3D macro state (two tangential tractions, a 2D cell carries one) and is
  refused.  On a surface of revolution about ``z`` (the shipped 3D shapes)
  the default reference ``e_x`` of the frame gives ``t1 = -e_theta``,
  ``t2 = -e_z`` on every cylinder, so the cell's ``y`` axis is the
  axisymmetric cell's ``x`` axis ``t0 = -e_z`` and its ``x`` axis the hoop
  direction: the two settings load a cell symmetric under ``x <-> y`` (the
  square hills) identically.  On a cone of half-angle ``alpha`` the 3D
  tangents are turned in the tangent plane against ``(hoop, meridian)`` by
  at most ``atan(sqrt(3) sin(alpha))`` (at 30 deg from the ``x`` axis, where
  the frame switches its reference), 7.4 deg on the femur's cone.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.macro import macro_measures as MM
from ngcontact.macro.macro_problem import MacroSolution

#: ``{name: array}`` of the macro state at interface points (and ``status``: a list of strings)
States = dict[str, np.ndarray | list[str]]

#: share of the way from a sample to its element's centre by which it is moved before the offset off ``S_0``
INWARD = 1e-3


def _offset(sol: MacroSolution, offset: float) -> float:
    pts = np.array([v.point for v in sol.problem.mesh.vertices])
    return offset * float(np.max(pts.max(axis=0) - pts.min(axis=0)))


def _mean_strain(sol: MacroSolution, points: np.ndarray, normals: np.ndarray, delta: float) -> np.ndarray:
    """Mean of the strain tensors at ``points + delta n0`` and ``points - delta n0``, shape ``(n, 3, 3)``.

    Raises
    ------
    ModelError
        A moved point lies outside the mesh (``offset`` too large for the
        bodies' thickness there).
    """
    mesh = sol.problem.mesh
    eps = MM.strain(sol)
    out = np.zeros((len(points), 3, 3))
    for side in (1.0, -1.0):
        q = points + side * delta * normals
        mpts = mesh(*(q[:, i] for i in range(mesh.dim)))
        lost = np.flatnonzero(mpts["nr"] < 0)
        if len(lost):
            raise ModelError(f"interface state: the point {q[lost[0]].tolist()} moved {delta:.3g} off the "
                             "interface lies outside the mesh; reduce the offset")
        out += 0.5 * np.asarray(eps(mpts)).reshape(-1, 3, 3)
    return out


def interface_states(sol: MacroSolution, points_per_element: int = 5, offset: float = 1e-4) -> States:
    """Macro state at the interface samples of :func:`ngcontact.macro.macro_measures.interface_samples`.

    2D and axisymmetric: the interface profile (``s``, coordinates,
    ``pressure``, ``shear``, ...) plus ``e_t`` (strain along ``t0``) and
    ``e_hoop`` (axisymmetric hoop strain, else 0).  3D: the interface surface
    (``x, y, z``, ``pressure``, ``shear_1``, ``shear_2``, ...) plus ``e_11``,
    ``e_22``, ``e_12``, the strain in the tangents ``t1, t2``.  The strains
    are the mean of the two bodies' strains at points moved ``offset`` times
    the mesh's extent off the interface along ``+-n0``, after a step of
    :data:`INWARD` towards the element's centre (module docstring).
    """
    prof = MM.interface_samples(sol, points_per_element)
    delta = _offset(sol, offset)
    out: States = {k: v for k, v in prof.items() if k != "contact_area"}
    if sol.problem.mesh.dim == 3:
        frame = MM.interface_surface_frame(sol)
        n = len(MM.SURFACE_POINTS)
        xyz = np.column_stack([prof["x"], prof["y"], prof["z"]]).reshape(-1, n, 3)
        xyz = (xyz + INWARD * (xyz[:, -1:, :] - xyz)).reshape(-1, 3)   # the last point is the centroid
        E = _mean_strain(sol, xyz, frame[:, 0], delta)
        t1, t2 = frame[:, 1], frame[:, 2]
        out["e_11"] = np.einsum("ni,nij,nj->n", t1, E, t1)
        out["e_22"] = np.einsum("ni,nij,nj->n", t2, E, t2)
        out["e_12"] = np.einsum("ni,nij,nj->n", t1, E, t2)
        return out
    from ngcontact.fem.elasticity import COMPONENTS
    k = max(2, int(points_per_element))
    names = COMPONENTS[sol.problem.setting]
    xy = np.column_stack([prof[names[0]], prof[names[1]]])
    # the profile runs element by element, k points each: tangent and centre per element
    seg = xy.reshape(-1, k, 2)
    t = seg[:, -1] - seg[:, 0]
    t /= np.linalg.norm(t, axis=1)[:, None]
    normal = np.repeat(np.column_stack([-t[:, 1], t[:, 0]]), k, axis=0)
    moved = (seg + INWARD * (seg.mean(axis=1, keepdims=True) - seg)).reshape(-1, 2)
    E = _mean_strain(sol, moved, normal, delta)
    tt = np.repeat(t, k, axis=0)
    out["e_t"] = np.einsum("ni,nij,nj->n", tt, E[:, :2, :2], tt)
    out["e_hoop"] = E[:, 2, 2] if sol.problem.setting == "axisymmetric" else np.zeros(len(xy))
    return out


def cell_loads(states: Mapping[str, np.ndarray | list[str]], dim: int) -> np.ndarray:
    """Load vectors (rows) of a ``dim``-D cell from :func:`interface_states` (frames: module docstring).

    Raises
    ------
    ModelError
        A 3D macro state for a 2D cell.
    """
    p = np.asarray(states["pressure"], float)
    z = np.zeros_like(p)
    if "e_11" in states:
        if dim != 3:
            raise ModelError("a 3D macro state has two tangential tractions and strains; a 2D cell takes one "
                             "of each: use a 3D cell")
        return np.column_stack([-np.asarray(states["shear_1"], float), -np.asarray(states["shear_2"], float), p,
                                states["e_11"], states["e_22"], states["e_12"]])
    tau = np.asarray(states["shear"], float)
    if dim == 2:
        return np.column_stack([-tau, p, states["e_t"]])
    return np.column_stack([-tau, z, p, states["e_t"], states["e_hoop"], z])
