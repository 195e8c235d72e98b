"""Scale-out of a batch of independent cell solves: 1 and 2 local workers and a Dask cluster.

The batch: the 2D FE cell of a sinusoidal profile (conforming, order 2,
``maxh = 0.08``, ``interface_maxh = 0.015``: about 1 s per solve here) under
16 pressures with ``load.independent = true``, so each load is a member of
the batch (:mod:`ngcontact.drivers.cell_members`) that meshes and solves its
own cell.  Runs, each through the ``cell`` driver under the executor of
:mod:`ngcontact.solvers.executor`:

* ``serial``: one worker, in this process;
* ``local`` with 2 workers: cold (the pool is spawned for the run, as
  ``ngcontact run --workers 2`` does: interpreters start and import NGSolve)
  and warm (the same pool again);
* ``dask``: a ``distributed.LocalCluster`` of 2 worker processes with one
  thread each, cold (its workers import the package on the first task) and
  warm.

Reported: wall time, speedup over serial, the largest relative difference of
any per-load result from the serial run, and the scheduler's overhead per
task: the wall time of 200 no-op members (``operator.neg``) over their
number, on 1 worker, as a percentage of the mean serial cell solve.  Writes
``scale_out.csv`` and ``scale_out.png`` into the output directory (default
``results/scale_out``).

Wall times on a shared machine are noisy: re-measure on a quiet one with::

    PYTHONPATH=$PWD MPLBACKEND=Agg python scripts/scale_out.py results/scale_out
"""
from __future__ import annotations

import argparse
import csv
import operator
import os
import tempfile
import time

import numpy as np

from ngcontact.drivers import run_cell
from ngcontact.output.report import Clock
from ngcontact.scene import loader
from ngcontact.solvers import executor

LOADS = np.geomspace(0.002, 0.02, 16)
SCENE = """kind = "cell"
title = "scale-out: sinusoidal cell, 16 independent pressures"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "sinusoid"
amplitude = 0.05
period = 1.0
h_rough = 0.6
h_counter = 0.6
[contact]
k_n = 1.0e3
[load]
pressure = [{loads}]
independent = true
[discretization]
order = 2
maxh = 0.08
interface_maxh = 0.015
"""
KEYS = ("contact_fraction", "mean_closure", "mean_pressure", "transmitted_pressure")
NOOP_TASKS = 200


def solve(scene, ex) -> tuple[float, list[dict]]:
    with executor.use(ex) as e:
        t0 = time.perf_counter()
        outcome = run_cell.run(scene, Clock())
        wall = time.perf_counter() - t0
        e.close()
    return wall, outcome.results["loads"]


def difference(a: list[dict], b: list[dict]) -> float:
    """Largest relative difference of the per-load results ``KEYS``."""
    return max(abs(x[k] - y[k]) / max(abs(x[k]), abs(y[k]), 1e-300) for x, y in zip(a, b) for k in KEYS)


def overhead(ex) -> float:
    """Seconds per no-op member through the executor ``ex`` (after one warm-up batch)."""
    items = list(range(NOOP_TASKS))
    names = [f"noop {k}" for k in items]
    ex.map(operator.neg, items[:4], names[:4])
    t0 = time.perf_counter()
    ex.map(operator.neg, items, names)
    return (time.perf_counter() - t0) / NOOP_TASKS


class Reusable(executor.Executor):
    """An executor that :func:`executor.use` does not close (the warm runs reuse it)."""

    def __init__(self, inner: executor.Executor):
        self.inner, self.name, self.workers = inner, inner.name, inner.workers

    def _map(self, fn, items, names, label, progress, fault):
        return self.inner._map(fn, items, names, label, progress, fault)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=os.path.join("results", "scale_out"))
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "scale_out.toml")
        with open(path, "w") as fh:
            fh.write(SCENE.format(loads=", ".join(f"{p:.6g}" for p in LOADS)))
        scene = loader.load(path)
    rows = []
    t_serial, ref = solve(scene, executor.Serial())
    per_solve = t_serial / len(LOADS)
    serial_overhead = overhead(executor.Serial())
    rows.append(dict(run="serial", workers=1, wall=t_serial, speedup=1.0, max_rel_diff=0.0,
                     overhead_per_task=serial_overhead))
    print(f"serial: {t_serial:.2f} s ({per_solve:.2f} s per solve)", flush=True)

    pool = executor.LocalPool(2)
    for run in ("local cold", "local warm"):
        wall, res = solve(scene, Reusable(pool))
        rows.append(dict(run=run, workers=2, wall=wall, speedup=t_serial / wall, max_rel_diff=difference(ref, res),
                         overhead_per_task=float("nan")))
        print(f"{run}: {wall:.2f} s, speedup {t_serial / wall:.2f}", flush=True)
    one = executor.LocalPool(1)
    rows[-1]["overhead_per_task"] = overhead(one)
    one.close()
    pool.close()

    from distributed import LocalCluster
    with LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None) as cluster:
        dask = executor.DaskCluster(cluster.scheduler_address)
        for run in ("dask cold", "dask warm"):
            wall, res = solve(scene, Reusable(dask))
            rows.append(dict(run=run, workers=2, wall=wall, speedup=t_serial / wall,
                             max_rel_diff=difference(ref, res), overhead_per_task=float("nan")))
            print(f"{run}: {wall:.2f} s, speedup {t_serial / wall:.2f}", flush=True)
        dask.close()
    with LocalCluster(n_workers=1, processes=True, threads_per_worker=1, dashboard_address=None) as cluster:
        dask1 = executor.DaskCluster(cluster.scheduler_address)
        rows[-1]["overhead_per_task"] = overhead(dask1)
        dask1.close()
    for r in rows:
        r["overhead_percent_of_solve"] = 100 * r["overhead_per_task"] / per_solve
    write(args.out, rows, per_solve)


def write(out: str, rows: list[dict], per_solve: float) -> None:
    keys = ["run", "workers", "wall", "speedup", "max_rel_diff", "overhead_per_task", "overhead_percent_of_solve"]
    with open(os.path.join(out, "scale_out.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow([r[k] if isinstance(r[k], str) or not np.isnan(r[k]) else "" for k in keys])
    for r in rows:
        over = "" if np.isnan(r["overhead_per_task"]) else (f"  overhead {1e3 * r['overhead_per_task']:.2f} ms/task "
                                                            f"= {r['overhead_percent_of_solve']:.2f} % of a solve")
        print(f"{r['run']:>11}: {r['wall']:7.2f} s  speedup {r['speedup']:.2f}  "
              f"max rel diff {r['max_rel_diff']:.1e}{over}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    names = [r["run"] for r in rows]
    ax[0].bar(names, [r["wall"] for r in rows], color=["C0", "C1", "C1", "C2", "C2"])
    for i, r in enumerate(rows):
        ax[0].text(i, r["wall"], f"x{r['speedup']:.2f}", ha="center", va="bottom", fontsize=8)
    ax[0].set_ylabel("wall time of 16 cell solves [s]")
    ax[0].set_title(f"speedup over serial ({per_solve:.2f} s per solve)", fontsize=9)
    ax[0].tick_params(axis="x", rotation=30)
    measured = [r for r in rows if not np.isnan(r["overhead_per_task"])]
    ax[1].bar([r["run"].split()[0] for r in measured], [r["overhead_percent_of_solve"] for r in measured])
    ax[1].axhline(5.0, color="k", ls=":", label="5 % of a solve")
    ax[1].set_yscale("log")
    ax[1].set_ylabel("overhead per task [% of one cell solve]")
    ax[1].legend(fontsize=8)
    fig.suptitle("scale-out on a shared 2-core machine (noisy: re-measure on a quiet one)", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scale_out.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
