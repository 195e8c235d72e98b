"""CPU seconds of one ensemble member wherever it runs: the run's own process, a local worker, a Dask worker.

The member: one realization of ``scripts/ensemble_executors.py``'s 256 x 256
ensemble (``ngcontact.drivers.run_ensemble.realization``, three loads and
the accuracy estimate), the batch on which the speed issue compares the
executors.  Each configuration runs in a fresh interpreter of its own
(glibc reads its heap variables as a process starts), solves one member to
warm up (imports, FFT plans), then ``MEMBERS`` members, each timed where it
runs; the configurations take turns, ``ROUNDS`` times (the machine's other
jobs change meanwhile).  Per member:

* ``cpu``: the CPU seconds of the whole process that runs it (every thread:
  a Dask worker's event loop and heartbeats count), ``thread``: of the
  thread that solves it, ``faults``: the process's minor page faults (a
  buffer mapped and zero-filled afresh), ``threads``: its OS threads;

reported as the median over the members with the quartiles (the machine is
shared: CPU time is far less disturbed by other jobs than wall time, which
is not reported), and ``cpu / run``: the median over the median of the run's
own process.  Configurations:

* ``run``: the run's process as ``ngcontact run --workers 1`` solves a
  member (``ngcontact.runner.threads`` with the threads of the run), from a
  shell's environment;
* ``run, 1 thread``: the same with ``NGCONTACT_THREADS=1`` (a worker's
  threads: no task manager);
* ``run, nanny env``: the same as ``run`` with the variables Dask's nanny leaks into a
  process that starts a ``LocalCluster`` (``MALLOC_TRIM_THRESHOLD_=65536``,
  BLAS and OpenMP on one thread): what a run started by such a process
  inherits (``ngcontact.parallel.heap_thresholds``);
* ``local worker``: a spawned process started as a local pool's worker
  (``ngcontact.parallel.batch_member.one_thread``);
* ``forked worker``: a local pool's worker as the pool starts it by
  default, forked by a fork server that imported NGSolve and the
  package (``ngcontact.parallel.fork_server``);
* ``dask worker``: a one-thread worker of a ``distributed.LocalCluster``,
  started as a member's task starts it (``one_thread``);
* ``dask worker, bare``: the same worker without that start (Dask's
  environment as it is): what the start changes.

Also ``item_bytes`` and ``result_bytes``: the member's item and result
pickled (what travels to and from a worker).  Writes ``member_cpu.csv`` and
``member_cpu.png``::

    MPLBACKEND=Agg python scripts/member_cpu.py results/member_cpu
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import pickle
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

MEMBERS, ROUNDS = 6, 3
NANNY_ENV = {"MALLOC_TRIM_THRESHOLD_": "65536", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
             "OPENBLAS_NUM_THREADS": "1"}
CONFIGS = ("run", "run, 1 thread", "run, nanny env", "local worker", "forked worker", "dask worker",
           "dask worker, bare")


def timed(job) -> dict:
    """One member solved in this process, timed here."""
    from ngcontact.drivers.run_ensemble import realization
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    cpu, thread = time.process_time(), time.thread_time()
    result = realization(job)
    cpu, thread = time.process_time() - cpu, time.thread_time() - thread
    with open("/proc/self/status") as fh:
        threads = int(next(line for line in fh if line.startswith("Threads:")).split()[1])
    return dict(cpu=cpu, thread=thread, faults=resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults,
                threads=threads, result_bytes=len(pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)))


def in_worker_task(job, start: bool) -> dict:
    """A Dask task: the worker started as a member's task starts it (``start``), then the member timed."""
    from ngcontact.parallel import batch_member
    if start and not batch_member.in_worker():
        batch_member.one_thread(ignore_sigint=False)
    return timed(job)


def measure(config: str) -> list[dict]:
    """Every member's timing in ``config`` (this process is that configuration's fresh interpreter)."""
    from ensemble_executors import large
    from ngcontact.scene import loader
    with tempfile.TemporaryDirectory() as tmp:
        scene = loader.load(large(tmp))
    jobs = [(scene, m) for m in range(MEMBERS)]
    item = len(pickle.dumps(jobs[0], protocol=pickle.HIGHEST_PROTOCOL))
    if config.startswith("run"):
        from ngcontact import runner
        with runner.threads(runner.thread_count()):
            timed(jobs[0])
            rows = [timed(job) for job in jobs]
    elif config == "local worker":
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor
        from ngcontact.parallel.batch_member import one_thread
        with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"), initializer=one_thread,
                                 initargs=(True,)) as pool:
            pool.submit(timed, jobs[0]).result()
            rows = [pool.submit(timed, job).result() for job in jobs]
    elif config == "forked worker":
        from ngcontact.parallel.local_pool import LocalPool
        pool = LocalPool(1, method="forkserver")
        try:
            pool.start(("ngsolve", "ngcontact.drivers.build", "ngcontact.drivers.run_ensemble"))
            pool.wait_ready()
            pool._pool_map(timed, jobs[:1], ["warm"], "warm", None, None)
            rows = pool._pool_map(timed, jobs, [f"m{k}" for k in range(len(jobs))], "members", None, None)
        finally:
            pool.close()
    else:
        from distributed import Client, LocalCluster
        start = config == "dask worker"
        with LocalCluster(n_workers=1, processes=True, threads_per_worker=1, dashboard_address=None) as cluster, \
                Client(cluster) as client:
            client.submit(in_worker_task, jobs[0], start, pure=False).result()
            rows = [client.submit(in_worker_task, job, start, pure=False).result() for job in jobs]
    return [dict(row, item_bytes=item) for row in rows]


def summary(config: str, rows: list[dict], reference: float | None) -> dict:
    """The median and quartiles of a configuration's members."""
    q = {k: np.percentile([r[k] for r in rows], [25, 50, 75]) for k in ("cpu", "thread", "faults")}
    cpu = float(q["cpu"][1])
    return dict(where=config, members=len(rows), cpu=cpu, cpu_q1=float(q["cpu"][0]), cpu_q3=float(q["cpu"][2]),
                thread=float(q["thread"][1]), cpu_over_run=cpu / (reference or cpu), faults=float(q["faults"][1]),
                threads=int(np.median([r["threads"] for r in rows])), item_bytes=rows[0]["item_bytes"],
                result_bytes=int(np.median([r["result_bytes"] for r in rows])))


def run_config(config: str) -> list[dict]:
    """``config`` measured in a fresh interpreter with its environment (the shell's, or the nanny's leak)."""
    env = {k: v for k, v in os.environ.items() if k not in NANNY_ENV}
    if config == "run, nanny env":
        env.update(NANNY_ENV)
    if config == "run, 1 thread":
        env["NGCONTACT_THREADS"] = "1"
    with tempfile.NamedTemporaryFile(suffix=".json") as out:
        subprocess.run([sys.executable, os.path.abspath(__file__), "--config", config, "--json", out.name],
                       env=env, check=True, stderr=subprocess.DEVNULL)
        with open(out.name) as fh:
            return json.load(fh)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=os.path.join("results", "member_cpu"))
    parser.add_argument("--config", choices=CONFIGS, help=argparse.SUPPRESS)
    parser.add_argument("--json", help=argparse.SUPPRESS)
    benchmark_doc.add_flag(parser)
    args = parser.parse_args()
    if args.config:                                   # one configuration, in this fresh interpreter
        with open(args.json, "w") as fh:
            json.dump(measure(args.config), fh)
        return
    os.makedirs(args.out, exist_ok=True)
    load = os.getloadavg()[0]
    timings: dict[str, list[dict]] = {config: [] for config in CONFIGS}
    for _ in range(ROUNDS):                # the configurations in turn: the machine's other jobs drift
        for config in CONFIGS:
            timings[config] += run_config(config)
    rows: list[dict] = []
    for config in CONFIGS:
        rows.append(summary(config, timings[config], rows[0]["cpu"] if rows else None))
        r = rows[-1]
        print(f"{config:>18}: cpu {r['cpu']:.3f} s [{r['cpu_q1']:.3f}, {r['cpu_q3']:.3f}] (x{r['cpu_over_run']:.2f}), "
              f"thread {r['thread']:.3f} s, {r['faults']:.0f} faults, {r['threads']} threads, "
              f"item {r['item_bytes']} B, result {r['result_bytes']} B", flush=True)
    path = write(args.out, rows)
    if args.publish:
        benchmark_doc.publish(
            "member_cpu", "CPU of one ensemble member on each executor", path,
            note=f"One member of the 256 x 256 ensemble of section `ensemble_executors`: {MEMBERS} members "
                 f"after one to warm up, in a fresh interpreter per configuration, the configurations in turn "
                 f"{ROUNDS} times (`where`: the run's own process from a shell's environment, on one thread, and "
                 "with the "
                 "variables Dask's nanny leaks into a process that starts a cluster; a spawned local worker; a "
                 "worker forked by the local pool's fork server; a "
                 "Dask worker as a member's task starts it, and without that start). `cpu`: CPU seconds of the "
                 "whole process per member, median with its quartiles `cpu_q1`, `cpu_q3`; `thread`: of the "
                 "solving thread; `cpu_over_run`: over the run's own process; `faults`: minor page faults per "
                 "member; `threads`: the process's OS threads; `item_bytes`, `result_bytes`: pickled. CPU time, "
                 f"not wall time: the machine is shared (load average {load:.1f} as the benchmark began).",
            png=os.path.join(args.out, "member_cpu.png"))


def write(out: str, rows: list[dict]) -> str:
    keys = list(rows[0])
    path = os.path.join(out, "member_cpu.csv")
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow([r[k] for k in keys])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.5))
    med = np.array([r["cpu"] for r in rows])
    err = np.array([[r["cpu"] - r["cpu_q1"] for r in rows], [r["cpu_q3"] - r["cpu"] for r in rows]])
    ax.bar(range(len(rows)), med, yerr=err, capsize=4, color="tab:blue")
    ax.set_xticks(range(len(rows)), [r["where"] for r in rows], fontsize=8)
    ax.set_ylabel("CPU seconds per member (median, quartiles)")
    ax.set_title("one 256^2 ensemble member: CPU where it runs", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "member_cpu.png"), dpi=120)
    plt.close(fig)
    return path


if __name__ == "__main__":
    main()
