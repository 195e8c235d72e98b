"""A macro problem on a mesh the caller built: arguments -> problem -> solve -> the macro run's report.

The same problem and the same post-processing as a ``macro`` scene
(:mod:`ngcontact.drivers.run_macro`): the energy of paper eq. 44 (the
bodies' elastic energy, the interface law's ``int_S0 W(a) w ds``, the surface
loads), minimized by Newton with the scene's solver settings, and the
``results`` of that driver (resultant, interface profile or surface, maxima,
equilibrium, ...).  Only the geometry and the law come from the caller: an
``ngsolve.Mesh`` with two body regions and an internal interface boundary
(:mod:`ngcontact.macro.interface_form` states what it must be) and an
:class:`~ngcontact.laws.homogenized.InterfaceLaw` (e.g.
:func:`ngcontact.drivers.cell_scene_law.cell_law`).

Supports, loads and the ``[solver]`` / ``[output]`` settings are given as a
macro scene writes them (dictionaries with the same keys, validated by the
same rules; errors name ``supports[0].boundary`` and so on), materials per
region as an :class:`~ngcontact.fem.materials.ElasticLaw` or a
``[materials.NAME]`` table (``E`` and ``nu``, or ``C``).
"""
from __future__ import annotations

from types import SimpleNamespace

import ngsolve as ng

from ngcontact.drivers import run_macro
from ngcontact.drivers.scene_laws import elastic_law
from ngcontact.drivers.cell_scene_law import CellLaw
from ngcontact.fem.elasticity import COMPONENTS
from ngcontact.fem.materials import ElasticLaw
from ngcontact.fem.two_body import boundary_labels
from ngcontact.geometry.bodies import MacroGeometry
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.macro.interface_form import check_interface, interface_law, refuse, setting_of
from ngcontact.output.report import Outcome
from ngcontact.scene import loader, mesh_size, schema
from ngcontact.scene.macro_scene import LoadSpec, OutputSpec, SupportSpec
from ngcontact.scene.sections import MaterialSpec, SolverSpec

#: the names of the normal laws in a report (a macro scene's ``interface.law``)
LAW_NAMES = {il.LinearLaw: "linear", il.BundleLaw: "bundle", il.TabulatedLaw: "tabulated"}


def _material(region: str, value) -> tuple[ElasticLaw, dict]:
    """An elastic law and its echo for the report."""
    if isinstance(value, ElasticLaw):
        return value, {"C": [list(r) for r in value.voigt]}
    if isinstance(value, dict):
        spec = schema.build(MaterialSpec, value, f"materials[{region!r}]")
        return elastic_law(spec), loader.as_dict(spec)
    raise refuse(f"materials[{region!r}]", value, "an ElasticLaw (ngcontact.fem.materials.isotropic(E, nu)) or "
                 "a table {'E': ..., 'nu': ...} or {'C': 6x6 Voigt matrix}")


def _materials(materials, rough: str, counter: str) -> tuple[dict, dict]:
    if not isinstance(materials, dict) or set(materials) != {rough, counter}:
        shown = sorted(materials) if isinstance(materials, dict) else materials
        raise refuse("materials", shown, f"one material per body region: keys {rough!r} and {counter!r}")
    built = {name: _material(name, value) for name, value in materials.items()}
    return {k: v[0] for k, v in built.items()}, {k: v[1] for k, v in built.items()}


def _specs(items, cls, key: str, labels: list[str]) -> list:
    """Supports or loads as the scene's sections, on boundaries the mesh has."""
    if isinstance(items, dict):
        raise refuse(key, items, "a list of tables, one per boundary")
    specs = [schema.build(cls, item, f"{key}[{i}]") for i, item in enumerate(items)]
    for i, spec in enumerate(specs):
        if spec.boundary not in labels:
            raise refuse(f"{key}[{i}].boundary", spec.boundary, "no such boundary in the mesh; its boundaries "
                         "are " + ", ".join(map(repr, labels)))
    return specs


def _check_components(supports, setting: str) -> None:
    """Components of the setting, one displacement per component."""
    comps = COMPONENTS[setting]
    for i, s in enumerate(supports):
        bad = [c for c in s.components if c not in comps]
        if bad:
            raise refuse(f"supports[{i}].components", list(s.components), f"components of {setting}: "
                         + ", ".join(comps))
        if s.displacement and len(s.displacement) != len(s.components or comps):
            raise refuse(f"supports[{i}].displacement", list(s.displacement),
                         f"one value per component ({len(s.components or comps)})")


def _law_info(law: il.InterfaceLaw, dim: int) -> dict:
    """The report's description of the law (``results.law``), as a macro run's."""
    if isinstance(law, CellLaw):
        return dict(law.source)
    K0 = law.normal.full_contact_K0(dim)
    friction = {"source": "none"} if law.friction is None else {"source": "given",
                                                                  "type": type(law.friction).__name__}
    return {"type": LAW_NAMES.get(type(law.normal), type(law.normal).__name__), "source": "given by the caller",
            "full_contact_K0": None if K0 is None else [list(map(float, r)) for r in K0], "friction": friction}


def _effects(law: il.InterfaceLaw, info: dict, gap, supports, loads) -> list[str]:
    """The terms assembled, named as a macro scene's (:func:`ngcontact.scene.macro_scene.effects`)."""
    out = ["elasticity", f"interface_{info['type']}" + ("_from_cell" if isinstance(law, CellLaw) else "")]
    if not (isinstance(gap, (int, float)) and gap == 0.0):
        out.append("initial_gap")
    if isinstance(law.friction, il.Friction):
        out += ["coulomb_friction"] * (law.friction.mu > 0) + ["tresca_friction"] * (law.friction.threshold > 0)
    if any(lo.pressure or lo.traction for lo in loads):
        out.append("surface_loads")
    if any(any(s.displacement) for s in supports):
        out.append("prescribed_displacement")
    return out


def _echo_mesh(mesh) -> dict:
    return {"dim": mesh.dim, "regions": sorted(set(mesh.GetMaterials())), "boundaries": boundary_labels(mesh),
            "elements": mesh.ne, "vertices": mesh.nv}


def accuracy_of(settings, sol: M.MacroSolution, info: dict, balance: dict) -> dict:
    """The macro run's accuracy verdict (:func:`ngcontact.drivers.macro_accuracy.accuracy`) on the caller's
    mesh: the default tolerance, no strength check or two-scale loop, and no roughness period (the law's
    modelling error is not estimated)."""
    from functools import partial

    from ngcontact.drivers.macro_accuracy import accuracy
    described = SimpleNamespace(
        solver=settings.solver, output=settings.output, two_scale=None,
        discretization=SimpleNamespace(tolerance=None),
        interface=SimpleNamespace(law=info.get("type", "given"), roughness_period=None, cell=None,
                                  cell_length_unit=1.0))
    return accuracy(described, sol, partial(run_macro.solve_scene, described), balance)


def run(mesh, law, *, rough: str, counter: str, materials: dict, interface: str = "interface",
        setting: str | None = None, supports=(), loads=(), gap=0.0, order: int = 2, solver: dict | None = None,
        output: dict | None = None, title: str = "", clock) -> tuple[Outcome, dict, list[str]]:
    """Solve the macro problem on ``mesh``; the outcome, the inputs echoed for the report, the effects.

    Arguments as :func:`ngcontact.runner.solve_mesh`; ``clock`` times the stages.

    Raises
    ------
    ModelError
        An argument the mesh or the problem cannot take (its name, value and what is allowed), supports
        that leave a rigid motion free.
    SceneError
        A value inside a support, load, material, solver or output table (named as the scene's key).
    ConvergenceError
        Newton failed, or the solution is not in equilibrium.
    """
    check_interface(mesh, rough, counter, interface)
    setting = setting_of(mesh, setting)
    law = interface_law(law, mesh.dim)
    if not (isinstance(order, int) and 1 <= order <= schema.MAX_ORDER):
        raise refuse("order", order, f"an integer in [1, {schema.MAX_ORDER}]")
    if isinstance(gap, bool) or not (isinstance(gap, ng.CoefficientFunction) or isinstance(gap, (int, float))
                                     and abs(gap) <= mesh_size.LENGTH_RANGE[1]):   # not NaN: no comparison holds
        raise refuse("gap", gap, f"a finite number of magnitude at most {mesh_size.LENGTH_RANGE[1]:g} (the macro "
                     "normal gap g0 in the mesh's length unit, < 0 an interference) or a CoefficientFunction")
    elastic, materials_echo = _materials(materials, rough, counter)
    labels = boundary_labels(mesh)
    support_specs = _specs(supports, SupportSpec, "supports", labels)
    _check_components(support_specs, setting)
    load_specs = _specs(loads, LoadSpec, "loads", labels)
    settings = SimpleNamespace(solver=schema.build(SolverSpec, solver or {}, "solver"),
                               output=schema.build(OutputSpec, output or {}, "output"))
    info = _law_info(law, mesh.dim)
    problem = M.MacroProblem(
        mesh=mesh, setting=setting, rough=rough, counter=counter, materials=elastic, law=law, gap=gap,
        order=order, interface=interface,
        supports=tuple(M.Support(label=s.boundary, components=s.components, value=s.displacement)
                       for s in support_specs),
        loads=tuple(M.Load(label=lo.boundary, pressure=lo.pressure, traction=lo.traction) for lo in load_specs))
    with clock.stage("solve"):
        sol = run_macro.solve_scene(settings, problem)
    with clock.stage("post-processing"):
        outcome = run_macro.measured(sol, MacroGeometry(mesh=mesh, rough=rough, counter=counter,
                                                        boundaries={b: "" for b in labels}, dims={}),
                                     info, settings.output)
    with clock.stage("discretization error"):
        outcome.results["accuracy"] = accuracy_of(settings, sol, info, outcome.results["equilibrium"])
    echo = {"kind": "macro", "title": title, "mesh": _echo_mesh(mesh), "setting": setting,
            "bodies": {"rough": rough, "counter": counter}, "interface": interface, "materials": materials_echo,
            "components": list(COMPONENTS[setting]), "supports": [loader.as_dict(s) for s in support_specs],
            "loads": [loader.as_dict(lo) for lo in load_specs],
            "gap": float(gap) if isinstance(gap, (int, float)) else "CoefficientFunction", "order": order,
            "solver": loader.as_dict(settings.solver), "output": loader.as_dict(settings.output), "law": info}
    return outcome, echo, _effects(law, info, gap, support_specs, load_specs)
