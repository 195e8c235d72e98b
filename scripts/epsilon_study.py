"""Epsilon study of a ``direct`` scene: resolved runs against the homogenized laws.

For each number of periods N (the scene's ``[study] periods`` or ``--periods``)
the resolved problem and the homogenized problems with the bundle, the linear
whole-surface and the effective-stiffness laws are solved and compared (see
:func:`ngcontact.runner.study_epsilon`).  Writes, atomically, ``DIR/report.json``
(``results.rows``, ``results.rates``, ``results.below_1_percent``),
``DIR/epsilon.csv`` and ``DIR/epsilon.png`` (error and cost against eps).

Usage: python scripts/epsilon_study.py SCENE [--periods 4 8 16 32] [--meshes 3] [--out DIR]
(runs ``ngcontact study epsilon SCENE`` and prints its table; ``--meshes 3`` solves each level on a third
discretization, ``study.meshes``)

Exit status as ``ngcontact run``: 0 success, 2 invalid scene or output
directory, 3 solver failure.
"""
from __future__ import annotations

import argparse
import json
import os
import sys

from ngcontact.cli import EXIT_OK
from ngcontact.cli import main as cli_main

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)


#: the corrector's columns of the bundle law (ngcontact.drivers.modelling_error)
CORRECTOR = ("l2", "l2_corrected", "h1", "h1_corrected", "probe_corrected")


#: what the errors and their estimates are, with two and with three discretizations per level
TWO = ("Each error is the modelling error on meshes refined by `study.refinement` r, `*_discretization` the estimate "
       "of its discretization error, 1.5 delta / (r - 1) from the change delta from the scene's meshes (an error "
       "at least linear in h, times 1.5: the rule of a resolved run's default estimate); `contact_fraction_resolved` "
       "the resolved run's, with its estimate by the same rule; seconds of the refined pair.")
THREE = ("Each level on three discretizations (`study.meshes = 3`: the scene's, refined once and twice by "
         "`study.refinement` r); each error is the modelling error on the finest, `*_discretization` the sum of the "
         "resolved and the homogenized solution's Richardson estimates 1.5 d2 q / (1 - q) of their discretization "
         "errors, from each solution's changes d1 (scene to once refined) and d2 (once to twice refined), "
         "`*_ratio_resolved` and `*_ratio_homogenized` the observed q = d2 / d1; where q < 1/r each term is the "
         "larger of that and d2 / (r - 1), the bound of an error linear in h (where q >= 1 that solution's "
         "term is 1.5 times its largest change over r - 1: {largest}); `contact_fraction_resolved` the resolved "
         "run's, with its estimate by the same rule; seconds of the finest pair.")


def largest_changes(results: dict) -> str:
    """The levels whose estimate is the largest change (the changes did not contract), per law and error."""
    listed = results["discretization"]["largest_change"]
    return "; ".join(f"{law} {key} at N = {ns}" for law, keys in listed.items() for key, ns in keys.items()) or "none"


def rate_lines(results: dict) -> str:
    """One Markdown line per law: each error's rate in eps and the levels it rests on, or why it has none."""
    lines = []
    for law, rates in results["rates"].items():
        parts = []
        for key, rate in rates.items():
            if rate is None:
                parts.append(f"{key}: none ({results['refused'][law][key]})")
            else:
                parts.append(f"{key}: {rate:.2f} (N = {results['rate_levels'][law][key]})")
        lines.append(f"- rates of the {law} law: " + "; ".join(parts))
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene", help="scene file of kind 'direct' with a [study] section")
    p.add_argument("--periods", type=int, nargs="+", help="numbers of periods N (default: the scene's)")
    p.add_argument("--meshes", type=int, choices=(2, 3), help="discretizations per level (default: the scene's "
                                                               "study.meshes)")
    p.add_argument("--out", metavar="DIR", help="output directory (default: results/<scene name>_epsilon)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    benchmark_doc.add_flag(p)
    args = p.parse_args(argv)
    out = args.out or os.path.join("results", os.path.splitext(os.path.basename(args.scene))[0] + "_epsilon")
    code = cli_main(["study", "epsilon", args.scene, "--out", out]
                    + (["--periods", *map(str, args.periods)] if args.periods else [])
                    + (["--meshes", str(args.meshes)] if args.meshes else [])
                    + (["--quiet"] if args.quiet else []))
    if code != EXIT_OK:
        return code
    with open(os.path.join(out, "report.json"), encoding="utf-8") as fh:
        results = json.load(fh)["results"]
    rows = results["rows"]
    laws = ("bundle", "linear", "effective")
    print(f"{'N':>4} {'eps':>9} {'t_res':>7} {'t_hom':>7} " + " ".join(
        f"{law + '_' + key:>18}" for law in laws for key in ("field", "reaction")))
    for r in rows:
        print(f"{r['N']:>4} {r['eps']:9.4g} {r['time_resolved']:7.2f} {r['time_homogenized']:7.2f} " + " ".join(
            f"{r[law + '_' + key]:18.3e}" for law in laws for key in ("field", "reaction")))
    if args.publish:
        name = os.path.splitext(os.path.basename(args.scene))[0]
        present = [law for law in laws if f"{law}_field" in rows[0]]
        three = results["discretization"].get("meshes") == 3
        parts = ("", "_discretization", "_ratio_resolved", "_ratio_homogenized") if three else ("", "_discretization")
        what = THREE.format(largest=largest_changes(results)) if three else TWO
        columns = ["N", "eps", "ndof_resolved", "contact_fraction_resolved",
                   "contact_fraction_resolved_discretization"] + [
            f"{law}_{key}{part}" for law in present for key in ("field", "probe", "interface") + CORRECTOR
            if f"{law}_{key}" in rows[0] for part in parts] + ["time_resolved", "time_homogenized"]
        benchmark_doc.publish(f"epsilon_{name}", f"Epsilon study of `{name}`: resolved against homogenized",
                              os.path.join(out, "epsilon.csv"), columns=columns,
                              note=f"`{args.scene}` with N periods (period eps): the resolved run against the "
                                   "homogenized runs with the bundle, the linear whole-surface and the "
                                   "effective-stiffness laws. " + what + " Where "
                                   "S_0 is straight (blocks) also, for the bundle law, `l2` (relative L2 over "
                                   "each whole body, the rough layer included; the larger of the two), `h1` "
                                   "(relative H1 seminorm outside the coarsest level's band, away from the "
                                   "outer faces) and `*_corrected` (the same of u^0 + eps u^1, the first-order "
                                   "corrector). Theory: `l2` eps^(1/2) without, eps with the corrector; `h1`, "
                                   "`probe` eps either way.\n\n"
                                   + rate_lines(results),
                              png=os.path.join(out, "epsilon.png"))
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
