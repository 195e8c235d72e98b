"""Epsilon study: the resolved rough interface against the homogenized laws.

Paper Sec. 3.3 (Prop. 29): as the period ``eps`` of the roughness tends to
zero, the solution ``u^eps`` of the resolved micro problem converges to the
solution ``u^0`` of the macro problem whose flat interface ``S_0`` carries
the homogenized law.  For each ``N`` of a list (``eps = L / N``, ``L`` the
arc length of ``S_0``) this module solves the resolved problem of a
``direct`` scene and the homogenized problems on the same bodies (blocks,
or the axisymmetric femur with a stem) with a flat interface, with

* ``bundle``: the unilateral direction bundle of the cell (paper eqs. 31-33,
  :func:`ngcontact.cell.coefficients.direction_bundle`), independent of ``eps``;
* ``linear``: its linearization with the whole surface in contact,
  ``K0 = sum_q w_q n_q n_q^T`` (paper eq. 34), independent of ``eps``;
* ``effective``: the linear law whose matrix is the effective stiffness of
  the cell scaled to the period ``eps`` (:mod:`ngcontact.cell.fe.stiffness`, "Beyond the
  paper": the tangent of the mean traction with respect to the interface's
  share of the far faces' relative displacement, including the compliance
  of the asperities), evaluated by a cell solve at the mean interface
  traction of the bundle solution (pressure ``p = mean tau_n``, shear on the
  counter's far face ``-mean tau_t``); cell heights scale with ``eps``.

Errors of each law against the resolved solution ``u^eps``:

* ``field``: relative L2 error of the displacement outside the band of
  half-width ``band * eps`` around ``S_0``, ``||u_h - u^eps|| / ||u^eps||``
  (axisymmetric: with the weight ``2 pi r``), by the midpoint rule on a
  uniform grid (blocks: of each block; femur: of the bounding box, points
  in the bodies only), the same points for every law;
* ``reaction``: ``|R_h - R^eps| / |R^eps|`` of the force vector (the fixed
  components) on each supported boundary (maximum over the boundaries).
  When the supports carry the whole load (the femur's base) equilibrium
  fixes this number; it then only shows the discretization error;
* ``moment``: relative error of the reaction moment (plane strain; maximum
  over the boundaries);
* ``probe``: largest ``|u_h - u^eps|`` at the probe points divided by the
  largest ``|u^eps|`` there;
* ``interface``: ``|F_h - F^eps| / |F^eps|`` of the force transmitted
  through a part of the interface, an interface resultant that equilibrium
  does not fix: blocks, the left half ``x < x0 + L/2``; femur, the axial
  force through the cylindrical part ``z > z_corner`` (the rest goes
  through the cone).

The levels are independent solves: a batch (:mod:`ngcontact.parallel.executor`)
spreads them over the run's workers, so the wall times of a level are
measured while the other workers run too.

The observed rate of each law is the least-squares slope of ``log error``
against ``log eps`` (:func:`ngcontact.verification.rates.fit_rate`).
"""
from __future__ import annotations

import contextlib
import logging
import time
from typing import Any

import ngsolve as ng
import numpy as np

from ngcontact.resolved import resolved_problem as D
from ngcontact.parallel import executor
from ngcontact.fem import elasticity
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.macro import macro_measures as MM
from ngcontact.coupling.cell_law import bundle_law
from ngcontact.drivers import run_resolved as drv
from ngcontact.output import plots
from ngcontact.geometry.profiles import profile_cell
from ngcontact.errors import SceneError
from ngcontact.geometry.resolved_bodies import scaled_profile
from ngcontact.cell.coefficients import direction_bundle
from ngcontact.output.report import Outcome
from ngcontact.verification.rates import fit_rate
from ngcontact.fem.quadrature import resultant_order

log = logging.getLogger(__name__)

LAWS = ("bundle", "linear", "effective")
ERRORS = ("field", "reaction", "moment", "probe", "interface")


# ------------------------------------------------------------------ laws
def cell_bundle(scene) -> il.BundleLaw:
    """The cell's direction bundle in the frame ``(n0, t0)`` (scale-free weights and normals)."""
    cell_scene = scene.cell_scene
    g, d = cell_scene.geometry, cell_scene.discretization
    prof = drv.profile_of(cell_scene)
    cell = profile_cell(prof, h_rough=g.h_rough, h_counter=g.h_counter, maxh=d.maxh,
                        interface_maxh=d.interface_maxh, order=d.order)
    kw = drv.micro_law(cell_scene)
    b = direction_bundle(cell, kn=kw["k_n"], gap=kw["gap"])
    return bundle_law({"w": b.w, "n": b.n, "g": b.g}, dim=2)


def effective_law(scene, eps: float, mean_traction) -> tuple[il.LinearLaw, dict]:
    """Linear law from the effective stiffness of the cell scaled to period ``eps``.

    Parameters
    ----------
    scene
        The ``direct`` scene (its materials; the cell's profile and ``k_n``).
    eps
        Period of the resolved roughness.
    mean_traction
        ``(tau_n, tau_t)``: mean traction the rough body transmits to the
        counter body on ``S_0`` (compression positive), the cell's load.
    """
    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
    cell_scene = scene.cell_scene
    g, d = cell_scene.geometry, cell_scene.discretization
    s = eps / g.period
    kw = drv.micro_law(cell_scene)
    cell = profile_cell(scaled_profile(drv.profile_of(cell_scene), eps), h_rough=s * g.h_rough,
                        h_counter=s * g.h_counter, maxh=s * d.maxh,
                        interface_maxh=s * (d.interface_maxh or d.maxh), order=d.order)
    mats = drv.materials_of(scene)
    model = CellModel(rough=mats["rough"], counter=mats["counter"], k_n=kw["k_n"],
                      gap=None if kw["gap"] is None else ng.CF(kw["gap"]), friction=kw["friction"],
                      order=scene.discretization.order)
    tau_n, tau_t = (float(v) for v in mean_traction)
    if not tau_n > 0:
        raise ValueError(f"mean interface pressure {tau_n!r} <= 0: the cell has no load state in contact")
    prob = CellProblem(cell, model, rtol=scene.solver.rtol, max_iter=scene.solver.max_iter)
    sol = prob.sweep([cell_load(2, pressure=tau_n, shear=(-tau_t,))])[0]
    eff = sol.results["effective_stiffness"]
    K = np.asarray(eff["matrix"], float)
    comps = eff["components"]
    if comps != ["t0", "n0"]:
        raise ValueError(f"the cell's effective stiffness has components {comps}; need t0 and n0")
    law = il.LinearLaw(kn=float(K[1, 1]), kt=float(K[0, 0]), knt=float(K[0, 1]))
    info = {"K_eff": [[law.kn, law.knt], [law.knt, law.kt]], "cell_load": [tau_n, -tau_t],
            "cell_contact_fraction": sol.results["contact_fraction"]}
    return law, info


def homogenized_problem(scene, flat, law: il.InterfaceLaw) -> M.MacroProblem:
    """The macro problem on the flat bodies of ``scene`` with the homogenized ``law`` on ``S_0``.

    The same materials, supports, loads and order as the resolved problem;
    no macro gap (the cell's own gap terms are in the law).
    """
    return M.MacroProblem(mesh=flat.mesh, setting=scene.geometry.setting, rough="rough", counter="counter",
                          materials=drv.materials_of(scene), law=law, supports=drv.supports_of(scene, flat.mesh),
                          loads=drv.loads_of(scene), order=scene.discretization.order, interface=flat.interface)


def solve_homogenized(scene, flat, law: il.InterfaceLaw) -> M.MacroSolution:
    """:func:`ngcontact.macro.macro_problem.solve` with the scene's solver settings."""
    s = scene.solver
    return M.solve(homogenized_problem(scene, flat, law), rtol=s.rtol, atol=s.atol, max_iter=s.max_iter,
                   inverse=s.inverse, coulomb_rtol=s.coulomb_rtol, coulomb_max_iter=s.coulomb_max_iter,
                   coulomb=s.coulomb)


def mean_interface_traction(sol: M.MacroSolution) -> np.ndarray:
    """``int_S0 tau w ds / int_S0 w ds`` in the local frame ``(n0, t0)`` of a homogenized solution.

    ``w`` is the measure weight (``2 pi r`` in axisymmetry).
    """
    p = sol.problem
    mesh = p.mesh
    w = elasticity.weight(p.setting)
    on_s0 = mesh.Boundaries(p.interface)
    area = ng.Integrate(w, mesh, ng.BND, definedon=on_s0)
    vals = [ng.Integrate(t * w, mesh, ng.BND, definedon=on_s0) for t in MM.interface_tractions(sol)]
    return np.asarray(vals, float) / area


# -------------------------------------------------------------- measures
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


def errors(ref: dict, other: dict, weights: np.ndarray) -> dict:
    """Relative errors of ``other`` against the resolved ``ref`` (see the module docstring)."""
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
    return out


# ------------------------------------------------------------------ study
def level(scene, N: int, bundle: il.BundleLaw, *, laws=LAWS) -> dict:
    """One level: the resolved run with ``N`` periods and the homogenized runs; a row of results."""
    st = scene.study
    eps = drv.eps_of(scene, N)
    length = drv.interface_length(scene)
    points, weights, body = sample_grid(scene, st.band * eps)
    t0 = time.perf_counter()
    geo = drv.build_resolved(scene, N)
    ref_sol = drv.solve_scene(scene, drv.problem_of(scene, geo))
    time_resolved = time.perf_counter() - t0
    ref = measures(scene, ref_sol, points, body)
    row: dict[str, Any] = {"N": N, "eps": eps, "ndof_resolved": ref_sol.ndof, "time_resolved": time_resolved,
           "contact_fraction_resolved": D.contact_fraction(ref_sol, length)}
    t0 = time.perf_counter()
    flat = drv.build_flat(scene, st.interface_maxh)
    t_mesh = time.perf_counter() - t0
    homogenized: dict[str, il.NormalLaw] = {"bundle": bundle, "linear": il.linearized(bundle)}
    bundle_sol: M.MacroSolution | None = None
    for name in laws:
        t0 = time.perf_counter()
        normal: il.NormalLaw
        if name == "effective":
            if bundle_sol is None:
                raise ValueError("the effective law is evaluated at the bundle solution: list 'bundle' before it")
            normal, info = effective_law(scene, eps, mean_interface_traction(bundle_sol))
            row["effective_law"] = info
        else:
            normal = homogenized[name]
        sol = solve_homogenized(scene, flat, il.InterfaceLaw(normal=normal))
        seconds = time.perf_counter() - t0 + t_mesh
        if name == "bundle":
            bundle_sol = sol
            row["time_homogenized"] = seconds
            row["ndof_homogenized"] = sol.ndof
        row[f"time_{name}"] = seconds
        for key, value in errors(ref, measures(scene, sol, points, body), weights).items():
            row[f"{name}_{key}"] = value
    log.info("N = %d: resolved %.2f s (%d dofs), bundle field error %.3e, linear %.3e", N, time_resolved,
             ref_sol.ndof, row.get("bundle_field", float("nan")), row.get("linear_field", float("nan")))
    return row


def level_member(job: tuple) -> dict:
    """Member of the batch of levels (:mod:`ngcontact.parallel.executor`): ``(scene, N, bundle, laws)`` -> row."""
    scene, N, bundle, laws = job
    return level(scene, N, bundle, laws=laws)


def per_error(rows: list, laws, summary) -> dict:
    """``{law: {error: summary(column)}}`` over the error columns present in ``rows``."""
    return {name: {key: summary(f"{name}_{key}") for key in ERRORS if f"{name}_{key}" in rows[0]}
            for name in laws}


def rates(rows: list, laws=LAWS) -> dict:
    """Fitted rate in ``eps`` of every error of every law (``None`` where an error is 0)."""
    eps = [r["eps"] for r in rows]

    def rate(col):
        vals = [r[col] for r in rows]
        return fit_rate(eps, vals) if min(vals) > 0 else None

    return per_error(rows, laws, rate)


def threshold_eps(rows: list, laws=LAWS, tol: float = 0.01) -> dict:
    """Per law and error: the largest ``eps`` of the study from which on the error stays below ``tol``.

    ``None`` where no level qualifies; otherwise ``{"eps", "N", "cost_ratio"}``
    with the cost ratio resolved / homogenized (bundle) wall time at that level.
    """
    def first_below(col):
        for r in sorted(rows, key=lambda r: -r["eps"]):
            if all(q[col] < tol for q in rows if q["eps"] <= r["eps"]):
                return {"eps": r["eps"], "N": r["N"], "cost_ratio": r["time_resolved"] / r["time_homogenized"]}
        return None

    return per_error(rows, laws, first_below)


def run_study(scene, periods=None, *, laws=LAWS, clock=None) -> Outcome:
    """The epsilon study of a ``direct`` scene with a ``[study]`` section; no file I/O.

    Returns an :class:`~ngcontact.output.report.Outcome` with ``results.rows`` (one
    per ``N``), ``results.rates`` (per law and error), ``results.below_1_percent``
    (per law and error, the ``eps`` from which on the error stays below 1 %
    and the cost ratio there), a CSV table ``epsilon`` and a plot ``epsilon``.
    """
    if scene.study is None:
        raise ValueError("the scene has no [study] section")
    periods = tuple(periods or scene.study.periods)
    if len(sample_grid(scene, scene.study.band * drv.eps_of(scene, min(periods)))[0]) == 0:
        raise SceneError("study.band", scene.study.band, f"the band of N = {min(periods)} covers both "
                         "bodies: no points are left for the field error; take a smaller band or more periods")
    bundle = cell_bundle(scene)
    jobs = [(scene, N, bundle, tuple(laws)) for N in periods]
    names = [f"N = {N}" for N in periods]
    with clock.stage("levels") if clock is not None else contextlib.nullcontext():
        rows = executor.current().map(level_member, jobs, names, label="epsilon levels")
    results = {"rows": rows, "rates": rates(rows, laws) if len(rows) >= 3 else {},
               "below_1_percent": threshold_eps(rows, laws),
               "bundle": {"directions": len(bundle.weights), "K0": bundle.matrix().tolist()},
               "error_definitions": {k: v for k, v in zip(ERRORS, (
                   "relative L2 displacement error outside the band of half-width band * eps around S_0",
                   "largest relative error of a support's reaction force vector",
                   "largest relative error of a support's reaction moment",
                   "largest displacement error at the probes / largest resolved probe displacement",
                   "relative error of the force through a part of the interface (blocks: x < x0 + L/2; "
                   "femur: axial force through the cylinder z > z_corner)"))}}
    header = [k for k in rows[0] if not isinstance(rows[0][k], dict)]
    table = (header, [[r[k] for k in header] for r in rows])
    return Outcome(results=results, ndof=max(r["ndof_resolved"] for r in rows),
                   tables={"epsilon": table},
                   plots={"epsilon": lambda path, rows=rows, laws=laws: plots.epsilon_study(path, rows, laws)})
