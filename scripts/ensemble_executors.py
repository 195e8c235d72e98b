"""Ensembles of a random surface on each executor: serial, a local pool of two workers, a Dask cluster of two.

Three batches, each run as the command a user types (``ngcontact run SCENE
--out DIR --quiet`` plus the executor's flag, in a fresh interpreter):

* the shipped ``geometries/cells/self_affine_ensemble.toml`` (32 members on
  a 64 x 64 grid: a batch of about two seconds, too small to repay two
  workers' start);
* the same class on a 256 x 256 grid, 16 members (seconds per member);
* the shipped ``geometries/cells/measured_scan_ensemble.toml``.

Executors: ``--workers 1`` (serial, the reference), ``--workers 2`` (a local
pool, its workers forked by a fork server that imports NGSolve and the
package once, ``ngcontact.parallel.fork_server``: a batch goes to its
workers only where its rest repays them, column ``ran``) twice: ``local 2 first``, the run of a machine that has not run
the batch before (its workers start, if ever, once the batch's first
members have shown that they repay), and ``local 2``, after the serial run
of the same repeat has recorded the batch (its workers start with the run
where that record forecasts that the batch goes to them:
``ngcontact.parallel.batch_forecast``; column ``started``); and
``--scheduler`` on a ``distributed.LocalCluster``
of two one-thread worker processes that this script starts once (the runs
get the environment this script was started with, not the variables Dask's
nanny leaks into the process that starts a cluster) and warms
with one run of each scene (a cluster outlives the runs it serves, and the
run's record of the cluster's costs, ``ngcontact.parallel.dask_payoff``, with
it: the warming run writes it where the runs after it read it; a batch
goes to it only where its rest repays the members' trips,
``ngcontact.parallel.dask_payoff``, column ``ran``); last, ``serial again``,
the serial run once more: its ratio to the first is what the machine's noise
alone makes of two identical runs.  Per
run: the one-minute load average as it began (the machine is shared; a
local pool keeps a batch in the run's process while other jobs keep the
cores busy), the command's wall time, the batch's wall time (``compute.batches``),
both over the serial run's of the same repeat, and the largest relative
difference of the members' contact fractions from the serial run; per
ensemble and executor, the medians over the ``REPEATS`` repeats (the
machine is shared: a single repeat's ratio carries the other jobs' noise), and their lowest and
highest (of ``serial again``: the band of identical runs, beside which the
executors' lowest ratios are read).  The aims
(the speed issue): no executor slower than serial on any shipped batch,
two local workers at least 1.6x serial on the 256^2 ensemble, Dask within
1.2x of the local pool; they are judged on the raw ratios, the band only
says how much of a shortfall the machine's noise can explain.  The records live in a temporary cache directory
(``NGCONTACT_CACHE``), an empty one for each ``local 2 first`` run.  Each
run's batch decision (where it went, and the payoff rule's inputs: ``c``,
``R``, ``F``, ``S``, the free cores and how they were read) goes to
``decisions.txt`` beside the CSV; ``--repeats`` and ``--only`` make a
shorter run (never published).

    MPLBACKEND=Agg python scripts/ensemble_executors.py results/ensemble_executors --publish
"""
from __future__ import annotations

import argparse
import csv
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)
from scale_out import run  # noqa: E402  (a scene run as a user types it: wall seconds and report)

ROOT = benchmark_doc.ROOT
SHIPPED = os.path.join(ROOT, "geometries", "cells", "self_affine_ensemble.toml")
MEASURED = os.path.join(ROOT, "geometries", "cells", "measured_scan_ensemble.toml")
REPEATS = 5
ENSEMBLES = ("shipped 64^2 x 32", "256^2 x 16", "measured scan")


def large(tmp: str) -> str:
    """The shipped ensemble's surface class on a 256 x 256 grid with 16 members (a scene file in ``tmp``)."""
    with open(SHIPPED) as fh:
        text = fh.read()
    text = text.replace("grid = 64,", "grid = 256,").replace("members = 32", "members = 16")
    assert "grid = 256," in text and "members = 16" in text, "the shipped ensemble's text changed"
    path = os.path.join(tmp, "self_affine_ensemble_256.toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


def batch_seconds(report: dict) -> float:
    return sum(b["seconds"] for b in report["compute"]["batches"])


def ran(report: dict) -> str:
    """Where the batch ran: ``serial`` (the run's process, also a local pool's batch too small to repay its
    workers), ``local`` or ``dask`` (``compute.batches[].executor``, else the run's executor)."""
    batch = report["compute"]["batches"][0]
    return batch.get("executor", report["compute"]["executor"])


def started(report: dict) -> str:
    """When a local pool's workers started (``compute.workers_started``); empty for other executors."""
    return report["compute"].get("workers_started", "")


def fractions(report: dict) -> np.ndarray:
    """Every member's contact fraction at every load (the ensemble's members, in order)."""
    return np.array([[load["contact_fraction"] for load in loads] for loads in report["results"]["members"]],
                    dtype=float)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default=os.path.join("results", "ensemble_executors"))
    parser.add_argument("--repeats", type=int, default=REPEATS, help=f"repeats per ensemble (default {REPEATS})")
    parser.add_argument("--only", choices=ENSEMBLES, action="append",
                        help="only this ensemble (repeatable; default: all three)")
    benchmark_doc.add_flag(parser)
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats = {args.repeats}: must be >= 1")
    if args.publish and (args.repeats != REPEATS or args.only):
        parser.error("--publish: only the whole benchmark (every ensemble, the default --repeats)")
    os.makedirs(args.out, exist_ok=True)
    from distributed import LocalCluster
    rows: list[dict] = []
    decisions: list[str] = []        # each run's batch: where it went and the payoff rule's inputs
    shell = dict(os.environ)
    with tempfile.TemporaryDirectory() as tmp, LocalCluster(
            n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None) as cluster:
        os.environ.clear()              # the nanny's variables leak into this process: the runs get the shell's
        os.environ.update(shell)
        scenes = dict(zip(ENSEMBLES, (SHIPPED, large(tmp), MEASURED)))
        scenes = {name: scene for name, scene in scenes.items() if not args.only or name in args.only}
        dask = ("--scheduler", cluster.scheduler_address)
        records = os.path.join(tmp, "cache")
        for name, scene in scenes.items():
            os.environ["NGCONTACT_CACHE"] = records      # as in the runs after it (also the first ensemble's)
            run(scene, os.path.join(tmp, f"warm_{len(rows)}"), *dask)      # the cluster imports the package
            for repeat in range(args.repeats):
                ref: tuple[float, dict] | None = None
                for executor, flags in (("serial", ("--workers", "1")), ("local 2 first", ("--workers", "2")),
                                        ("local 2", ("--workers", "2")), ("dask 2", dask),
                                        ("serial again", ("--workers", "1"))):
                    load = os.getloadavg()[0]            # the machine's other jobs as the run begins
                    fresh = os.path.join(tmp, f"empty_{len(rows)}")
                    os.environ["NGCONTACT_CACHE"] = fresh if executor == "local 2 first" else records
                    wall, report = run(scene, os.path.join(tmp, f"{len(rows)}"), *flags)
                    ref = ref or (wall, report)
                    diff = np.max(np.abs(fractions(report) - fractions(ref[1])) / np.abs(fractions(ref[1])))
                    rows.append(dict(ensemble=name, executor=executor, repeat=repeat,
                                     members=report["results"]["ensemble"]["members"], load=load,
                                     ran=ran(report),
                                     started=started(report), wall=wall,
                                     batch=batch_seconds(report), speedup=ref[0] / wall,
                                     batch_speedup=batch_seconds(ref[1]) / batch_seconds(report),
                                     max_rel_diff=float(diff)))
                    r = rows[-1]
                    print(f"{name:>18} {executor:>13} #{repeat} (load {load:.1f}): {wall:6.2f} s "
                          f"(x{r['speedup']:.2f}), batch "
                          f"{r['batch']:6.2f} s (x{r['batch_speedup']:.2f}), {r['ran']}, {r['started']}, "
                          f"diff {diff:.1e}", flush=True)
                    decisions.append(f"{name} | {executor} | #{repeat} | load {load:.2f} | "
                                     f"{report['compute']['batches'][0].get('decision', '')}")
    loads = [r["load"] for r in rows]
    rows += medians(rows)
    write(args.out, rows)
    for line in bands(rows):
        print(line)
    with open(os.path.join(args.out, "decisions.txt"), "w") as fh:
        fh.write("\n".join(decisions) + "\n")
    print(f"load average as the runs began: {min(loads):.1f} to {max(loads):.1f}, median {np.median(loads):.1f}")
    if args.publish:
        benchmark_doc.publish(
            "ensemble_executors", "Ensembles on each executor",
            os.path.join(args.out, "ensemble_executors.csv"),
            note="`ngcontact run` of three ensembles with `--workers 1` (serial, the reference: its FFTs on one "
                 "thread on these grids of at most 256^2 points, as a worker's, "
                 "`ngcontact.cell.spectral.fft_threads`), `--workers 2` (workers forked by a fork server that "
                 "imports NGSolve and the package once, `ngcontact.parallel.fork_server`) "
                 "twice (`local 2 first`: no record of the batch, its workers start only once its first members "
                 "have shown that they repay; `local 2`: after the serial run has recorded the batch, its "
                 "workers start with the run where the record forecasts that the batch goes to them, "
                 "`ngcontact.parallel.batch_forecast`; `started`: when the workers started) "
                 "and `--scheduler` on a local Dask cluster of two one-thread workers (warmed by one run, which also "
                 "fills the record of its costs that the Dask runs read). "
                 "`ran`: where the batch ran (a local pool sends a batch to its workers only where its rest "
                 "repays them, `ngcontact.parallel.worker_payoff`, a Dask cluster only where it repays the "
                 "members' trips, `ngcontact.parallel.dask_payoff`; else `serial`, in the run's process). "
                 "`load`: the one-minute load average as the run began (2 cores; over the whole benchmark "
                 f"{min(loads):.1f} to {max(loads):.1f}, median {np.median(loads):.1f}): the payoff rule "
                 "keeps a batch in the run's process while other jobs keep the cores busy "
                 "(`ngcontact.parallel.free_cores`), so under load `local 2` is the serial run by design. "
                 "`wall` and `batch` in seconds; speedups over the serial run of the same repeat; "
                 "`max_rel_diff`: the members' contact fractions against the serial run. Timed on a machine "
                 f"shared with other jobs (load average above): the ratios within one repeat are what counts, "
                 f"and the `median` rows (over the {REPEATS} repeats; `ran`, `started`: every value seen) "
                 "are the figures; the bar chart shows them. `serial again`: the serial run once more at the end "
                 "of each repeat, its ratios over the first serial run those of two identical runs; "
                 "`speedup_lo` to `speedup_hi` and `batch_lo` to `batch_hi` of the median rows: the lowest and "
                 "highest ratio over the repeats, of `serial again` the band within which the machine's noise "
                 "alone moves a ratio. The aims stand on the raw ratios (no executor's run or batch below 1x "
                 "on any shipped batch, `local 2` at least 1.6x on the 256^2 ensemble, `dask 2` within 1.2x of "
                 "`local 2`); a ratio below 1x is read beside the band of its ensemble, which says how much of "
                 "it the noise of identical runs can explain, not that it is met. Per ensemble: "
                 + "; ".join(bands(rows)) + ".",
            png=os.path.join(args.out, "ensemble_executors.png"))


def medians(rows: list[dict]) -> list[dict]:
    """One row per ensemble and executor (``repeat = median``): the median over the repeats of each time and
    speedup (the machine is shared: one repeat's ratio may be another job's noise), the lowest and highest
    speedups of the repeats (``speedup_lo`` ... ``batch_hi``; of ``serial again``, the band in which identical
    serial runs scatter), the largest difference."""
    out = []
    for name in dict.fromkeys(r["ensemble"] for r in rows):
        for ex in dict.fromkeys(r["executor"] for r in rows):
            sel = [r for r in rows if r["ensemble"] == name and r["executor"] == ex]
            if not sel:
                continue
            med = {k: float(np.median([r[k] for r in sel]))
                   for k in ("load", "wall", "batch", "speedup", "batch_speedup")}
            spread = {f"{k}_{end}": float(f([r[key] for r in sel]))
                      for k, key in (("speedup", "speedup"), ("batch", "batch_speedup"))
                      for end, f in (("lo", min), ("hi", max))}
            out.append(dict(ensemble=name, executor=ex, repeat="median", members=sel[0]["members"],
                            ran="/".join(dict.fromkeys(r["ran"] for r in sel)),
                            started="/".join(dict.fromkeys(r["started"] for r in sel)), **med, **spread,
                            max_rel_diff=max(r["max_rel_diff"] for r in sel)))
    return out


def bands(rows: list[dict]) -> list[str]:
    """Per ensemble: the band of identical serial runs (``serial again`` over ``serial``, lowest to highest
    over the repeats) beside each executor's lowest and median ratio, the batch's and the whole run's."""
    lines = []
    for name in dict.fromkeys(r["ensemble"] for r in rows):
        med = {r["executor"]: r for r in rows if r["ensemble"] == name and r["repeat"] == "median"}
        if "serial again" not in med:
            continue
        band = med["serial again"]
        lines.append(f"{name}: identical serial runs batch x{band['batch_lo']:.2f}-{band['batch_hi']:.2f}, "
                     f"run x{band['speedup_lo']:.2f}-{band['speedup_hi']:.2f}; " + "; ".join(
                         f"{ex} batch x{r['batch_speedup']:.2f} (lowest {r['batch_lo']:.2f}), run "
                         f"x{r['speedup']:.2f} (lowest {r['speedup_lo']:.2f})"
                         for ex, r in med.items() if ex not in ("serial", "serial again")))
    return lines


def write(out: str, rows: list[dict]) -> None:
    keys = ["ensemble", "executor", "repeat", "members", "load", "ran", "started", "wall", "batch", "speedup",
            "batch_speedup", "speedup_lo", "speedup_hi", "batch_lo", "batch_hi", "max_rel_diff"]
    with open(os.path.join(out, "ensemble_executors.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(keys)
        for r in rows:
            w.writerow([r.get(k, "") for k in keys])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(dict.fromkeys(r["ensemble"] for r in rows))
    execs = ["serial", "local 2 first", "local 2", "dask 2", "serial again"]
    fig, ax = plt.subplots(figsize=(7.5, 4))
    width = 0.8 / len(execs)
    for j, ex in enumerate(execs):
        med = [next(r for r in rows if r["ensemble"] == n and r["executor"] == ex and r["repeat"] == "median")
               for n in names]
        heights = [r["speedup"] for r in med]
        ax.bar(np.arange(len(names)) + (j - (len(execs) - 1) / 2) * width, heights, width, label=ex,
               yerr=[[h - r["speedup_lo"] for h, r in zip(heights, med)],
                     [r["speedup_hi"] - h for h, r in zip(heights, med)]], capsize=2)
    ax.axhline(1.0, color="k", lw=0.8)
    ax.axhline(1.6, color="k", ls=":", lw=0.8, label="aim of 2 workers on 256^2")
    ax.set_xticks(np.arange(len(names)), names)
    ax.set_ylabel(f"whole-run speedup over serial (median, bars lowest to highest of {REPEATS})")
    ax.legend(fontsize=8)
    ax.set_title("ensembles on 2 cores: serial, local pool of 2, Dask cluster of 2", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "ensemble_executors.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
