"""Driver of the ``cell`` kind: mesh the cell, solve the load sweep, collect results.

Results (``report.json`` ``results``): ``whole_surface`` coefficients of the
whole contact surface (paper eqs. 34, 42-43, purely geometric), and per load
``contact_fraction``, ``mean_pressure`` (compression positive),
``mean_traction``, ``mean_jump``, ``mean_closure``, ``coefficients`` on the
real contact set, ``effective_stiffness`` and the largest von Mises / Tresca
stress per body with its location (see :mod:`ngcontact.cell.cell_problem`).
"""
from __future__ import annotations

import logging
import math

import ngsolve as ng

from ngcontact.drivers.build import build_cell, cell_loads, gap_cf, model_of
from ngcontact.cell.cell_problem import CellProblem
import numpy as np

from ngcontact.cell.coefficients import coefficients
from ngcontact.output.report import Outcome, VtkField

log = logging.getLogger(__name__)


def run(scene, clock) -> Outcome:
    """Solve a ``cell`` scene; no file I/O (see :mod:`ngcontact.output.report`)."""
    with clock.stage("mesh"):
        cell = build_cell(scene)
    c = scene.contact
    G = c.G if c.friction == "tresca" else None
    with clock.stage("whole-surface coefficients"):
        whole = coefficients(cell, kn=c.k_n, gap=gap_cf(scene), G=G).as_dict()
    results = {"whole_surface": whole}
    if c.geometric_only:
        return Outcome(results=results, ndof=0)
    with clock.stage("setup"):
        s = scene.solver
        P = CellProblem(cell, model_of(scene), rtol=s.rtol, atol=s.atol, max_iter=s.max_iter,
                        inverse=s.inverse)
    with clock.stage("solve"):
        sols = P.sweep(cell_loads(scene))
    per_load, tables, newton = [], {}, []
    for k, sol in enumerate(sols):
        entry = dict(sol.results)
        entry["newton_iterations"] = sol.iterations
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
        plots["surface"] = lambda path, sols=sols: _plot_surface(path, sols)
    if len(sols) > 1:
        plots["contact_curve"] = lambda path, sols=sols: _plot_curve(path, sols)
    return Outcome(results=results, ndof=P.ndof, solver=solver, tables=tables, vtk=vtk, plots=plots)


def _plot_surface(path, sols):
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(6, 5))
    for k, sol in enumerate(sols):
        sf = sol.surface
        a1.plot(sf["x"], sf["pressure"], label=f"load {k}")
        a2.plot(sf["x"], sf["slip"])
    a1.set_ylabel("pressure (compression +)")
    a2.set_ylabel("|slip|")
    a2.set_xlabel("x")
    a1.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _plot_curve(path, sols):
    import matplotlib.pyplot as plt
    p = [s.results["transmitted_pressure"] for s in sols]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(8, 3.5))
    a1.plot(p, [s.results["contact_fraction"] for s in sols], "o-")
    a1.set_xlabel("mean pressure")
    a1.set_ylabel("contact fraction")
    a2.plot(p, [s.results["mean_closure"] for s in sols], "o-")
    a2.set_xlabel("mean pressure")
    a2.set_ylabel("mean closure")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
