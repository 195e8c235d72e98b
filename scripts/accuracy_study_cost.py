"""What the accuracy study of a scene costs beside one run of the scene, and what it finds.

Runs ``ngcontact run SCENE`` into ``OUT/run_before``, ``ngcontact study accuracy SCENE`` into ``OUT/study``
and ``ngcontact run SCENE`` again into ``OUT/run`` (each as a user runs it, in a process of its own, timed
from start to exit; the single run is the faster of the two that bracket the study, so that a load that
rises or falls on a shared machine while the study runs does not shrink the ratio), and writes
``OUT/accuracy_study_cost.csv``: per level of the study its knob, setting, wall time, unknowns and the error
of each headline quantity against its knob's finest level (``ngcontact.drivers.study_accuracy``), each
knob's observed rates, then a row with the whole study's wall time and one with the single run's.  Issue 35
aims at a study of the femur with at least four levels, the errors of peak pressure and safety factor
falling at a stated rate, in less than 20 times one solve: :func:`verdict` says of each whether it holds.

    python scripts/accuracy_study_cost.py [SCENE] [--out OUT] [--levels N] [--figure QUANTITY] [--publish]

Default scene ``geometries/femur_stem.toml``; ``--figure`` names the quantity whose work-precision plot
the published section shows (default: the first).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.output.writer import write_csv  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: issue 35's aims for the femur's study: levels per knob, the quantities whose errors fall, runs of the scene
AIM_LEVELS, AIM_QUANTITIES, AIM_RUNS = 4, ("peak_pressure", "safety_factor"), 20.0


def timed(args: list[str]) -> float:
    """Wall time of ``python -m ngcontact ARGS`` (which must succeed)."""
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "ngcontact", *args, "--quiet"], check=True)
    return time.perf_counter() - t0


def rows(results: dict, study_seconds: float, run_seconds: float) -> tuple[list[str], list[list]]:
    """The table: one row per level, then the whole study and the single run."""
    names = list(dict.fromkeys(n for lv in results["levels"] for n in (lv.get("quantities") or {})))
    header = ["knob", "setting", "role", "seconds", "ndof"] + [f"error_{n}" for n in names]
    out = []
    for lv in results["levels"]:
        role = "reference" if lv["reference"] else ("scene" if lv["own_scene"] else "")
        qs = lv.get("quantities") or {}
        out.append([lv["knob"], lv["setting"].replace("discretization.", ""), role or "-",
                    lv.get("seconds", ""), lv.get("ndof", "")]
                   + [(qs.get(n) or {}).get("error", "") for n in names])
    for knob, fit in results["rates"].items():
        out.append([knob, f"rate in {fit['variable']}", "rate", "", ""]
                   + [fit["rates"].get(n) if fit["rates"].get(n) is not None else "" for n in names])
    blank = [""] * len(names)
    out.append(["whole study", f"{results['distinct_runs']} runs", "wall", study_seconds, ""] + blank)
    out.append(["one run", "the scene, the faster of two", "wall", run_seconds, ""] + blank)
    return header, out


def falling(results: dict, name: str, knob: str) -> str:
    """A quantity's errors along one knob (its levels below the reference, coarsest first), whether each is
    below the one before, and the knob's observed rate."""
    errors = [lv["quantities"][name]["error"] for lv in results["levels"]
              if lv["knob"] == knob and not lv["reference"] and name in (lv.get("quantities") or {})]
    fit = results["rates"].get(knob, {})
    rate = fit.get("rates", {}).get(name)
    trend = "falling" if all(b < a for a, b in zip(errors, errors[1:])) else "not falling at every level"
    stated = f"rate {rate:.3g} in {fit['variable']}" if rate is not None else "no rate (round-off)"
    return f"{knob} {', '.join(f'{e:.2g}' for e in errors)} ({trend}; {stated})"


def verdict(results: dict, study_seconds: float, run_seconds: float) -> str:
    """One sentence per aim of issue 35 (:data:`AIM_LEVELS`, :data:`AIM_QUANTITIES`, :data:`AIM_RUNS`), each
    saying what was measured and whether it holds; quantities the scene does not report are left out."""
    knobs = list(dict.fromkeys(lv["knob"] for lv in results["levels"]))
    counts = {k: sum(lv["knob"] == k for lv in results["levels"]) for k in knobs}
    parts = [f"Levels per knob (aim: at least {AIM_LEVELS}): "
             + ", ".join(f"{k} {n}" for k, n in counts.items())
             + (": met." if min(counts.values(), default=0) >= AIM_LEVELS else ": not met.")]
    for name in AIM_QUANTITIES:
        if any(name in (lv.get("quantities") or {}) for lv in results["levels"]):
            parts.append(f"Errors of {name}: " + "; ".join(falling(results, name, k) for k in knobs) + ".")
    runs = study_seconds / run_seconds
    parts.append(f"Cost: the study {study_seconds:.4g} s against one run's {run_seconds:.4g} s, {runs:.3g} runs "
                 f"(aim: fewer than {AIM_RUNS:g}): {'met' if runs < AIM_RUNS else 'not met'}.")
    return " ".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?", default=os.path.join(ROOT, "geometries", "femur_stem.toml"))
    ap.add_argument("--out", default=os.path.join("results", "accuracy_study_cost"))
    ap.add_argument("--levels", type=int, default=4)
    ap.add_argument("--figure", help="the quantity whose plot is published (default: the first)")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    study_dir, run_dir = os.path.join(args.out, "study"), os.path.join(args.out, "run")
    before = timed(["run", args.scene, "--out", os.path.join(args.out, "run_before")])
    study_seconds = timed(["study", "accuracy", args.scene, "--out", study_dir, "--levels", str(args.levels)])
    run_seconds = min(before, timed(["run", args.scene, "--out", run_dir]))
    with open(os.path.join(study_dir, "report.json")) as fh:
        results = json.load(fh)["results"]
    header, table = rows(results, study_seconds, run_seconds)
    csv_path = os.path.join(args.out, "accuracy_study_cost.csv")
    write_csv(csv_path, header, table)
    summary = verdict(results, study_seconds, run_seconds)
    print(summary)
    if args.publish:
        figure = args.figure or header[5][len("error_"):]
        stem = os.path.splitext(os.path.basename(args.scene))[0]
        benchmark_doc.publish(f"accuracy_study_{stem}", f"Accuracy study of `{stem}`: errors, rates and cost",
                              csv_path, png=os.path.join(study_dir, f"accuracy_{figure}.png"),
                              note="`ngcontact study accuracy` on the scene (default 4 levels per knob, from "
                              "coarser ones through the scene's own, `scene`, to the finest, `reference`: two "
                              "coarser and one finer where the knob's range allows; an order ladder starts at "
                              "the lowest admissible order, so it may hold more finer levels), and `ngcontact run` of "
                              "the scene alone before and after it, each timed from start to exit on the same "
                              "machine (`one run`: the faster of the two; `seconds` of a level: its own run inside "
                              "the study's batch). Errors are against "
                              "the finest level of each knob (relative; 0 for that level); the rows `rate` give "
                              "each knob's observed rate (the slope of log error against log x over the other "
                              "levels; empty where the error sits at round-off). Issue 35 aims at at least four "
                              "levels, errors of peak pressure and safety factor falling at a stated rate, and "
                              "less than 20 runs of the scene for the whole study. " + summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
