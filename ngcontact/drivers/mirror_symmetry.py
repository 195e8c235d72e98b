"""Whether a 3D FE cell is meshed as its mirror-symmetric quarter: ``discretization.symmetry``.

The cell problem of paper eqs. 49-51 on the flat 3D cell (the small-slope model: the roughness in the
initial gap ``g``) is invariant under the mirrors ``x -> P - x`` and ``y -> P - y`` when its data are:

* the gap is even about the cell's mid-lines, ``g(P - x, y) = g(x, y) = g(x, P - y)`` (a periodic function
  even about ``P/2`` is even about ``0`` too), decided on the gap's samples (:func:`even_gap`, to round-off);
* the load is normal: no shear or tangential jump, no in-plane macro shear strain ``e_xy`` (the normal
  strains ``e_xx``, ``e_yy`` of eq. 63 are mirror-invariant);
* no friction (eqs. 57 and 65 couple the tangential response to the slip's direction), and bodies
  isotropic or orthotropic along the axes (their stiffness invariant under the mirrors).

Its energy is then convex with the same minimum on the mirrored states, and its minimizer (unique up to
the free ``U_t``, held at 0) mirror-symmetric: the in-plane displacement normal to each mirror plane vanishes
on it, the shear traction on it too.  The quarter ``[0, P/2]^2`` with ``u_x = 0`` on ``x = 0, P/2`` and
``u_y = 0`` on ``y = 0, P/2`` (the shear traction natural) solves the same problem
(:mod:`ngcontact.geometry.cell3d`); its means over the quarter are those over the period, so the contact
fraction, the mean closure, the normal stiffness and the eq. 34 coefficients are unchanged in the limit,
at a quarter of the unknowns.  ``symmetry = "auto"`` uses the quarter where the cell is admissible and
states why not where it is not (:class:`SymmetryChoice`); ``"off"`` always meshes the period.

The default (:func:`requested`).  A cell refined along its contact edge
(:func:`~ngcontact.scene.cell_method.refines_along_edge`: exact contact, frictionless, isotropic, the flat
3D mesh) defaults to ``"auto"``: its reported contact fraction is the extrapolation in the edge size, whose
estimate (:mod:`ngcontact.cell.fe.edge_size_extrapolation`) is checked on the quarter against the converged
bisinusoid (docs/benchmarks.md, section ``bisinusoid_scene_accuracy``), and at the same sizes the quarter
solves a quarter of the unknowns.  Every other FE cell defaults to ``"off"``: its estimate is the interface
halving's geometric tail (:mod:`ngcontact.cell.fe.second_discretization`), whose ratio floor of ``1/2``
assumes first-order convergence, and the quarter's finer halved levels of the shipped penalty bisinusoid
converge more slowly than that (their tail under-estimates the error), so the quarter is asked for there,
not chosen for the user.

The choice is made once per scene: :func:`ngcontact.drivers.build.with_symmetry` sets it as the scene's
typed field ``symmetry_choice`` where the drivers take a cell scene in, and the mesh
(:func:`~ngcontact.drivers.build.build_cell`), the contact edge's refiner and the report read that field.
The rule depends on the scene alone, so a scene meshed without the field (built by hand and handed to the
mesh or the cell problem directly) is decided where it is meshed (:func:`quarter`), with the same answer: a
scene that asks for ``"auto"`` is never meshed over its period for want of the field.
"""
from __future__ import annotations

import numpy as np

from ngcontact.drivers.cell_gap import gap_samples
from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.scene.cell_geometry import small_slope
from ngcontact.scene.cell_method import SymmetryChoice, refines_along_edge
from ngcontact.scene.cell_scene import CellScene, load_states

#: grid points per period and direction on which the gap's mirror symmetry is checked
CHECK_GRID = 64
#: the gap is even where its samples and their mirror images differ by at most this times its largest value
EVEN_RTOL = 1e-10


def even_gap(samples: np.ndarray) -> bool:
    """Whether a periodic gap sampled at ``(x_j, y_i) = (j, i) P / n`` (array ``[i, j]``) is even about the
    mid-lines: each sample equals its mirror images ``[i, -j]`` and ``[-i, j]`` (indices modulo ``n``) to
    :data:`EVEN_RTOL` of the gap's largest magnitude."""
    g = np.asarray(samples, float)
    mirror = (-np.arange(g.shape[0])) % g.shape[0], (-np.arange(g.shape[1])) % g.shape[1]
    tol = EVEN_RTOL * max(float(np.abs(g).max()), np.finfo(float).tiny)
    return bool(np.abs(g - g[:, mirror[1]]).max() <= tol and np.abs(g - g[mirror[0], :]).max() <= tol)


def mirror_invariant(C) -> bool:
    """Whether a 6x6 Voigt stiffness (order 11, 22, 33, 23, 13, 12) is invariant under ``x -> -x`` and
    ``y -> -y``: its entries coupling the normal strains to the shears and the shears to each other vanish
    (orthotropic along the axes)."""
    c = np.asarray(C, float)
    off = np.concatenate((c[:3, 3:].ravel(), [c[3, 4], c[3, 5], c[4, 5]]))
    return bool(np.abs(off).max() <= 1e-12 * np.abs(c).max())


def _refusal(scene: CellScene) -> str:
    """Why the scene's cell is not mirror-symmetric (module docstring), or ``""`` where it is; the gap last,
    since its check samples it."""
    g, c = scene.geometry, scene.contact
    kind = PROFILES[g.profile]
    if g.dim != 3:
        return "a 2D cell (the symmetric quarter is built for 3D cells)"
    if not (kind.solid is None and (kind.heights is None or small_slope(g))):
        return f"geometry.profile = {g.profile!r} is not meshed as the flat small-slope cell"
    for name in (scene.bodies.rough, scene.bodies.counter):
        C = scene.materials[name].C
        if C is not None and not mirror_invariant(C):
            return f"materials.{name}.C is not orthotropic along the cell's axes"
    if not scene.contact.geometric_only:
        for state in load_states(scene):
            for key in ("shear", "tangential_jump"):
                if any(v != 0.0 for v in state[key] or ()):
                    return f"load.{key} = {list(state[key])} is tangential"
            if state["macro_strain"] is not None and state["macro_strain"][2] != 0.0:
                return f"load.macro_strain = {list(state['macro_strain'])} shears the cell (e_xy)"
    if c.friction != "none":
        return f"contact.friction = {c.friction!r} couples the tangential response"
    if not even_gap(gap_samples(scene, CHECK_GRID)):
        return "the initial gap is not even about the cell's mid-lines"
    return ""


def requested(scene: CellScene) -> str:
    """``discretization.symmetry`` as the scene sets it, else its default: ``"auto"`` for a cell refined along
    its contact edge, ``"off"`` for any other (module docstring)."""
    d = scene.discretization
    return d.symmetry if "symmetry" in d.given or not refines_along_edge(scene) else "auto"


def symmetry_choice(scene: CellScene) -> SymmetryChoice:
    """The :class:`SymmetryChoice` of a cell scene's FE cell (module docstring)."""
    asked = requested(scene)
    if asked == "off":
        default = "" if "symmetry" in scene.discretization.given else " (the default; 'auto' meshes the quarter)"
        return SymmetryChoice(False, f"discretization.symmetry = 'off'{default}", asked)
    refusal = _refusal(scene)
    if refusal:
        return SymmetryChoice(False, refusal, asked)
    return SymmetryChoice(True, "the gap is even about the cell's mid-lines and the load normal and frictionless: "
                          "the quarter [0, P/2]^2 with zero normal displacement on its mirror faces", asked)


def quarter(scene: CellScene) -> bool:
    """Whether the scene's FE cell is meshed as its mirror-symmetric quarter: its field ``symmetry_choice``
    where a driver resolved it, else :func:`symmetry_choice` decided now (module docstring)."""
    choice = scene.symmetry_choice
    return (symmetry_choice(scene) if choice is None else choice).used
