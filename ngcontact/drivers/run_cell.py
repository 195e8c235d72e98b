"""Driver of the ``cell`` kind: mesh the cell, solve the load sweep, collect results.

Results (``report.json`` ``results``): ``whole_surface`` coefficients of the
whole contact surface (paper eqs. 34, 42-43, purely geometric), and per load
``contact_fraction``, ``mean_pressure`` (compression positive),
``mean_traction``, ``mean_jump``, ``mean_closure``, ``coefficients`` on the
real contact set, ``effective_stiffness`` and the largest von Mises / Tresca
stress per body with its location (see :mod:`ngcontact.cell.cell_problem`).
With ``discretization.tolerance`` each load is solved on its own mesh,
graded towards its contact edges (:mod:`ngcontact.cell.edge_grading`), and
its entry adds ``error_estimate`` and ``mesh_history``.  With
``discretization.method = "spectral"`` the small-slope cell is solved on a
grid (:mod:`ngcontact.cell.spectral_cell`, :func:`run_spectral`): the same
per-load keys (no body stresses: the layers' interiors are not sampled), the
grid fields as ``.npy`` and ``results.method`` stating the grid; with a
tolerance the grid is refined (:mod:`ngcontact.cell.spectral_refinement`),
each load adds ``error_estimate`` and ``results.method.refinement`` holds the
levels.  With ``load.independent`` every load is solved from the unloaded
cell as a member of a batch (:mod:`ngcontact.drivers.cell_members`), on the
run's workers.
"""
from __future__ import annotations

import logging
from dataclasses import replace
from typing import Any

import numpy as np


from ngcontact.drivers.build import (build_cell, cell_loads, cell_problem, gap_cf, micro_friction, model_of,
                                    predictor_twin, spectral_cell)
from ngcontact.cell.edge_grading import (LEVELS_PER_STEP, MAX_STEPS, RATIO, GradedSolve, graded_flat_cell,
                                        solve_to_tolerance)
from ngcontact.cell.spectral_predictor import twin_edges

from ngcontact.cell import spectral_measures
from ngcontact.drivers import cell_members
from ngcontact.cell.spectral_refinement import sweep_to_tolerance
from ngcontact.scene.cell_scene import MAX_SPECTRAL_POINTS
from ngcontact.cell.coefficients import coefficients
from ngcontact.output import plots as figures
from ngcontact.output.report import Outcome, VtkField

log = logging.getLogger(__name__)


def solve_graded(scene, loads) -> list[GradedSolve]:
    """Each load on its own mesh, graded towards its contact edges until ``discretization.tolerance`` is met."""
    g, d = scene.geometry, scene.discretization
    model = model_of(scene)
    h0 = d.interface_maxh or d.maxh
    # one twin for every load and level, as fine as the finest grading asks (within the grid's bound): it seeds
    # each load's first mesh with its contact edges and starts every level (edge_grading's docstring)
    twin = predictor_twin(scene, h0 * RATIO ** (MAX_STEPS * LEVELS_PER_STEP))

    def make_problem(vertices, order):
        cell = graded_flat_cell(g.period, g.h_rough, g.h_counter, maxh=d.maxh, interface_maxh=h0, order=order,
                                vertices=vertices)
        return cell_problem(scene, cell, replace(model, order=order), twin=twin)

    out = []
    for k, load in enumerate(loads):
        seed = twin_edges(twin, load) if twin is not None else None
        out.append(solve_to_tolerance(make_problem, load, d.tolerance, h0, g.period, d.order, seed=seed))
        log.info("load %d: contact fraction %.10g after %d grading steps", k,
                 out[-1].solution.results["contact_fraction"], len(out[-1].history) - 1)
    return out


def contact_curve_plot(sols) -> dict:
    """``{"contact_curve": draw}`` for a sweep of more than one load (either cell's solutions), else empty."""
    if len(sols) < 2:
        return {}
    curve = {k: [s.results[k] for s in sols] for k in ("transmitted_pressure", "contact_fraction", "mean_closure")}
    return {"contact_curve": lambda path: figures.cell_contact_curve(
        path, curve["transmitted_pressure"], curve["contact_fraction"], curve["mean_closure"])}


def run_spectral(scene, clock) -> Outcome:
    """Solve a small-slope ``cell`` scene with the spectral cell."""
    with clock.stage("grid"):
        cell = spectral_cell(scene)
    whole = spectral_measures.coefficients(cell, np.ones(cell.shape, bool)).as_dict()
    tolerance = scene.discretization.tolerance
    results: dict[str, Any] = {"method": {"name": "spectral", "grid": cell.grid, "points": cell.points,
                                          "enforcement": cell.enforcement,
                                          "solver": "constrained_cg" if cell.friction is None
                                          else "accelerated_proximal_gradient",
                                          "tolerance": cell.tol},
                               "whole_surface": whole}
    if scene.contact.geometric_only:
        return Outcome(results=results, ndof=cell.points)
    estimates: list[dict[str, float] | None] = []
    with clock.stage("solve"):
        if tolerance is None and scene.load.independent:
            sols = cell_members.solve_spectral(scene)
            estimates = [None] * len(sols)
        elif tolerance is None:
            sols = cell.sweep(cell_loads(scene))
            estimates = [None] * len(sols)
        else:
            first = cell                   # the first level is the scene's own grid: built already
            refined = sweep_to_tolerance(lambda n: first if n == first.grid else spectral_cell(scene, grid=n),
                                         cell_loads(scene), tolerance, cell.grid, cell.dim, MAX_SPECTRAL_POINTS)
            cell, sols = refined.cell, refined.solutions
            estimates = list(refined.estimates)
            results["method"].update(grid=cell.grid, points=cell.points, refinement=refined.history)
    per_load, tables, arrays = [], {}, {}
    for k, sol in enumerate(sols):
        entry = dict(sol.results)
        entry["iterations"] = sol.iterations
        if estimates[k] is not None:
            entry["error_estimate"] = estimates[k]
        per_load.append(entry)
        for name in ("pressure", "gap", "shear", "slip"):
            if name in sol.fields:
                arrays[f"{name}_load{k}"] = sol.fields[name]
        if cell.dim == 2:
            x = cell.period * np.arange(cell.grid) / cell.grid
            tables[f"surface_load{k}"] = (["x", "pressure", "gap", "closure"], list(zip(
                x, sol.fields["pressure"], sol.fields["gap"], sol.fields["closure"])))
        log.info("load %d: %d constrained CG steps, contact fraction %.8f", k, sol.iterations,
                 sol.results["contact_fraction"])
    results["loads"] = per_load
    solver = {"iterations": sum(s.iterations for s in sols), "converged": True,
              "per_load": [{"method": "constrained_cg", "iterations": s.iterations,
                            "residuals": s.residuals} for s in sols]}
    plots: dict[str, Any] = {}
    if cell.dim == 2:
        xs = cell.period * np.arange(cell.grid) / cell.grid
        surfaces = [{"x": xs, "pressure": s.fields["pressure"], "slip": np.zeros(cell.grid)} for s in sols]
        plots["surface"] = lambda path, sf=surfaces: figures.cell_surface(path, sf)
    else:
        maps = [s.fields["pressure"] for s in sols]
        plots["pressure_map"] = lambda path, m=maps: figures.pressure_map(path, m, cell.period)
    plots.update(contact_curve_plot(sols))
    return Outcome(results=results, ndof=cell.points, solver=solver, tables=tables, plots=plots, arrays=arrays)


def run(scene, clock) -> Outcome:
    """Solve a ``cell`` scene; no file I/O (see :mod:`ngcontact.output.report`)."""
    if scene.discretization.method == "spectral":
        return run_spectral(scene, clock)
    with clock.stage("mesh"):
        cell = build_cell(scene)
    c = scene.contact
    friction = micro_friction(c)
    G = None if friction is None or friction.couples_to_pressure else friction.threshold(None)
    with clock.stage("whole-surface coefficients"):
        whole = coefficients(cell, kn=c.k_n, gap=gap_cf(scene), G=G).as_dict()
    results: dict[str, Any] = {"whole_surface": whole}
    if c.geometric_only:
        return Outcome(results=results, ndof=0)
    with clock.stage("setup"):
        P = cell_problem(scene, cell)
    graded: list[GradedSolve] = []
    with clock.stage("solve"):
        if scene.discretization.tolerance is None and scene.load.independent:
            sols = cell_members.solve_fe(scene, P)
        elif scene.discretization.tolerance is None:
            sols = P.sweep(cell_loads(scene))
        else:
            graded = solve_graded(scene, cell_loads(scene))
            sols = [g.solution for g in graded]
            P = graded[-1].problem
            cell = P.cell
    per_load, tables, newton = [], {}, []
    for k, sol in enumerate(sols):
        entry = dict(sol.results)
        if graded:
            entry["error_estimate"] = graded[k].estimate
            entry["mesh_history"] = graded[k].history
        # graded: the Newton steps of every level the load was solved on, not only the last
        entry["newton_iterations"] = (sum(h["newton_iterations"] for h in graded[k].history) if graded
                                      else sol.iterations)
        entry["coulomb_iterations"] = sol.coulomb_iterations
        per_load.append(entry)
        newton.append(graded[k].newton if graded else sol.newton)
        sf = sol.surface
        coords = [k for k in ("x", "y", "z") if k in sf]
        tables[f"surface_load{k}"] = (coords + ["pressure", "slip", "closure"],
                                      list(zip(*[sf[n] for n in coords + ["pressure", "slip", "closure"]])))
    results["loads"] = per_load
    solver = {"iterations": sum(entry["newton_iterations"] for entry in per_load),
              "converged": True, "per_load": newton, "linear": P.linear.summary()}
    comps = P.gfu.components
    vtk = {"cell": VtkField(mesh=cell.mesh, fields={"u_rough": comps[0], "u_counter": comps[1]},
                            subdivision=1)}
    plots = {}
    if cell.dim == 2:
        surfaces = [{k: sol.surface[k] for k in ("x", "pressure", "slip")} for sol in sols]
        plots["surface"] = lambda path, sf=surfaces: figures.cell_surface(path, sf)
    plots.update(contact_curve_plot(sols))
    return Outcome(results=results, ndof=P.ndof, solver=solver, tables=tables, vtk=vtk, plots=plots)
