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

from ngcontact.drivers.build import body_laws, elastic_law
from ngcontact.cell.cell_problem import CellModel, CellProblem, Friction
import numpy as np

from ngcontact.cell.coefficients import coefficients
from ngcontact.scene.cell_scene import GAP_PROFILES, loads, profile_2d, small_slope
from ngcontact.output.report import Outcome, VtkField
from ngcontact.scene.sections import resolve

log = logging.getLogger(__name__)


def build_cell(scene, maxh=None, interface_maxh=None, order=None):
    """Mesh the cell of ``scene.geometry`` (mesh sizes may be overridden)."""
    g, d = scene.geometry, scene.discretization
    maxh = maxh or d.maxh
    ih = interface_maxh or d.interface_maxh
    order = order or d.order
    if g.dim == 3:
        from ngcontact.geometry import cell3d
        if g.profile in GAP_PROFILES and not small_slope(g):
            if g.profile == "bisinusoid":
                heights = cell3d.bisinusoid_heights(g.amplitude, g.period)
            else:
                from ngcontact.geometry.tabulated import read_height_map
                heights = read_height_map(resolve(scene, g.file), path="geometry.file")
            return cell3d.surface_cell(heights, period=g.period, h_rough=g.h_rough,
                                       h_counter=g.h_counter, maxh=maxh, interface_maxh=ih,
                                       order=order)
        if g.profile != "square_hills":  # flat, or a small-slope profile carried by the gap
            return cell3d.flat_cell3d(g.period, g.h_rough, g.h_counter, maxh=maxh, interface_maxh=ih)
        return cell3d.square_hills_cell(g.width, g.depth, period=g.period, arrangement=g.arrangement,
                                        h_rough=g.h_rough, h_counter=g.h_counter, maxh=maxh,
                                        interface_maxh=ih)
    from ngcontact.geometry import profiles as pr
    if g.profile == "tabulated":
        from ngcontact.geometry.tabulated import read_profile_csv
        prof = read_profile_csv(resolve(scene, g.file), path="geometry.file")
    else:
        prof = profile_2d(g)
    return pr.profile_cell(prof, arrangement=g.arrangement, h_rough=g.h_rough, h_counter=g.h_counter,
                           maxh=maxh, interface_maxh=ih, order=order)


def gap_cf(scene):
    """The initial gap as a CoefficientFunction, or ``None`` when there is none.

    The sum of the explicit gap ``scene.contact.gap`` and, for the 3D
    small-slope profiles (bisinusoid, height map), the height below the
    highest summit.
    """
    terms = [t for t in (_profile_gap(scene), _explicit_gap(scene)) if t is not None]
    if not terms:
        return None
    return terms[0] if len(terms) == 1 else terms[0] + terms[1]


def _profile_gap(scene):
    g = scene.geometry
    if not small_slope(g):
        return None
    from ngcontact.geometry import cell3d
    if g.profile == "bisinusoid":
        return cell3d.bisinusoid_gap(g.amplitude, g.period)
    from ngcontact.geometry.tabulated import read_height_map
    return cell3d.height_map_gap(read_height_map(resolve(scene, g.file), path="geometry.file"), g.period)


def _explicit_gap(scene):
    gs, P = scene.contact.gap, scene.geometry.period
    if gs.kind == "none":
        return None
    if gs.kind == "constant":
        return ng.CF(gs.value)
    if gs.kind == "sinusoid":
        return 2 * gs.h * ng.sin(math.pi * ng.x / P) ** 2
    if gs.kind == "bisinusoid":
        return gs.h * (2 - ng.cos(2 * math.pi * ng.x / P) - ng.cos(2 * math.pi * ng.y / P))
    from ngcontact.geometry import tabulated
    if scene.geometry.dim == 2:
        x, g = tabulated.read_gap_csv(resolve(scene, gs.file), path="contact.gap.file")
        return periodic_table_1d(x, g, P)
    g = tabulated.read_gap_map(resolve(scene, gs.file), path="contact.gap.file")
    return ng.VoxelCoefficient((0.0, 0.0), (P, P), np.ascontiguousarray(g), linear=True)


def periodic_table_1d(x, g, period: float, samples: int = 4096):
    """Piecewise-linear interpolant of the samples ``(x_i, g_i)`` as a function of ``x``.

    Resampled on a uniform grid of ``samples`` intervals (exact for the
    polyline up to the resampling of its kinks) and carried by a 2D voxel
    coefficient that is constant in ``y``.
    """
    xs = np.linspace(0.0, period, samples + 1)
    row = np.interp(xs, x, g)
    data = np.ascontiguousarray(np.vstack([row, row]))
    return ng.VoxelCoefficient((0.0, -1e3), (period, 1e3), data, linear=True)


def model_of(scene) -> CellModel:
    c = scene.contact
    fr = None
    if c.friction == "tresca":
        fr = Friction("tresca", w=c.w, G=c.G)
    elif c.friction == "coulomb":
        fr = Friction("coulomb", w=c.w, mu=c.mu)
    ms = scene.load is not None and scene.load.macro_strain is not None
    return CellModel(rough=elastic_law(scene.materials[scene.bodies.rough]),
                     counter=elastic_law(scene.materials[scene.bodies.counter]),
                     k_n=c.k_n, gap=gap_cf(scene), friction=fr, order=scene.discretization.order,
                     macro_strain=ms)


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
        sols = P.sweep(loads(scene))
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
