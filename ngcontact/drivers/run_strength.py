"""Driver part of ``[strength]`` (macro kind): macro state -> cell stresses -> check of eq. 78.

No file I/O: returns results, a table, a VTK field and plot callables for
the caller's :class:`~ngcontact.output.report.Outcome`.  See
:mod:`ngcontact.coupling.strength` for the mathematics.

``results["strength"]``: ``criterion``, ``recovery``, ``safety_factor``
(``min_B sigma_u,B / max sigma_eq,B``), ``holds`` (eq. 78: safety factor
> 1), ``critical_body``, per body ``max_sigma_eq`` [Pa], ``sigma_u`` [Pa],
``safety_factor``, ``macro_point`` (index into the interface samples: the
profile in 2D and axisymmetry, with its ``s`` [m], the surface in 3D;
coordinates [m]) and ``cell_point`` (cell coordinates, cell units),
``cell`` (scene path, ``ndof``, the fixed contact set, ``source``: where its correctors came from,
``shipped`` with the package, ``cached`` or ``computed``, :mod:`ngcontact.drivers.strength_cell`),
``tangential_stiffness`` and, with nonlinear recovery, the linear and
nonlinear maxima at the re-solved points.  The table
``strength_map`` has one row per interface sample with its macro state (2D:
``pressure, shear, e_t, e_hoop``; 3D: ``pressure, shear_1, shear_2, e_11,
e_22, e_12`` in the law's frame, :mod:`ngcontact.coupling.interface_state`).
"""
from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypedDict

import numpy as np

from ngcontact.coupling import strength as S
from ngcontact.coupling.interface_state import cell_loads, interface_states
from ngcontact.drivers.build import recovery_cell_scene
from ngcontact.drivers.strength_cell import fixed_set_correctors
from ngcontact.errors import ModelError, SceneError
from ngcontact.macro.away_maxima import AWAY
from ngcontact.macro.discretization_error import Sample
from ngcontact.macro.macro_problem import MacroSolution
from ngcontact.output import plots as figures
from ngcontact.output.report import VtkField
from ngcontact.scene.cell_scene import CellScene
from ngcontact.scene.macro_scene import MacroScene
from ngcontact.scene.sections import resolve

log = logging.getLogger(__name__)


class StrengthEvaluation(TypedDict):
    """What :func:`evaluate` returns for the caller's :class:`~ngcontact.output.report.Outcome`."""

    results: dict[str, Any]  # results["strength"] (module docstring)
    table: tuple[list[str], list[tuple[Any, ...]]]  # (header, rows) of the strength map
    vtk: VtkField  # the worst cell
    plots: dict[str, Callable[..., None]]  # name -> plot, called as plot(path)
    recovery: "Recovery"  # the cell's correctors, for further evaluations on other macro solutions


@dataclass(frozen=True)
class Recovery:
    """What the recovery of micro stresses needs of the cell, built once per law: the cell problem, its
    tangential stiffness and the unit-load correctors (paper eq. 75)."""

    path: str
    problem: Any                # the cell problem (drivers.build.recovery_cell_problem)
    tangential_stiffness: float
    fixed_set: bool             # the contact set is S_C without gap (else all of S_C)
    correctors: S.Correctors
    source: str = "computed"    # where its corrector states came from (drivers.strength_cell)


def strength_cell(scene: MacroScene, law) -> tuple[str, CellScene, float]:
    """The cell of ``scene.strength`` for the macro interface law ``law``: its path, its scene
    (:func:`ngcontact.drivers.build.recovery_cell_scene`) and the stick stiffness ``k_t`` of its fixed set."""
    spec = scene.strength
    # set: the caller (drivers.run_macro) evaluates only scenes with a [strength] section
    assert spec is not None
    path = resolve(scene, spec.cell)
    cs = recovery_cell_scene(path, key="strength.cell")
    kt = spec.tangential_stiffness
    if kt is None:
        assert cs.contact.k_n is not None  # set by CellScene.check (exact contact: its default scale)
        kt = cs.contact.k_n if law.friction is not None else 0.0
    return path, cs, float(kt)


def recovery_of(scene: MacroScene, law) -> Recovery:
    """The cell of ``scene.strength`` and its correctors for the macro interface law ``law`` (shipped with
    the package, cached or computed: :mod:`ngcontact.drivers.strength_cell`)."""
    path, cs, kt = strength_cell(scene, law)
    P, corr, source = fixed_set_correctors(cs, kt)
    return Recovery(path, P, kt, P.gap is not None, corr, source)


def _cell_loads(scene: MacroScene, sol: MacroSolution, rec: Recovery, warn: bool = True):
    """The interface states of ``sol`` and the cell loads they give (the shear dropped where the cell
    cannot carry it, said once: ``warn``)."""
    spec, P = scene.strength, rec.problem
    assert spec is not None
    states = interface_states(sol, scene.output.points_per_element)
    try:
        loads = cell_loads(states, P.dim)
    except ModelError as exc:
        raise SceneError("strength.cell", spec.cell, f"a {P.dim}D cell: {exc}") from None
    if rec.tangential_stiffness == 0 and not P.tangential_free and np.any(loads[:, :P.dim - 1] != 0):
        if warn:
            log.warning("the cell carries no shear (flat, frictionless, k_t = 0): the macro shear is dropped")
        loads[:, :P.dim - 1] = 0.0
    return states, loads


def _sigma_u(scene: MacroScene) -> dict[str, float]:
    sigma_u_rough = scene.materials[scene.bodies.rough].sigma_u
    sigma_u_counter = scene.materials[scene.bodies.counter].sigma_u
    # set: MacroScene.check requires sigma_u of both bodies when [strength] is present
    assert sigma_u_rough is not None and sigma_u_counter is not None
    return {"rough": sigma_u_rough, "counter": sigma_u_counter}


def linear_safety_factor(scene: MacroScene, sol: MacroSolution, rec: Recovery) -> float:
    """The safety factor of eq. 78 on ``sol`` by the linear recovery (eq. 75) with the correctors ``rec``."""
    assert scene.strength is not None
    states, loads = _cell_loads(scene, sol, rec, warn=False)
    smap = S.strength_map(rec.correctors, loads, scene.strength.criterion)
    names = ["r", "z"] if "r" in states else [k for k in ("x", "y", "z") if k in states]
    return float(S.check(smap, _sigma_u(scene), np.column_stack([states[k] for k in names]))["safety_factor"])


def linear_safety_factors(scene: MacroScene, sol: MacroSolution, rec: Recovery,
                          keep: Callable[[np.ndarray], np.ndarray] | None = None) -> dict[str, Sample]:
    """:func:`linear_safety_factor` with the interface point where it is attained (``safety_factor``) and,
    with ``keep`` (which of an array of interface points count), the smallest factor over the points kept
    (``safety_factor_away``: :mod:`ngcontact.macro.away_maxima`; absent where none is kept)."""
    assert scene.strength is not None
    states, loads = _cell_loads(scene, sol, rec, warn=False)
    smap = S.strength_map(rec.correctors, loads, scene.strength.criterion)
    names = ["r", "z"] if "r" in states else [k for k in ("x", "y", "z") if k in states]
    coords = np.column_stack([states[k] for k in names])
    out = {"safety_factor": _smallest_factor(smap, _sigma_u(scene), coords, np.ones(len(coords), dtype=bool))}
    kept = None if keep is None else np.asarray(keep(coords), dtype=bool)
    if kept is not None and kept.any():
        out["safety_factor" + AWAY] = _smallest_factor(smap, _sigma_u(scene), coords, kept)
    return out


def _smallest_factor(smap: S.StrengthMap, sigma_u: dict[str, float], coords: np.ndarray, kept: np.ndarray) -> Sample:
    """The smallest ``sigma_u / sigma_eq`` of the bodies over the interface points ``kept`` (eq. 78), and where."""
    best, at = math.inf, None
    for body, values in smap.values.items():
        masked = np.where(kept, values, -math.inf)
        k = int(np.argmax(masked))
        if masked[k] > 0 and sigma_u[body] / masked[k] < best:
            best, at = float(sigma_u[body] / masked[k]), tuple(float(c) for c in coords[k])
    return Sample(best, at)


def evaluate(scene: MacroScene, sol: MacroSolution, rec: Recovery | None = None) -> StrengthEvaluation:
    """Strength check of ``scene.strength`` on the macro solution ``sol`` (``rec``: correctors already
    built for its law).

    Returns ``{"results", "table", "vtk", "plots", "recovery"}``.
    """
    spec = scene.strength
    assert spec is not None
    rec = recovery_of(scene, sol.problem.law) if rec is None else rec
    path, P, kt, corr = rec.path, rec.problem, rec.tangential_stiffness, rec.correctors
    states, loads = _cell_loads(scene, sol, rec)
    smap = S.strength_map(corr, loads, spec.criterion)
    names = ["r", "z"] if "r" in states else [k for k in ("x", "y", "z") if k in states]
    along = "s" if "s" in states else "z"   # the abscissa of the map: arc length (2D) or the axis z (3D)
    coords = np.column_stack([states[k] for k in names])
    extra: dict[str, list[dict[str, Any]]] = {}
    if spec.recovery == "nonlinear":
        extra["nonlinear"] = _nonlinear_recovery(P, smap, loads, states, along, spec)
    res = S.check(smap, _sigma_u(scene), coords)
    for b, e in res["bodies"].items():
        if "s" in states:
            e["macro_point"]["s"] = float(states["s"][e["macro_point"]["index"]])
        e["macro_point"]["names"] = names
    crit = res["critical_body"]
    k = res["bodies"][crit]["macro_point"]["index"]
    worst_load = loads[k]
    worst_stress, vtk = _worst_cell(P, corr, worst_load, spec.recovery == "nonlinear"
                                    and any(e["index"] == k for e in extra.get("nonlinear", [])))
    res.update({"recovery": spec.recovery, "tangential_stiffness": float(kt), "load_names": list(corr.names),
                "worst_cell_load": worst_load.tolist(),
                "cell": {"scene": path, "ndof": int(P.ndof), "dim": P.dim,
                         "fixed_contact_set": "S_C without gap" if rec.fixed_set else "all of S_C",
                         "source": rec.source}})
    res.update(extra)
    table, plots = _table_and_plots(res, smap, states, names, along, worst_stress, spec.criterion, P.dim)
    return {"results": res, "table": table, "vtk": vtk, "plots": plots, "recovery": rec}


def _nonlinear_recovery(P, smap, loads, states, along: str, spec) -> list[dict[str, Any]]:
    """The cell solved nonlinearly at the ``spec.nonlinear_points`` macro points of the largest linear
    stress; their stresses replace the linear ones in ``smap`` (paper eqs. 76-78)."""
    worst = np.maximum(smap.values["rough"], smap.values["counter"])
    picks = [int(i) for i in np.argsort(-worst)[:spec.nonlinear_points]]
    solved: list[dict[str, Any]] = []
    for i in picks:
        try:
            st, csol = S.nonlinear_stress(P, loads[i])
        except ValueError as exc:
            raise SceneError("strength.recovery", "nonlinear", f"the cell cannot be solved at the macro "
                             f"state of interface point {i}: {exc}") from None
        entry: dict[str, Any] = {"index": i, along: float(states[along][i]), "load": loads[i].tolist(),
                                 "contact_fraction": csol.results["contact_fraction"], "bodies": {}}
        for b in S.BODIES:
            eq = S.equivalent(st[b]["stress"], spec.criterion)
            k = int(np.argmax(eq))
            entry["bodies"][b] = {"linear": float(smap.values[b][i]), "nonlinear": float(eq[k])}
            smap.values[b][i] = eq[k]
            smap.cell_point[b][i] = st[b]["points"][k]
        solved.append(entry)
    return solved


def _worst_cell(P, corr, worst_load, nonlinear: bool):
    """The cell's state at the critical macro point (nonlinear where it was solved so), its stresses per
    body and the VTK field of its von Mises stress and displacements."""
    if nonlinear:
        worst_stress, _ = S.nonlinear_stress(P, worst_load)
    else:
        P.gfu.vec.data = corr.state(worst_load)
        S.apply_load_vector(P, worst_load)
        worst_stress = {b: {"stress": corr.stress(worst_load)[b], "points": corr.points[b]} for b in S.BODIES}
    m = P.model
    comps = P.gfu.components
    sig = P.mesh.MaterialCF({"rough": m.rough.stress(P.body_strain(comps[0])),
                             "counter": m.counter.stress(P.body_strain(comps[1]))})
    from ngcontact.fem.materials import von_mises
    vtk = VtkField(mesh=P.mesh, fields={"von_mises": von_mises(sig), "u_rough": comps[0],
                                        "u_counter": comps[1]}, subdivision=1)
    return worst_stress, vtk


def _table_and_plots(res, smap, states, names, along: str, worst_stress, criterion: str, dim: int):
    """The strength table along the interface and the two figures (the map, the worst cell)."""
    state_keys = ["pressure", "shear", "e_t", "e_hoop"] if "s" in states else \
        ["pressure", "shear_1", "shear_2", "e_11", "e_22", "e_12"]
    header = (["s"] if "s" in states else []) + names + state_keys + [f"sigma_eq_{b}" for b in S.BODIES]
    cols = [states[h] for h in header[:-2]] + [smap.values[b] for b in S.BODIES]
    table = (header, list(zip(*cols)))
    sig_u = {b: res["bodies"][b]["sigma_u"] for b in S.BODIES}
    map_data: dict[str, Any] = {"s": np.asarray(states[along]), "values": {b: smap.values[b] for b in S.BODIES},
                                "sigma_u": sig_u, "criterion": smap.criterion,
                                "pressure": np.asarray(states["pressure"]), "shear": np.asarray(states["shear"]),
                                "xlabel": None if along == "s" else "axial position z of the interface point [mm]"}
    cell_data: dict[str, Any] = {"points": np.concatenate([worst_stress[b]["points"] for b in S.BODIES]),
                                 "eq": np.concatenate([S.equivalent(worst_stress[b]["stress"], criterion)
                                                       for b in S.BODIES]),
                                 "criterion": criterion, "dim": dim,
                                 "tangents": ("t0", "hoop") if "s" in states else ("t1", "t2")}
    plots: dict[str, Callable[..., None]] = {
        "strength_map": lambda p, d=map_data: figures.strength_map(p, **d),
        "worst_cell": lambda p, d=cell_data: figures.worst_cell(p, **d)}
    return table, plots
