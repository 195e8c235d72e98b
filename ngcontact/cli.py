"""The ``ngcontact`` command.

``ngcontact run SCENE [--out DIR]`` solves a scene and writes ``report.json``,
CSV tables, VTK files for ParaView and PNG plots into ``DIR`` (default
``results/<scene name>``); ``ngcontact check SCENE`` only validates it;
``ngcontact study epsilon SCENE [--periods N ...] [--meshes 2|3] [--out DIR]`` runs the
epsilon study of a ``direct`` scene (:func:`ngcontact.runner.study_epsilon`) and
writes ``report.json``, ``epsilon.csv`` and ``epsilon.png`` into ``DIR``
(default ``results/<scene name>_epsilon``); ``ngcontact study accuracy SCENE
[--target T] [--levels N] [--out DIR]`` runs the accuracy study of a cell, macro,
two-scale or resolved (``direct``) scene (:func:`ngcontact.runner.study_accuracy`: a ladder over its
discretization knobs, :mod:`ngcontact.scene.studied_kinds`) and writes ``report.json``, ``accuracy_study.csv``, one
``accuracy_<quantity>.png`` per headline quantity and, with a target met,
``recommended.toml`` (default ``results/<scene name>_accuracy``); ``ngcontact export SCENE --format
abaqus|calculix|ansys|json [--out DIR]`` writes the interface law of a cell or
macro scene for another FE code (:mod:`ngcontact.export.export_law`; default
``results/<scene name>_export``), what the format cannot carry as a warning.

Batches of independent solves (loads with ``load.independent``, ensemble
members, study levels) run on ``--workers N`` local processes (default: one
per core) or on the dask.distributed scheduler ``--scheduler ADDRESS``, with a
progress bar on a terminal (plain lines otherwise, none with ``--quiet``).

Exit status: 0 success, 2 invalid scene or output directory (also a
scheduler address that is malformed or where no scheduler answers: nothing
was solved), 3 solver failure (also a member of a batch that failed twice),
130 interrupted (SIGINT), 143 terminated (SIGTERM); every failure prints
one line on stderr and leaves the output directory as it was
(:mod:`ngcontact.output.writer`: only the package's own files are ever
written or replaced).
"""
from __future__ import annotations

import argparse
from contextlib import contextmanager
import logging
import os
import signal
import sys
import threading

from ngcontact._version import __version__
from ngcontact.distributed.vtk_pieces import written
from ngcontact.distributed.world import launched_rank
from ngcontact.scene import loader as scene_mod
from ngcontact.scene.cell_scene import CellScene
from ngcontact.errors import ConvergenceError, ModelError, NgcontactError, OutputError, SceneError

EXIT_OK, EXIT_SCENE, EXIT_SOLVER = 0, 2, 3
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143


class Terminated(BaseException):
    """SIGTERM, raised where the program stands so that every ``finally`` cleans up."""


#: Signals received by this run.  An exception raised by the handler can be
#: lost inside a compiled library that swallows errors of Python callbacks,
#: so the record is checked again at every stage and before any file is
#: written: an interrupted run never writes.
_RECEIVED: list[int] = []


def _interruption(signum: int) -> BaseException:
    return KeyboardInterrupt() if signum == signal.SIGINT else Terminated()


def _on_signal(signum, frame):
    _RECEIVED.append(signum)
    raise _interruption(signum)


def _check_signals() -> None:
    if _RECEIVED:
        raise _interruption(_RECEIVED[0])


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="ngcontact",
        description="Contact of elastic bodies with periodically rough interfaces, "
                    "by two-scale homogenization (NGSolve).",
        epilog="Exit status: 0 success, 2 invalid scene, output directory or scheduler address (or no "
               "scheduler answers there), 3 solver failure (and any unexpected error).")
    p.add_argument("--version", action="version", version=f"ngcontact {__version__}")
    p.add_argument("--debug", action="store_true",
                   help="show the traceback of an unexpected error (and debug log lines)")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    run = sub.add_parser("run", help="solve a scene and write report.json, VTK, CSV and PNG",
                         description="Solve a scene; write DIR/report.json, VTK files, CSV tables and PNG plots.")
    run.add_argument("scene", help="scene file (TOML)")
    run.add_argument("--out", metavar="DIR", type=_out_dir, help="output directory (default: results/<scene name>)")
    run.add_argument("--quiet", action="store_true", help="no progress lines")
    run.add_argument("--mpi", action="store_true",
                     help="a macro scene distributed over the MPI ranks of mpiexec -n N (the same happens under "
                          "mpiexec without it); needs the extra ngcontact[mpi]")
    _compute_options(run)
    chk = sub.add_parser("check", help="validate a scene file without solving",
                         description="Validate a scene file and list the effects it calls for.")
    chk.add_argument("scene", help="scene file (TOML)")
    _study_parser(sub)
    ex = sub.add_parser("export", help="write a cell's or macro scene's interface law for Abaqus, CalculiX, "
                        "ANSYS or as JSON", description="Export the homogenized interface law of a cell scene (its "
                        "direction bundle) or of a macro scene (the law its interface uses).")
    ex.add_argument("scene", help="scene file (TOML) of kind cell or macro")
    ex.add_argument("--format", required=True, metavar="FORMAT", help="abaqus, calculix, ansys or json")
    ex.add_argument("--out", metavar="DIR", type=_out_dir,
                    help="output directory (default: results/<scene name>_export)")
    ex.add_argument("--length-unit", type=float, default=1.0, metavar="M",
                    help="cell scene: metres per cell length unit, in [1e-12, 1000] (default 1)")
    ex.add_argument("--max-pressure", type=float, metavar="PA", help="largest pressure of the table [Pa] "
                    "(> 0; default: from the law's kinks, the scene's loads and interference)")
    ex.add_argument("--table-tol", type=float, default=1e-3, metavar="T",
                    help="largest departure of the table from the law between nodes, times the largest "
                         "pressure (default 1e-3)")
    ex.add_argument("--mu", type=float, metavar="MU", help="friction coefficient to write, >= 0 (default: the macro "
                    "scene's interface.mu, else |k_nt0|/k_n0)")
    return p


def _study_parser(sub) -> None:
    """The ``study`` command: epsilon and accuracy."""
    st = sub.add_parser("study", help="run a study of a scene (epsilon: resolved against homogenized; accuracy: "
                        "the work-precision diagram of the scene's discretization)",
                        description="epsilon: a 'direct' scene's resolved runs against the homogenized laws; write "
                                    "DIR/report.json, DIR/epsilon.csv and DIR/epsilon.png.  accuracy: a ladder over "
                                    "the scene's discretization knobs (mesh size, order, spectral grid, penalty, "
                                    "tolerance; a two-scale loop's table and loop tolerances and its cell's grid, "
                                    "mesh, order and penalty), each level a whole run; write DIR/report.json, "
                                    "DIR/accuracy_study.csv, a PNG per headline quantity (error against wall time) "
                                    "and, with --target met, DIR/recommended.toml.")
    st.add_argument("study", choices=("epsilon", "accuracy"), help="which study")
    st.add_argument("scene", help="scene file (TOML): epsilon, of kind 'direct' with a [study] section; accuracy, "
                                  "a cell, macro, two-scale (macro with [two_scale]) or resolved ('direct') "
                                  "scene")
    st.add_argument("--periods", type=int, nargs="+", metavar="N", help="epsilon: numbers of periods (default: the "
                                                                        "scene's)")
    st.add_argument("--meshes", type=int, choices=(2, 3), help="epsilon: discretizations per level (default: the "
                                                                "scene's study.meshes)")
    st.add_argument("--target", type=float, metavar="T", help="accuracy: the error to meet, in (0, 1) (contact "
                    "fractions absolute, other quantities relative); the cheapest level meeting it is written as "
                    "DIR/recommended.toml")
    st.add_argument("--levels", type=int, metavar="N", help="accuracy: levels per knob, in [3, 6] (default 4: two "
                    "coarser than the scene, the scene, one finer)")
    st.add_argument("--out", metavar="DIR", type=_out_dir,
                    help="output directory (default: results/<scene name>_epsilon or _accuracy)")
    st.add_argument("--quiet", action="store_true", help="no progress lines")
    _compute_options(st)


def _out_dir(text: str) -> str:
    """An output directory named by a non-blank path (an empty ``--out`` is no directory; without the option
    the run writes to its default)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"{text!r}: must name a directory (omit --out for the default, "
                                         "results/<scene name>)")
    return text


def _workers(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: the number of worker processes, an integer >= 1")
    return n


def _scheduler(text: str) -> str:
    """A scheduler address of a valid form (nothing is connected yet)."""
    from ngcontact.runner import check_scheduler
    try:
        check_scheduler(text, "--scheduler")
    except SceneError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {exc.allowed}") from None
    return text


def _compute_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--workers", type=_workers, metavar="N",
                   help="local worker processes for independent solves (loads with load.independent, ensemble "
                        "members, study levels), one NGSolve thread each (default: [compute] workers, else the "
                        "number of cores); at most one per member of the batch and two per core")
    p.add_argument("--scheduler", metavar="ADDRESS", type=_scheduler,
                   help="run independent solves on the workers of this dask.distributed scheduler "
                        "(tcp://HOST:PORT or HOST:PORT, e.g. tcp://10.0.0.5:8786) instead of local processes "
                        "(default: [compute] scheduler)")


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.command is None:
        _parser().print_help()
        return EXIT_SCENE
    logging.basicConfig(level=logging.DEBUG if args.debug else logging.WARNING, format="%(message)s")
    _RECEIVED.clear()
    previous = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            if signal.getsignal(sig) is not signal.SIG_IGN:  # an ignored signal stays ignored (nohup, &)
                previous[sig] = signal.signal(sig, _on_signal)
    try:
        if args.command == "check":
            return _check(args.scene)
        if args.command == "export":
            return _export(args)
        compute = {"workers": args.workers, "scheduler": args.scheduler}
        if args.command == "study" and args.study == "accuracy":
            return _study_accuracy(args, compute)
        if args.command == "study":
            if args.target is not None or args.levels is not None:
                return _fail(EXIT_SCENE, "--target, --levels: options of the accuracy study only")
            return _study(args.scene, args.periods, args.out, quiet=args.quiet, compute=compute, meshes=args.meshes)
        return _run(args.scene, args.out, quiet=args.quiet, compute=compute, mpi=args.mpi)
    except KeyboardInterrupt:
        return _fail(EXIT_INTERRUPTED, f"{args.scene}: interrupted; the output directory is as it was")
    except Terminated:
        return _fail(EXIT_TERMINATED, f"{args.scene}: terminated; the output directory is as it was")
    except Exception as exc:  # an unexpected failure still ends in one line and exit 3
        if args.debug:
            raise
        return _fail(EXIT_SOLVER, f"{args.scene}: unexpected error ({type(exc).__name__}): {exc}; "
                                  "rerun with --debug for the traceback")
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


@contextmanager
def _native_output_silenced(active: bool):
    """With ``--quiet``: the compiled libraries' own lines on file descriptor 1 (Netgen's
    ``identify surfaces ...``) go to the null device while the scene is solved."""
    if not active:
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.close(null)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def _fail(code: int, message: str) -> int:
    if launched_rank() == 0:     # under mpiexec every rank fails alike: rank 0 says it
        print(f"ngcontact: error: {message}", file=sys.stderr)
    return code


def _check(path: str) -> int:
    """Load and validate; for kinds whose driver has ``check_model``, mesh and check the model too."""
    from ngcontact.runner import check

    try:
        sc = scene_mod.load(path)
        with _native_output_silenced(True):
            notes = check(sc)
    except Exception as exc:
        return _classified(path, exc)
    for line in notes:
        print(line)
    choice = sc.method_choice if isinstance(sc, CellScene) else None   # discretization.method, resolved
    if choice is not None:
        print(f"{path}: cell method {choice.statement}")
    print(f"{path}: valid {sc.kind} scene; effects: {', '.join(scene_mod.effects(sc)) or 'none'}")
    return EXIT_OK


@contextmanager
def _scheduler_named(compute: dict):
    """The runner names its ``scheduler`` argument ``scheduler``: here it is ``--scheduler``."""
    try:
        yield
    except SceneError as exc:
        if exc.path == "scheduler" and compute.get("scheduler") is not None:
            raise SceneError("--scheduler", exc.value, exc.allowed) from exc
        raise


def _run(path: str, out: str | None, quiet: bool, compute: dict, mpi: bool = False) -> int:
    from ngcontact.output.progress_bar import BatchProgress
    from ngcontact.runner import solve

    quiet = quiet or launched_rank() > 0

    def compute_run(sc, progress):
        with _scheduler_named(compute):
            return solve(sc, progress, batch_progress=BatchProgress(quiet), mpi_requested=mpi, **compute)

    return _execute(path, out, quiet, compute_run, suffix="")


def _study(path: str, periods, out: str | None, quiet: bool, compute: dict, meshes: int | None = None) -> int:
    """``ngcontact study epsilon``: the same code as ``scripts/epsilon_study.py``; ``meshes`` (``--meshes``)
    replaces the scene's ``study.meshes``."""
    from ngcontact.runner import study_epsilon

    def require_study(sc):
        if sc.kind != "direct" or sc.study is None:
            raise SceneError("kind", sc.kind, "the epsilon study needs a 'direct' scene with a [study] section")

    from ngcontact.output.progress_bar import BatchProgress

    def run_study(sc, progress):
        with _scheduler_named(compute):
            return study_epsilon(sc, periods, progress, batch_progress=BatchProgress(quiet), meshes=meshes,
                                 **compute)

    if periods is not None and (len(periods) < 3 or any(n < 1 for n in periods)
                                or any(b <= a for a, b in zip(periods, periods[1:]))):
        return _fail(EXIT_SCENE, f"--periods {' '.join(map(str, periods))}: at least 3 increasing numbers "
                                 "N >= 1 (a rate needs three distinct levels)")
    return _execute(path, out, quiet, run_study, suffix="_epsilon", validate=require_study)


def _study_accuracy(args, compute: dict) -> int:
    """``ngcontact study accuracy``: options checked first, then the scene and ``--out``; nothing is written
    on a refusal."""
    from ngcontact.output.progress_bar import BatchProgress
    from ngcontact.runner import study_accuracy
    from ngcontact.scene.refinement_ladder import check_study

    if args.periods is not None:
        return _fail(EXIT_SCENE, "--periods: an option of the epsilon study only")
    if args.meshes is not None:
        return _fail(EXIT_SCENE, "--meshes: an option of the epsilon study only")
    if args.target is not None and not 0 < args.target < 1:
        return _fail(EXIT_SCENE, f"--target {args.target:g}: an error in (0, 1) (contact fractions absolute, other "
                                 "quantities relative), e.g. 0.01 for 1 %")
    if args.levels is not None and not 3 <= args.levels <= 6:
        return _fail(EXIT_SCENE, f"--levels {args.levels}: an integer in [3, 6] (levels per knob)")

    def run_study(sc, progress):
        with _scheduler_named(compute):
            return study_accuracy(args.scene, args.levels, args.target, progress,
                                  batch_progress=BatchProgress(args.quiet), **compute)

    return _execute(args.scene, args.out, args.quiet, run_study, suffix="_accuracy", validate=check_study)


def _export(args) -> int:
    """``ngcontact export``: check format, scene and ``--out`` first; write one file; warn what is lost."""
    from ngcontact.export.export_law import FORMATS, check, export, warnings
    from ngcontact.export.law_source import check_options
    from ngcontact.scene.sections import check_input_file

    if args.format not in FORMATS:
        return _fail(EXIT_SCENE, f"--format {args.format}: unknown format; one of " + ", ".join(FORMATS))
    try:
        check_options(length_unit=args.length_unit, p_max=args.max_pressure, tolerance=args.table_tol, mu=args.mu)
    except ModelError as exc:
        return _fail(EXIT_SCENE, str(exc))
    out = args.out or os.path.join("results", os.path.splitext(os.path.basename(args.scene))[0] + "_export")
    try:
        check_input_file("SCENE", args.scene, "scene file", missing="an existing scene file")
        check(args.scene, args.format, out)
        with _native_output_silenced(True):
            path, law = export(args.scene, args.format, out, length_unit=args.length_unit,
                               p_max=args.max_pressure, tolerance=args.table_tol, mu=args.mu)
    except Exception as exc:
        return _classified(args.scene, exc)
    for note in warnings(law, args.format):
        print(f"ngcontact: warning: {args.format} cannot carry: {note}", file=sys.stderr)
    print(f"wrote {path}", file=sys.stderr)
    return EXIT_OK


def _classified(path: str, exc: Exception) -> int:
    """Exit code and one line for an exception of a run: 2 for input, 3 for a solver failure.

    Anything unforeseen is raised again (a traceback is a bug to fix, not an
    answer to hide).
    """
    if isinstance(exc, SceneError):
        return _fail(EXIT_SCENE, f"{path}: {exc}")
    if isinstance(exc, ModelError):
        return _fail(EXIT_SCENE, f"{path}: inadmissible model input: {exc}")
    if isinstance(exc, OutputError):
        return _fail(EXIT_SCENE, str(exc))
    if isinstance(exc, ConvergenceError):
        return _fail(EXIT_SOLVER, f"{path}: solver failed: {exc}")
    if isinstance(exc, (NgcontactError, ValueError)):
        return _fail(EXIT_SOLVER, f"{path}: {exc}")
    if type(exc).__name__ == "NgException" and "meshing" in str(exc).lower():
        return _fail(EXIT_SCENE, f"{path}: the mesher failed on this geometry ({exc}); the usual causes are a "
                                 "feature smaller than discretization.maxh / interface_maxh, or these two sizes "
                                 "far apart (a ratio near 100): change the geometry's sizes or the mesh sizes")
    raise exc


def _execute(path: str, out: str | None, quiet: bool, compute, *, suffix: str, validate=None) -> int:
    """Load, check the output directory, ``compute(scene, progress)``, write atomically.

    Maps every failure to its exit status with a one-line message: invalid
    scene or output directory 2, solver failure 3.
    """
    from ngcontact.output.writer import check_output_dir, write_outputs

    try:
        sc = scene_mod.load(path)
        if validate is not None:
            validate(sc)
        inputs = scene_mod.inputs(sc, path)
    except SceneError as exc:
        return _fail(EXIT_SCENE, f"{path}: {exc}")
    out = out or os.path.join("results", os.path.splitext(os.path.basename(path))[0] + suffix)
    try:
        check_output_dir(out, inputs)
    except OutputError as exc:
        return _fail(EXIT_SCENE, str(exc))
    def progress(line: str) -> None:  # called at every stage
        _check_signals()
        if not quiet:
            print(line, file=sys.stderr, flush=True)

    try:
        with _native_output_silenced(quiet):
            report, outcome = compute(sc, progress)
        _check_signals()
        # under mpiexec rank 0 holds the results and writes; the other ranks write their VTK pieces
        written(outcome, lambda: write_outputs(out, report, outcome, inputs))
    except Exception as exc:
        return _classified(path, exc)
    if not quiet:
        print(f"wrote {os.path.join(out, 'report.json')}", file=sys.stderr, flush=True)
    return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
