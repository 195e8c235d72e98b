"""Work-precision of the femur / hip-stem scene: peak interface pressure and peak von Mises stress.

Solves ``geometries/femur_stem.toml`` under h-refinement (mesh sizes halved,
orders 2 and 3) and p-refinement (orders 2 to 5 on the scene's mesh; order 1 is
refused on a mesh touching the axis, see :func:`ngcontact.macro.macro_problem.check_problem`), and
compares the peak contact pressure along the interface and the peak von
Mises stress with those of a reference solution (order 5 on the finest
mesh).  Each run is timed from meshing to post-processing (wall clock,
including the Newton / Coulomb iterations, on one NGSolve thread).  The
discretizations are independent solves: one batch on ``--workers N`` local
processes (default 1; each solve is timed inside its worker, on one thread,
so the figures do not depend on N, only the study's wall time does).

Writes ``OUT/work_precision_femur.csv`` and ``OUT/work_precision_femur.png``
(relative error against seconds).  Usage::

    python scripts/work_precision_femur.py [--out DIR] [--quick] [--workers N]
"""
from __future__ import annotations

import argparse
import csv
import logging
import os
import sys
import time

import numpy as np


from ngcontact.macro import macro_measures as MM
from ngcontact.scene import loader as scene_mod
from ngcontact.drivers.run_macro import build_geometry, problem_of, solve_scene
from ngcontact.parallel import executor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
log = logging.getLogger("work_precision_femur")


def peaks(sc, maxh: float, interface_maxh: float, order: int) -> dict:
    """Peak pressure and von Mises stress of one discretization, with its cost."""
    t0 = time.perf_counter()
    geo = build_geometry(sc, maxh=maxh, interface_maxh=interface_maxh)
    problem, _ = problem_of(sc, geo, order=order)
    sol = solve_scene(sc, problem)
    prof = MM.interface_profile(sol, points_per_element=sc.output.points_per_element)
    fields = MM.stress_fields(sol)
    vm = MM.field_extrema(sol, {"von_mises": fields["von_mises"]})["von_mises"]["max"]
    seconds = time.perf_counter() - t0
    k = int(np.argmax(prof["pressure"]))
    return {"maxh": maxh, "interface_maxh": interface_maxh, "order": order, "ndof": sol.ndof,
            "seconds": seconds, "newton": sol.history["newton_iterations"],
            "peak_pressure": float(prof["pressure"][k]), "peak_pressure_z": float(prof["z"][k]),
            "peak_von_mises": vm["value"], "peak_von_mises_r": vm["location"][0],
            "peak_von_mises_z": vm["location"][1]}


def member(job: tuple) -> dict:
    """One discretization of the study as a member of a batch (:mod:`ngcontact.parallel.executor`)."""
    sc, maxh, interface_maxh, order = job
    return peaks(sc, maxh, interface_maxh, order)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "work_precision_femur"))
    ap.add_argument("--quick", action="store_true", help="fewer levels (a smoke run)")
    ap.add_argument("--workers", type=int, default=1, help="local worker processes for the discretizations")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    sc = scene_mod.load(os.path.join(ROOT, "geometries", "femur_stem.toml"))
    d = sc.discretization
    h0, hi0 = d.maxh, d.interface_maxh or d.maxh
    factors = (2.0, 1.0, 0.5) if args.quick else (2.0, 1.0, 0.5, 0.25)
    runs = []
    for order in (2, 3):
        for f in factors:
            runs.append(("h", h0 * f, hi0 * f, order))
    for order in ((2, 3, 4) if args.quick else (2, 3, 4, 5)):
        runs.append(("p", h0, hi0, order))
    fine = min(factors)
    order_ref = 4 if args.quick else 5
    jobs = [(sc, h0 * fine, hi0 * fine, order_ref)] + [(sc, maxh, ih, order) for _, maxh, ih, order in runs]
    names = ["reference"] + [f"{study}: order {order}, maxh {maxh:.4g}" for study, maxh, _, order in runs]
    with executor.use(executor.make(args.workers)) as ex:
        ex.start()
        ref, *solved = ex.map(member, jobs, names, label="discretizations")
    log.info("reference: %s", ref)
    rows = []
    for (study, maxh, ih, order), r in zip(runs, solved):
        r["study"] = study
        r["err_pressure"] = abs(r["peak_pressure"] / ref["peak_pressure"] - 1)
        r["err_von_mises"] = abs(r["peak_von_mises"] / ref["peak_von_mises"] - 1)
        rows.append(r)
        log.info("%s order %d maxh %.4g ih %.4g: %d dofs %.2f s, pressure err %.2e, von Mises err %.2e",
                 study, order, maxh, ih, r["ndof"], r["seconds"], r["err_pressure"], r["err_von_mises"])
    os.makedirs(args.out, exist_ok=True)
    keys = ["study", "order", "maxh", "interface_maxh", "ndof", "seconds", "newton", "peak_pressure",
            "err_pressure", "peak_pressure_z", "peak_von_mises", "err_von_mises", "peak_von_mises_r",
            "peak_von_mises_z"]
    with open(os.path.join(args.out, "work_precision_femur.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow([r[k] for k in keys])
        w.writerow([dict(ref, study="reference", err_pressure=0.0, err_von_mises=0.0)[k] for k in keys])
    _plot(os.path.join(args.out, "work_precision_femur.png"), rows)
    log.info("wrote %s", args.out)
    if args.publish:
        benchmark_doc.publish("work_precision_femur", "Work-precision of the femur / hip-stem scene",
                              os.path.join(args.out, "work_precision_femur.csv"),
                              columns=["study", "order", "maxh", "interface_maxh", "ndof", "seconds", "newton",
                                       "peak_pressure", "err_pressure", "peak_von_mises", "err_von_mises"],
                              note="`geometries/femur_stem.toml` under h-refinement (orders 2 and 3) and "
                                   "p-refinement on the scene's mesh: peak contact pressure and peak von Mises "
                                   "stress, their relative errors against the reference (the last row), wall "
                                   "seconds from meshing to post-processing on one NGSolve thread, Newton steps.",
                              png=os.path.join(args.out, "work_precision_femur.png"))
    return 0


def _plot(path, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, key, title in ((axes[0], "err_pressure", "peak interface pressure"),
                           (axes[1], "err_von_mises", "peak von Mises stress")):
        for study, order, style in (("h", 2, "o-"), ("h", 3, "s-"), ("p", None, "^-")):
            sel = [r for r in rows if r["study"] == study and (order is None or r["order"] == order)]
            label = f"h-refinement, order {order}" if study == "h" else "p-refinement (orders 2..5)"
            ax.loglog([r["seconds"] for r in sel], [max(r[key], 1e-16) for r in sel], style, label=label)
        ax.axhline(0.01, color="gray", lw=0.8, ls="--")
        ax.set_xlabel("wall-clock seconds (mesh + solve + post-processing)")
        ax.set_ylabel("relative error against the reference")
        ax.set_title(title)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    raise SystemExit(main())
