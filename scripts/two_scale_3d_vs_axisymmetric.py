"""The 3D femur's two-scale loop and strength check side by side with the axisymmetric femur (issue 13).

Cases, all order 2 and the scene's own groove cell (``cells/stem_grooves.toml``)
and hip-hills strength cell:

* ``3d``: ``geometries/femur_stem_3d_two_scale.toml`` (a quarter, 8 mm / 4 mm);
* ``axisymmetric``: ``geometries/femur_stem_two_scale.toml`` at the same sizes;
* ``axisymmetric_fine``: the same at 4 mm / 2 mm, whose distance to the
  former estimates the discretization error of the axisymmetric scene.

The cell responses are shared between the cases (one cell problem, each
pressure solved once); every case fills its own table from empty, so the
loops' update counts compare.  Per case: dofs, law updates, macro solves,
``cell_solves`` (the pressures its table asked for; a pressure another case
asked for first is not solved again), the mean contact pressure on three bands of the interface, the mean
over the seated cylinder of the cell's largest von Mises stress per body,
the safety factor (eq. 78) with the axial position of its point, and the
wall time.  Writes ``two_scale_3d.csv`` and ``two_scale_3d.png`` (pressure
and strength map against the axial position, 3D samples as points) into the
output directory (default ``results/two_scale_3d``).

Usage::

    python scripts/two_scale_3d_vs_axisymmetric.py [OUT_DIR] [--publish]
"""
from __future__ import annotations

import argparse
import csv
import os
from functools import partial
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

GEOMETRIES = os.path.join(HERE, "..", "geometries")
BANDS = {"cylinder": (0.14, 0.17), "upper_cone": (0.11, 0.125), "lower_cone": (0.095, 0.11)}
CASES = (("3d", "femur_stem_3d_two_scale.toml", {}),
         ("axisymmetric", "femur_stem_two_scale.toml", {"maxh": 0.008, "interface_maxh": 0.004}),
         ("axisymmetric_fine", "femur_stem_two_scale.toml", {"maxh": 0.004, "interface_maxh": 0.002}))


def shared_response():
    """``p -> cell response`` of the groove cell, each pressure solved once."""
    from ngcontact.coupling import pressure_table as PT
    from ngcontact.drivers.run_two_scale import PressureSolve
    solve = PressureSolve(os.path.join(GEOMETRIES, "cells", "stem_grooves.toml"), 1.0)
    known: dict[float, dict] = {}

    def response(p: float) -> PT.Response:
        if p not in known:
            known[p] = solve(p)
        return known[p]
    return response


def measure(case: str, name: str, sizes: dict, response) -> tuple[dict, dict]:
    import ngsolve as ng
    from ngcontact import runner
    from ngcontact.coupling import pressure_table as PT
    from ngcontact.coupling import two_scale as T
    from ngcontact.drivers import run_macro as RM
    from ngcontact.drivers.run_strength import evaluate
    from ngcontact.laws import interface_energy as ie
    from ngcontact.macro import macro_problem as M
    from ngcontact.scene.loader import load
    t0 = time.perf_counter()
    scene = load(os.path.join(GEOMETRIES, name))
    problem, _ = RM.problem_of(scene, RM.build_geometry(scene, **sizes), order=2)
    spec = scene.two_scale
    table = PT.CellTable(response, tol=spec.table_tol)
    with runner.threads(runner.thread_count()):   # as ngcontact run: task manager, BLAS on one thread
        out = T.couple(problem, table, tol=spec.tol, max_iter=spec.max_iter, table_min=spec.table_min,
                       solve=partial(RM.solve_scene, scene))
        st = evaluate(scene, out.solution)
    sol = out.solution
    mesh, three = sol.problem.mesh, sol.problem.setting == "3d"
    p = ie.pressure(sol.problem.law.normal, sol.local_jump, M.gap_cf(sol.problem.gap))
    axial = ng.z if three else ng.y
    weight = ng.CF(1.0) if three else 2 * np.pi * ng.x
    header, rows = st["table"]
    data = np.array(rows, dtype=float)
    z = data[:, header.index("z")]
    res = st["results"]
    row = {"case": case, "ndof": sol.ndof, "updates": len(out.history) - 1, "macro_solves": out.macro_solves,
           "cell_solves": table.solves, "safety_factor": res["safety_factor"], "critical_body": res["critical_body"],
           "critical_z": res["bodies"][res["critical_body"]]["macro_point"]["coordinates"][-1]}
    for band, (lo, hi) in BANDS.items():
        inside = ng.IfPos(axial - lo, 1.0, 0.0) * ng.IfPos(hi - axial, 1.0, 0.0)
        force, area = (ng.Integrate(f * inside * weight, mesh, ng.BND, definedon=mesh.Boundaries("interface"),
                                    order=8) for f in (p, ng.CF(1.0)))
        row[f"p_{band}_MPa"] = force / area / 1e6
    cyl = (z > BANDS["cylinder"][0]) & (z < BANDS["cylinder"][1])
    for body in ("rough", "counter"):
        row[f"sigma_eq_cylinder_{body}_MPa"] = float(np.mean(data[cyl, header.index(f"sigma_eq_{body}")])) / 1e6
    row["wall_seconds"] = time.perf_counter() - t0
    print(", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}" for k, v in row.items()), flush=True)
    curve = {"z": z, "pressure": data[:, header.index("pressure")],
             **{b: data[:, header.index(f"sigma_eq_{b}")] for b in ("rough", "counter")}}
    return row, curve


def plot(path: str, curves: dict) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(2, 1, figsize=(8, 7.5), sharex=True, constrained_layout=True)
    styles = {"3d": {"ls": "none", "marker": ".", "ms": 2, "alpha": 0.6}, "axisymmetric": {"lw": 1.2},
              "axisymmetric_fine": {"lw": 0.8, "ls": "--"}}
    for case, c in curves.items():
        order = np.argsort(c["z"]) if case != "3d" else slice(None)
        z = c["z"][order] * 1e3
        ax[0].plot(z, c["pressure"][order] / 1e6, label=case, **styles[case])
        for body, color in (("rough", "C0"), ("counter", "C1")):
            ax[1].plot(z, c[body][order] / 1e6, color=color, label=f"{case}, {body}", **styles[case])
    ax[0].set_ylabel("contact pressure p [MPa]")
    ax[0].legend(fontsize=8)
    ax[1].set_yscale("log")
    ax[1].set_ylabel("largest von Mises stress\nover the cell [MPa]")
    ax[1].set_xlabel("axial position z [mm]")
    ax[1].legend(fontsize=7, ncol=3)
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("femur two-scale + strength: 3D quarter (points) against axisymmetry (lines)")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(out: str, publish: bool = False) -> list[dict]:
    os.makedirs(out, exist_ok=True)
    response = shared_response()
    rows, curves = [], {}
    for case, name, sizes in CASES:
        row, curves[case] = measure(case, name, sizes, response)
        rows.append(row)
    with open(os.path.join(out, "two_scale_3d.csv"), "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    plot(os.path.join(out, "two_scale_3d.png"), curves)
    if publish:
        benchmark_doc.publish("two_scale_3d_vs_axisymmetric", "The 3D femur's two-scale loop beside the "
                              "axisymmetric femur", os.path.join(out, "two_scale_3d.csv"),
                              note="`3d`: `geometries/femur_stem_3d_two_scale.toml`; `axisymmetric`: "
                                   "`geometries/femur_stem_two_scale.toml` at the same sizes; `axisymmetric_fine` "
                                   "at half of them (its distance to `axisymmetric` estimates the latter's "
                                   "discretization error). Dofs, law updates, macro and cell solves, mean "
                                   "pressures on three bands, the seated cylinder's mean largest von Mises stress "
                                   "per body, the safety factor (eq. 78) and its axial position, seconds.",
                              png=os.path.join(out, "two_scale_3d.png"))
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "two_scale_3d"), help="output directory")
    ap.add_argument("--publish", action="store_true", help="write the section of docs/benchmarks.md")
    a = ap.parse_args()
    main(a.out, publish=a.publish)
