"""Driver part of ``[strength]`` (macro kind): macro state -> cell stresses -> check of eq. 78.

No file I/O: returns results, a table, a VTK field and plot callables for
the caller's :class:`~ngcontact.report.Outcome`.  See
:mod:`ngcontact.coupling.strength` for the mathematics.

``results["strength"]``: ``criterion``, ``recovery``, ``safety_factor``
(``min_B sigma_u,B / max sigma_eq,B``), ``holds`` (eq. 78: safety factor
> 1), ``critical_body``, per body ``max_sigma_eq`` [Pa], ``sigma_u`` [Pa],
``safety_factor``, ``macro_point`` (index into the interface profile, its
``s`` [m] and coordinates [m]) and ``cell_point`` (cell coordinates, cell
units), ``cell`` (scene path, ``ndof``, contact fraction of the fixed
contact set), ``tangential_stiffness`` and, with nonlinear recovery, the
linear and nonlinear maxima at the re-solved points.
"""
from __future__ import annotations

import dataclasses
import logging

import numpy as np
import ngsolve as ng

from ngcontact.coupling import strength as S
from ngcontact.cell.cell_problem import CellProblem
from ngcontact.errors import SceneError
from ngcontact.output.report import VtkField
from ngcontact.scene.loader import load
from ngcontact.scene.sections import resolve

log = logging.getLogger(__name__)


def cell_problem_of(cell_path: str, *, key: str):
    """Cell scene -> :class:`CellProblem` with the macro strain term (for recovery)."""
    from ngcontact.drivers.build import build_cell, model_of
    cs = load(cell_path)
    if cs.kind != "cell":
        raise SceneError(key, cell_path, f"names a {cs.kind!r} scene; a 'cell' scene is needed")
    if cs.contact.geometric_only:
        raise SceneError(key, cell_path, "the cell scene has contact.geometric_only = true; the recovery "
                         "solves the cell, so it needs a contact model and a [load] section")
    cell = build_cell(cs)
    model = dataclasses.replace(model_of(cs), macro_strain=True)
    s = cs.solver
    return cs, CellProblem(cell, model, rtol=s.rtol, atol=s.atol, max_iter=s.max_iter, inverse=s.inverse)


def evaluate(scene, sol) -> dict:
    """Strength check of ``scene.strength`` on the macro solution ``sol``.

    Returns ``{"results", "table", "vtk", "plots"}``.
    """
    spec = scene.strength
    path = resolve(scene, spec.cell)
    cs, P = cell_problem_of(path, key="strength.cell")
    law = sol.problem.law
    kt = spec.tangential_stiffness
    if kt is None:
        kt = cs.contact.k_n if law.friction is not None else 0.0
    chi = None if P.gap is None else ng.IfPos(P.gap - 1e-14 * max(P.max_gap(), 1e-300), 0.0, 1.0)
    corr = S.linear_correctors(P, contact_set=chi, tangential_stiffness=kt)
    states = S.interface_states(sol, scene.output.points_per_element)
    loads = S.cell_loads(states, P.dim)
    if kt == 0 and not P.tangential_free and np.any(loads[:, :P.dim - 1] != 0):
        log.warning("the cell carries no shear (flat, frictionless, k_t = 0): the macro shear is dropped")
        loads[:, :P.dim - 1] = 0.0
    smap = S.strength_map(corr, loads, spec.criterion)
    names = [k for k in ("r", "z", "x", "y") if k in states]
    coords = np.column_stack([states[k] for k in names])
    extra = {}
    if spec.recovery == "nonlinear":
        worst = np.maximum(smap.values["rough"], smap.values["counter"])
        picks = [int(i) for i in np.argsort(-worst)[:spec.nonlinear_points]]
        solved = []
        for i in picks:
            try:
                st, csol = S.nonlinear_stress(P, loads[i])
            except ValueError as exc:
                raise SceneError("strength.recovery", "nonlinear", f"the cell cannot be solved at the macro "
                                 f"state of interface point {i}: {exc}") from None
            entry = {"index": i, "s": float(states["s"][i]), "load": loads[i].tolist(),
                     "contact_fraction": csol.results["contact_fraction"], "bodies": {}}
            for b in S.BODIES:
                eq = S.equivalent(st[b]["stress"], spec.criterion)
                k = int(np.argmax(eq))
                entry["bodies"][b] = {"linear": float(smap.values[b][i]), "nonlinear": float(eq[k])}
                smap.values[b][i] = eq[k]
                smap.cell_point[b][i] = st[b]["points"][k]
            solved.append(entry)
        extra["nonlinear"] = solved
    res = S.check(smap, {"rough": scene.materials[scene.bodies.rough].sigma_u,
                         "counter": scene.materials[scene.bodies.counter].sigma_u}, coords)
    for b, e in res["bodies"].items():
        e["macro_point"]["s"] = float(states["s"][e["macro_point"]["index"]])
        e["macro_point"]["names"] = names
    crit = res["critical_body"]
    k = res["bodies"][crit]["macro_point"]["index"]
    worst_load = loads[k]
    # the worst cell's state, for the VTK field and the figure
    if spec.recovery == "nonlinear" and any(e["index"] == k for e in extra.get("nonlinear", [])):
        worst_stress, _ = S.nonlinear_stress(P, worst_load)
    else:
        P.gfu.vec.data = corr.state(worst_load)
        S._set_load(P, worst_load)
        worst_stress = {b: {"stress": corr.stress(worst_load)[b], "points": corr.points[b]} for b in S.BODIES}
    m = P.model
    comps = P.gfu.components
    sig = P.mesh.MaterialCF({"rough": m.rough.stress(P.body_strain(comps[0])),
                             "counter": m.counter.stress(P.body_strain(comps[1]))})
    from ngcontact.fem.materials import von_mises
    vtk = VtkField(mesh=P.mesh, fields={"von_mises": von_mises(sig), "u_rough": comps[0],
                                        "u_counter": comps[1]}, subdivision=1)
    res.update({"recovery": spec.recovery, "tangential_stiffness": float(kt), "load_names": list(corr.names),
                "worst_cell_load": worst_load.tolist(),
                "cell": {"scene": path, "ndof": int(P.ndof), "dim": P.dim,
                         "fixed_contact_set": "S_C without gap" if chi is not None else "all of S_C"}})
    res.update(extra)
    header = ["s"] + names + ["pressure", "shear", "e_t", "e_hoop"] + \
             [f"sigma_eq_{b}" for b in S.BODIES]
    cols = [states["s"]] + [states[n] for n in names] + [states["pressure"], states["shear"], states["e_t"],
                                                         states["e_hoop"]] + [smap.values[b] for b in S.BODIES]
    table = (header, list(zip(*cols)))
    sig_u = {b: res["bodies"][b]["sigma_u"] for b in S.BODIES}
    plots = {"strength_map": lambda p, st=states, sm=smap, su=sig_u: plot_map(p, st, sm, su),
             "worst_cell": lambda p, ws=worst_stress, c=spec.criterion, d=P.dim: plot_cell(p, ws, c, d)}
    return {"results": res, "table": table, "vtk": vtk, "plots": plots}


def plot_map(path, states, smap, sigma_u) -> None:
    """Largest micro ``sigma_eq`` along the interface per body, against ``sigma_u``."""
    import matplotlib.pyplot as plt
    s = np.asarray(states["s"]) * 1e3
    fig, ax = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for b, c in zip(S.BODIES, ("C0", "C1")):
        ax[0].plot(s, smap.values[b] / 1e6, color=c, label=f"max over the cell, {b}")
        ax[0].axhline(sigma_u[b] / 1e6, color=c, ls="--", label=f"sigma_u {b}")
    ax[0].set_ylabel(f"{smap.criterion.replace('_', ' ')} [MPa]")
    ax[0].set_yscale("log")
    ax[0].legend(fontsize=7)
    ax[1].plot(s, np.asarray(states["pressure"]) / 1e6, label="macro pressure p")
    ax[1].plot(s, np.asarray(states["shear"]) / 1e6, label="macro shear")
    ax[1].set_ylabel("MPa")
    ax[1].set_xlabel("arc length s along the interface [mm] (from the top end)")
    ax[1].legend(fontsize=7)
    for a in ax:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_cell(path, stress, criterion, dim) -> None:
    """Equivalent stress in the worst cell (paper Fig. 8).

    2D: the map over the cell.  3D: two sections through the point of the
    largest equivalent stress, the vertical plane ``y = y_max`` (x-z) and the
    horizontal plane ``z = z_max`` (x-y), each from the sample points within
    a thin slab around the plane.
    """
    import matplotlib.pyplot as plt
    pts = np.concatenate([stress[b]["points"] for b in S.BODIES])
    eq = np.concatenate([S.equivalent(stress[b]["stress"], criterion) for b in S.BODIES]) / 1e6
    label = f"{criterion.replace('_', ' ')} [MPa]"
    k = int(np.argmax(eq))
    if dim == 2:
        fig, ax = plt.subplots(figsize=(7, 5.5))
        sc = ax.scatter(pts[:, 0], pts[:, 1], c=eq, s=4, cmap="viridis")
        ax.plot(*pts[k, :2], "r+", ms=14, mew=2)
        ax.set_aspect("equal")
        ax.set_xlabel("x (t0)")
        ax.set_ylabel("y (n0)")
        fig.colorbar(sc, ax=ax, shrink=0.8, label=label)
        ax.set_title(f"worst cell: max {eq[k]:.3g} MPa (+)")
    else:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.8))
        span = np.ptp(pts, axis=0)
        for ax, (normal, a, b, names) in zip(axes, ((1, 0, 2, ("x (t0)", "z (n0)")),
                                                    (2, 0, 1, ("x (t0)", "y (hoop)")))):
            slab = np.abs(pts[:, normal] - pts[k, normal]) <= 0.03 * span[normal]
            sc = ax.scatter(pts[slab, a], pts[slab, b], c=eq[slab], s=6, cmap="viridis",
                            vmin=eq.min(), vmax=eq.max())
            ax.plot(pts[k, a], pts[k, b], "r+", ms=14, mew=2)
            ax.set_aspect("equal")
            ax.set_xlabel(names[0])
            ax.set_ylabel(names[1])
            which = "y" if normal == 1 else "z"
            ax.set_title(f"section {which} = {pts[k, normal]:.3g}")
        fig.colorbar(sc, ax=axes, shrink=0.85, label=label)
        fig.suptitle(f"worst cell: max {eq[k]:.3g} MPa (+)")
    fig.savefig(path, dpi=110)
    plt.close(fig)
