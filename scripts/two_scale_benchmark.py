"""Cost of the two-scale femur against one macro solve with the fixed start law (issue 14's aims).

In one process, side by side on the same machine, for
``geometries/femur_stem_two_scale.toml`` without its strength check:

* ``fixed_law``: one macro solve with the scene's start law (``[two_scale]`` removed);
* ``two_scale_cold``: the coupling loop with an empty cell-table cache;
* ``two_scale_warm``: the same loop again with the table cached by the first;
* ``cold_restarts``: the loop with a cold start of every macro solve (``warm = False``), empty cache.

For each: wall and process (CPU) time of the solve stage, macro solves, Newton steps per macro
solve, cell solves, loop updates, and the peak pressure.  Writes ``two_scale_benchmark.csv``
and ``two_scale_benchmark.png`` (times relative to the fixed-law solve) into the output
directory (default ``results/two_scale_benchmark``) and prints the table.  Wall times on a
shared machine are noisy: rerun on a quiet machine before quoting them.

Usage::

    python scripts/two_scale_benchmark.py [OUT_DIR]
"""
from __future__ import annotations

import csv
import dataclasses
import os
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "geometries", "femur_stem_two_scale.toml")
KEYS = ("case", "wall_seconds", "cpu_seconds", "macro_solves", "newton_per_solve", "cell_solves", "updates",
        "peak_pressure_MPa")


def measure(case: str, scene, cache_dir: str, warm: bool = True) -> dict:
    from ngcontact.drivers import run_macro as D
    from ngcontact.drivers import run_two_scale as R
    from ngcontact.macro import macro_measures as MM
    geo = D.build_geometry(scene)
    problem, _ = D.problem_of(scene, geo)
    t0, c0 = time.perf_counter(), time.process_time()
    if scene.two_scale is None:
        sol = D.solve_scene(scene, problem)
        row = {"macro_solves": 1, "newton_per_solve": str(sol.history["newton_iterations"]), "cell_solves": 0,
               "updates": 0}
    else:
        sol, res = R.couple(scene, problem, lambda prob, start: D.solve_scene(scene, prob, start),
                            cache_dir=cache_dir, warm=warm)
        row = {"macro_solves": res["macro_solves"], "newton_per_solve": " ".join(map(str, res["newton_per_solve"])),
               "cell_solves": res["cell_solves"], "updates": res["iterations"]}
    row.update(case=case, wall_seconds=time.perf_counter() - t0, cpu_seconds=time.process_time() - c0,
               peak_pressure_MPa=float(np.max(MM.interface_profile(sol)["pressure"])) / 1e6)
    print(", ".join(f"{k} = {row[k]}" for k in KEYS), flush=True)
    return row


def main(out: str) -> list[dict]:
    from ngcontact.scene.loader import load
    shipped = load(SCENE)

    def variant(**changes):
        new = dataclasses.replace(shipped, **changes)
        object.__setattr__(new, "base_dir", shipped.base_dir)   # not an init field: keep the scene's folder
        return new
    scene = variant(strength=None)
    rows = [measure("fixed_law", variant(strength=None, two_scale=None), "")]
    with tempfile.TemporaryDirectory() as cache:
        rows.append(measure("two_scale_cold", scene, cache))
        rows.append(measure("two_scale_warm", scene, cache))
    with tempfile.TemporaryDirectory() as cache:
        rows.append(measure("cold_restarts", scene, cache, warm=False))
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "two_scale_benchmark.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=KEYS)
        w.writeheader()
        w.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    base = rows[0]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    x = np.arange(len(rows))
    ax.bar(x - 0.2, [r["wall_seconds"] / base["wall_seconds"] for r in rows], 0.4, label="wall")
    ax.bar(x + 0.2, [r["cpu_seconds"] / base["cpu_seconds"] for r in rows], 0.4, label="CPU")
    for aim, style in ((2.0, "--"), (1.2, ":")):
        ax.axhline(aim, color="k", ls=style, lw=0.8)
    ax.set_xticks(x, [r["case"] for r in rows])
    ax.set_ylabel("time / one fixed-law macro solve")
    ax.set_title("femur_stem_two_scale: cost of the loop (aims 2x cold, 1.2x warm)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "two_scale_benchmark.png"), dpi=120)
    return rows


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join("results", "two_scale_benchmark"))
