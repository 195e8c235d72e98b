"""Coulomb friction on the femur / hip-stem scene under one-line changes: coupled Newton against the fixed point.

Each variant changes one line of ``geometries/femur_stem.toml`` (the top
load, the interference, a line-to-line fit, a clearance, mu, the Huber
width, the order) and is solved with ``solver.coulomb = "newton"`` (the
coupled equations, with width continuation where needed) and with
``"fixed_point"`` (Tresca passes), from the same mesh.  Recorded per run:
converged or the failure, wall time of the solve (mesh and law excluded),
Newton steps, the rungs of the width continuation, the equilibrium error,
and the worst violation of the friction law (|tau| - mu p, over mu p_max).

Writes ``OUT/femur_coulomb_variants.csv`` and ``.png``.  Usage::

    python scripts/femur_coulomb_variants.py [--out DIR] [--only NAME ...] [--methods newton|fixed_point ...]
"""
from __future__ import annotations

import argparse
import csv
import os
import re
import sys
import tempfile
import time

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from ngcontact import runner  # noqa: E402
import numpy as np  # noqa: E402

from ngcontact.drivers import run_macro as RM  # noqa: E402
from ngcontact.errors import ConvergenceError  # noqa: E402
from ngcontact.macro import macro_measures as MM  # noqa: E402
from ngcontact.scene.loader import load  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FEMUR = os.path.join(ROOT, "geometries", "femur_stem.toml")
TABLE = r"^gap_table = .*$"
VARIANTS = {
    "as shipped": [],
    "load 0.1 MPa": [(r"^pressure = 1e6", "pressure = 1e5")],
    "load 3 MPa": [(r"^pressure = 1e6", "pressure = 3e6")],
    "load 10 MPa": [(r"^pressure = 1e6", "pressure = 10e6")],
    "load 30 MPa": [(r"^pressure = 1e6", "pressure = 30e6")],
    "interference 1 um": [(r"-50e-6\]", "-1e-6]")],
    "interference 5 um": [(r"-50e-6\]", "-5e-6]")],
    "interference 20 um": [(r"-50e-6\]", "-20e-6]")],
    "interference 100 um": [(r"-50e-6\]", "-100e-6]")],
    "interference 200 um": [(r"-50e-6\]", "-200e-6]")],
    "line-to-line": [(TABLE, "gap_table = [[0.05, 0.0], [0.18, 0.0]]")],
    "clearance 1 um": [(TABLE, "gap_table = [[0.05, 1e-6], [0.18, 1e-6]]")],
    "clearance 10 um": [(TABLE, "gap_table = [[0.05, 10e-6], [0.18, 10e-6]]")],
    "clearance 50 um": [(TABLE, "gap_table = [[0.05, 50e-6], [0.18, 50e-6]]")],
    "mu 0.1": [(r"^mu = 0.3", "mu = 0.1")],
    "mu 0.6": [(r"^mu = 0.3", "mu = 0.6")],
    "mu 1.0": [(r"^mu = 0.3", "mu = 1.0")],
    "width 1e-5": [(r"^huber_width = 1e-6", "huber_width = 1e-5")],
    "width 1e-7": [(r"^huber_width = 1e-6", "huber_width = 1e-7")],
    "width 1e-8": [(r"^huber_width = 1e-6", "huber_width = 1e-8")],
    "order 2": [(r"^order = 3", "order = 2")],
    "order 4": [(r"^order = 3", "order = 4")],
    "line-to-line, mu 0.6": [(TABLE, "gap_table = [[0.05, 0.0], [0.18, 0.0]]"), (r"^mu = 0.3", "mu = 0.6")],
    "load 10 MPa, interference 5 um": [(r"^pressure = 1e6", "pressure = 10e6"), (r"-50e-6\]", "-5e-6]")],
}
METHODS = ("newton", "fixed_point")
FIELDS = ("variant", "method", "converged", "seconds", "newton_steps", "widths", "equilibrium_error",
          "friction_violation", "failure")


def scene_text(changes, method: str) -> str:
    text = open(FEMUR).read().replace('"cells/hip_hills.toml"', '"' + os.path.join(ROOT, "geometries", "cells",
                                                                                  "hip_hills.toml") + '"')
    for pattern, repl in changes + [(r"^rtol = 1e-10", f'rtol = 1e-10\ncoulomb = "{method}"')]:
        text, n = re.subn(pattern, repl, text, flags=re.M)
        if n == 0:
            raise ValueError(f"pattern {pattern!r} not in {FEMUR}")
    return text


def run(name: str, method: str, tmp: str) -> dict:
    path = os.path.join(tmp, "scene.toml")
    with open(path, "w") as fh:
        fh.write(scene_text(VARIANTS[name], method))
    scene = load(path)
    geo = RM.build_geometry(scene)
    problem, _ = RM.problem_of(scene, geo)
    row = {"variant": name, "method": method}
    t0 = time.perf_counter()
    try:
        with runner.threads(runner.thread_count()):   # as ngcontact run: task manager, BLAS on one thread
            sol = RM.solve_scene(scene, problem)
    except ConvergenceError as err:
        return {**row, "converged": False, "seconds": time.perf_counter() - t0, "failure": str(err)[:160]}
    seconds = time.perf_counter() - t0
    prof = MM.interface_profile(sol)
    bound = scene.interface.mu * np.maximum(prof["pressure"], 0.0)
    violation = float(np.max(np.abs(prof["shear"]) - bound)) / max(float(bound.max()), 1.0)
    widths = (sol.history["coulomb"] or {}).get("widths", [])
    return {**row, "converged": True, "seconds": seconds, "newton_steps": sol.history["newton_iterations"],
            "widths": len(widths), "equilibrium_error": MM.equilibrium(sol)["error"],
            "friction_violation": violation, "failure": ""}


def plot(rows: list[dict], path: str) -> None:
    names = list(dict.fromkeys(r["variant"] for r in rows))
    fig, ax = plt.subplots(figsize=(9, 0.32 * len(names) + 1.5))
    for k, method in enumerate(METHODS):
        for i, name in enumerate(names):
            r = next((r for r in rows if r["variant"] == name and r["method"] == method), None)
            if r is None:
                continue
            y = i + (k - 0.5) * 0.35
            colour = "C0" if method == "newton" else "C1"
            ax.barh(y, r["seconds"], height=0.33, color=colour if r["converged"] else "lightgrey",
                    edgecolor=colour, label=method if i == 0 else None)
            if not r["converged"]:
                ax.text(r["seconds"], y, " failed", va="center", fontsize=7)
    ax.set_yticks(range(len(names)), names, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("solve time [s] (grey: did not converge)")
    ax.set_title("Femur / hip stem, Coulomb friction: coupled Newton vs fixed point")
    ax.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/femur_coulomb_variants")
    ap.add_argument("--only", nargs="*", default=None, help="variant names (default: all)")
    ap.add_argument("--methods", nargs="*", default=list(METHODS), choices=METHODS, help="default: both")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.only or VARIANTS:
            for method in args.methods:
                rows.append(run(name, method, tmp))
                r = rows[-1]
                print(f"{name:32s} {method:12s} {'ok' if r['converged'] else 'FAILED':7s} {r['seconds']:7.2f} s "
                      f"steps {r.get('newton_steps', '-')} {r.get('failure', '')[:80]}", flush=True)
    with open(os.path.join(args.out, "femur_coulomb_variants.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        w.writerows({k: r.get(k, "") for k in FIELDS} for r in rows)
    plot(rows, os.path.join(args.out, "femur_coulomb_variants.png"))
    print("wrote", os.path.join(args.out, "femur_coulomb_variants.csv"))
    if args.publish:
        benchmark_doc.publish("femur_coulomb_variants", "Coulomb friction on femur / hip-stem variants",
                              os.path.join(args.out, "femur_coulomb_variants.csv"), columns=FIELDS,
                              note="Each variant changes one line of `geometries/femur_stem.toml` and is solved "
                                   "by the coupled Newton (`newton`) and by the fixed point of Tresca passes "
                                   "(`fixed_point`): converged, seconds of the solve, Newton steps, width-"
                                   "continuation rungs, equilibrium error, worst friction-law violation.",
                              png=os.path.join(args.out, "femur_coulomb_variants.png"))


if __name__ == "__main__":
    main()
