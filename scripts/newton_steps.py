"""Newton steps per load of every shipped cell scene: the largest and the mean, against the aim of ten.

The aim of issue 12: the rigid predictor, the rigid continuation and the
coupled Coulomb Newton keep Newton at no more than ``AIM = 10`` steps per
load on every cell scene in ``geometries/cells/``.  Each scene is run
through the command line (``ngcontact run SCENE --out DIR``, one process
per scene, :func:`cell_scenes_benchmark.bench`), and the steps per load are
the report's ``results.loads[k].newton_iterations``: every tangent solve of
the load counted, the rigid continuation's, every Coulomb pass's or coupled
step's, and on graded meshes every level's.  Scenes whose loads report no
Newton steps (the spectral cells, which solve by FFT and CG, and purely
geometric scenes) are listed with their status and no steps.

The largest single Newton solve is listed beside them
(``max_per_solve``, from the report's ``solver.per_load``): one stage of a
load (the rigid continuation, a coupled Coulomb solve, an Uzawa pass's
Newton) or, on graded meshes, one level's solve.

Writes ``newton_steps.csv`` (scene, status, loads, steps per load, max,
mean, largest single solve, within the aim) and ``newton_steps.png`` (max and mean per scene,
the aim as a line) into the output directory (default
``results/newton_steps``) and prints the table.  Exit status 1 when a
scene fails to run; a scene over the aim is reported, not an error.

Usage::

    python scripts/newton_steps.py [OUT_DIR] [--scenes DIR] [--only NAME ...]
"""
from __future__ import annotations

import argparse
import csv
import glob
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from cell_scenes_benchmark import bench  # noqa: E402  (the sibling script runs one scene)
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

AIM = 10
KEYS = ("scene", "status", "loads", "newton_per_load", "max_newton", "mean_newton", "max_per_solve", "within_aim")


def row_of(path: str, out_root: str) -> dict:
    """One scene's run: steps per load, their maximum and mean (empty where no Newton step was taken)."""
    b = bench(path, out_root)
    steps = [int(s) for s in b["newton_per_load"].split()]
    newton = b["status"] == "ok" and any(steps)
    return {"scene": b["scene"], "status": b["status"], "loads": b["loads"],
            "newton_per_load": b["newton_per_load"],
            "max_newton": max(steps) if newton else "",
            "mean_newton": round(sum(steps) / len(steps), 2) if newton else "",
            "max_per_solve": b["max_per_solve"] if newton else "",
            "within_aim": (max(steps) <= AIM) if newton else ""}


def plot(rows: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    shown = [r for r in rows if r["max_newton"] != ""]
    x = range(len(shown))
    fig, ax = plt.subplots(figsize=(9, 4))
    ax.bar([i - 0.2 for i in x], [r["max_newton"] for r in shown], width=0.4, label="max per load")
    ax.bar([i + 0.2 for i in x], [r["mean_newton"] for r in shown], width=0.4, label="mean per load")
    ax.axhline(AIM, color="k", ls="--", lw=1, label=f"aim ({AIM})")
    ax.set_xticks(list(x))
    ax.set_xticklabels([r["scene"] for r in shown], rotation=45, ha="right")
    ax.set_ylabel("Newton steps per load")
    ax.set_title("Shipped cell scenes: Newton steps per load (predictor, passes counted)")
    ax.legend()
    fig.tight_layout()
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=120)
    plt.close(fig)
    os.replace(tmp, path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "newton_steps"))
    ap.add_argument("--scenes", default=os.path.join(HERE, "..", "geometries", "cells"))
    ap.add_argument("--only", nargs="*", default=None, help="scene names (without .toml) to run")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    paths = sorted(glob.glob(os.path.join(args.scenes, "*.toml")))
    if args.only:
        unknown = sorted(set(args.only) - {os.path.splitext(os.path.basename(p))[0] for p in paths})
        if unknown:
            sys.stderr.write(f"--only: no scene {', '.join(unknown)} in {args.scenes}\n")
            return 2
        paths = [p for p in paths if os.path.splitext(os.path.basename(p))[0] in args.only]
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for p in paths:
        rows.append(row_of(p, args.out))
        r = rows[-1]
        sys.stdout.write(f"{r['scene']:24s} {r['status'][:12]:12s} {r['loads']:5d} {str(r['max_newton']):>4s} "
                         f"{str(r['mean_newton']):>6s} {str(r['max_per_solve']):>4s}  {r['newton_per_load']}\n")
        sys.stdout.flush()
    csv_path = os.path.join(args.out, "newton_steps.csv")
    with open(csv_path + ".tmp", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(KEYS)
        w.writerows([[r[k] for k in KEYS] for r in rows])
    os.replace(csv_path + ".tmp", csv_path)
    plot(rows, os.path.join(args.out, "newton_steps.png"))
    over = [r["scene"] for r in rows if r["within_aim"] is False]
    sys.stdout.write(f"over the aim of {AIM}: {', '.join(over) if over else 'none'}\n")
    if args.publish:
        benchmark_doc.publish("newton_steps", f"Newton steps per load of the shipped cell scenes (aim: {AIM})",
                              csv_path,
                              note="Every tangent solve of a load counted (the rigid continuation's, every "
                                   "Coulomb pass's or coupled step's, every graded level's); `max_per_solve` is "
                                   "the largest single Newton solve. Spectral and purely geometric scenes take "
                                   "no Newton step.",
                              png=os.path.join(args.out, "newton_steps.png"))
    return 1 if any(r["status"] != "ok" for r in rows) else 0


if __name__ == "__main__":
    raise SystemExit(main())
