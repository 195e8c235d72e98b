"""The coupled Coulomb Newton's two globalizations, on the cell and on the femur: steps and time.

:func:`ngcontact.solvers.coulomb_newton.coupled_newton` takes the full
Newton step when it lowers ``|R|``; otherwise either the exact line search
on the Tresca energy with the threshold frozen at the iterate (``frozen``,
what the cell and the macro problem pass) or backtracking on ``|R|`` (no
``frozen``).  This script solves

* the cell ``geometries/cells/rectangular_coulomb.toml`` (its three loads
  by one sweep, the shear loads' rigid continuation counted), and
* femur / hip-stem variants of ``scripts/femur_coulomb_variants.py``
  (``solver.coulomb = "newton"``, width continuation where Newton fails),

once as shipped (frozen-energy search) and once with the ``frozen``
argument withheld (residual backtracking), and records converged, Newton
steps (per load on the cell), width-continuation rungs and wall time.
Timings are those of one run on a shared machine.

Writes ``OUT/coulomb_newton_globalization.csv`` and ``.png``.  Usage::

    python scripts/coulomb_newton_globalization.py [--out DIR] [--variants NAME ...]
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import os
import sys
import tempfile
import time
from contextlib import contextmanager

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from ngcontact import runner  # noqa: E402

from ngcontact.cell.fe import coulomb_friction  # noqa: E402
from ngcontact.drivers.build import cell_loads, cell_problem  # noqa: E402
from ngcontact.errors import ConvergenceError  # noqa: E402
from ngcontact.macro import macro_problem  # noqa: E402
from ngcontact.scene.loader import load  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CELL = os.path.join(ROOT, "geometries", "cells", "rectangular_coulomb.toml")
GLOBALIZATIONS = ("frozen_energy", "residual")
DEFAULT_VARIANTS = ("as shipped", "load 0.1 MPa", "load 3 MPa", "interference 200 um", "line-to-line", "mu 1.0",
                    "width 1e-8")
FIELDS = ("case", "globalization", "converged", "seconds", "newton_steps", "steps_per_load", "widths", "failure")


def _variants_module():
    spec = importlib.util.spec_from_file_location("femur_coulomb_variants",
                                                  os.path.join(ROOT, "scripts", "femur_coulomb_variants.py"))
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@contextmanager
def globalization(name: str):
    """Within: the cell's and the macro problem's coupled Newton with the given globalization."""
    originals = (coulomb_friction.coupled_newton, macro_problem.coupled_newton)
    if name == "residual":
        def without_frozen(*args, **kwargs):
            kwargs.pop("frozen", None)
            return originals[0](*args, **kwargs)
        coulomb_friction.coupled_newton = macro_problem.coupled_newton = without_frozen
    try:
        yield
    finally:
        coulomb_friction.coupled_newton, macro_problem.coupled_newton = originals


def run_cell() -> dict:
    scene = load(CELL)
    problem = cell_problem(scene)
    t0 = time.perf_counter()
    try:
        with runner.threads(runner.thread_count()):   # as ngcontact run: task manager, BLAS on one thread
            sols = problem.sweep(cell_loads(scene))
    except ConvergenceError as err:
        return {"case": "cell rectangular_coulomb", "converged": False, "seconds": time.perf_counter() - t0,
                "failure": str(err)[:160]}
    steps = [s.iterations for s in sols]
    fell_back = any(s.newton[-1].get("stage") != "coulomb_newton" for s in sols)
    return {"case": "cell rectangular_coulomb", "converged": True, "seconds": time.perf_counter() - t0,
            "newton_steps": sum(steps), "steps_per_load": " ".join(map(str, steps)), "widths": "",
            "failure": "fixed point fallback" if fell_back else ""}


def run_femur(variants, name: str, tmp: str) -> dict:
    row = variants.run(name, "newton", tmp)
    return {"case": f"femur {name}", "converged": row["converged"], "seconds": row["seconds"],
            "newton_steps": row.get("newton_steps", ""), "steps_per_load": "", "widths": row.get("widths", ""),
            "failure": row.get("failure", "")}


def plot(rows: list[dict], path: str) -> None:
    cases = list(dict.fromkeys(r["case"] for r in rows))
    fig, axes = plt.subplots(1, 2, figsize=(11, 0.35 * len(cases) + 1.8), sharey=True)
    for k, glob in enumerate(GLOBALIZATIONS):
        for i, case in enumerate(cases):
            r = next((r for r in rows if r["case"] == case and r["globalization"] == glob), None)
            if r is None:
                continue
            y = i + (k - 0.5) * 0.38
            colour = f"C{k}"
            for ax, key in zip(axes, ("newton_steps", "seconds")):
                value = r.get(key) or 0.0
                ax.barh(y, float(value), height=0.36, color=colour if r["converged"] else "lightgrey",
                        edgecolor=colour, label=glob if i == 0 else None)
    axes[0].set_yticks(range(len(cases)), cases, fontsize=8)
    axes[0].invert_yaxis()
    axes[0].set_xlabel("Newton steps (grey: did not converge)")
    axes[1].set_xlabel("wall time [s]")
    axes[0].legend(loc="lower right")
    fig.suptitle("Coupled Coulomb Newton: frozen-energy line search vs residual backtracking")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/coulomb_newton_globalization")
    ap.add_argument("--variants", nargs="*", default=list(DEFAULT_VARIANTS), help="femur variants")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args()
    variants = _variants_module()
    unknown = [v for v in args.variants if v not in variants.VARIANTS]
    if unknown:
        raise SystemExit(f"--variants: unknown {unknown}; allowed: {list(variants.VARIANTS)}")
    os.makedirs(args.out, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for glob in GLOBALIZATIONS:
            with globalization(glob):
                cases = [run_cell] + [lambda name=name: run_femur(variants, name, tmp) for name in args.variants]
                for case in cases:
                    r = {**case(), "globalization": glob}
                    rows.append(r)
                    print(f"{r['case']:34s} {glob:14s} {'ok' if r['converged'] else 'FAILED':7s} "
                          f"{r['seconds']:7.2f} s steps {r.get('newton_steps', '-')} ({r.get('steps_per_load', '')}) "
                          f"widths {r.get('widths', '')} {r.get('failure', '')[:60]}", flush=True)
    path = os.path.join(args.out, "coulomb_newton_globalization.csv")
    with open(path + ".tmp", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        w.writerows({k: r.get(k, "") for k in FIELDS} for r in rows)
    os.replace(path + ".tmp", path)
    plot(rows, os.path.join(args.out, "coulomb_newton_globalization.png"))
    print("wrote", path)
    if args.publish:
        benchmark_doc.publish("coulomb_newton_globalization", "Coupled Coulomb Newton: the two globalizations",
                              path, columns=FIELDS,
                              note="The cell `geometries/cells/rectangular_coulomb.toml` (steps per load, the "
                                   "shear loads' rigid continuation counted) and femur / hip-stem variants "
                                   "solved with the frozen-energy line search (as shipped) and with residual "
                                   "backtracking: converged, seconds, Newton steps, width-continuation rungs.",
                              png=os.path.join(args.out, "coulomb_newton_globalization.png"))


if __name__ == "__main__":
    main()
