"""Driver of the ``cell`` kind: build the scene's cell, solve the load sweep, collect results.

Results (``report.json`` ``results``): ``whole_surface`` coefficients of the
whole contact surface (paper eqs. 34, 42-43, purely geometric), and per load
``contact_fraction``, ``mean_pressure`` (compression positive),
``mean_traction``, ``mean_jump``, ``mean_closure``, ``coefficients`` on the
real contact set, ``effective_stiffness``, ``far_face_strain`` (the far-face jump over the
cell's height, warned beyond small strain: :mod:`ngcontact.cell.small_strain`)
and, where the method samples the
bodies, the largest von Mises / Tresca stress per body with its location.
A measured topography (``geometry.file`` in an instrument's format) adds its
record ``topography`` (:func:`ngcontact.drivers.cell_gap.topography`, with
the small-slope check of its rms slope) and the plot of its PSD ``psd.png``.
The cell is reached through the cell protocol only
(:mod:`ngcontact.cell.cell_solver`; ``discretization.method`` chooses the
implementation in :func:`ngcontact.drivers.build.cell_solver`): the method
adds its own iteration counts to each load, its ``results.method`` record
(the spectral cell's grid) and its grid fields as ``.npy``.  With
``discretization.tolerance`` the sweep is refined until the estimate meets
it (:meth:`~ngcontact.cell.cell_solver.CellSolver.refine_to`) and each load
adds ``error_estimate`` (FE: also ``mesh_history``); without it the sweep is
held to :data:`~ngcontact.cell.admissibility.DEFAULT_TOLERANCE`
(:meth:`~ngcontact.cell.cell_solver.CellSolver.default_accuracy`): the
spectral cell is refined to it within a tighter size bound; the FE cell
estimates its own answer's error from one order more
(:mod:`ngcontact.cell.fe.saturation`; each load adds ``error_estimate`` and
``next_order``) and, where that misses it, is refined within
``discretization.budget_dofs`` (:mod:`ngcontact.cell.fe.default_refinement`;
``discretization.estimate = "estimate"``: not refined); one that misses it
is reported with ``accuracy.met = false``, ``accuracy.shortfall`` where the
budget ended first, and one warning line rather than failed (exit 0);
``discretization.estimate = "off"`` skips that estimate and says so
(``accuracy.how``).  ``accuracy.method`` states the method that solved
the cell and why (``discretization.method = "auto"`` resolved: :mod:`ngcontact.scene.cell_method`), and of a 3D
FE cell ``accuracy.symmetry`` whether it was meshed as its mirror-symmetric quarter and why
(``discretization.symmetry``: :mod:`ngcontact.drivers.mirror_symmetry`, decided once as the run starts).  With
``load.independent`` every load is solved from the unloaded cell as a member
of a batch (:mod:`ngcontact.drivers.cell_members`), on the run's workers, and
held to the default tolerance on its own where the method holds a load alone
(the FE cell; the spectral cell, each load on its own grids): the same
accuracy, report and warning as the chained sweep's.
"""
from __future__ import annotations

import logging
from typing import Any

from ngcontact.cell import admissibility, small_strain, whole_surface
from ngcontact.cell.cell_solver import Refinement, joined
from ngcontact.cell.penalty_share import penalty_share
from ngcontact.errors import ConvergenceError
from ngcontact.drivers import cell_gap, cell_members
from ngcontact.drivers.build import cell_facts, cell_loads, cell_solver, with_symmetry
from ngcontact.output import cell_plots as figures
from ngcontact.output.report import Outcome, VtkField

log = logging.getLogger(__name__)


def contact_curve_plot(sols) -> dict:
    """``{"contact_curve": draw}`` for a sweep of more than one load, else empty."""
    if len(sols) < 2:
        return {}
    curve = {k: [s.results[k] for s in sols] for k in ("transmitted_pressure", "contact_fraction", "mean_closure")}
    return {"contact_curve": lambda path: figures.cell_contact_curve(
        path, curve["transmitted_pressure"], curve["contact_fraction"], curve["mean_closure"])}


def surface_plots(sols, dim: int, period: float) -> dict:
    """The surface plots of a sweep: pressure and slip along a 2D cell's ``S_C``; a 3D grid's pressure map."""
    plots: dict[str, Any] = {}
    if dim == 2:
        surfaces = [{"x": s.surface["x"], "pressure": s.surface["pressure"],
                     "slip": s.surface.get("slip", 0.0 * s.surface["pressure"])} for s in sols]
        plots["surface"] = lambda path, sf=surfaces: figures.cell_surface(path, sf)
    elif sols and "pressure" in sols[0].fields:
        maps = [s.fields["pressure"] for s in sols]
        plots["pressure_map"] = lambda path, m=maps: figures.pressure_map(path, m, period)
    return plots


def accuracy_verdict(per_load: list[dict], tolerance: float | None, facts: dict[str, float],
                     refinement: Refinement | None = None, unestimated: str = "", warn: bool = True) -> dict:
    """The sweep's verdict (:mod:`ngcontact.cell.admissibility`) with the cell's own ``facts`` and the
    refinement's estimates (``unestimated``: why there is none, where the scene says it); each failed check
    is one warning line, and so is an estimate beyond the default tolerance (not ``warn``: none, the caller
    says it); a plainly wrong answer is no answer (exit 3)."""
    estimated = refinement is not None and bool(refinement.estimates)
    verdict, failed = admissibility.verdict(
        per_load, tolerance, admissibility.cell_checks(facts),
        estimates=refinement.estimates if estimated and refinement is not None else None,
        how=unestimated if refinement is None else refinement.how,
        reached=refinement is None or refinement.met,
        uncontrolled=refinement.uncontrolled if refinement is not None else (),
        scales=refinement.scales if refinement is not None else (),
        loose=refinement.loose if refinement is not None else ())
    wrong = [c for c in failed if c.plainly_wrong]
    if wrong:
        raise ConvergenceError(
            f"the cell's answer contradicts its own load: {wrong[0].message()}; the interface is not resolved "
            "(a contact patch narrower than the elements): refine the interface mesh, use contact.enforcement = "
            "'exact', or discretization.method = 'spectral' for a small-slope cell", {"checks": verdict["checks"]})
    for c in failed if warn else ():
        # the cell's own checks were said before the solve, the small strain by its own warning
        if c.load is not None and c.name not in admissibility.MODEL_LIMITS:
            log.warning("accuracy not met: %s", c.message())
    if refinement is not None and refinement.shortfall and not verdict["met"]:
        verdict["shortfall"] = refinement.shortfall
    if refinement is not None and warn:
        warn_unmet(verdict, refinement)
    return verdict


def warn_unmet(verdict: dict, refinement: Refinement) -> None:
    """One warning line for a refinement that did not meet its (default) tolerance: the largest estimate,
    and what to do."""
    unmet = [q for q in verdict["quantities"] if not q["met"] and q["counted"]]
    if not unmet and refinement.met:
        return
    if unmet:
        q = max(unmet, key=lambda q: q["controlled_error"])
        size = q["controlled_error"]
        what = f"the estimated {q['controlled']} error {size:.3g} of load {q['load']}'s {q['name']} exceeds"
    elif refinement.scene_discretization:
        what = "no estimate shows"
    else:
        what = "too few grids within the size bound to show"
    if refinement.shortfall:
        log.warning("accuracy not met: %s the %s tolerance %g %s; %s", what if unmet else "the refinement did not show",
                    verdict["tolerance_from"], verdict["tolerance"], refinement.shortfall, refinement.remedy)
        return
    if refinement.scene_discretization:
        log.warning("accuracy not met: %s the %s tolerance %g on the scene's own discretization (%s); state "
                    "discretization.tolerance to refine it, or a finer discretization (FE: interface_maxh, order; "
                    "spectral: grid)", what,
                    verdict["tolerance_from"], verdict["tolerance"], refinement.how.split(";")[0])
        return
    log.warning("accuracy not met: %s the %s tolerance %g on the finest discretization allowed (%s); state "
                "discretization.tolerance to refine beyond the default size bound, or a finer discretization",
                what, verdict["tolerance_from"], verdict["tolerance"], refinement.how.split(";")[0])


def load_records(cell, sols: list, refinement: Refinement | None, height: float
                 ) -> tuple[list[dict], dict[str, Any], dict[str, Any]]:
    """Per load its entry of ``results.loads`` (with the refinement's estimate of its controlled quantities
    and its per-load record where refined), its surface table and its fields' arrays; each load's strain
    checked small against the cell's ``height`` (:mod:`ngcontact.cell.small_strain`)."""
    per_load, tables, arrays = [], {}, {}
    for k, sol in enumerate(sols):
        entry = cell.load_entry(sol)
        small_strain.check(entry, height, f"load {k}")
        if refinement is not None and refinement.estimates:
            entry["error_estimate"] = {name: e for name, e in refinement.estimates[k].items()
                                       if name not in refinement.uncontrolled}
            if refinement.per_load:
                entry.update(refinement.per_load[k])
        per_load.append(entry)
        if sol.surface:
            tables[f"surface_load{k}"] = sol.surface_table()
        for name, values in sol.fields.items():
            arrays[f"{name}_load{k}"] = values
        log.info("load %d: %d iterations, contact fraction %.8f", k, sol.iterations, sol.results["contact_fraction"])
    return per_load, tables, arrays


def refine(scene, cell, loads, by_default: bool = True) -> Refinement | None:
    """The sweep refined to the scene's tolerance, or held to the default one (the cell's
    :meth:`~ngcontact.cell.cell_solver.CellSolver.default_accuracy`: the spectral cell refined to it, the FE
    cell estimated on its own discretization and refined where that misses it; independent loads each on its
    own as a member of a batch, :func:`ngcontact.drivers.cell_members.held`); where the caller says not
    ``by_default`` (an ensemble's member) the scene's discretization with its error estimated
    (:meth:`~ngcontact.cell.cell_solver.CellSolver.scene_estimate`); ``None`` where the scene opts out (the
    fixed discretization, not estimated)."""
    tolerance = scene.discretization.tolerance
    if tolerance is not None:
        return cell.refine_to(tolerance, loads, required=True)
    if scene.discretization.estimate == "off":
        return None
    if not by_default:       # independent loads each from the unloaded cell, in this process (a member already)
        parts = [cell.scene_estimate([load]) for load in loads] if scene.load.independent else [
            cell.scene_estimate(loads)]
        return None if any(p is None for p in parts) else joined([p for p in parts if p is not None])
    if scene.load.independent:
        return cell_members.held(scene, cell, admissibility.DEFAULT_TOLERANCE)
    return cell.default_accuracy(admissibility.DEFAULT_TOLERANCE, loads)


#: the verdict's ``how`` of a scene that opts out of the default estimate
OPTED_OUT = "not estimated (discretization.estimate = off)"


def opted_out(scene) -> str:
    """The verdict's ``how`` where the scene opts out of the default estimate (:data:`OPTED_OUT`), else ``""``."""
    d = scene.discretization
    return OPTED_OUT if d.tolerance is None and d.estimate == "off" else ""


def warn_before_solving(facts: dict[str, float]) -> None:
    """What is known before the solve: a cell that cannot meet its accuracy says so at once."""
    for c in admissibility.cell_checks(facts):
        if not c.ok:
            hint = ("; use discretization.method = 'spectral', which solves on the map's own points, or a finer "
                    "discretization.interface_maxh" if c.name == "interface_resolution" else "")
            log.warning("accuracy not met, known before solving: %s%s", c.message(), hint)


def method_choice(scene) -> dict[str, Any]:
    """``results.accuracy.method``: the method that solved the scene and why
    (:class:`~ngcontact.scene.cell_method.MethodChoice`; a scene not built by the loader: its method only)."""
    choice = scene.method_choice
    if choice is not None:
        return choice.as_dict()
    method = scene.discretization.method
    return {"method": method, "requested": method, "reason": "", "statement": method}


def run(scene, clock, member: bool = False) -> Outcome:
    """Solve a ``cell`` scene; no file I/O (see :mod:`ngcontact.output.report`).  ``member``: an ensemble's
    member, not refined unless the scene states a tolerance but estimated on its own discretization, and its
    verdict's warnings left to the ensemble's (:mod:`ngcontact.drivers.run_ensemble`)."""
    with clock.stage("setup"):
        scene = with_symmetry(scene)       # its FE cell's quarter or period, decided once for the run
        cell = cell_solver(scene)
        facts = cell_facts(scene)
    warn_before_solving(facts)
    with clock.stage("whole-surface coefficients"):
        results: dict[str, Any] = {"whole_surface": cell.whole_surface()}
    method = cell.method_record()
    if method is not None:
        results = {"method": method, **results}
    topography = cell_gap.topography(scene)
    if topography is not None:     # its small-slope check is the cell's rms_slope check, on the spectral grid
        checks = [c.as_dict() for c in admissibility.cell_checks(facts) if c.name == "rms_slope"]
        results["topography"] = dict(topography, small_slope=checks[0] if checks else None)
    if scene.contact.geometric_only:
        with clock.stage("whole-surface estimate"):
            errors, how = cell.whole_surface_error()
        tolerance = scene.discretization.tolerance or admissibility.DEFAULT_TOLERANCE
        accuracy = whole_surface.verdict(results["whole_surface"], errors, tolerance, how)
        if not accuracy["met"]:
            log.warning("accuracy not met: %s", accuracy["how"] if errors is None else ", ".join(
                f"{q['name']} {q['controlled_error']:.3g}" for q in accuracy["quantities"] if not q["met"]))
        return Outcome(results={**results, "accuracy": dict(accuracy, method=method_choice(scene))}, ndof=0)
    loads = cell_loads(scene)
    refinement: Refinement | None = None
    with clock.stage("solve"):
        refinement = refine(scene, cell, loads, not member)
        if refinement is not None:
            sols = refinement.solutions
            if method is not None:
                results["method"].update(refinement.method)
        elif scene.load.independent:
            sols = cell_members.solve(scene, cell)
        else:
            sols = cell.sweep(loads)
    per_load, tables, arrays = load_records(cell, sols, refinement, scene.geometry.h_rough + scene.geometry.h_counter)
    results["loads"] = per_load
    results["accuracy"] = dict(accuracy_verdict(per_load, scene.discretization.tolerance, facts, refinement,
                                                unestimated=opted_out(scene), warn=not member),
                               method=method_choice(scene))
    symmetry = scene.symmetry_choice             # of a 3D FE cell: its quarter or its period, and why
    if scene.discretization.method == "fe" and scene.geometry.dim == 3 and symmetry is not None:
        results["accuracy"]["symmetry"] = symmetry.as_dict()
    if cell.penalty() is not None:  # the model's share: reported and printed, not counted against the tolerance
        with clock.stage("penalty share"):
            share = penalty_share(cell, loads, per_load,
                                  refined=refinement is not None and not refinement.scene_discretization)
        if share is not None:
            results["accuracy"]["model"] = share
    vtk = {}
    displaced = cell.displacements()
    if displaced is not None:
        mesh, fields = displaced
        vtk["cell"] = VtkField(mesh=mesh, fields=fields, subdivision=1)
    plots = surface_plots(sols, cell.dim, cell.period)
    plots.update(contact_curve_plot(sols))
    if topography is not None:
        plots["psd"] = lambda path, t=topography: figures.topography_psd(path, t["psd"], f"{t['file']} ({t['source']})")
    return Outcome(results=results, ndof=cell.unknowns(),
                   solver=cell.solver_record(sols, refinement), tables=tables, vtk=vtk, plots=plots,
                   arrays=arrays)
