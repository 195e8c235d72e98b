"""Driver of the ``macro`` kind: geometry -> macro problem -> solve -> results.

Returns an :class:`~ngcontact.output.report.Outcome` (no file I/O here; a law from a cell scene is read
through :mod:`ngcontact.coupling.cell_law`, which keeps its cache).

``results``:

* ``interface``: arrays along the interface (2D / axisymmetric): ``s`` arc length from the end with the
  largest ``z`` (``y``) [m], ``r, z`` (or ``x, y``) [m], ``pressure`` [Pa, compression positive], ``shear``
  [Pa, traction along ``t0``], ``jump_n`` [m, ``J . n0``, positive closes], ``jump_t`` [m, ``J . t0``],
  ``status`` (``open`` / ``stick`` / ``slip``);
  3D: the same on the interface surface (``x, y, z``, ``pressure``,
  ``shear_1``, ``shear_2`` along the law's tangents ``t1, t2``, ``shear`` their
  magnitude, ``jump_n``, ``jump_t1``, ``jump_t2``, ``status``) with
  ``contact_area`` (share of ``S_0`` in contact) and ``mean_pressure`` (the
  pressure averaged over ``S_0``, Pa), written as ``interface.csv``
  and plotted on the surface (``interface.png``) and against the axial
  position ``z`` (``interface_axial.png``); with ``[two_scale]`` also the
  cell's ``contact_fraction`` at every sample; the stress fields of 3D
  quarters on their symmetry plane ``y = 0`` (``stress.png``, as in 2D);
* ``resultant``: force through the interface from the rough to the counter
  body [N; axisymmetric: axial, per full revolution; plane strain: per metre];
* ``reactions``: per supported boundary the force the bodies exert on the
  support in the fixed components (axisymmetric: axial only) and, in plane
  strain for a support fixing every component, its moment about the
  boundary's mid-point, as the ``direct`` kind reports them
  (:func:`ngcontact.fem.reaction.support_reactions`);
* ``maxima``: peak pressure and largest |shear| with their location, the
  largest and smallest stress components, von Mises stress and strain with location and body;
* ``detachment``: points where the interface changes between open and closed;
* ``accuracy``: the headline quantities with their estimated discretization errors against
  ``discretization.tolerance`` (:mod:`ngcontact.drivers.macro_accuracy`), which a scene that states it is
  first refined towards (:mod:`ngcontact.drivers.macro_refinement`; ``accuracy.refinement``);
* ``law``, ``dimensions``, ``newton_iterations``, ``coulomb_iterations``.
"""
from __future__ import annotations

import logging
from collections import Counter
from functools import partial
from typing import Any

import numpy as np
import ngsolve as ng

from ngcontact.drivers.mesh_supports import supports_on
from ngcontact.drivers.macro_accuracy import accuracy, check_radius, safety_factor_of
from ngcontact.drivers.macro_refinement import refine
from ngcontact.drivers.build import friction_from_cell, law_from_cell, law_from_file, linear_solver
from ngcontact.drivers.scene_laws import body_laws, interface_friction, interface_normal_law
from ngcontact.laws import homogenized as il
from ngcontact.fem.interpolants import piecewise_linear
from ngcontact.macro import macro_problem as M
from ngcontact.macro import macro_measures as MM
from ngcontact.errors import ConvergenceError, SceneError
from ngcontact.geometry import bodies as gm
from ngcontact.scene.macro_shapes import REGIONS
from ngcontact.drivers.macro_geometry import MACRO_SHAPES, build_geometry
from ngcontact.output import plots as figures
from ngcontact.output.report import Outcome, VtkField
from ngcontact.scene import cell_links
from ngcontact.scene.sections import resolve

from ngcontact.fem.rigid_modes import check_rigid_modes
from ngcontact.macro.solution_measures import WHOLE_MESH, Measures, reactions_of

log = logging.getLogger(__name__)


def interface_law_of(scene, dim: int) -> tuple[il.InterfaceLaw, dict]:
    """The interface law of ``scene`` and a description of it for the report."""
    spec = scene.interface
    normal: il.NormalLaw | None
    overrides = cell_links.overrides(spec)
    if spec.law == "file":
        normal, info = law_from_file(resolve(scene, spec.law_file), spec.law_file_form, dim=dim)
    elif spec.cell is not None:
        normal, info = law_from_cell(resolve(scene, spec.cell), dim=dim, linear=spec.law == "linear",
                                     length_unit=spec.cell_length_unit, overrides=overrides)
    else:
        normal = interface_normal_law(spec)
        info = {"source": "explicit numbers"}
        if isinstance(normal, il.BundleLaw) and len(normal.directions[0]) != dim:
            raise SceneError("interface.directions", normal.directions,
                             f"need {dim} components per direction in this setting")
    assert normal is not None  # only a scene with a cell has no explicit law, and that branch is above
    info = {"type": scene.interface.law, **info, "full_contact_K0": _K0(normal, dim)}
    friction: il.Friction | None
    if spec.friction == "from_cell":
        cell = spec.cell if spec.cell is not None else scene.two_scale.cell
        friction, info["friction"] = friction_from_cell(resolve(scene, cell), width=spec.huber_width,
                                                        overrides=overrides)
    else:
        friction = interface_friction(spec)
        info["friction"] = {"source": "scene", "mu0": spec.mu, "G0": spec.threshold, "huber_width": spec.huber_width}
    if overrides:
        info["cell_overrides"] = overrides
    return il.InterfaceLaw(normal=normal, friction=friction), info


def _K0(normal: il.NormalLaw, dim: int):
    K0 = normal.full_contact_K0(dim)
    return None if K0 is None else np.asarray(K0).tolist()


#: Largest equivalent strain for which the linear (small-strain) elasticity of the model is meaningful.
SMALL_STRAIN = 0.05


def small_strain_warnings(strain: float) -> list[str]:
    """A warning (logged and reported) when the largest von Mises strain leaves the small-strain range.

    Loads far beyond a joint's gave strains of ~7000 without a word: the
    linear model still solves, but its answer is no longer physical.
    """
    if not strain > SMALL_STRAIN:
        return []
    text = (f"the largest von Mises strain {strain:.3g} exceeds {SMALL_STRAIN:g}: linear (small-strain) "
            "elasticity does not hold there, so stresses and displacements are not physical; check the loads, "
            "gaps and units")
    log.warning("ngcontact: warning: %s", text)
    return [text]


def check_gap_table_covers(scene, mesh) -> None:
    """``interface.gap_table`` must span the interface along its coordinate.

    Outside its rows the piecewise linear gap would be held at the end
    values, silently; a table that stops short of the interface is refused.
    """
    spec = scene.interface
    if spec.gap_table is None:
        return
    axis = {"x": 0, "r": 0, "y": 1, "z": 2}[spec.gap_coordinate]
    if spec.gap_coordinate == "z" and scene.geometry.setting == "axisymmetric":
        axis = 1
    coords = [mesh[v].point[axis] for el in mesh.Elements(ng.BND) if el.mat == "interface" for v in el.vertices]
    lo, hi = min(coords), max(coords)
    first, last = spec.gap_table[0][0], spec.gap_table[-1][0]
    tol = 1e-9 * max(abs(hi - lo), abs(last - first), 1e-300)
    if first > lo + tol or last < hi - tol:
        raise SceneError("interface.gap_table", [list(r) for r in spec.gap_table],
                         f"covers {spec.gap_coordinate} in [{first:g}, {last:g}], but the interface spans "
                         f"[{lo:g}, {hi:g}]; give rows that cover it (outside them the gap would be held "
                         "at the end values)")


def gap_of(scene):
    """The macro normal gap ``g0``: a number or a piecewise linear CoefficientFunction."""
    spec = scene.interface
    if spec.gap_table is None:
        return spec.gap
    coord = {"x": ng.x, "r": ng.x, "y": ng.y, "z": ng.z}[spec.gap_coordinate]
    if spec.gap_coordinate == "z" and scene.geometry.setting == "axisymmetric":
        coord = ng.y
    return piecewise_linear(coord, spec.gap_table)


def check_boundaries(scene, mesh) -> None:
    """Every support and load names a boundary of the meshed shape, and the gap table covers the interface."""
    labels = M.boundary_labels(mesh)
    for what, items in (("supports", scene.supports), ("loads", scene.loads)):
        for i, item in enumerate(items):
            if item.boundary not in labels:
                raise SceneError(f"{what}[{i}].boundary", item.boundary,
                                 f"no such boundary in {scene.geometry.shape!r}; labels are " + ", ".join(labels))
    check_gap_table_covers(scene, mesh)


def check_model(scene) -> list[str]:
    """What ``run`` checks before the solve, without solving (``ngcontact check``).

    Meshes the shape, checks its boundary labels and the gap table's
    coverage, and refuses supports that leave a rigid motion free.  A law
    taken from a cell is not computed here: it is assumed to hold
    tangentially (a cell has a tangential stiffness), and ``run`` repeats
    the rigid-motion check with the computed law.  Returns the lines the
    shape lists about itself (a file's bodies and faces), made before meshing.
    """
    notes = MACRO_SHAPES[scene.geometry.shape].inventory(scene)
    geo = build_geometry(scene)
    check_boundaries(scene, geo.mesh)
    tangential = scene.interface.cell is not None or interface_law_of(scene, geo.mesh.dim)[0].holds_tangentially
    check_rigid_modes(geo.mesh, scene.geometry.setting, REGIONS[scene.geometry.shape], supports_of(scene, geo.mesh),
                      "interface", tangential)
    return notes


def supports_of(scene, mesh) -> tuple[M.Support, ...]:
    """The scene's ``[[supports]]`` on ``mesh`` as the problem's supports
    (:func:`ngcontact.drivers.mesh_supports.supports_on`: symmetry planes and slopes read off the mesh)."""
    return supports_on(scene.supports, mesh, scene.geometry.setting)


def body_forces_of(scene) -> dict[str, tuple[float, ...]]:
    """The scene's ``[body_forces]`` by region."""
    rough, counter = REGIONS[scene.geometry.shape]
    f = scene.body_forces
    return {region: tuple(v) for region, v in ((rough, f.rough), (counter, f.counter)) if any(v)}


def problem_of(scene, geometry: gm.MacroGeometry, *, order=None) -> tuple[M.MacroProblem, dict]:
    """The :class:`~ngcontact.macro.macro_problem.MacroProblem` of ``scene`` on ``geometry``.

    Raises
    ------
    SceneError
        A boundary label the geometry does not have (the message lists those it has).
    """
    check_boundaries(scene, geometry.mesh)
    law, info = interface_law_of(scene, geometry.mesh.dim)
    rough, counter = REGIONS[scene.geometry.shape]
    mats = body_laws(scene, {rough: scene.bodies.rough, counter: scene.bodies.counter})
    problem = M.MacroProblem(
        mesh=geometry.mesh, setting=scene.geometry.setting, rough=rough, counter=counter, materials=mats,
        law=law, gap=gap_of(scene), order=order or scene.discretization.order,
        supports=supports_of(scene, geometry.mesh), body_forces=body_forces_of(scene),
        loads=tuple(M.Load(label=lo.boundary, pressure=lo.pressure, traction=lo.traction) for lo in scene.loads))
    return problem, info


def reactions(sol: M.MacroSolution) -> dict:
    """Reaction force (and moment) of every supported boundary (:func:`ngcontact.fem.reaction.support_reactions`)."""
    return reactions_of(sol)


def solve_scene(scene, problem: M.MacroProblem, start=None, rtol: float | None = None) -> M.MacroSolution:
    """:func:`ngcontact.macro.macro_problem.solve` with the scene's solver settings.

    ``start``: warm start; ``rtol``: a looser Newton tolerance than the
    scene's, for a solve that only starts another (the scene's where it is
    looser already).
    """
    s = scene.solver
    return M.solve(problem, rtol=max(s.rtol, rtol or 0.0), atol=s.atol, max_iter=s.max_iter, inverse=s.inverse,
                   coulomb_rtol=s.coulomb_rtol, coulomb_max_iter=s.coulomb_max_iter, linear=linear_solver(scene),
                   coulomb=s.coulomb, start=start)


def checked_equilibrium(sol: M.MacroSolution, measures: Measures = WHOLE_MESH) -> dict:
    """:func:`ngcontact.macro.macro_measures.equilibrium` (taken by ``measures``), refused beyond its tolerance.

    Raises
    ------
    ConvergenceError
        A body's forces do not balance: the figures of the worst one.
    """
    eq = measures.equilibrium(sol)
    if not eq["error"] <= eq["tolerance"]:
        body, comp, f = max(((b, c, f) for b, fc in eq["bodies"].items() for c, f in fc.items()),
                            key=lambda t: abs(t[2]["imbalance"]))
        raise ConvergenceError(
            f"the solution is not in equilibrium: body {body!r} in {comp}: applied {f['applied']:.6g}, "
            f"interface {f['interface']:.6g}, supports {f['supports']:.6g} leave {f['imbalance']:.3g} "
            f"({eq['error']:.2g} of the largest force {eq['scale']:.6g}, allowed {eq['tolerance']:g}); "
            "tighten solver.rtol or check the supports and the law's stiffness", sol.history)
    return eq


def run(scene, clock) -> Outcome:
    """Solve a ``macro`` scene; no file I/O (see :mod:`ngcontact.output.report`)."""
    with clock.stage("mesh"):
        geo = build_geometry(scene)
    with clock.stage("interface law"):
        problem, law_info = problem_of(scene, geo)
        check_radius(scene, problem)
    two_scale = relevel = recovery = refined = None
    if scene.strength is not None:
        from ngcontact.drivers.run_strength import recovery_of
        with clock.stage("strength check"):
            # before the loop (which keeps the one feature of the law the correctors depend on: a tangential part)
            recovery = recovery_of(scene, problem.law)
    with clock.stage("solve"):
        if scene.two_scale is None:
            sol = solve_scene(scene, problem)
        else:
            from ngcontact.drivers.run_two_scale import couple_loop
            sol, two_scale, relevel = couple_loop(scene, problem, partial(solve_scene, scene),
                                                  safety=safety_factor_of(scene, recovery))   # in the table share
    if scene.discretization.tolerance is not None:
        with clock.stage("refinement to the tolerance"):
            refined = refine(scene, sol, partial(solve_scene, scene), safety_factor_of(scene, recovery), relevel)
        sol = refined.solution if refined else sol
    with clock.stage("post-processing"):
        outcome = measured(sol, geo, law_info, scene.output)
        results = outcome.results
        if two_scale is not None:
            results["two_scale"] = two_scale if relevel is None else relevel.record(two_scale, sol)
            if "interface" in results:
                results["interface"]["contact_fraction"] = np.asarray(two_scale["interface_coefficients"]
                                                                     ["contact_fraction"])
    if scene.strength is not None:
        from ngcontact.drivers.run_strength import evaluate
        with clock.stage("strength check"):
            st = evaluate(scene, sol, recovery)
        results["strength"] = st["results"]
        if two_scale is not None:
            results["two_scale"]["summary"] = two_scale_summary(two_scale, st["results"])
        outcome.tables["strength_map"] = st["table"]
        outcome.vtk["worst_cell"] = st["vtk"]
        outcome.plots.update(st["plots"])
    with clock.stage("discretization error"):
        results["accuracy"] = accuracy(scene, sol, partial(solve_scene, scene), results["equilibrium"], two_scale,
                                       recovery, refined)
    if refined is not None:
        results["accuracy"]["refinement"] = refined.record()
    return outcome


def measured(sol: M.MacroSolution, geo: gm.MacroGeometry, law_info: dict, output,
             measures: Measures = WHOLE_MESH) -> Outcome:
    """What a macro run reports of a solution on ``geo``: ``results`` (see the module's docstring; without
    the two-scale and strength parts), the interface table, the figures, the VTK fields and the solver's
    record.  ``output``: the scene's ``[output]`` section (samples per interface element, VTK subdivision);
    ``measures``: where the measures are taken (one process's whole mesh, or reduced over MPI ranks).

    Raises
    ------
    ConvergenceError
        The solution is not in equilibrium (:func:`checked_equilibrium`).
    """
    balance = checked_equilibrium(sol, measures)
    fields = MM.stress_fields(sol)
    extrema = measures.extrema(sol, fields)
    problem = sol.problem
    results = {"setting": problem.setting, "bodies": {"rough": problem.rough, "counter": problem.counter},
               "dimensions": geo.dims, "law": law_info, "resultant": MM.resultant(sol),
               "reactions": measures.reactions(sol),
               "newton_iterations": sol.history["newton_iterations"],
               "coulomb_iterations": sol.history["coulomb_iterations"], "equilibrium": balance}
    maxima = {name: ext for name, ext in extrema.items()}
    tables: dict[str, Any] = {}
    plots: dict[str, Any] = {}
    interface = interface_2d if geo.mesh.dim == 2 else interface_3d
    interface(sol, fields, output, geo, results, maxima, tables, plots, measures)
    results["maxima"] = maxima
    results["warnings"] = small_strain_warnings(maxima["von_mises_strain"]["max"]["value"])
    vtk = {"stress": VtkField(mesh=geo.mesh, fields=dict(fields, u_rough=sol.u_rough, u_counter=sol.u_counter),
                              subdivision=output.vtk_subdivision)}
    newton = sol.history["newton"]
    solver = {"iterations": sol.history["newton_iterations"], "converged": sol.history["converged"],
              "linear_solve_only": sol.history["quadratic"],
              "coulomb": sol.history["coulomb"], "coulomb_changes": sol.history["coulomb_changes"], "solves": newton,
              "linear": sol.history["linear"]}
    return Outcome(results=results, ndof=sol.ndof, solver=solver, tables=tables, vtk=vtk, plots=plots)


def interface_2d(sol, fields, output, geo, results, maxima, tables, plots, measures: Measures) -> None:
    """The interface of a 2D (plane strain, axisymmetric) solution along its arc: profile, status, peaks,
    detachment, its table and figures (``output.points_per_element`` samples per element)."""
    prof = measures.profile(sol, output.points_per_element)
    results["interface"] = {k: (list(v) if k == "status" else np.asarray(v)) for k, v in prof.items()}
    results["status_counts"] = dict(Counter(prof["status"]))
    maxima["pressure"] = MM.peak_pressure(prof)
    k = int(np.argmax(np.abs(prof["shear"])))
    maxima["shear"] = {key: (v[k] if key == "status" else float(v[k])) for key, v in prof.items()}
    results["detachment"] = MM.detachments(prof)
    header = list(prof)
    tables["interface"] = (header, list(zip(*[prof[h] for h in header])))
    plots["interface"] = lambda path, prof=prof: figures.macro_interface(path, prof)
    samples = measures.samples(field_samples, sol, fields)
    plots["stress"] = lambda path, d=samples: figures.macro_fields(path, **d)


def interface_3d(sol, fields, output, geo, results, maxima, tables, plots, measures: Measures) -> None:
    """The interface of a 3D solution over its surface: samples, contact area, status, peaks, its table and
    figures (and the stress on the section plane where the mesh has one)."""
    surf = measures.surface(sol)
    results["contact_area"] = surf.pop("contact_area")
    results["mean_pressure"] = MM.mean_pressure(sol)
    results["interface"] = {k: (list(v) if k == "status" else np.asarray(v)) for k, v in surf.items()}
    results["status_counts"] = dict(Counter(surf["status"]))
    for key in ("pressure", "shear"):
        k = int(np.argmax(surf[key]))
        maxima[key] = {name: (v[k] if name == "status" else float(v[k])) for name, v in surf.items()}
    header = list(surf)
    tables["interface"] = (header, list(zip(*[surf[h] for h in header])))
    plots["interface"] = lambda path, sf=surf: figures.macro_interface_3d(path, sf)
    plots["interface_axial"] = lambda path, sf=surf: figures.macro_interface_axial(path, sf)
    if SECTION in M.boundary_labels(geo.mesh):
        section = measures.samples(section_samples, sol, fields)
        plots["stress"] = lambda path, d=section: figures.macro_fields(path, **d)


def two_scale_summary(two_scale: dict, strength: dict) -> dict:
    """The two-scale loop and the strength check of its converged state in one place."""
    return {"iterations": two_scale["iterations"], "macro_solves": two_scale["macro_solves"],
            "cell_solves": two_scale["cell_solves"], "table_from_cache": two_scale["cache"]["table_from_cache"],
            "table_error_estimate": two_scale["table"]["error_estimate"],
            "newton_per_solve": two_scale["newton_per_solve"],
            "max_change": [h["max_change"] for h in two_scale["history"][1:]],
            "safety_factor": strength["safety_factor"], "critical_body": strength["critical_body"],
            "critical_points": {b: {"macro_point": e["macro_point"], "cell_point": e.get("cell_point"),
                                    "max_sigma_eq": e["max_sigma_eq"]} for b, e in strength["bodies"].items()}}


# ------------------------------------------------------------------ plot data
#: the symmetry plane y = 0 of the 3D quarters: the (r, z) section of a body of revolution at angle 0
SECTION = "sym_y"


def section_samples(sol: M.MacroSolution, fields: dict) -> dict:
    """Arrays for :func:`ngcontact.output.plots.macro_fields` from a 3D solution: the stress fields on
    the symmetry plane ``y = 0`` (:data:`SECTION`), where ``x`` is the radius ``r``.

    Three points near the vertices of every boundary triangle of the plane,
    each evaluated in the body behind it (moved ``1e-6`` of the mesh's
    extent to ``y > 0``, never on the plane itself), one plotted triangle per
    boundary triangle, so each body keeps its colouring.  Fields:
    ``sigma_xx`` (radial there), ``sigma_zz`` (axial), von Mises stress and strain.
    """
    p = sol.problem
    mesh = p.mesh
    names = ["sigma_xx", "sigma_zz", "von_mises", "von_mises_strain"]
    rule = ng.IntegrationRule([(1e-3, 1e-3), (1 - 2e-3, 1e-3), (1e-3, 1 - 2e-3)], [0.0] * 3)
    mips = mesh.MapToAllElements(rule, mesh.Boundaries(SECTION))
    xyz = np.asarray(ng.CF((ng.x, ng.y, ng.z))(mips)).reshape(-1, 3)
    pts = np.array([v.point for v in mesh.vertices])
    xyz[:, 1] += 1e-6 * float(np.max(pts.max(axis=0) - pts.min(axis=0)))
    inside = mesh(xyz[:, 0], xyz[:, 1], xyz[:, 2])
    keep = (inside["nr"] >= 0).reshape(-1, 3).all(axis=1).repeat(3)
    inside, xyz = inside[keep], xyz[keep]
    return {"x": xyz[:, 0], "y": xyz[:, 2], "triangles": np.arange(len(xyz)).reshape(-1, 3),
            "values": {n: np.asarray(fields[n](inside)).ravel() for n in names}, "axisymmetric": True}


def field_samples(sol: M.MacroSolution, fields: dict) -> dict:
    """Arrays for :func:`ngcontact.output.plots.macro_fields`: the stress fields at
    three points near the vertices of every element of both bodies (one
    triangle per element, so each body's colouring stays its own)."""
    p = sol.problem
    mesh = p.mesh
    names = [n for n in fields if n in ("sigma_r", "sigma_xx")][:1] + \
            [n for n in fields if n in ("sigma_z", "sigma_yy")][:1] + ["von_mises", "von_mises_strain"]
    rule = ng.IntegrationRule([(1e-3, 1e-3), (1 - 2e-3, 1e-3), (1e-3, 1 - 2e-3)], [0.0] * 3)
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    vals: dict[str, list[np.ndarray]] = {n: [] for n in names}
    for region in (p.rough, p.counter):
        mips = mesh.MapToAllElements(rule, mesh.Materials(region))
        xy = np.asarray(ng.CF((ng.x, ng.y))(mips)).reshape(-1, 2)
        xs.append(xy[:, 0])
        ys.append(xy[:, 1])
        for n in names:
            vals[n].append(np.asarray(fields[n](mips)).ravel())
    x, y = np.concatenate(xs), np.concatenate(ys)
    return {"x": x, "y": y, "triangles": np.arange(len(x)).reshape(-1, 3),
            "values": {n: np.concatenate(v) for n, v in vals.items()},
            "axisymmetric": p.setting == "axisymmetric"}
