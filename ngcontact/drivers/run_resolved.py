"""Driver of the ``direct`` kind: resolved geometry -> resolved contact problem -> results.

Returns an :class:`~ngcontact.output.report.Outcome`; no file I/O.

``results``:

* ``periods`` ``N`` and ``eps`` [m], the resolved period (femur: the
  interface arc length over ``N``; ``segments`` lists ``[N_i, eps_i]`` of
  the cylinder and the cone);
* ``reactions``: per supported boundary the force the body exerts on the
  support in the fixed components [N per metre of thickness; axisymmetric:
  N per revolution, axial component only] and, in plane strain, its moment
  about the boundary's mid-point [N m / m]
  (:func:`ngcontact.fem.reaction.boundary_reaction`);
* ``contact_force``: force the counter body receives through the resolved
  surface [N/m; axisymmetric: ``int p n 2 pi r ds``, whose ``r`` entry is
  the integral of the radial line load, not a net force], from the micro
  pressure (compression positive);
* ``contact_fraction``: length of the closed part of ``S_C^eps`` per unit
  length of the macro interface (it exceeds 1 where valley walls are
  closed: the whole surface of a rectangular valley profile is
  ``1 + 2 depth / period``);
* ``probes``: displacements [m] at the study's probe points, if any;
* ``accuracy``: the contact fraction and the contact force's magnitude with their discretization errors
  estimated from one more solve at the run's order on its mesh refined uniformly once
  (:mod:`ngcontact.drivers.resolved_accuracy`);
  with ``discretization.tolerance`` the run is first refined towards it, order then interface mesh
  (:mod:`ngcontact.drivers.resolved_refinement`; ``accuracy.refinement``), and every result is the
  refined solution's;
* ``newton_iterations``, ``ndof``.
"""
from __future__ import annotations

import logging
from functools import partial

import numpy as np

from ngcontact.drivers.build import micro_friction
from ngcontact.drivers.scene_laws import body_laws
from ngcontact.drivers.mesh_supports import supports_on
from ngcontact.drivers.resolved_accuracy import accuracy
from ngcontact.drivers.resolved_refinement import refine
from ngcontact.resolved import resolved_problem as D
from ngcontact.geometry import profiles as pr
from ngcontact.geometry import resolved_shapes as rs
from ngcontact.scene.cell_geometry import profile_2d
from ngcontact.macro.macro_problem import Load
from ngcontact.output.report import Outcome, VtkField
from ngcontact.fem.reaction import support_reactions
from ngcontact.fem.sampling import probe

log = logging.getLogger(__name__)


def profile_of(cell_scene) -> pr.Profile:
    """The roughness profile of a 2D ``cell`` scene (parametric profiles only)."""
    return profile_2d(cell_scene.geometry)


def micro_law(cell_scene) -> dict:
    """``k_n``, ``gap`` and ``friction`` of the cell as keyword arguments of :class:`DirectProblem`."""
    c = cell_scene.contact
    gap = c.gap.value if c.gap.kind == "constant" else None
    return {"k_n": c.k_n, "gap": gap, "friction": micro_friction(c)}


def materials_of(scene) -> dict:
    return body_laws(scene, {"rough": scene.bodies.rough, "counter": scene.bodies.counter})


#: Region names of the two bodies in the ``direct`` kind (the femur's too).
REGIONS = rs.REGIONS


def shape_of(scene) -> rs.ResolvedShape:
    """The shape of the bodies (:mod:`ngcontact.geometry.resolved_shapes`) the scene's ``geometry`` names."""
    return rs.resolved_shape(scene.geometry)


def supports_of(scene, mesh) -> tuple:
    """The supports on ``mesh`` (:func:`ngcontact.drivers.mesh_supports.supports_on`); a support's slope runs
    along ``x`` on the shape's horizontal boundaries, else along ``y``."""
    horizontal = shape_of(scene).horizontal
    return supports_on(scene.supports, mesh, scene.geometry.setting,
                       along=lambda label: "x" if label in horizontal else "y")


def loads_of(scene) -> tuple:
    return tuple(Load(label=lo.boundary, pressure=lo.pressure, traction=lo.traction) for lo in scene.loads)


def interface_length(scene) -> float:
    """Arc length of the macro interface ``S_0`` (block width; femur: cone plus cylinder)."""
    return shape_of(scene).interface_length()


def eps_of(scene, periods: int) -> float:
    """Resolved period ``eps = (interface length) / N``."""
    return shape_of(scene).eps(periods)


def build_resolved(scene, periods: int | None = None, periodic: bool = False):
    """Mesh the bodies of ``scene`` with ``periods`` resolved periods (default: the scene's)."""
    d = scene.discretization
    shape = shape_of(scene)
    N = periods or scene.geometry.periods
    return shape.resolved(profile_of(scene.cell_scene), N, maxh=d.maxh,
                          interface_maxh=shape.eps(N) / d.elements_per_period, order=d.order, grading=d.grading,
                          periodic=periodic)


def build_flat(scene, interface_maxh: float):
    """The same bodies with the flat macro interface ``S_0`` (boundary ``interface``)."""
    d = scene.discretization
    return shape_of(scene).flat(maxh=d.maxh, interface_maxh=interface_maxh, grading=d.grading)


def body_of(scene, points) -> np.ndarray:
    """Body of each point with the flat interface: 0 rough, 1 counter, -1 outside."""
    return shape_of(scene).body_of(points)


def interface_distance(scene, points) -> np.ndarray:
    """Distance of each point from the flat macro interface ``S_0``."""
    return shape_of(scene).interface_distance(points)


def interface_part(scene):
    """Indicator (CoefficientFunction) of the interface part whose transmitted force the study compares.

    Blocks: the left half ``x < x0 + L/2``.  Femur: the cylindrical part
    ``z > z_corner`` (its share of the axial load against the cone's).
    """
    return shape_of(scene).interface_part()


def problem_of(scene, geometry) -> D.DirectProblem:
    """The resolved problem of ``scene`` on ``geometry``."""
    kw = micro_law(scene.cell_scene)
    return D.DirectProblem(mesh=geometry.mesh, materials=materials_of(scene), setting=scene.geometry.setting,
                           supports=supports_of(scene, geometry.mesh), loads=loads_of(scene),
                           order=scene.discretization.order,
                           contact=geometry.interface,
                           coulomb_rtol=scene.solver.coulomb_rtol,
                           coulomb_max_iter=scene.solver.coulomb_max_iter, **kw)


def solve_scene(scene, problem) -> D.DirectSolution:
    s = scene.solver
    return D.solve(problem, rtol=s.rtol, atol=s.atol, max_iter=s.max_iter, inverse=s.inverse)


def reactions(scene, sol) -> dict:
    """Reaction force and moment of every supported boundary
    (:func:`ngcontact.fem.reaction.support_reactions`; resolved or homogenized solution)."""
    p = sol.problem
    return support_reactions(p.mesh, p.setting, p.order, p.supports,
                             (("rough", p.materials["rough"], sol.u_rough),
                              ("counter", p.materials["counter"], sol.u_counter)))


def probes(scene, sol) -> list:
    """Displacements at the study's probe points, each from the body it lies in (:func:`body_of`)."""
    mesh = sol.problem.mesh
    out = []
    for x, y in (scene.study.probes if scene.study else ()):
        u = sol.u_rough if body_of(scene, [(x, y)])[0] == 0 else sol.u_counter
        out.append(probe(mesh, u, [(x, y)])[0].tolist())
    return out


def run(scene, clock) -> Outcome:
    """Solve a ``direct`` scene; no file I/O (see :mod:`ngcontact.output.report`)."""
    with clock.stage("mesh"):
        geo = build_resolved(scene)
    with clock.stage("solve"):
        sol = solve_scene(scene, problem_of(scene, geo))
    refined = None
    if scene.discretization.tolerance is not None:
        with clock.stage("refinement to the tolerance"):
            refined = refine(scene, sol, geo.length, partial(solve_scene, scene))
        if refined is not None:
            sol = refined.solution
    with clock.stage("post-processing"):
        results = {"periods": geo.periods, "eps": geo.eps, "setting": scene.geometry.setting,
                   "shape": scene.geometry.shape, "segments": [list(sg) for sg in geo.segments],
                   "reactions": reactions(scene, sol),
                   "contact_force": D.contact_force(sol).tolist(),
                   "contact_fraction": D.contact_fraction(sol, geo.length),
                   "probes": probes(scene, sol),
                   "newton_iterations": sol.history["newton_iterations"],
                   "elements": sol.problem.mesh.ne}
    with clock.stage("discretization error"):
        results["accuracy"] = accuracy(sol, geo.length, partial(solve_scene, scene), scene.discretization.tolerance,
                                       None if refined is None else refined.estimates)
    if refined is not None:
        results["accuracy"]["refinement"] = refined.record()
    vtk = {"resolved": VtkField(mesh=geo.mesh, fields={"u_rough": sol.u_rough, "u_counter": sol.u_counter},
                                subdivision=1)}
    solver = {"iterations": sol.history["newton_iterations"], "converged": sol.history["converged"],
              "solves": sol.history["newton"]}
    return Outcome(results=results, ndof=sol.ndof, solver=solver, vtk=vtk)
