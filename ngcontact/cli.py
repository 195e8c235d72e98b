"""The ``ngcontact`` command.

``ngcontact run SCENE [--out DIR]`` solves a scene and writes ``report.json``,
CSV tables, VTK files for ParaView and PNG plots into ``DIR`` (default
``results/<scene name>``); ``ngcontact check SCENE`` only validates it;
``ngcontact study epsilon SCENE [--periods N ...] [--out DIR]`` runs the
epsilon study of a ``direct`` scene (:func:`ngcontact.runner.study_epsilon`) and
writes ``report.json``, ``epsilon.csv`` and ``epsilon.png`` into ``DIR``
(default ``results/<scene name>_epsilon``).

Exit status: 0 success, 2 invalid scene or output directory, 3 solver
failure; every failure prints one line on stderr and leaves no output behind.
"""
from __future__ import annotations

import argparse
import logging
import os
import sys

from ngcontact import __version__
from ngcontact.scene import loader as scene_mod
from ngcontact.errors import ConvergenceError, ModelError, NgcontactError, OutputError, SceneError

EXIT_OK, EXIT_SCENE, EXIT_SOLVER = 0, 2, 3


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="ngcontact",
        description="Contact of elastic bodies with periodically rough interfaces, "
                    "by two-scale homogenization (NGSolve).",
        epilog="Exit status: 0 success, 2 invalid scene or output directory, 3 solver failure "
               "(and any unexpected error).")
    p.add_argument("--version", action="version", version=f"ngcontact {__version__}")
    p.add_argument("--debug", action="store_true",
                   help="show the traceback of an unexpected error (and debug log lines)")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    run = sub.add_parser("run", help="solve a scene and write report.json, VTK, CSV and PNG",
                         description="Solve a scene; write DIR/report.json, VTK files, CSV tables and PNG plots.")
    run.add_argument("scene", help="scene file (TOML)")
    run.add_argument("--out", metavar="DIR", help="output directory (default: results/<scene name>)")
    run.add_argument("--quiet", action="store_true", help="no progress lines")
    chk = sub.add_parser("check", help="validate a scene file without solving",
                         description="Validate a scene file and list the effects it calls for.")
    chk.add_argument("scene", help="scene file (TOML)")
    st = sub.add_parser("study", help="run a study of a scene (epsilon: resolved against homogenized)",
                        description="Epsilon study of a 'direct' scene: resolved runs against the homogenized "
                                    "laws; write DIR/report.json, DIR/epsilon.csv and DIR/epsilon.png.")
    st.add_argument("study", choices=("epsilon",), help="which study")
    st.add_argument("scene", help="scene file (TOML) of kind 'direct' with a [study] section")
    st.add_argument("--periods", type=int, nargs="+", metavar="N", help="numbers of periods (default: the scene's)")
    st.add_argument("--out", metavar="DIR", help="output directory (default: results/<scene name>_epsilon)")
    st.add_argument("--quiet", action="store_true", help="no progress lines")
    return p


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.command is None:
        _parser().print_help()
        return EXIT_SCENE
    logging.basicConfig(level=logging.DEBUG if args.debug else logging.WARNING, format="%(message)s")
    try:
        if args.command == "check":
            return _check(args.scene)
        if args.command == "study":
            return _study(args.scene, args.periods, args.out, quiet=args.quiet)
        return _run(args.scene, args.out, quiet=args.quiet)
    except Exception as exc:  # an unexpected failure still ends in one line and exit 3
        if args.debug:
            raise
        return _fail(EXIT_SOLVER, f"{args.scene}: unexpected error ({type(exc).__name__}): {exc}; "
                                  "rerun with --debug for the traceback")


def _fail(code: int, message: str) -> int:
    print(f"ngcontact: error: {message}", file=sys.stderr)
    return code


def _check(path: str) -> int:
    try:
        sc = scene_mod.load(path)
    except SceneError as exc:
        return _fail(EXIT_SCENE, f"{path}: {exc}")
    print(f"{path}: valid {sc.kind} scene; effects: {', '.join(scene_mod.effects(sc)) or 'none'}")
    return EXIT_OK


def _run(path: str, out: str | None, quiet: bool) -> int:
    from ngcontact.runner import solve

    return _execute(path, out, quiet, solve, suffix="")


def _study(path: str, periods, out: str | None, quiet: bool) -> int:
    """``ngcontact study epsilon``: the same code as ``scripts/epsilon_study.py``."""
    from ngcontact.runner import study_epsilon

    def require_study(sc):
        if sc.kind != "direct" or sc.study is None:
            raise SceneError("kind", sc.kind, "the epsilon study needs a 'direct' scene with a [study] section")

    def compute(sc, progress):
        return study_epsilon(sc, periods, progress)

    if periods is not None and any(n < 1 for n in periods):
        return _fail(EXIT_SCENE, f"--periods {periods}: every N must be >= 1")
    return _execute(path, out, quiet, compute, suffix="_epsilon", validate=require_study)


def _execute(path: str, out: str | None, quiet: bool, compute, *, suffix: str, validate=None) -> int:
    """Load, check the output directory, ``compute(scene, progress)``, write atomically.

    Maps every failure to its exit status with a one-line message: invalid
    scene or output directory 2, solver failure 3.
    """
    from ngcontact.output.report import ensure_writable, write_outputs

    try:
        sc = scene_mod.load(path)
        if validate is not None:
            validate(sc)
    except SceneError as exc:
        return _fail(EXIT_SCENE, f"{path}: {exc}")
    out = out or os.path.join("results", os.path.splitext(os.path.basename(path))[0] + suffix)
    try:
        ensure_writable(out)
    except OutputError as exc:
        return _fail(EXIT_SCENE, str(exc))
    progress = None if quiet else (lambda line: print(line, file=sys.stderr, flush=True))
    try:
        report, outcome = compute(sc, progress)
        write_outputs(out, report, outcome)
    except SceneError as exc:
        return _fail(EXIT_SCENE, f"{path}: {exc}")
    except ModelError as exc:
        return _fail(EXIT_SCENE, f"{path}: inadmissible model input: {exc}")
    except OutputError as exc:
        return _fail(EXIT_SCENE, str(exc))
    except ConvergenceError as exc:
        return _fail(EXIT_SOLVER, f"{path}: solver failed: {exc}")
    except (NgcontactError, ValueError) as exc:
        return _fail(EXIT_SOLVER, f"{path}: {exc}")
    if progress:
        progress(f"wrote {os.path.join(out, 'report.json')}")
    return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
