"""Cost of the two-scale femur against one macro solve with the fixed start law (issue 14's aims).

In one process, side by side on the same machine, for
``geometries/femur_stem_two_scale.toml`` without its strength check, every case inside
NGSolve's task manager on every core (as ``ngcontact run``):

* ``fixed_law``: one macro solve with the scene's start law (``[two_scale]`` removed);
* ``two_scale_cold``: the coupling loop with an empty cell-table cache, the cell solves of each
  table level one after the other in this process (the scene's ``two_scale.cell_method``:
  the spectral small-slope cell on 1024 grid points);
* ``two_scale_cold_fe_cell``: the same with ``two_scale.cell_method = "fe"`` (the groove
  cell's finite elements, 7.6k dofs);
* ``two_scale_cold_2_workers``: the same with ``ngcontact run``'s default on two cores: a local
  pool of two worker processes started on demand (a table level solves its first cell here and
  starts the workers only if the rest repays their start; else the level runs here);
* ``two_scale_cold_2_workers_started``: the table levels on a local pool of two workers started
  as the run begins (their start overlaps with the first macro solve and is counted);
* ``two_scale_warm``: the loop again with the table cached by a cold run;
* ``cold_restarts``: the loop with a cold start of every macro solve (``warm = False``), empty cache.

An untimed fixed-law solve runs first, so that no case pays the process's one-time setup
(imports, first assembly), and the cases then run ``--repeats`` times in turn (default
``REPEATS``); the table
reports each case's fastest repeat and the median (a wall time on a shared machine varies by 30 %
between repeats: quote the median).  For each: wall and process (CPU, this process only)
time of the solve stage, macro solves, Newton steps per macro solve, cell solves, loop
updates, and the peak pressure.  Writes ``two_scale_benchmark.csv`` and
``two_scale_benchmark.png`` (times relative to the fixed-law solve) into the output directory
(default ``results/two_scale_benchmark``) and prints the table.  Wall times on a shared
machine are noisy: rerun on a quiet machine before quoting them.

Usage::

    python scripts/two_scale_benchmark.py [OUT_DIR] [--repeats N] [--publish]
"""
from __future__ import annotations

import csv
import dataclasses
import os
from functools import partial
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

SCENE = os.path.join(HERE, "..", "geometries", "femur_stem_two_scale.toml")
REPEATS = 2
KEYS = ("case", "repeat", "wall_seconds", "cpu_seconds", "macro_solves", "newton_per_solve", "cell_solves", "updates",
        "peak_pressure_MPa")


def measure(case: str, scene, cache_dir: str, warm: bool = True, workers: int = 1, started: bool = False) -> dict:
    from ngcontact import runner
    from ngcontact.drivers import run_macro as D
    from ngcontact.drivers import run_two_scale as R
    from ngcontact.macro import macro_measures as MM
    geo = D.build_geometry(scene)
    problem, _ = D.problem_of(scene, geo)
    with runner.threads(runner.thread_count()):
        t0, c0 = time.perf_counter(), time.process_time()
        with runner.batches(scene, workers, start=True if started else None):  # as ngcontact run
            row = solve(scene, problem, cache_dir, warm, D, R)
        sol = row.pop("solution")
        row.update(case=case, wall_seconds=time.perf_counter() - t0, cpu_seconds=time.process_time() - c0,
                   peak_pressure_MPa=float(np.max(MM.interface_profile(sol)["pressure"])) / 1e6)
    print(", ".join(f"{k} = {row.get(k)}" for k in KEYS), flush=True)
    return row


def solve(scene, problem, cache_dir, warm, D, R) -> dict:
    if scene.two_scale is None:
        sol = D.solve_scene(scene, problem)
        row = {"macro_solves": 1, "newton_per_solve": str(sol.history["newton_iterations"]), "cell_solves": 0,
               "updates": 0}
    else:
        sol, res = R.couple(scene, problem, partial(D.solve_scene, scene),
                            cache_dir=cache_dir, warm=warm)
        row = {"macro_solves": res["macro_solves"], "newton_per_solve": " ".join(map(str, res["newton_per_solve"])),
               "cell_solves": res["cell_solves"], "updates": res["iterations"]}
    row["solution"] = sol
    return row


def main(out: str, repeats: int = REPEATS) -> list[dict]:
    from ngcontact.scene.loader import load
    shipped = load(SCENE)

    def variant(**changes):
        new = dataclasses.replace(shipped, **changes)
        object.__setattr__(new, "base_dir", shipped.base_dir)   # not an init field: keep the scene's folder
        return new
    scene = variant(strength=None)
    fixed = variant(strength=None, two_scale=None)
    fe_cell = variant(strength=None, two_scale=dataclasses.replace(shipped.two_scale, cell_method="fe"))
    measure("warm-up (not reported)", fixed, "")
    every = []
    for repeat in range(repeats):
        every.append(dict(measure("fixed_law", fixed, ""), repeat=repeat))
        with tempfile.TemporaryDirectory() as cache:
            every.append(dict(measure("two_scale_cold", scene, cache), repeat=repeat))
            every.append(dict(measure("two_scale_warm", scene, cache), repeat=repeat))
        with tempfile.TemporaryDirectory() as cache:
            every.append(dict(measure("two_scale_cold_fe_cell", fe_cell, cache), repeat=repeat))
        with tempfile.TemporaryDirectory() as cache:
            every.append(dict(measure("two_scale_cold_2_workers", scene, cache, workers=2), repeat=repeat))
        with tempfile.TemporaryDirectory() as cache:
            every.append(dict(measure("two_scale_cold_2_workers_started", scene, cache, workers=2, started=True),
                              repeat=repeat))
        with tempfile.TemporaryDirectory() as cache:
            every.append(dict(measure("cold_restarts", scene, cache, warm=False), repeat=repeat))
    cases = list(dict.fromkeys(r["case"] for r in every))
    rows = [min((r for r in every if r["case"] == c), key=lambda r: r["wall_seconds"]) for c in cases]
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "two_scale_benchmark.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=KEYS + ("fastest",))
        w.writeheader()
        w.writerows([dict(r, fastest=any(r is f for f in rows)) for r in every])
    base = rows[0]
    median = {c: float(np.median([r["wall_seconds"] for r in every if r["case"] == c])) for c in cases}
    for r in rows:
        c = r["case"]
        print(f"{c:>26}: fastest {r['wall_seconds']:6.2f} s wall = {r['wall_seconds'] / base['wall_seconds']:.2f}x, "
              f"median {median[c]:6.2f} s = {median[c] / median[cases[0]]:.2f}x, "
              f"cell solves {r['cell_solves']}, Newton per solve {r['newton_per_solve']}", flush=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 3.8))
    x = np.arange(len(rows))
    ax.bar(x - 0.27, [r["wall_seconds"] / base["wall_seconds"] for r in rows], 0.27, label="wall, fastest")
    ax.bar(x, [median[c] / median[cases[0]] for c in cases], 0.27, label="wall, median")
    ax.bar(x + 0.27, [r["cpu_seconds"] / base["cpu_seconds"] for r in rows], 0.27, label="CPU, fastest")
    for aim, style in ((2.0, "--"), (1.2, ":")):
        ax.axhline(aim, color="k", ls=style, lw=0.8)
    ax.set_xticks(x, [r["case"].replace("_", " ") for r in rows], rotation=20, ha="right", fontsize=8)
    ax.set_ylabel("time / one fixed-law macro solve")
    ax.set_title(f"femur_stem_two_scale: cost of the loop, {repeats} repeats (aims 2x cold, 1.2x warm)",
                 fontsize=9)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "two_scale_benchmark.png"), dpi=120)
    return rows


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser(description="cost of the two-scale femur against one fixed-law macro solve")
    ap.add_argument("out", nargs="?", default=os.path.join("results", "two_scale_benchmark"))
    ap.add_argument("--repeats", type=int, default=REPEATS, help="runs of every case; the fastest is reported")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args()
    main(args.out, args.repeats)
    if args.publish:
        benchmark_doc.publish("two_scale_benchmark", "Cost of the two-scale femur against one fixed-law macro solve",
                              os.path.join(args.out, "two_scale_benchmark.csv"),
                              note="`geometries/femur_stem_two_scale.toml` without its strength check, every case "
                                   "in one process on every core: the fixed start law, the coupling loop cold "
                                   "(spectral and FE cell, in this process and on two workers), warm from a cached "
                                   "table, and with cold macro restarts. Every repeat is listed (`fastest` marks "
                                   "each case's fastest); wall times on a shared machine vary between repeats.",
                              png=os.path.join(args.out, "two_scale_benchmark.png"))
