"""Epsilon study of a ``direct`` scene: resolved runs against the homogenized laws.

For each number of periods N (the scene's ``[study] periods`` or ``--periods``)
the resolved problem and the homogenized problems with the bundle, the linear
whole-surface and the effective-stiffness laws are solved and compared (see
:mod:`ngcontact.verification.epsilon_study`).  Writes, atomically, ``DIR/report.json``
(``results.rows``, ``results.rates``, ``results.below_1_percent``),
``DIR/epsilon.csv`` and ``DIR/epsilon.png`` (error and cost against eps).

Usage: python scripts/epsilon_study.py SCENE [--periods 4 8 16 32] [--out DIR]
(the same study as ``ngcontact study epsilon SCENE``, which writes the same
files; this script also prints the table)

Exit status as ``ngcontact run``: 0 success, 2 invalid scene or output
directory, 3 solver failure.
"""
from __future__ import annotations

import argparse
import os
import sys

from ngcontact.scene import loader as scene_mod
from ngcontact.cli import EXIT_OK, EXIT_SCENE, EXIT_SOLVER
from ngcontact.verification.epsilon_study import epsilon_report
from ngcontact.errors import ConvergenceError, NgcontactError, OutputError, SceneError
from ngcontact.output.report import Clock, ensure_writable, write_outputs


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene", help="scene file of kind 'direct' with a [study] section")
    p.add_argument("--periods", type=int, nargs="+", help="numbers of periods N (default: the scene's)")
    p.add_argument("--out", metavar="DIR", help="output directory (default: results/<scene name>_epsilon)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    args = p.parse_args(argv)
    try:
        sc = scene_mod.load(args.scene)
        if sc.kind != "direct" or sc.study is None:
            raise SceneError("kind", sc.kind, "the epsilon study needs a 'direct' scene with a [study] section")
    except SceneError as exc:
        print(f"epsilon_study: error: {args.scene}: {exc}", file=sys.stderr)
        return EXIT_SCENE
    out = args.out or os.path.join("results", os.path.splitext(os.path.basename(args.scene))[0] + "_epsilon")
    try:
        ensure_writable(out)
    except OutputError as exc:
        print(f"epsilon_study: error: {exc}", file=sys.stderr)
        return EXIT_SCENE
    clock = Clock(None if args.quiet else (lambda line: print(line, file=sys.stderr, flush=True)))
    try:
        report, outcome = epsilon_report(sc, args.periods, clock)
        write_outputs(out, report, outcome)
    except (SceneError, OutputError) as exc:
        print(f"epsilon_study: error: {exc}", file=sys.stderr)
        return EXIT_SCENE
    except (ConvergenceError, NgcontactError, ValueError) as exc:
        print(f"epsilon_study: error: {args.scene}: {exc}", file=sys.stderr)
        return EXIT_SOLVER
    rows = outcome.results["rows"]
    print(f"{'N':>4} {'eps':>9} {'t_res':>7} {'t_hom':>7} " + " ".join(
        f"{law + '_' + key:>18}" for law in ("bundle", "linear", "effective") for key in ("field", "reaction")))
    for r in rows:
        print(f"{r['N']:>4} {r['eps']:9.4g} {r['time_resolved']:7.2f} {r['time_homogenized']:7.2f} " + " ".join(
            f"{r[law + '_' + key]:18.3e}" for law in ("bundle", "linear", "effective") for key in ("field", "reaction")))
    print(f"wrote {os.path.join(out, 'report.json')}")
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
