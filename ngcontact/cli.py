"""The ``ngcontact`` command.

``ngcontact run SCENE [--out DIR]`` solves a scene and writes ``report.json``,
CSV tables, VTK files for ParaView and PNG plots into ``DIR`` (default
``results/<scene name>``); ``ngcontact check SCENE`` only validates it.

Exit status: 0 success, 2 invalid scene or output directory, 3 solver
failure; every failure prints one line on stderr and leaves no output behind.
"""
from __future__ import annotations

import argparse
import logging
import os
import sys

from . import __version__
from . import scene as scene_mod
from .errors import ConvergenceError, NgcontactError, OutputError, SceneError

EXIT_OK, EXIT_SCENE, EXIT_SOLVER = 0, 2, 3


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="ngcontact",
        description="Contact of elastic bodies with periodically rough interfaces, "
                    "by two-scale homogenization (NGSolve).",
        epilog="Exit status: 0 success, 2 invalid scene or output directory, 3 solver failure.")
    p.add_argument("--version", action="version", version=f"ngcontact {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    run = sub.add_parser("run", help="solve a scene and write report.json, VTK, CSV and PNG",
                         description="Solve a scene; write DIR/report.json, VTK files, CSV tables and PNG plots.")
    run.add_argument("scene", help="scene file (TOML)")
    run.add_argument("--out", metavar="DIR", help="output directory (default: results/<scene name>)")
    run.add_argument("--quiet", action="store_true", help="no progress lines")
    chk = sub.add_parser("check", help="validate a scene file without solving",
                         description="Validate a scene file and list the effects it calls for.")
    chk.add_argument("scene", help="scene file (TOML)")
    return p


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.command is None:
        _parser().print_help()
        return EXIT_SCENE
    logging.basicConfig(level=logging.WARNING, format="%(message)s")
    if args.command == "check":
        return _check(args.scene)
    return _run(args.scene, args.out, quiet=args.quiet)


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
    from .report import ensure_writable, write_outputs
    from .runner import solve

    try:
        sc = scene_mod.load(path)
    except SceneError as exc:
        return _fail(EXIT_SCENE, f"{path}: {exc}")
    out = out or os.path.join("results", os.path.splitext(os.path.basename(path))[0])
    try:
        ensure_writable(out)
    except OutputError as exc:
        return _fail(EXIT_SCENE, str(exc))
    progress = None if quiet else (lambda line: print(line, file=sys.stderr, flush=True))
    try:
        report, outcome = solve(sc, progress)
        write_outputs(out, report, outcome)
    except SceneError as exc:
        return _fail(EXIT_SCENE, f"{path}: {exc}")
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
