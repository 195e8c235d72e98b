"""Driver of the ``cell`` kind: mesh the cell, solve the load sweep, collect results.

Results (``report.json`` ``results``): ``whole_surface`` coefficients of the
whole contact surface (paper eqs. 34, 42-43, purely geometric), and per load
``contact_fraction``, ``mean_pressure`` (compression positive),
``mean_traction``, ``mean_jump``, ``mean_closure``, ``coefficients`` on the
real contact set, ``effective_stiffness`` and the largest von Mises / Tresca
stress per body with its location (see :mod:`ngcontact.cell.cell_problem`).
With ``discretization.tolerance`` each load is solved on its own mesh,
graded towards its contact edges (:mod:`ngcontact.cell.edge_grading`), and
its entry adds ``error_estimate`` and ``mesh_history``.
"""
from __future__ import annotations

import logging
from dataclasses import replace
from typing import Any


from ngcontact.drivers.build import build_cell, cell_loads, gap_cf, model_of
from ngcontact.cell.cell_problem import CellProblem
from ngcontact.cell.edge_grading import GradedSolve, graded_flat_cell, solve_to_tolerance

from ngcontact.cell.coefficients import coefficients
from ngcontact.output import plots as figures
from ngcontact.output.report import Outcome, VtkField

log = logging.getLogger(__name__)


def solve_graded(scene, loads) -> list[GradedSolve]:
    """Each load on its own mesh, graded towards its contact edges until ``discretization.tolerance`` is met."""
    g, d, s = scene.geometry, scene.discretization, scene.solver
    model = model_of(scene)
    h0 = d.interface_maxh or d.maxh

    def make_problem(vertices, order):
        cell = graded_flat_cell(g.period, g.h_rough, g.h_counter, maxh=d.maxh, interface_maxh=h0, order=order,
                                vertices=vertices)
        return CellProblem(cell, replace(model, order=order), rtol=s.rtol, atol=s.atol, max_iter=s.max_iter,
                           inverse=s.inverse)

    out = []
    for k, load in enumerate(loads):
        out.append(solve_to_tolerance(make_problem, load, d.tolerance, h0, g.period, d.order))
        log.info("load %d: contact fraction %.10g after %d grading steps", k,
                 out[-1].solution.results["contact_fraction"], len(out[-1].history) - 1)
    return out


def run(scene, clock) -> Outcome:
    """Solve a ``cell`` scene; no file I/O (see :mod:`ngcontact.output.report`)."""
    with clock.stage("mesh"):
        cell = build_cell(scene)
    c = scene.contact
    G = c.G if c.friction == "tresca" else None
    with clock.stage("whole-surface coefficients"):
        whole = coefficients(cell, kn=c.k_n, gap=gap_cf(scene), G=G).as_dict()
    results: dict[str, Any] = {"whole_surface": whole}
    if c.geometric_only:
        return Outcome(results=results, ndof=0)
    with clock.stage("setup"):
        s = scene.solver
        P = CellProblem(cell, model_of(scene), rtol=s.rtol, atol=s.atol, max_iter=s.max_iter,
                        inverse=s.inverse)
    graded: list[GradedSolve] = []
    with clock.stage("solve"):
        if scene.discretization.tolerance is None:
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
        newton.append(sol.newton)
        sf = sol.surface
        coords = [k for k in ("x", "y", "z") if k in sf]
        tables[f"surface_load{k}"] = (coords + ["pressure", "slip", "closure"],
                                      list(zip(*[sf[n] for n in coords + ["pressure", "slip", "closure"]])))
    results["loads"] = per_load
    solver = {"iterations": sum(x.iterations for x in sols),
              "converged": True, "per_load": newton}
    comps = P.gfu.components
    vtk = {"cell": VtkField(mesh=cell.mesh, fields={"u_rough": comps[0], "u_counter": comps[1]},
                            subdivision=1)}
    plots = {}
    if cell.dim == 2:
        surfaces = [{k: sol.surface[k] for k in ("x", "pressure", "slip")} for sol in sols]
        plots["surface"] = lambda path, sf=surfaces: figures.cell_surface(path, sf)
    if len(sols) > 1:
        curve = {k: [s.results[k] for s in sols] for k in ("transmitted_pressure", "contact_fraction",
                                                            "mean_closure")}
        plots["contact_curve"] = lambda path, c=curve: figures.cell_contact_curve(
            path, c["transmitted_pressure"], c["contact_fraction"], c["mean_closure"])
    return Outcome(results=results, ndof=P.ndof, solver=solver, tables=tables, vtk=vtk, plots=plots)
