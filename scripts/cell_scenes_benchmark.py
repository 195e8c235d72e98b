"""Newton iterations per load and wall time for every cell scene in ``geometries/cells/``.

Runs the ``cell`` driver on each scene through the command line
(``ngcontact run SCENE --out DIR``, one process per scene, so every scene
pays its own imports and meshing) and reads ``report.json``: Newton steps
per load (``results.loads[k].newton_iterations``, summed over the Coulomb
fixed-point passes), the largest number of steps of any single Newton solve
and the number of Newton solves (``solver.per_load``: more than one per load
under Coulomb friction), the number of dofs, the solve stage and the total
wall time.  Scenes of other kinds and purely
geometric scenes (``contact.geometric_only``) are listed with zero loads.
Writes ``cell_scenes_benchmark.csv`` into the output directory (default
``results/cell_scenes_benchmark``) and prints the table.

Usage::

    python scripts/cell_scenes_benchmark.py [OUT_DIR] [--scenes DIR]
"""
from __future__ import annotations

import argparse
import glob
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

KEYS = ("scene", "status", "ndof", "loads", "newton_per_load", "max_newton", "max_per_solve",
        "newton_solves", "solve_seconds", "total_seconds", "wall_seconds")


def bench(path: str, out_root: str) -> dict:
    name = os.path.splitext(os.path.basename(path))[0]
    out = os.path.join(out_root, name)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "ngcontact.cli", "run", path, "--out", out, "--quiet"],
                          capture_output=True, text=True)
    wall = time.perf_counter() - t0
    row = {"scene": name, "status": "ok" if proc.returncode == 0 else f"exit {proc.returncode}",
           "ndof": 0, "loads": 0, "newton_per_load": "", "max_newton": 0, "max_per_solve": 0,
           "newton_solves": 0, "solve_seconds": 0.0,
           "total_seconds": 0.0, "wall_seconds": wall}
    report = os.path.join(out, "report.json")
    if proc.returncode != 0 or not os.path.exists(report):
        row["status"] += ": " + (proc.stderr.strip().splitlines() or ["no message"])[-1][:80]
        return row
    with open(report) as fh:
        rep = json.load(fh)
    loads = rep.get("results", {}).get("loads", [])
    its = [int(entry.get("newton_iterations", 0)) for entry in loads]
    # FE cells: a list of Newton histories per load; spectral cells: one solver record per load
    solves = [h["iterations"] for per in rep.get("solver", {}).get("per_load", [])
              for h in (per if isinstance(per, list) else [per])]
    t = rep.get("timings", {})
    row.update(max_per_solve=max(solves) if solves else 0, newton_solves=len(solves),
               ndof=rep.get("ndof", 0), loads=len(its), newton_per_load=" ".join(map(str, its)),
               max_newton=max(its) if its else 0, solve_seconds=t.get("solve", 0.0),
               total_seconds=t.get("total", 0.0))
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "cell_scenes_benchmark"))
    ap.add_argument("--scenes", default=os.path.join(HERE, "..", "geometries", "cells"))
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    rows = [bench(p, args.out) for p in sorted(glob.glob(os.path.join(args.scenes, "*.toml")))]
    import csv
    with open(os.path.join(args.out, "cell_scenes_benchmark.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(KEYS)
        w.writerows([[r[k] for k in KEYS] for r in rows])
    head = (f"{'scene':24s} {'status':10s} {'ndof':>7s} {'loads':>5s} {'max it':>6s} {'max/solve':>9s} "
            f"{'solves':>6s} {'solve s':>8s} {'total s':>8s}  per-load")
    sys.stdout.write(head + "\n" + "-" * len(head) + "\n")
    for r in rows:
        sys.stdout.write(f"{r['scene']:24s} {r['status'][:10]:10s} {r['ndof']:7d} {r['loads']:5d} "
                         f"{r['max_newton']:6d} {r['max_per_solve']:9d} {r['newton_solves']:6d} "
                         f"{r['solve_seconds']:8.2f} {r['total_seconds']:8.2f}  "
                         f"{r['newton_per_load']}\n")
    bad = [r for r in rows if r["status"] != "ok"]
    for r in bad:
        sys.stdout.write(f"{r['scene']}: {r['status']}\n")
    if args.publish:
        benchmark_doc.publish("cell_scenes_benchmark", "Cell scenes: Newton steps and wall time",
                              os.path.join(args.out, "cell_scenes_benchmark.csv"),
                              note="Every scene of `geometries/cells/` run by `ngcontact run` in its own process: "
                                   "Newton steps per load, the largest single Newton solve, the number of solves, "
                                   "the solve stage's and the whole run's seconds.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
