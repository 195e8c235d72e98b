"""Driver of the ``direct`` kind: resolved geometry -> resolved contact problem -> results.

Returns an :class:`~ngcontact.report.Outcome`; no file I/O.

``results``:

* ``periods`` ``N`` and ``eps`` [m], the resolved period;
* ``reactions``: per supported boundary the force the body exerts on the
  support [N per metre of thickness] and its moment about the boundary's
  mid-point [N m / m] (:func:`ngcontact.direct.boundary_reaction`);
* ``contact_force``: force the counter block receives through the resolved
  surface [N/m], from the micro pressure (compression positive);
* ``contact_fraction``: length of the closed part of ``S_C^eps`` per unit
  block width (it exceeds 1 where valley walls are closed: the whole
  surface of a rectangular valley profile is ``1 + 2 depth / period``);
* ``probes``: displacements [m] at the study's probe points, if any;
* ``newton_iterations``, ``ndof``.
"""
from __future__ import annotations

import logging

import ngsolve as ng
import numpy as np

from .. import direct as D
from ..geometry import profiles as pr
from ..geometry.resolved import resolved_blocks
from ..report import Outcome, VtkField

log = logging.getLogger(__name__)


def profile_of(cell_scene) -> pr.Profile:
    """The roughness profile of a 2D ``cell`` scene."""
    g = cell_scene.geometry
    if g.profile == "flat":
        return pr.flat(g.period)
    if g.profile == "rectangular":
        return pr.rectangular_valley(g.width, g.depth, g.period)
    if g.profile == "triangular":
        return pr.triangular_valley(g.angles[0], g.angles[1], g.width, g.period)
    if g.profile == "semicircular":
        return pr.semicircular_valley(g.radius, g.period)
    if g.profile == "sinusoid":
        return pr.sinusoid(g.amplitude, g.period)
    raise ValueError(f"profile {g.profile!r} cannot be resolved")


def micro_law(cell_scene) -> dict:
    """``k_n``, ``gap`` and ``friction`` of the cell as keyword arguments of :class:`DirectProblem`."""
    c = cell_scene.contact
    gap = c.gap.value if c.gap.kind == "constant" else None
    fr = None
    if c.friction == "tresca":
        fr = D.Friction(law="tresca", w=c.w, G=c.G)
    elif c.friction == "coulomb":
        fr = D.Friction(law="coulomb", w=c.w, mu=c.mu)
    return {"k_n": c.k_n, "gap": gap, "friction": fr}


def materials_of(scene) -> dict:
    return {"rough": scene.materials[scene.bodies.rough].law(),
            "counter": scene.materials[scene.bodies.counter].law()}


def supports_of(scene) -> tuple:
    return tuple(D.Support(label=s.boundary, components=s.components, value=s.displacement, slope=s.slope,
                           along="x" if s.boundary in ("top", "bottom") else "y") for s in scene.supports)


def loads_of(scene) -> tuple:
    return tuple(D.Load(label=lo.boundary, pressure=lo.pressure, traction=lo.traction) for lo in scene.loads)


def build_resolved(scene, periods: int | None = None, periodic: bool = False):
    """Mesh the blocks of ``scene`` with ``periods`` resolved periods (default: the scene's)."""
    g, d = scene.geometry, scene.discretization
    N = periods or g.periods
    eps = g.length / N
    return resolved_blocks(profile_of(scene.cell_scene), N, g.length, g.h_rough, g.h_counter,
                           maxh=d.maxh, interface_maxh=eps / d.elements_per_period,
                           order=d.order, periodic=periodic, grading=d.grading)


def problem_of(scene, geometry, *, law=None) -> D.DirectProblem:
    """The resolved problem (``law=None``) or its homogenized counterpart on a flat geometry."""
    kw = micro_law(scene.cell_scene)
    return D.DirectProblem(mesh=geometry.mesh, materials=materials_of(scene), setting=scene.geometry.setting,
                           supports=supports_of(scene), loads=loads_of(scene), order=scene.discretization.order,
                           contact=geometry.interface, law=law, **kw)


def solve_scene(scene, problem) -> D.DirectSolution:
    s = scene.solver
    return D.solve(problem, rtol=s.rtol, atol=s.atol, max_iter=s.max_iter, inverse=s.inverse)


def reactions(scene, sol) -> dict:
    """Reaction force and moment of every supported boundary (see :func:`ngcontact.direct.boundary_reaction`)."""
    p = sol.problem
    mesh = p.mesh
    out = {}
    for s in scene.supports:
        label = s.boundary
        xs = [mesh[v].point for el in mesh.Elements(ng.BND) if el.mat == label for v in el.vertices]
        about = tuple(0.5 * (np.min(xs, axis=0) + np.max(xs, axis=0)))
        total = None
        for region, u in (("rough", sol.u_rough), ("counter", sol.u_counter)):
            r = D.boundary_reaction(mesh, p.setting, p.materials[region], u, region, label, p.order, about=about)
            total = r if total is None else {k: total[k] + r[k] for k in r}
        out[label] = total
    return out


def probes(scene, sol) -> list:
    """Displacements at the study's probe points (rough block below ``y = 0``, counter above)."""
    mesh = sol.problem.mesh
    out = []
    for x, y in (scene.study.probes if scene.study else ()):
        u = sol.u_rough if y < 0 else sol.u_counter
        out.append(D.probe(mesh, u, [(x, y)])[0].tolist())
    return out


def run(scene, clock) -> Outcome:
    """Solve a ``direct`` scene; no file I/O (see :mod:`ngcontact.report`)."""
    with clock.stage("mesh"):
        geo = build_resolved(scene)
    with clock.stage("solve"):
        sol = solve_scene(scene, problem_of(scene, geo))
    with clock.stage("post-processing"):
        results = {"periods": geo.periods, "eps": geo.eps, "setting": scene.geometry.setting,
                   "reactions": reactions(scene, sol),
                   "contact_force": D.contact_force(sol).tolist(),
                   "contact_fraction": D.contact_fraction(sol, geo.length),
                   "probes": probes(scene, sol),
                   "newton_iterations": sol.history["newton_iterations"],
                   "elements": geo.mesh.ne}
    vtk = {"resolved": VtkField(mesh=geo.mesh, fields={"u_rough": sol.u_rough, "u_counter": sol.u_counter},
                                subdivision=1)}
    solver = {"iterations": sol.history["newton_iterations"], "converged": sol.history["converged"],
              "solves": sol.history["newton"]}
    return Outcome(results=results, ndof=sol.ndof, solver=solver, vtk=vtk)
