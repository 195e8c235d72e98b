"""Scale-out of a batch of independent cell solves: 1 and 2 local workers and a Dask cluster.

The batch: the 2D FE cell of a sinusoidal profile (conforming, order 2,
``maxh = 0.06``, ``interface_maxh = 0.01``: a solve of well under a second,
short enough for a worker's start to matter) under 16 pressures with ``load.independent = true``, so each
load is a member of the batch (:mod:`ngcontact.drivers.cell_members`) that
meshes and solves its own cell (``discretization.estimate = "off"``: one solve
per load, not held to the default tolerance).  Each run is the command a user types,
``ngcontact run SCENE --out DIR --quiet`` in a fresh interpreter, with

* ``--workers 1`` with ``NGCONTACT_THREADS=1``: one worker on one thread, the
  reference of the speedups (a worker of the pool runs one NGSolve thread);
* ``--workers 1``: the serial executor in the run's process with NGSolve's
  task manager on every core (what a run without a batch uses);
* ``--workers 2``: a local pool of two spawned workers, one NGSolve thread
  each, started when the run begins (their interpreter start and imports
  overlap with the run's own mesh and setup);
* two ``--workers 1`` one-thread runs at the same time (``2 runs at once``):
  twice the work of one, so their throughput over one run's (twice its time
  over theirs) is the ceiling of any two workers on this machine, whose
  cores share caches and memory bandwidth;
* ``--scheduler ADDRESS``: a ``distributed.LocalCluster`` of 2 worker
  processes with one thread each, started by this script before the runs (a
  cluster outlives the runs it serves); its first run imports the package on
  the workers (``dask cold``), the next finds it imported (``dask warm``).

Each configuration runs ``REPEATS`` times; reported per run: the command's
wall time, the batch's wall time (``report.json`` ``compute.batches``), the
speedups of both over the one-thread ``--workers 1`` run of the same repeat,
and the largest relative difference of any number in ``results.loads`` from
the first one-thread run (the
effective stiffness, a difference of compliances that loses digits to
cancellation, separately; its spread between two serial runs is reported
too).  The scheduler's overhead per task: the wall time of 200 no-op members
(``operator.neg``) over their number, on 1 worker, as a percentage of the
mean serial cell solve.  Writes ``scale_out.csv`` and ``scale_out.png`` into
the output directory (default ``results/scale_out``).

Wall times on a shared machine are noisy: re-measure on a quiet one with::

    MPLBACKEND=Agg python scripts/scale_out.py results/scale_out
"""
from __future__ import annotations

import argparse
import csv
import json
import operator
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from ngcontact.parallel import executor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

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
maxh = 0.06
interface_maxh = 0.01
estimate = "off"
"""
NOOP_TASKS = 200
REPEATS = 2


def run(path: str, out: str, *flags: str, threads: int | None = None) -> tuple[float, dict]:
    """``ngcontact run path --out out --quiet flags`` in a fresh interpreter: (wall seconds, report)."""
    env = dict(os.environ)
    if threads is not None:
        env["NGCONTACT_THREADS"] = str(threads)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "ngcontact", "run", path, "--out", out, "--quiet", *flags], check=True,
                   env=env)
    wall = time.perf_counter() - t0
    with open(os.path.join(out, "report.json")) as fh:
        return wall, json.load(fh)


def run_pair(path: str, outs: tuple[str, str]) -> tuple[float, list[dict]]:
    """Two one-thread ``--workers 1`` runs of ``path`` at the same time, in two fresh interpreters: the wall
    time until both end and their reports (what two independent processes get out of the machine)."""
    env = dict(os.environ, NGCONTACT_THREADS="1")
    t0 = time.perf_counter()
    procs = [subprocess.Popen([sys.executable, "-m", "ngcontact", "run", path, "--out", out, "--quiet",
                               "--workers", "1"], env=env) for out in outs]
    for proc in procs:
        if proc.wait() != 0:
            raise RuntimeError(f"ngcontact run exited with {proc.returncode}")
    wall = time.perf_counter() - t0
    reports = []
    for out in outs:
        with open(os.path.join(out, "report.json")) as fh:
            reports.append(json.load(fh))
    return wall, reports


def numbers(value, path: str = "") -> dict[str, float]:
    """Every float of a nested report value, by its path."""
    if isinstance(value, dict):
        return {k: v for key, item in value.items() for k, v in numbers(item, f"{path}.{key}").items()}
    if isinstance(value, list):
        return {k: v for i, item in enumerate(value) for k, v in numbers(item, f"{path}[{i}]").items()}
    return {path: float(value)} if isinstance(value, float) else {}


def difference(a: dict, b: dict, cancelling: bool) -> float:
    """Largest relative difference (to the larger magnitude, at least 1) of the numbers of ``results.loads``,
    with (``cancelling``) or without the effective stiffness."""
    x, y = numbers(a["results"]["loads"]), numbers(b["results"]["loads"])
    keys = [k for k in x if ("effective_stiffness" in k) == cancelling]
    return max(abs(x[k] - y[k]) / max(1.0, abs(x[k]), abs(y[k])) for k in keys)


def overhead(ex) -> float:
    """Seconds per no-op member through the executor ``ex`` (after one warm-up batch)."""
    items = list(range(NOOP_TASKS))
    names = [f"noop {k}" for k in items]
    ex.map(operator.neg, items[:4], names[:4])
    t0 = time.perf_counter()
    ex.map(operator.neg, items, names)
    return (time.perf_counter() - t0) / NOOP_TASKS


def batch_seconds(report: dict) -> float:
    (batch,) = report["compute"]["batches"]
    return batch["seconds"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=os.path.join("results", "scale_out"))
    benchmark_doc.add_flag(parser)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    from distributed import LocalCluster
    rows = []
    with tempfile.TemporaryDirectory() as tmp, LocalCluster(
            n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None) as cluster:
        path = os.path.join(tmp, "scale_out.toml")
        with open(path, "w") as fh:
            fh.write(SCENE.format(loads=", ".join(f"{p:.6g}" for p in LOADS)))
        configs = [("1 worker", ("--workers", "1"), 1), ("serial 2 threads", ("--workers", "1"), None),
                   ("local 2", ("--workers", "2"), None), ("dask 2", ("--scheduler", cluster.scheduler_address), None)]
        base: list[tuple[float, dict]] = []
        for repeat in range(REPEATS):
            for name, flags, threads in configs:
                wall, report = run(path, os.path.join(tmp, f"{name}_{repeat}".replace(" ", "_")), *flags,
                                   threads=threads)
                if name == "1 worker":
                    base.append((wall, report))
                ref_wall, ref = base[repeat]
                label = name if name != "dask 2" else ("dask cold" if repeat == 0 else "dask warm")
                rows.append(dict(run=label, repeat=repeat, workers=report["compute"]["workers"],
                                 executor=report["compute"]["executor"], wall=wall, batch=batch_seconds(report),
                                 speedup=ref_wall / wall, batch_speedup=batch_seconds(ref) / batch_seconds(report),
                                 max_rel_diff=difference(base[0][1], report, False),
                                 effective_stiffness_rel_diff=difference(base[0][1], report, True)))
                print(f"{label:>10} (repeat {repeat}): {wall:6.2f} s, batch {rows[-1]['batch']:6.2f} s, "
                      f"speedup {rows[-1]['speedup']:.2f} (batch {rows[-1]['batch_speedup']:.2f})", flush=True)
            # the machine's ceiling: two independent one-thread runs at once do twice the work; their
            # throughput over one run's is what any two workers can reach on this machine
            wall, pair = run_pair(path, tuple(os.path.join(tmp, f"pair_{repeat}_{k}") for k in "ab"))
            ref_wall, ref = base[repeat]
            slowest = max(batch_seconds(r) for r in pair)
            rows.append(dict(run="2 runs at once", repeat=repeat, workers=1, executor="serial", wall=wall,
                             batch=slowest, speedup=2 * ref_wall / wall,
                             batch_speedup=2 * batch_seconds(ref) / slowest,
                             max_rel_diff=max(difference(base[0][1], r, False) for r in pair),
                             effective_stiffness_rel_diff=max(difference(base[0][1], r, True) for r in pair)))
            print(f"2 runs at once (repeat {repeat}): {wall:6.2f} s, batch {slowest:6.2f} s, throughput "
                  f"{rows[-1]['speedup']:.2f} (batch {rows[-1]['batch_speedup']:.2f})", flush=True)
        per_solve = batch_seconds(base[0][1]) / len(LOADS)
        with executor.use(executor.Serial()) as serial:
            over = {"serial": overhead(serial)}
        one = executor.LocalPool(1)
        over["local"] = overhead(one)
        one.close()
        with LocalCluster(n_workers=1, processes=True, threads_per_worker=1, dashboard_address=None) as c1:
            dask1 = executor.DaskCluster(c1.scheduler_address)
            over["dask"] = overhead(dask1)
            dask1.close()
    for r in rows:
        r["overhead_per_task"] = over[r["executor"]]
        r["overhead_percent_of_solve"] = 100 * r["overhead_per_task"] / per_solve
    write(args.out, rows, per_solve)
    if args.publish:
        benchmark_doc.publish("scale_out", "Scale-out of a batch of independent cell solves",
                              os.path.join(args.out, "scale_out.csv"),
                              note=f"16 independent solves of a 2D sinusoidal cell ({per_solve:.3g} s each on one "
                                   "thread) run as `ngcontact run`: one worker on one thread (the reference), the "
                                   "serial executor on every core, a local pool of two workers, a Dask cluster of "
                                   "two, and two one-thread runs at once (the machine's ceiling). `wall`, `batch` "
                                   "in seconds; speedups over the one-thread run of the same repeat; the "
                                   "scheduler's overhead per task.",
                              png=os.path.join(args.out, "scale_out.png"))


def write(out: str, rows: list[dict], per_solve: float) -> None:
    keys = ["run", "repeat", "executor", "workers", "wall", "batch", "speedup", "batch_speedup", "max_rel_diff",
            "effective_stiffness_rel_diff", "overhead_per_task", "overhead_percent_of_solve"]
    with open(os.path.join(out, "scale_out.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow([r[k] for k in keys])
    for r in rows:
        print(f"{r['run']:>10} #{r['repeat']}: command {r['wall']:6.2f} s (x{r['speedup']:.2f}), batch "
              f"{r['batch']:6.2f} s (x{r['batch_speedup']:.2f}), max rel diff {r['max_rel_diff']:.1e}, "
              f"effective stiffness {r['effective_stiffness_rel_diff']:.1e}, overhead "
              f"{1e3 * r['overhead_per_task']:.2f} ms/task = {r['overhead_percent_of_solve']:.2f} % of a solve")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    names = [f"{r['run']} #{r['repeat']}" for r in rows]
    x = np.arange(len(rows))
    colors = {"serial": "C0", "local": "C1", "dask": "C2"}
    ax[0].bar(x - 0.2, [r["wall"] for r in rows], 0.4, color=[colors[r["executor"]] for r in rows],
              label="whole command")
    ax[0].bar(x + 0.2, [r["batch"] for r in rows], 0.4, color=[colors[r["executor"]] for r in rows], alpha=0.5,
              hatch="//", label="batch of 16 solves")
    for i, r in enumerate(rows):
        ax[0].text(i + 0.2, r["batch"], f"x{r['batch_speedup']:.2f}", ha="center", va="bottom", fontsize=7)
    ax[0].set_xticks(x, names, rotation=30, ha="right", fontsize=8)
    ax[0].set_ylabel("wall time [s]")
    ax[0].set_title(f"16 independent cell solves ({per_solve:.2f} s each on one thread); batch speedup over "
                    "one worker", fontsize=8)
    ax[0].legend(fontsize=8)
    execs = ["serial", "local", "dask"]
    per = {r["executor"]: r["overhead_percent_of_solve"] for r in rows}
    ax[1].bar(execs, [per[e] for e in execs], color=[colors[e] for e in execs])
    ax[1].axhline(5.0, color="k", ls=":", label="5 % of a solve")
    ax[1].set_yscale("log")
    ax[1].set_ylabel("scheduler overhead per task [% of one cell solve]")
    ax[1].legend(fontsize=8)
    fig.suptitle("scale-out on a 2-core machine (wall times: re-measure on a quiet machine)", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "scale_out.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
