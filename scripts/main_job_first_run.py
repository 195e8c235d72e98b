"""The main job on a fresh machine and again: ``ngcontact run geometries/femur_stem.toml``, cold and warm.

A fresh machine has an empty cell-law cache (``$NGCONTACT_CACHE``); the
first run fills whatever the run caches, the next one finds it.  Each
repeat makes a new empty cache directory and runs the main job twice in it
(``cold``, then ``warm``), each in a fresh interpreter as a user types it;
per run the command's wall time, its peak resident memory (the child's
``ru_maxrss``), the report's stage times, whether the cache directory
holds anything afterwards and where the strength check's cell came from
(``strength_cell``: shipped with the package, cached or computed,
:mod:`ngcontact.drivers.strength_cell`).  The speed issue's aims: the first
run within 2x a warm one, and the strength check's stage no longer than
the macro solve's (``strength_over_solve`` <= 1).

    MPLBACKEND=Agg python scripts/main_job_first_run.py results/main_job_first_run --publish
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

SCENE = os.path.join(benchmark_doc.ROOT, "geometries", "femur_stem.toml")
REPEATS = 3


def run(cache: str, out: str) -> dict:
    """The main job with ``cache`` as its cell-law cache: wall seconds, peak memory, report."""
    env = dict(os.environ, NGCONTACT_CACHE=cache)
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "ngcontact", "run", SCENE, "--out", out, "--quiet"], check=True, env=env)
    wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    with open(os.path.join(out, "report.json")) as fh:
        report = json.load(fh)
    cached = sum(len(files) for _, _, files in os.walk(cache))
    return dict(wall=wall, peak_memory_mb=max(peak, before) / 1024, report=report, cached_files=cached)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=os.path.join("results", "main_job_first_run"))
    benchmark_doc.add_flag(parser)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for repeat in range(REPEATS):
            cache = os.path.join(tmp, f"cache_{repeat}")
            os.makedirs(cache)
            for state in ("cold", "warm"):
                r = run(cache, os.path.join(tmp, f"{state}_{repeat}"))
                stages = r["report"]["timings"]
                rows.append(dict(run=state, repeat=repeat, wall=r["wall"], peak_memory_mb=r["peak_memory_mb"],
                                 cached_files=r["cached_files"], solve=stages["solve"],
                                 strength=stages["strength check"],
                                 strength_over_solve=stages["strength check"] / stages["solve"],
                                 strength_cell=r["report"]["results"]["strength"]["cell"].get("source", "computed"),
                                 stages="; ".join(f"{k} {v:.2f}" for k, v in stages.items())))
                print(f"{state} #{repeat}: {r['wall']:.2f} s, {r['cached_files']} cached files", flush=True)
    for r in rows:
        warm = [w["wall"] for w in rows if w["run"] == "warm" and w["repeat"] == r["repeat"]][0]
        r["over_warm"] = r["wall"] / warm
    keys = ["run", "repeat", "wall", "over_warm", "solve", "strength", "strength_over_solve", "strength_cell",
            "peak_memory_mb", "cached_files", "stages"]
    path = os.path.join(args.out, "main_job_first_run.csv")
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow([r[k] for k in keys])
    if args.publish:
        benchmark_doc.publish("main_job_first_run", "The main job on a fresh machine", path,
                              note="`ngcontact run geometries/femur_stem.toml` with an empty cell-law cache "
                                   "(`cold`) and again with what that run cached (`warm`), each repeat in a new "
                                   "cache directory. `wall` in seconds; `over_warm`: the run's time over the warm "
                                   "run of its repeat (aim: the cold run within 2x); `solve` and `strength`: the "
                                   "report's stages of the macro solve and of the strength check (both of its "
                                   "parts: the cell's correctors and the check), `strength_over_solve` their "
                                   "ratio (aim: <= 1); `strength_cell`: where the strength cell's correctors "
                                   "came from (`shipped` with the package, `cached`, `computed`).")


if __name__ == "__main__":
    main()
