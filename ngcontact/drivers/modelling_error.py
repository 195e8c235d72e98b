"""The modelling error of a homogenized solution against the resolved one, and how much of it is discretization.

Paper Sec. 3.3 (Prop. 29): the resolved solution ``u^eps`` converges to the homogenized ``u^0`` as the
period ``eps`` falls.  What a study measures is the difference of two *discrete* solutions,

    e_h = Q(u^0_h) - Q(u^eps_h) = [Q(u^0) - Q(u^eps)] + [d^0_h - d^eps_h],

the modelling error plus the difference of the two discretization errors ``d_h``.  Once the modelling
error is small, the second bracket dominates and a rate fitted to ``|e_h|`` measures the meshes, not
the model.  Each quantity ``Q`` (the :data:`ERRORS`) is therefore compared on two discretizations of
the same level, the scene's and one refined by a factor ``r``; the change of the signed difference,

    delta = |e_h - e_(h/r)|,

is the quantity's change over the refinement, from which the discretization error of the refined pair's
``e_(h/r)`` is estimated by the rule of :func:`ngcontact.drivers.richardson_tail.tail`: ``1.5 delta / (r - 1)``
once both discretization errors contract by ``1/r`` or faster (order 2 elements away from corners contract by
``r^-2`` or faster; at the re-entrant corners of the resolved valleys by about ``r^-1``), the factor 1.5 a
margin of safety.  The modelling error reported is the refined pair's, with that estimate beside it
(:func:`discretization_errors` gives ``delta``): a vector quantity (the field, the reactions, the probes, the
interface force) compares the vectors ``e``, so that the estimate is a norm of the change, not the change of a
norm.  With a third discretization (``study.meshes = 3``) the contraction is observed instead of presumed: the
errors are the finest pair's and the estimate the sum of the resolved and the homogenized solution's estimates
from their two changes (:func:`change`, :mod:`ngcontact.drivers.richardson_tail`).

Errors of a homogenized solution against the resolved solution ``u^eps`` (:func:`errors`):

* ``field``: relative L2 error of the displacement outside the band of half-width ``band * eps``
  around ``S_0``, ``||u_h - u^eps|| / ||u^eps||`` (axisymmetric: with the weight ``2 pi r``), by the
  midpoint rule on a uniform grid (blocks: of each block; femur: of the bounding box, points in the
  bodies only), the same points for every law and discretization;
* ``reaction``: ``|R_h - R^eps| / |R^eps|`` of the force vector (the fixed components) on each
  supported boundary (maximum over the boundaries).  When the supports carry the whole load (the
  femur's base) equilibrium fixes this number; it then only shows the discretization error;
* ``moment``: relative error of the reaction moment (plane strain; maximum over the boundaries);
* ``probe``: largest ``|u_h - u^eps|`` at the probe points divided by the largest ``|u^eps|`` there;
* ``interface``: ``|F_h - F^eps| / |F^eps|`` of the force transmitted through a part of the interface,
  an interface resultant that equilibrium does not fix: blocks, the left half ``x < x0 + L/2``; femur,
  the axial force through the cylindrical part ``z > z_corner`` (the rest goes through the cone).

Where ``S_0`` is the line ``y = 0`` (blocks; :func:`body_sampling`), also the norms of the first-order
corrector's table (:mod:`ngcontact.coupling.first_order_corrector`):

* ``l2``: relative L2 error over each whole resolved body (the larger of the two), the layer
  ``|y| < band * eps`` included: the far points of ``field`` plus a grid of the layer fine enough to
  resolve the roughness (``16`` columns a period, ``64`` rows across the layer), each point of the body the
  resolved mesh puts it in;
* ``h1``: relative H1 seminorm error ``||grad(u_h - u^eps)|| / ||grad u^eps||`` over both bodies outside
  the band of the study's coarsest level and farther than a quarter of the smallest block dimension from
  the blocks' outer faces (one interior region for every level: the corners of the outer faces, where
  the supports meet the free sides, carry stress singularities whose discretization error would swamp
  the modelling error in this norm);
* ``l2_corrected``, ``h1_corrected``, ``probe_corrected``: the same of ``u^0 + eps u^1`` (the bundle
  law's solution with its corrector).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import ngsolve as ng
import numpy as np

from ngcontact.drivers import run_resolved as drv
from ngcontact.fem import elasticity
from ngcontact.fem.quadrature import resultant_order
from ngcontact.geometry import resolved_shapes as rs
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import macro_problem as M
from ngcontact.resolved import resolved_problem as D

ERRORS = ("field", "reaction", "moment", "probe", "interface", "l2", "h1", "l2_corrected", "h1_corrected",
          "probe_corrected")
#: what each error measures (the report's ``error_definitions``)
DEFINITIONS = dict(zip(ERRORS, (
    "relative L2 displacement error outside the band of half-width band * eps around S_0",
    "largest relative error of a support's reaction force vector",
    "largest relative error of a support's reaction moment",
    "largest displacement error at the probes / largest resolved probe displacement",
    "relative error of the force through a part of the interface (blocks: x < x0 + L/2; femur: axial force "
    "through the cylinder z > z_corner)",
    "relative L2 displacement error over each whole resolved body, the layer included (the larger of the two)",
    "relative H1 seminorm error outside the band of the coarsest level",
    "l2 of the homogenized solution plus its first-order corrector",
    "h1 of the homogenized solution plus its first-order corrector",
    "probe of the homogenized solution plus its first-order corrector (probes lie outside the layer)")))

#: the layer grid: columns per period and rows across the layer
LAYER_COLUMNS, LAYER_ROWS = 16, 64


def interface_force(sol: D.DirectSolution | M.MacroSolution, part=None) -> np.ndarray:
    """Force the counter receives through a part of the interface (resolved or flat).

    ``int tau w ds`` over the part given by the indicator CoefficientFunction
    ``part`` (default: all of it); ``w = 2 pi r`` in axisymmetry.  Resolved:
    the micro pressure along the micro normal on ``S_C^eps``; homogenized:
    the law's traction in the frame of ``S_0``.
    """
    if isinstance(sol, D.DirectSolution):
        return D.contact_force(sol, part=part)
    p = sol.problem
    mesh = p.mesh
    glob = sum((t * e for t, e in zip(MM.interface_tractions(sol), sol.frame)), ng.CF((0.0, 0.0)))
    ind = ng.CF(1.0) if part is None else part
    w = elasticity.weight(p.setting)
    return np.asarray(ng.Integrate(glob * ind * w, mesh, ng.BND, definedon=mesh.Boundaries(p.interface),
                                   order=resultant_order(p.order)), float).ravel()


def sample_grid(scene, band: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Midpoints, weights and bodies (0 rough, 1 counter) of a uniform grid outside the band.

    Blocks: ``nx x ny`` cells in each block outside ``|y| <= band``.  Femur:
    ``nr x nz`` cells over the bounding box ``[0, r_bone] x [0, z_stem_top]``,
    keeping the midpoints inside a body and farther than ``band`` from
    ``S_0``.  Axisymmetric weights carry the factor ``2 pi r``.
    """
    g = scene.geometry
    pts, wts = drv.shape_of(scene).sample_grid(scene.study.grid, band)
    if g.setting == "axisymmetric":
        wts = wts * 2.0 * np.pi * pts[:, 0]
    return pts, wts, drv.body_of(scene, pts)


def displacement_at(sol: D.DirectSolution | M.MacroSolution, points: np.ndarray, body=None) -> np.ndarray:
    """Displacement at ``points``, shape ``(m, 2)``.

    ``body``: per point 0 (rough) or 1 (counter); default: rough below ``y = 0``.
    """
    mesh = sol.problem.mesh
    if body is None:
        body = np.where(points[:, 1] < 0, 0, 1)
    out = np.empty((len(points), 2))
    for mask, u in ((body == 0, sol.u_rough), (body == 1, sol.u_counter)):
        if np.any(mask):
            mp = mesh(points[mask, 0], points[mask, 1])
            out[mask] = np.asarray(u(mp)).reshape(-1, 2)
    return out


def measures(scene, sol: D.DirectSolution | M.MacroSolution, points: np.ndarray, body=None) -> dict:
    """The quantities of interest of one solution (resolved or homogenized).

    In axisymmetry the interface force keeps its axial component only (the
    radial entry integrates a line load that has no net resultant).
    """
    force = interface_force(sol, part=drv.interface_part(scene))
    if scene.geometry.setting == "axisymmetric":
        force = force[1:]
    return {"reactions": drv.reactions(scene, sol),
            "probes": np.asarray(drv.probes(scene, sol), float).reshape(-1, 2),
            "interface": force,
            "field": displacement_at(sol, points, body)}


def errors(ref: dict, other: dict, weights: np.ndarray, sampling: BodySampling | None = None) -> dict:
    """Relative errors of ``other`` against the resolved ``ref`` (see the module docstring); with a
    ``sampling`` and measures that carry the layer values, ``l2`` and ``h1`` too (:func:`body_errors`)."""
    diff = other["field"] - ref["field"]
    field = np.sqrt(np.sum(weights[:, None] * diff ** 2) / np.sum(weights[:, None] * ref["field"] ** 2))
    force, moment, has_moment = 0.0, 0.0, False
    for label, r in ref["reactions"].items():
        o = other["reactions"][label]
        keys = [k for k in r if k != "moment"]
        if keys:
            fr = np.array([r[k] for k in keys])
            fo = np.array([o[k] for k in keys])
            force = max(force, float(np.linalg.norm(fo - fr) / np.linalg.norm(fr)))
        if "moment" in r:
            has_moment = True
            moment = max(moment, abs(o["moment"] - r["moment"]) / abs(r["moment"]))
    out = {"field": float(field), "reaction": force,
           "interface": float(np.linalg.norm(other["interface"] - ref["interface"])
                              / np.linalg.norm(ref["interface"]))}
    if has_moment:
        out["moment"] = float(moment)
    if len(ref["probes"]):
        out["probe"] = float(np.max(np.linalg.norm(other["probes"] - ref["probes"], axis=1))
                             / np.max(np.linalg.norm(ref["probes"], axis=1)))
    if sampling is not None and "layer" in ref and "layer" in other:
        out.update(body_errors(ref, other, weights, sampling))
    return out


def combine(fn: Callable[..., Any], *trees):
    """``fn`` applied leaf by leaf to measures of the same structure (nested dicts of numbers and arrays)."""
    first = trees[0]
    if isinstance(first, dict):
        return {k: combine(fn, *(t[k] for t in trees)) for k in first}
    return fn(*(np.asarray(t, float) for t in trees))


def discretization_errors(resolved: dict, homogenized: dict, resolved_fine: dict, homogenized_fine: dict,
                          weights: np.ndarray, sampling: BodySampling | None = None) -> dict:
    """The change ``delta = |e_h - e_(h/r)|`` of each error (module docstring), relative to the refined
    resolved solution's size, as :func:`errors` measures it.

    Each argument is :func:`measures` of one solution: the resolved and the homogenized one on the
    scene's discretization, then both on the refined one.  ``errors(R, R + (e_h - e_(h/r)))`` is the
    norm of the change of the signed difference in each error's own measure.
    """
    return change(resolved, homogenized, resolved_fine, homogenized_fine, resolved_fine, weights, sampling)


def change(resolved: dict, homogenized: dict, resolved_fine: dict, homogenized_fine: dict, reference: dict,
           weights: np.ndarray, sampling: BodySampling | None = None) -> dict:
    """``|e_a - e_b|`` of each error between two pairs ``a`` (``resolved``, ``homogenized``) and ``b`` (the
    ``*_fine``), relative to the size of the resolved ``reference`` as :func:`errors` measures it:
    ``errors(reference, reference + (e_a - e_b))``.  With ``reference`` the pair ``b``'s resolved solution
    this is :func:`discretization_errors`; the three-mesh estimate (:mod:`ngcontact.drivers.richardson_tail`)
    measures each solution's changes (the other solution held at ``reference`` in both pairs) against the
    finest resolved solution, so that their ratio is one of changes alone."""
    shifted = combine(lambda r, h, rf, hf, ref: ref + (h - r) - (hf - rf), resolved, homogenized, resolved_fine,
                      homogenized_fine, reference)
    return errors(reference, shifted, weights, sampling)


@dataclass(frozen=True)
class BodySampling:
    """The points of the norms over each whole body (``l2``) and away from the layer (``h1``).

    ``far_*``: the points of ``field`` (outside the band), each body by its side of ``S_0``; ``layer_*``: a
    grid of the layer ``|y| < width``, whose resolved bodies (``layer_body``) each resolved mesh gives;
    ``h1_*``: the points outside the coarsest level's band and away from the outer faces.
    """

    far_body: np.ndarray
    far_weights: np.ndarray
    layer_points: np.ndarray
    layer_weights: np.ndarray
    h1_points: np.ndarray
    h1_weights: np.ndarray
    h1_body: np.ndarray
    width: float
    layer_body: np.ndarray | None = None


def body_sampling(scene, eps: float, h1_band: float) -> BodySampling | None:
    """The :class:`BodySampling` of a level of period ``eps`` on blocks (``S_0`` the line ``y = 0``); ``None``
    on other shapes (the layer grid follows a straight ``S_0``)."""
    shape = drv.shape_of(scene)
    if not isinstance(shape, rs.Blocks):
        return None
    width = scene.study.band * eps
    far, far_w, far_b = sample_grid(scene, width)
    nx = LAYER_COLUMNS * int(round(shape.length / eps))
    xs = shape.x0 + (np.arange(nx) + 0.5) * shape.length / nx
    ys = -width + (np.arange(LAYER_ROWS) + 0.5) * 2.0 * width / LAYER_ROWS
    X, Y = np.meshgrid(xs, ys)
    layer = np.column_stack([X.ravel(), Y.ravel()])
    layer_w = np.full(len(layer), shape.length / nx * 2.0 * width / LAYER_ROWS)
    if scene.geometry.setting == "axisymmetric":
        layer_w = layer_w * 2.0 * np.pi * layer[:, 0]
    h1, h1_w, h1_b = sample_grid(scene, h1_band)
    margin = 0.25 * min(shape.length, shape.h_rough, shape.h_counter)
    inner = (h1[:, 0] > shape.x0 + margin) & (h1[:, 0] < shape.x0 + shape.length - margin) & \
        (h1[:, 1] > -shape.h_rough + margin) & (h1[:, 1] < shape.h_counter - margin)
    h1, h1_w, h1_b = h1[inner], h1_w[inner], h1_b[inner]
    return BodySampling(far_body=far_b, far_weights=far_w, layer_points=layer, layer_weights=layer_w,
                        h1_points=h1, h1_weights=h1_w, h1_body=h1_b, width=width)


def resolved_body(mesh: ng.Mesh, points: np.ndarray) -> np.ndarray:
    """Body of each point in a resolved mesh (0 rough, 1 counter): the region of the element it lies in."""
    counter = mesh.MaterialCF({"counter": 1.0}, default=0.0)
    return np.rint(np.asarray(counter(mesh(points[:, 0], points[:, 1]))).ravel()).astype(int)


def gradient_at(sol, points: np.ndarray, body: np.ndarray) -> np.ndarray:
    """Displacement gradient at ``points`` (shape ``(m, 2, 2)``), each from the field of its ``body``."""
    mesh = sol.problem.mesh
    out = np.zeros((len(points), 2, 2))
    for b, u in enumerate((sol.u_rough, sol.u_counter)):
        mask = body == b
        if np.any(mask):
            out[mask] = np.asarray(ng.Grad(u)(mesh(points[mask, 0], points[mask, 1]))).reshape(-1, 2, 2)
    return out


def layer_measures(sol, sampling: BodySampling, layer_body: np.ndarray | None = None) -> dict:
    """The layer values and the gradients away from the layer of one solution: resolved (``layer_body``
    given: each point from the body it lies in) or homogenized (each point from its side of ``S_0``)."""
    body = layer_body if layer_body is not None else (sampling.layer_points[:, 1] > 0).astype(int)
    return {"layer": displacement_at(sol, sampling.layer_points, body),
            "gradient": gradient_at(sol, sampling.h1_points, sampling.h1_body)}


def body_errors(ref: dict, other: dict, weights: np.ndarray, sampling: BodySampling) -> dict:
    """``l2`` and ``h1`` of ``other`` against the resolved ``ref`` (module docstring)."""
    far, layer = other["field"] - ref["field"], other["layer"] - ref["layer"]
    lb = sampling.layer_body if sampling.layer_body is not None else (sampling.layer_points[:, 1] > 0)
    l2 = 0.0
    for b in (0, 1):
        fm, lm = sampling.far_body == b, lb == b

        def norm2(f, g):
            return float(np.sum(weights[fm, None] * f[fm] ** 2) + np.sum(sampling.layer_weights[lm, None]
                                                                        * g[lm] ** 2))

        l2 = max(l2, np.sqrt(norm2(far, layer) / norm2(ref["field"], ref["layer"])))
    out = {"l2": float(l2)}
    if len(sampling.h1_weights):
        dg = other["gradient"] - ref["gradient"]
        w = sampling.h1_weights[:, None, None]
        out["h1"] = float(np.sqrt(np.sum(w * dg ** 2) / np.sum(w * ref["gradient"] ** 2)))
    return out
