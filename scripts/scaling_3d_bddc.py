"""The BDDC studies of ``scaling_3d.py`` on the shipped bisinusoid cell meshed over its period.

* ``--breakdown INTERFACE_MAXH``: where one iterative cell solve spends its time (CG per iteration, one BDDC
  application, one product with the tangent, the size of BDDC's coarse problem): ``scaling_3d_breakdown.csv``
  and ``.png``;
* ``--coarse INTERFACE_MAXH [--k-n K]``: BDDC's coarse problem on the converged cell, the bubble term's
  ``gamma`` against the whole contact surface on the wirebasket: ``scaling_3d_coarse.csv`` and ``.png``.

Each publishes its own section of docs/benchmarks.md with ``--publish`` (:func:`study`).
"""
from __future__ import annotations

import logging
import os
import time

import numpy as np

import benchmark_doc
from ngcontact.output.writer import write_csv

log = logging.getLogger("scaling_3d")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def period_scene():
    """The shipped bisinusoid cell scene meshed over its whole period (``discretization.symmetry = "off"``):
    parts 1 and the solver studies measure cost against the period's dofs."""
    from dataclasses import replace
    from ngcontact.scene.loader import load
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    return replace(scene, discretization=replace(scene.discretization, symmetry="off"))


BREAKDOWN_KEYS = ("size", "ndof", "wirebasket_dofs", "wirebasket_contact_dofs", "cg_iterations", "cg_seconds",
                  "ms_per_cg_iteration", "ms_per_matvec", "ms_per_bddc")


def breakdown(size: float, out: str) -> dict:
    """Where an iterative 3D cell solve spends its time: CG's cost per iteration against one product with the
    tangent and one BDDC application, and the size of BDDC's coarse problem (its wirebasket dofs, and those of
    them on the contact surface).  Writes ``scaling_3d_breakdown.csv`` and ``.png``."""
    import ngsolve as ng
    from ngcontact import runner
    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.drivers.build import build_cell, cell_loads, model_of, predictor_twin
    from ngcontact.solvers.linear_solver import LinearSolver
    scene = period_scene()
    cell = build_cell(scene, interface_maxh=size)
    with runner.threads(runner.thread_count()):
        P = CellProblem(cell, model_of(scene), linear=LinearSolver("iterative"), predictor=predictor_twin(scene, size))
        import ngsolve.krylovspace as K
        spent = [0.0]
        solve = K.CGSolver._SolveImpl

        def timed(self, *a, **kw):
            t0 = time.perf_counter()
            try:
                return solve(self, *a, **kw)
            finally:
                spent[0] += time.perf_counter() - t0
        K.CGSolver._SolveImpl = timed
        try:
            P.solve(cell_loads(scene)[0], first=True, measure=False)
        finally:
            K.CGSolver._SolveImpl = solve
        A = P.energy().mat
        pre = next(iter(P.linear._pre.values())).mat
        x, y = A.CreateColVector(), A.CreateColVector()
        x.SetRandom()
        ms = {}
        for name, op in (("matvec", A), ("bddc", pre)):
            t0 = time.perf_counter()
            for _ in range(20):
                y.data = op * x
            ms[name] = (time.perf_counter() - t0) / 20 * 1e3
    wb = ng.COUPLING_TYPE.WIREBASKET_DOF
    X = P.X
    on_contact = {d for el in cell.mesh.Boundaries("contact").Elements() for d in X.GetDofNrs(el) if d >= 0}
    its = sum(P.linear.iterations)
    row = {"size": size, "ndof": X.ndof, "wirebasket_dofs": sum(X.CouplingType(d) == wb for d in range(X.ndof)),
           "wirebasket_contact_dofs": sum(X.CouplingType(d) == wb for d in on_contact), "cg_iterations": its,
           "cg_seconds": spent[0], "ms_per_cg_iteration": spent[0] / max(its, 1) * 1e3,
           "ms_per_matvec": ms["matvec"], "ms_per_bddc": ms["bddc"]}
    log.info("breakdown at interface_maxh %g: %s", size, ", ".join(f"{k} = {row[k]:.4g}" for k in BREAKDOWN_KEYS))
    os.makedirs(out, exist_ok=True)
    write_csv(os.path.join(out, "scaling_3d_breakdown.csv"), list(BREAKDOWN_KEYS), [[row[k] for k in BREAKDOWN_KEYS]])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.5))
    names = ("ms_per_cg_iteration", "ms_per_bddc", "ms_per_matvec")
    ax.bar(range(3), [row[k] for k in names])
    ax.set_xticks(range(3), ["CG iteration", "BDDC application", "tangent product"])
    ax.set_ylabel("ms")
    ax.set_title(f"3D cell, {row['ndof']} dofs: coarse problem {row['wirebasket_dofs']} dofs "
                 f"({row['wirebasket_contact_dofs']} on S_C)", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scaling_3d_breakdown.png"), dpi=120)
    plt.close(fig)
    return row


COARSE_KEYS = ("size", "ndof", "k_n", "coarse", "gamma", "wirebasket_dofs", "cg_iterations", "cg_seconds",
               "ms_per_cg_iteration")
COARSE_GAMMAS = (3e-5, 1.1e-4, 3e-4, 1e-3)


def coarse_study(size: float, out: str, k_n: float | None = None) -> list[dict]:
    """BDDC's coarse problem on the converged 3D cell: the bubble term's ``gamma`` (the contact surface's
    edge dofs as interface dofs, :func:`ngcontact.fem.elasticity.bubble_term`) against the whole contact
    surface on the wirebasket.  Each preconditioner is built at the converged state and CG solves one
    tangent system with a random right-hand side to 1e-8.  Writes ``scaling_3d_coarse.csv`` and ``.png``."""
    from dataclasses import replace

    import ngsolve as ng
    from ngsolve.krylovspace import CGSolver
    from ngcontact import runner
    from ngcontact.cell.fe.cell_energy import preconditioning_form
    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.drivers.build import build_cell, cell_loads, model_of, predictor_twin
    from ngcontact.fem import elasticity
    from ngcontact.solvers.linear_solver import LinearSolver
    scene = period_scene()
    model = model_of(scene) if k_n is None else replace(model_of(scene), k_n=k_n)
    rows = []
    with runner.threads(runner.thread_count()):
        P = CellProblem(build_cell(scene, interface_maxh=size), model, linear=LinearSolver("iterative"),
                        predictor=predictor_twin(scene, size))
        P.solve(cell_loads(scene)[0], first=True, measure=False)
        A = P.energy().mat
        b = A.CreateColVector()
        b.SetRandom()
        free = P.X.FreeDofs()
        b.FV().NumPy()[~np.array(free, dtype=bool)] = 0.0
        WB = ng.COUPLING_TYPE.WIREBASKET_DOF
        default = elasticity.BUBBLE_GAMMA

        def measure(form, coarse, gamma):
            pre = ng.Preconditioner(getattr(form, "form", form), "bddc")
            form.AssembleLinearization(P.gfu.vec)
            x = A.CreateColVector()
            cg = CGSolver(A, pre.mat, tol=1e-8, maxiter=5000, printrates=False)
            t0 = time.perf_counter()
            x.data = cg * b
            secs = time.perf_counter() - t0
            row = {"size": size, "ndof": P.X.ndof, "k_n": model.k_n, "coarse": coarse, "gamma": gamma,
                   "wirebasket_dofs": sum(P.X.CouplingType(d) == WB for d in range(P.X.ndof)),
                   "cg_iterations": cg.iterations, "cg_seconds": secs,
                   "ms_per_cg_iteration": secs / max(cg.iterations, 1) * 1e3}
            log.info("coarse %-20s gamma %-8s: %5d CG iterations, %.2f s, %.1f ms each, %d coarse dofs", coarse,
                     gamma, row["cg_iterations"], secs, row["ms_per_cg_iteration"], row["wirebasket_dofs"])
            rows.append(row)
        try:
            for gamma in COARSE_GAMMAS:
                elasticity.BUBBLE_GAMMA = gamma
                state = ng.GridFunction(P.X)        # the converged state the preconditioner is built at
                state.vec.data = P.gfu.vec
                measure(preconditioning_form(P.discrete, state), "vertices + bubble term", gamma)
        finally:
            elasticity.BUBBLE_GAMMA = default
        elasticity.surface_wirebasket(P.X, P.mesh, "contact")
        measure(P.form, "contact surface", "")
    os.makedirs(out, exist_ok=True)
    write_csv(os.path.join(out, "scaling_3d_coarse.csv"), list(COARSE_KEYS),
              [[r[k] for k in COARSE_KEYS] for r in rows])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.8))
    bubble = [r for r in rows if r["gamma"] != ""]
    ax.semilogx([r["gamma"] for r in bubble], [r["cg_seconds"] for r in bubble], "o-",
                label=f"vertices + bubble term ({bubble[0]['wirebasket_dofs']} coarse dofs)")
    ax.axhline(rows[-1]["cg_seconds"], color="k", ls="--",
               label=f"contact surface on the wirebasket ({rows[-1]['wirebasket_dofs']} coarse dofs)")
    ax.axvline(default, color="0.6", lw=0.8, ls=":", label=f"BUBBLE_GAMMA = {default:g}")
    ax.set_xlabel("gamma")
    ax.set_ylabel("CG solve to 1e-8 [s]")
    ax.set_title(f"3D bisinusoid cell, {rows[0]['ndof']} dofs, k_n = {model.k_n:g}", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scaling_3d_coarse.png"), dpi=120)
    plt.close(fig)
    return rows


#: the studies of this module: option, section, title, note (the CSV and PNG are named after the section)
STUDIES = (
    ("breakdown", "scaling_3d_breakdown", "3D cell: where an iterative solve spends its time",
     "One BDDC-CG cell solve of the bisinusoid: CG iterations and seconds, milliseconds per CG iteration, per BDDC "
     "application and per product with the tangent; the size of BDDC's coarse problem (wirebasket dofs, those on "
     "the contact surface)."),
    ("coarse", "scaling_3d_coarse", "3D cell: BDDC's coarse problem, bubble term against the contact surface on "
     "the wirebasket",
     "CG to 1e-8 on the tangent of the converged bisinusoid cell with a random right-hand side: the bubble term of "
     "`ngcontact.fem.elasticity.bubble_term` for several `gamma` (the shipped one is `BUBBLE_GAMMA`), and the whole "
     "contact surface on the wirebasket."),
)


def study(args) -> bool:
    """The study ``args`` ask for (``--breakdown`` or ``--coarse``), run into ``args.out`` and with
    ``--publish`` published; whether one was asked for."""
    for option, section, title, note in STUDIES:
        size = getattr(args, option)
        if size is None:
            continue
        if option == "breakdown":
            breakdown(size, args.out)
        else:
            coarse_study(size, args.out, args.k_n)
        if args.publish:
            benchmark_doc.publish(section, title, os.path.join(args.out, f"{section}.csv"), note=note,
                                  png=os.path.join(args.out, f"{section}.png"))
        return True
    return False
