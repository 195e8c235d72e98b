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

Each level is solved twice, on the scene's discretization and on one refined by ``study.refinement`` (``r``);
the errors of each law against the resolved solution (:mod:`ngcontact.drivers.modelling_error`: field,
reaction, moment, probe, interface) are the refined pair's, and beside each the estimate of its discretization
error from the change ``delta`` between the two pairs, ``1.5 delta / (r - 1)`` (an error at least linear in
``h``, times the factor of safety: :func:`ngcontact.drivers.richardson_tail.tail`, a resolved run's default
estimate's rule too).  With ``study.meshes = 3`` each level is solved once more, refined again by ``r``; the
errors are the finest pair's, each estimate the sum of the two solutions' by the same rule from their two
changes at their observed ratio, or the bound of an error linear in ``h`` where larger (a solution's largest
change where it does not contract, listed in ``results.discretization.largest_change``).  The resolved contact
fraction of each level (the finest mesh's) carries its estimate by the same rule
(``contact_fraction_resolved_discretization``).

On blocks (``S_0`` the line ``y = 0``) the bundle law's solution is also rebuilt on the resolved bodies by
the first-order corrector ``u^0 + eps u^1``
(:class:`~ngcontact.coupling.first_order_corrector.FirstOrderCorrector`, its boundary layer from the station
cells of :mod:`ngcontact.drivers.boundary_layer_cells`), and the row carries the L2 error over each whole
body and the interior H1 error without and with it (``l2``, ``h1``, ``*_corrected``,
:mod:`ngcontact.drivers.modelling_error`), each with its discretization estimate and fitted by the same rule.

The levels are independent solves: a batch (:mod:`ngcontact.parallel.executor`)
spreads them over the run's workers, so the wall times of a level are
measured while the other workers run too.

The observed rate of each law and error is the least-squares slope of
``log error`` against ``log eps`` (:func:`ngcontact.verification.rates.fit_rate`)
over the levels whose discretization estimate is at most
``study.discretization_share`` of the error: the modelling error, not the
meshes.  With fewer than three such levels the study fits no rate and says why
(``results.refused``).
"""
from __future__ import annotations

import contextlib
import logging
import time
from dataclasses import replace
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
from ngcontact.coupling.first_order_corrector import FirstOrderCorrector
from ngcontact.drivers import modelling_error as E
from ngcontact.drivers.boundary_layer_cells import boundary_layer, scaled_cell_problem
from ngcontact.drivers.richardson_tail import of_values, tail
from ngcontact.macro.discretization_error import NOISE
from ngcontact.drivers import run_resolved as drv
from ngcontact.output import plots
from ngcontact.geometry.profiles import profile_cell
from ngcontact.errors import SceneError
from ngcontact.cell.coefficients import direction_bundle
from ngcontact.output.report import Outcome
from ngcontact.verification.rates import fit_rate

log = logging.getLogger(__name__)

LAWS = ("bundle", "linear", "effective")
ERRORS = E.ERRORS


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
    tau_n, tau_t = (float(v) for v in mean_traction)
    if not tau_n > 0:
        raise ValueError(f"mean interface pressure {tau_n!r} <= 0: the cell has no load state in contact")
    prob = scaled_cell_problem(scene, eps)
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


# ------------------------------------------------------------------ study
def refined(scene, factor: float):
    """``scene`` with every mesh size of the study divided by ``factor`` (the resolved far field and interface,
    the homogenized interface); its linked cell stays."""
    d, st = scene.discretization, scene.study
    new = replace(scene, discretization=replace(d, maxh=d.maxh / factor,
                                                elements_per_period=d.elements_per_period * factor),
                  study=replace(st, interface_maxh=st.interface_maxh / factor))
    object.__setattr__(new, "cell_scene", scene.cell_scene)
    return new


def corrected_measures(scene, sol: M.MacroSolution, N: int, homogenized: dict, sampling: E.BodySampling,
                       resolved_mesh) -> dict:
    """The measures of ``u^0 + eps u^1`` (:class:`~ngcontact.coupling.first_order_corrector.FirstOrderCorrector`
    of the homogenized ``sol``, its boundary layer from the station cells of
    :func:`ngcontact.drivers.boundary_layer_cells.boundary_layer`) at the points of the resolved bodies: the
    layer's and the probes' values; the far field and the gradients away from the layer are
    ``homogenized``'s (the corrector is ``u^0`` there)."""
    corrector = FirstOrderCorrector(sol, drv.eps_of(scene, N), sampling.width, layer=boundary_layer(scene, sol, N))
    out = dict(homogenized)
    out["layer"] = corrector.at(sampling.layer_points, sampling.layer_body)
    if len(homogenized["probes"]):
        pts = np.asarray(scene.study.probes, float).reshape(-1, 2)
        out["probes"] = corrector.at(pts, E.resolved_body(resolved_mesh, pts))
    return out


def solve_pair(scene, N: int, bundle: il.BundleLaw, laws, points, body,
               sampling: E.BodySampling | None = None) -> dict[str, Any]:
    """The resolved run with ``N`` periods and the homogenized runs on one discretization: their measures
    (:func:`ngcontact.drivers.modelling_error.measures`), unknowns, seconds and the effective law's record.

    With a ``sampling`` (:func:`ngcontact.drivers.modelling_error.body_sampling`) each solution also carries
    its layer values and gradients (:func:`~ngcontact.drivers.modelling_error.layer_measures`), ``out``
    the resolved bodies of the layer points (``layer_body``), and the bundle law's corrected solution its
    measures (``laws["bundle_corrected"]``, :func:`corrected_measures`)."""
    t0 = time.perf_counter()
    geo = drv.build_resolved(scene, N)
    ref_sol = drv.solve_scene(scene, drv.problem_of(scene, geo))
    out: dict[str, Any] = {"resolved": E.measures(scene, ref_sol, points, body), "ndof_resolved": ref_sol.ndof,
                           "time_resolved": time.perf_counter() - t0, "laws": {},
                           "contact_fraction_resolved": D.contact_fraction(ref_sol, drv.interface_length(scene))}
    if sampling is not None:
        sampling = replace(sampling, layer_body=E.resolved_body(geo.mesh, sampling.layer_points))
        out["layer_body"] = sampling.layer_body
        out["resolved"].update(E.layer_measures(ref_sol, sampling, sampling.layer_body))
    t0 = time.perf_counter()
    flat = drv.build_flat(scene, scene.study.interface_maxh)
    t_mesh = time.perf_counter() - t0
    homogenized: dict[str, il.NormalLaw] = {"bundle": bundle, "linear": il.linearized(bundle)}
    bundle_sol: M.MacroSolution | None = None
    for name in laws:
        t0 = time.perf_counter()
        normal: il.NormalLaw
        if name == "effective":
            if bundle_sol is None:
                raise ValueError("the effective law is evaluated at the bundle solution: list 'bundle' before it")
            traction = mean_interface_traction(bundle_sol)
            normal, out["effective_law"] = effective_law(scene, drv.eps_of(scene, N), traction)
        else:
            normal = homogenized[name]
        sol = solve_homogenized(scene, flat, il.InterfaceLaw(normal=normal))
        out[f"time_{name}"] = time.perf_counter() - t0 + t_mesh
        if name == "bundle":
            bundle_sol = sol
            out["ndof_homogenized"] = sol.ndof
        out["laws"][name] = E.measures(scene, sol, points, body)
        if sampling is not None:
            out["laws"][name].update(E.layer_measures(sol, sampling))
            if name == "bundle":
                out["laws"]["bundle_corrected"] = corrected_measures(scene, sol, N, out["laws"][name], sampling,
                                                                     geo.mesh)
    return out


def estimates(pairs: list[tuple[dict, dict]], weights: np.ndarray, sampling: E.BodySampling | None,
              refinement: float) -> dict[str, tuple[float, dict | None, bool]]:
    """Per error: the discretization estimate of the finest of ``pairs`` (each ``(resolved, homogenized)``
    measures, coarsest first, each refined by ``refinement``), the observed ratios of the changes and whether
    they contract (:func:`ngcontact.drivers.richardson_tail.tail`; relative errors, so changes below
    :data:`~ngcontact.macro.discretization_error.NOISE` are round-off).

    Two pairs: from the change between them (:func:`~ngcontact.drivers.modelling_error.discretization_errors`),
    no ratios.  Three: the sum of the resolved and the homogenized solution's estimates from their own
    changes, ratios ``{"resolved": q, "homogenized": q}``, contracting where both do."""
    if len(pairs) == 2:
        check = E.discretization_errors(*pairs[0], *pairs[1], weights, sampling)
        return {k: (tail([v], refinement, noise=NOISE).estimate, None, True) for k, v in check.items()}
    ref = pairs[-1][0]
    moved = {"resolved": [E.change(a, ref, b, ref, ref, weights, sampling)
                          for (a, _), (b, _) in zip(pairs, pairs[1:])],
             "homogenized": [E.change(ref, a, ref, b, ref, weights, sampling)
                             for (_, a), (_, b) in zip(pairs, pairs[1:])]}
    out: dict[str, tuple[float, dict | None, bool]] = {}
    for key in moved["resolved"][-1]:
        tails = {side: tail([step[key] for step in steps], refinement, noise=NOISE) for side, steps in moved.items()}
        out[key] = (float(sum(t.estimate for t in tails.values())), {side: t.ratio for side, t in tails.items()},
                    all(t.contracts for t in tails.values()))
    return out


def level(scene, N: int, bundle: il.BundleLaw, *, laws=LAWS, h1_band: float | None = None) -> dict:
    """One level: the resolved and homogenized runs on the scene's discretization and on ``study.meshes - 1``
    ones refined by ``study.refinement`` each (module docstring); a row with the finest pair's errors and
    each error's discretization estimate (:func:`estimates`; three meshes: also ``*_ratio_resolved`` and
    ``*_ratio_homogenized``, the observed ratio of each solution's two changes, ``None`` where the first is
    zero, and ``*_contracts``, whether both contract).

    ``h1_band``: half-width of the layer the ``h1`` norms leave out (default: the band of the scene's
    coarsest level), the same for every level."""
    st = scene.study
    eps = drv.eps_of(scene, N)
    points, weights, body = E.sample_grid(scene, st.band * eps)
    if h1_band is None:
        h1_band = st.band * drv.eps_of(scene, min(st.periods))
    sampling = E.body_sampling(scene, eps, max(h1_band, st.band * eps))
    scenes = [scene] + [refined(scene, st.refinement ** k) for k in range(1, st.meshes)]
    pairs = [solve_pair(s, N, bundle, laws, points, body, sampling) for s in scenes]
    fine = pairs[-1]
    if sampling is not None:
        sampling = replace(sampling, layer_body=fine["layer_body"])
    row: dict[str, Any] = {"N": N, "eps": eps}
    row.update({k: v for k, v in fine.items() if k not in ("resolved", "laws", "layer_body")})
    row["time_homogenized"] = fine["time_bundle"] if "bundle" in laws else fine[f"time_{laws[0]}"]
    row["time_discretization_check"] = sum(v for p in pairs[:-1] for k, v in p.items() if k.startswith("time_"))
    row["contact_fraction_resolved_discretization"] = of_values(
        [p["contact_fraction_resolved"] for p in pairs], st.refinement, noise=NOISE).estimate
    for name in [*laws, "bundle_corrected"]:
        if name not in fine["laws"]:
            continue
        model = E.errors(fine["resolved"], fine["laws"][name], weights, sampling)
        check = estimates([(p["resolved"], p["laws"][name]) for p in pairs], weights, sampling, st.refinement)
        if name == "bundle_corrected":
            name = "bundle"
            model = {f"{k}_corrected": model[k] for k in ("l2", "h1", "probe") if k in model}
            check = {f"{k}_corrected": check[k] for k in ("l2", "h1", "probe") if k in check}
        for key, value in model.items():
            row[f"{name}_{key}"] = value
            row[f"{name}_{key}_discretization"], ratios, contracts = check[key]
            if ratios is not None:
                row.update({f"{name}_{key}_ratio_{side}": q for side, q in ratios.items()})
                row[f"{name}_{key}_contracts"] = contracts
    log.info("N = %d: resolved %.2f s (%d dofs), bundle field error %.3e (discretization %.1e)", N,
             row["time_resolved"], row["ndof_resolved"], row.get("bundle_field", float("nan")),
             row.get("bundle_field_discretization", float("nan")))
    return row


def level_member(job: tuple) -> dict:
    """Member of the batch of levels (:mod:`ngcontact.parallel.executor`): ``(scene, N, bundle, laws, h1_band)``
    -> row."""
    scene, N, bundle, laws, h1_band = job
    return level(scene, N, bundle, laws=laws, h1_band=h1_band)


def per_error(rows: list, laws, summary) -> dict:
    """``{law: {error: summary(column)}}`` over the error columns present in ``rows``."""
    return {name: {key: summary(f"{name}_{key}") for key in ERRORS if f"{name}_{key}" in rows[0]}
            for name in laws}


#: a relative error below this is round-off: the quantity is fixed by equilibrium (a support that carries the
#: whole load), and it has no rate in eps
ROUNDOFF = 1e-9


def refusal(rows: list, col: str, good: list, share: float) -> str:
    """Why no rate of column ``col`` was fitted on ``rows`` of which ``good`` qualify."""
    if all(r[col] < ROUNDOFF for r in rows):
        return (f"the error is at round-off ({max(r[col] for r in rows):.1e} at most): the quantity is fixed by "
                "equilibrium, nothing to fit")
    bad = [r["N"] for r in rows if r not in good]
    return (f"{len(good)} level(s) qualify: at N = {bad} the discretization estimate exceeds {share:g} of the "
            "error; refine the scene's discretization or the study's interface_maxh")


def rates(rows: list, laws=LAWS, share: float = 0.1) -> tuple[dict, dict, dict]:
    """Fitted rate in ``eps`` of every error of every law over the levels whose discretization estimate is at
    most ``share`` of the error (module docstring), at least three: ``(rates, levels, refused)``,
    ``rates[law][error]`` the rate or ``None``, ``levels[law][error]`` the ``N`` it was fitted on,
    ``refused[law][error]`` why no rate was fitted (only where none was)."""
    fitted: dict[str, dict] = {name: {} for name in laws}
    used: dict[str, dict] = {name: {} for name in laws}
    refused: dict[str, dict] = {}
    for name in laws:
        for key in ERRORS:
            col = f"{name}_{key}"
            if col not in rows[0]:
                continue
            good = [r for r in rows if ROUNDOFF <= r[col] and r[f"{col}_discretization"] <= share * r[col]]
            used[name][key] = [r["N"] for r in good]
            fitted[name][key] = fit_rate([r["eps"] for r in good], [r[col] for r in good]) if len(good) >= 3 \
                else None
            if fitted[name][key] is None:
                refused.setdefault(name, {})[key] = refusal(rows, col, good, share)
    return fitted, used, refused


#: how the three-mesh estimate is made (``results.discretization.estimate``)
THREE_MESHES = ("the finest pair's errors; each estimate the sum of the resolved and the homogenized solution's "
                "Richardson tails 1.5 d2 q / (1 - q), d1 and d2 the solution's changes (coarse to middle, middle "
                "to finest) and q = d2 / d1 their observed ratio (*_ratio_resolved, *_ratio_homogenized), or "
                "d2 / (r - 1) where larger (an error at least linear in h); where a solution's q does not contract, "
                "1.5 times its largest change over (r - 1) (listed in largest_change: law -> error -> N)")
#: how the two-mesh estimate is made (``results.discretization.estimate``)
TWO_MESHES = ("the refined pair's errors; each estimate 1.5 delta / (r - 1), delta the change of the pair's signed "
              "difference from the scene's meshes: an error at least linear in h, times 1.5 "
              "(ngcontact.drivers.richardson_tail)")


def discretization_record(rows: list, laws, study) -> dict:
    """``results.discretization``: the refinement, the share of the rule and how the estimate is made; with
    three meshes also, per law and error, the levels whose ratio did not contract (the largest change stands
    there, :mod:`ngcontact.drivers.richardson_tail`), each also a warning."""
    out: dict[str, Any] = {"refinement": study.refinement, "share": study.discretization_share}
    if study.meshes == 2:
        return {**out, "estimate": TWO_MESHES}
    largest: dict[str, dict] = {}
    for name in laws:
        for key in ERRORS:
            col = f"{name}_{key}_contracts"
            bad = [r["N"] for r in rows if col in r and not r[col]]
            if bad:
                largest.setdefault(name, {})[key] = bad
                log.warning("the %s law's %s error: the discretization changes do not contract at N = %s; its "
                            "estimate there rests on the largest change", name, key, bad)
    out.update(meshes=3, estimate=THREE_MESHES, largest_change=largest)
    return out


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
    per ``N``: each error and its discretization estimate), ``results.rates`` (per law
    and error, over ``results.rate_levels``; ``results.refused`` says why a rate is
    missing), ``results.below_1_percent``
    (per law and error, the ``eps`` from which on the error stays below 1 %
    and the cost ratio there), a CSV table ``epsilon`` and a plot ``epsilon``.
    """
    if scene.study is None:
        raise ValueError("the scene has no [study] section")
    periods = tuple(periods or scene.study.periods)
    if len(E.sample_grid(scene, scene.study.band * drv.eps_of(scene, min(periods)))[0]) == 0:
        raise SceneError("study.band", scene.study.band, f"the band of N = {min(periods)} covers both "
                         "bodies: no points are left for the field error; take a smaller band or more periods")
    bundle = cell_bundle(scene)
    h1_band = scene.study.band * drv.eps_of(scene, min(periods))
    jobs = [(scene, N, bundle, tuple(laws), h1_band) for N in periods]
    names = [f"N = {N}" for N in periods]
    with clock.stage("levels") if clock is not None else contextlib.nullcontext():
        rows = executor.current().map(level_member, jobs, names, label="epsilon levels")
    share = scene.study.discretization_share
    fitted, used, refused = rates(rows, laws, share)
    for name, keys in refused.items():
        for key, why in keys.items():
            log.warning("no rate of the %s law's %s error: %s", name, key, why)
    results = {"rows": rows, "rates": fitted, "rate_levels": used, "refused": refused,
               "discretization": discretization_record(rows, laws, scene.study),
               "below_1_percent": threshold_eps(rows, laws),
               "bundle": {"directions": len(bundle.weights), "K0": bundle.matrix().tolist()},
               "error_definitions": E.DEFINITIONS}
    header = [k for k in rows[0] if not isinstance(rows[0][k], dict)]
    table = (header, [[r[k] for k in header] for r in rows])
    return Outcome(results=results, ndof=max(r["ndof_resolved"] for r in rows),
                   tables={"epsilon": table},
                   plots={"epsilon": lambda path, rows=rows, laws=laws: plots.epsilon_study(path, rows, laws),
                          "epsilon_errors": lambda path: plots.epsilon_errors(path, rows, laws, fitted, used)})
