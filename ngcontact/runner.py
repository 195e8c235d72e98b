"""Run a validated scene: dispatch to its kind's driver and assemble the report.

The one code path behind ``ngcontact run`` and the Python API::

    report, outcome = ngcontact.solve(ngcontact.load("geometries/femur_stem.toml"))

``report`` is the JSON-ready dictionary (see the README's report reference);
``outcome`` keeps the NGSolve objects (meshes, fields) for further work.
Nothing is written to disk; :func:`ngcontact.output.writer.write_outputs` does that
(:func:`solve_mesh`, the macro problem on a mesh of the caller's, calls it when given a directory).
"""
from __future__ import annotations

import importlib
import json
import logging
import os
import time
from contextlib import contextmanager
from typing import Callable

from ngcontact._version import __version__
from ngcontact.errors import SceneError
from ngcontact.parallel.free_cores import affinity   # first: its window of the cores opens with the process
from ngcontact.output.progress_lines import progress_lines
from ngcontact.output.report import Clock, Outcome, accuracy_line, build_report, method_line
from ngcontact.scene import loader

#: kind -> the driver module whose ``run(scene, clock)`` solves it; imported
#: on first use, so that ``ngcontact check`` stays light.
DRIVERS = {
    "manufactured": "ngcontact.drivers.run_manufactured",
    "cell": "ngcontact.drivers.run_cell",
    "macro": "ngcontact.drivers.run_macro",
    "direct": "ngcontact.drivers.run_resolved",
}


#: Environment variable with the number of threads NGSolve's task manager runs with (default: every core
#: this process may use).
THREADS_ENV = "NGCONTACT_THREADS"


def thread_count() -> int:
    """Threads of a run: ``NGCONTACT_THREADS`` or the cores available to this process."""
    raw = os.environ.get(THREADS_ENV)
    if raw is None:
        return len(affinity())
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        raise SceneError(f"environment variable {THREADS_ENV}", raw, "the number of threads: an integer >= 1")
    return n


@contextmanager
def threads(n: int):
    """Assembly and solves inside NGSolve's task manager with ``n`` threads (NGSolve runs on one core otherwise).

    One thread runs without the task manager: with it a 3D cell solve is markedly slower.  It is told to
    NGSolve all the same (``SetNumThreads(1)``): a sparse Cholesky factorization (the direct solver of every
    2D FE cell) runs outside a task manager in a pool of its own on every core, whose partial sums meet in
    an order that changes from call to call, so that the same matrix factored twice gave solutions
    differing at round-off, which the exact cell's stiffness (a rigid limit taken from a Schur complement,
    :mod:`ngcontact.cell.fe.stiffness`) amplifies many times over: enough to move a stopping decision near the
    tolerance.  On one thread the factorization, and with it every number of a run, is the same bit for bit
    from run to run (``tests/test_threads.py``).  With ``n`` threads the factorization's order still varies
    (inside NGSolve): numbers then agree to that amplified round-off, not bit for bit.  The
    BLAS libraries loaded (NGSolve's OpenBLAS under its direct solvers, NumPy's) run on one thread
    meanwhile: their own threads, which keep spinning after each call, would share the cores with
    NGSolve's, and a solve with both pools on the same cores runs several times slower.  So do those the run
    loads later (SciPy's own OpenBLAS, loaded by the first ``scipy.linalg`` call), by the variables they read
    as they load (:data:`~ngcontact.parallel.batch_member.BLAS_THREADS_ENV`, where unset; restored after).
    The C heap keeps freed arrays as a batch worker's does, where the environment froze its thresholds
    (:func:`~ngcontact.parallel.heap_thresholds.keep_freed_arrays`; a process that started a Dask cluster
    has, and passes it on to the runs it starts): else every FFT buffer of a spectral step is mapped and
    zero-filled afresh, and a member solved here costs more CPU than on a worker.
    """
    from threadpoolctl import threadpool_limits
    from ngcontact.parallel.batch_member import BLAS_THREADS_ENV
    from ngcontact.parallel.heap_thresholds import keep_freed_arrays
    keep_freed_arrays()
    unset = [name for name in BLAS_THREADS_ENV if name not in os.environ]
    os.environ.update({name: "1" for name in unset})
    try:
        with threadpool_limits(limits=1):
            if n == 1:
                from pyngcore import SetNumThreads
                SetNumThreads(1)
                yield
                return
            import ngsolve as ng
            ng.SetNumThreads(n)
            with ng.TaskManager():
                yield
    finally:
        for name in unset:
            os.environ.pop(name, None)


#: What the members of every batch import (the scene translator and through it the model code): a worker
#: imports them as it starts (with the module of the batch's member function), while this process goes on
#: solving members.
WORKER_MODULES = ("ngsolve", "ngcontact.drivers.build")


@contextmanager
def batches(scene, workers: int | None = None, scheduler: str | None = None, progress=None,
            start: bool | None = None, note: Callable[[str], None] | None = None, members: int | None = None):
    """Context in which the run's batches of independent solves go to their executor.

    The command line's ``workers`` / ``scheduler`` first, then the scene's
    ``[compute]`` section; default: a pool of local processes, one per core
    (:func:`ngcontact.parallel.executor.make`), never more than the batch
    has members (``members``; default :func:`batch_members`) nor more than
    twice the cores: a request above that is cut, with one line to ``note``
    (else to the log).  No worker is started before a batch whose rest
    repays the workers' start (:mod:`ngcontact.parallel.worker_payoff`; its
    first members are solved and timed in this process, which keeps solving
    while the workers start): a batch kept in this process costs exactly the
    serial run.  They start with the run (their start overlapping with its
    preparation) where ``start`` says so, or where the last run of the same
    batch on this machine forecasts that the rule sends it to them
    (:mod:`ngcontact.parallel.batch_forecast`; recorded here after the run),
    and that batch then goes to them from its first member.
    A scheduler address that is malformed, or where no scheduler answers (at
    once, or at the first batch), is a :class:`SceneError` naming
    ``scheduler`` or ``compute.scheduler``.
    """
    from ngcontact.parallel import batch_forecast, executor
    from ngcontact.parallel.dask_cluster import SchedulerError
    compute = getattr(scene, "compute", None)
    key = "scheduler"
    if scheduler is None and workers is None and compute is not None:
        scheduler, workers = compute.scheduler, compute.workers
        key = "compute.scheduler"
    members = batch_members(scene) if members is None else members
    name = batch_forecast.key(json.dumps([__version__, str(getattr(scene, "base_dir", "")), loader.as_dict(scene)],
                                         sort_keys=True, default=str)) if start is None and members else None
    opened = time.perf_counter()
    if not scheduler:
        _, capped = executor.local_workers(workers, members)
        if capped is not None:
            (note or logging.getLogger("ngcontact.parallel.executor").info)(capped)
    try:
        ex = executor.make(workers, scheduler, members)
        forecast = batch_forecast.early(ex, name, members) if name is not None else None
        if start or forecast is not None:
            ex.start(WORKER_MODULES, forecast)
        else:  # workers only for a batch whose rest repays their start
            ex.start_on_demand(WORKER_MODULES)
        with executor.use(ex, progress):
            yield ex
        if name is not None:
            batch_forecast.remember_run(name, ex, opened)
    except SchedulerError as exc:
        raise SceneError(key, exc.address, exc.allowed) from None


def check_scheduler(address: str, key: str = "scheduler") -> None:
    """Refuse a malformed dask.distributed scheduler address (:class:`SceneError` naming ``key``), by Dask's
    own parsing (:func:`ngcontact.parallel.dask_cluster.check_address`); nothing is connected."""
    from ngcontact.parallel.dask_cluster import SchedulerError, check_address
    try:
        check_address(address)
    except SchedulerError as exc:
        raise SceneError(key, address, exc.allowed) from None


def has_batches(scene) -> bool:
    """Whether :func:`solve` runs a batch of independent solves for ``scene``: an ensemble, a cell's
    independent loads (without refinement to a tolerance), the levels of a convergence study.  (The levels
    of an epsilon study are a batch of :func:`study_epsilon`; ``solve`` of that scene is one resolved solve.)"""
    if scene.kind == "manufactured":
        return len(scene.manufactured.orders) * scene.manufactured.levels > 1
    if scene.kind == "cell":
        if getattr(scene, "ensemble", None) is not None:
            return True
        if scene.contact.geometric_only:  # no loads: one geometric solve
            return False
        return scene.load.independent and scene.discretization.tolerance is None
    return False


def batch_members(scene) -> int | None:
    """The members of the batches :func:`solve` runs for ``scene`` where known before the solve (the loads
    of a sweep of independent loads, the members of an ensemble, the levels of a convergence study); None
    otherwise (a two-scale cell table's levels, known only as it fills)."""
    if not has_batches(scene):
        return None
    if scene.kind == "manufactured":
        return len(scene.manufactured.orders) * scene.manufactured.levels
    if getattr(scene, "ensemble", None) is not None:
        return scene.ensemble.members
    from ngcontact.scene.cell_scene import load_states
    return len(load_states(scene))


def check(scene) -> list[str]:
    """Every check ``run`` makes before its solve, without solving; returns what the model lists about
    itself (the bodies and faces of a file geometry), else nothing.

    The scene is validated when loaded, its scheduler address (``compute.scheduler``) by its form (no
    connection); kinds whose driver defines
    ``check_model(scene)`` (the macro kind: boundary labels of the meshed
    shape, the gap table's coverage, rigid motions the supports leave free)
    are meshed and checked too.  Raises what ``run`` would raise.
    """
    if not hasattr(scene, "kind"):
        scene = loader.load(scene)
    compute = getattr(scene, "compute", None)
    if compute is not None and compute.scheduler:
        check_scheduler(compute.scheduler, "compute.scheduler")
    check_model = getattr(importlib.import_module(DRIVERS[scene.kind]), "check_model", None)
    if check_model is not None:
        return list(check_model(scene) or [])
    return []


def driver(scene):
    """The driver module of a scene: its kind's, or the ensemble driver for a cell scene with ``[ensemble]``."""
    if scene.kind == "cell" and getattr(scene, "ensemble", None) is not None:
        return importlib.import_module("ngcontact.drivers.run_ensemble")
    return importlib.import_module(DRIVERS[scene.kind])


def solve(scene, progress: Callable[[str], None] | None = None, *, workers: int | None = None,
          scheduler: str | None = None, batch_progress=None, mpi_requested: bool = False) -> tuple[dict, Outcome]:
    """Solve ``scene`` (a validated scene or a path to a scene file).

    Parameters
    ----------
    scene
        The result of :func:`ngcontact.load`, or a file path.
    progress
        Optional callable receiving one line per stage (e.g. ``print``).
    workers, scheduler
        Where batches of independent solves run (independent loads, ensemble
        members): ``workers`` local processes (default: the scene's
        ``[compute]``, else one per core), or the dask.distributed scheduler
        at the address ``scheduler``.
    batch_progress
        Optional ``callable(label, finished, total)`` called as a batch advances.
    mpi_requested
        ``--mpi``: refuse at once where ``mpi4py`` is missing.  Under ``mpiexec -n N`` (N > 1) a macro
        scene is solved distributed (:mod:`ngcontact.distributed.macro_run`) whether requested or not;
        its report's ``compute.mpi_ranks`` is N, and only rank 0's outcome holds the results.

    Returns
    -------
    (report, outcome)
    """
    if not hasattr(scene, "kind"):
        scene = loader.load(scene)
    mpi = mpi_world(scene, mpi_requested)
    n = thread_count()
    if mpi is not None and THREADS_ENV not in os.environ:
        n = max(1, n // mpi.size)           # the ranks of one machine share its cores
    clock = Clock(progress)
    with threads(n), batches(scene, workers, scheduler, batch_progress, note=progress) as ex, progress_lines(clock):
        if mpi is None:
            outcome = driver(scene).run(scene, clock)
        else:
            from ngcontact.distributed import macro_run
            outcome = macro_run.run(scene, clock, mpi)
    for line in (method_line(outcome.results), accuracy_line(outcome.results)):
        if line is not None:
            clock.note(line)
    compute = ex.describe()
    if mpi is not None:
        compute = {**compute, "mpi_ranks": mpi.size}
    report = build_report(kind=scene.kind, title=getattr(scene, "title", ""),
                          scene=loader.as_dict(scene), effects=loader.effects(scene),
                          outcome=outcome, timings=clock.total(), version=__version__, threads=n,
                          compute=compute)
    return report, outcome


def mpi_world(scene, requested: bool = False):
    """The MPI world of a distributed macro run (:func:`ngcontact.distributed.world.world`), or ``None``.

    Raises :class:`~ngcontact.errors.SceneError` for a scene of another kind on several ranks.
    """
    from ngcontact.distributed.world import world
    mpi = world(requested)
    if mpi is not None and mpi.size > 1 and scene.kind != "macro":
        raise SceneError("kind", scene.kind, f"'macro' on {mpi.size} MPI ranks (only a macro scene runs "
                         "distributed; run other kinds in one process)")
    return mpi if mpi is not None and mpi.size > 1 else None


def study_epsilon(scene, periods=None, progress: Callable[[str], None] | None = None, *, workers: int | None = None,
                  scheduler: str | None = None, batch_progress=None,
                  meshes: int | None = None) -> tuple[dict, Outcome]:
    """The epsilon study of a ``direct`` scene with a ``[study]`` section, as a report; no file I/O.

    The resolved rough interface at ``N`` periods against the homogenized
    laws (:mod:`ngcontact.drivers.study_epsilon`); the command
    ``ngcontact study epsilon`` and ``scripts/epsilon_study.py`` call this.
    The levels are independent solves: ``workers``, ``scheduler`` and
    ``batch_progress`` as in :func:`solve`; ``meshes`` (``--meshes``) replaces the scene's ``study.meshes``.

    Raises
    ------
    SceneError
        The scene is not a ``direct`` scene with a ``[study]`` section, or
        its band leaves no points for the field error.
    """
    if not hasattr(scene, "kind"):
        scene = loader.load(scene)
    if scene.kind != "direct" or getattr(scene, "study", None) is None:
        raise SceneError("kind", scene.kind, "the epsilon study needs a 'direct' scene with a [study] section")
    if periods is not None:
        from ngcontact.scene.resolved_scene import with_study_periods
        scene = with_study_periods(scene, periods)
    if meshes is not None:
        from ngcontact.scene.resolved_scene import with_study_meshes
        scene = with_study_meshes(scene, meshes)
    n = thread_count()
    clock = Clock(progress)
    with threads(n), batches(scene, workers, scheduler, batch_progress, start=True, note=progress,
                             members=len(periods or scene.study.periods)) as ex:
        from ngcontact.drivers.study_epsilon import run_study
        outcome = run_study(scene, periods, clock=clock)
    report = build_report(kind="direct-epsilon-study", title=scene.title, scene=loader.as_dict(scene),
                          effects=loader.effects(scene), outcome=outcome, timings=clock.total(),
                          version=__version__, threads=n, compute=ex.describe())
    return report, outcome


def solve_mesh(mesh, law, *, rough: str, counter: str, materials: dict, interface: str = "interface",
               setting: str | None = None, supports=(), loads=(), gap=0.0, order: int = 2,
               solver: dict | None = None, output: dict | None = None, title: str = "",
               out: str | None = None, progress: Callable[[str], None] | None = None) -> tuple[dict, Outcome]:
    """The macro problem on a mesh built in the caller's NGSolve script, reported as ``ngcontact run`` reports
    a ``macro`` scene (:mod:`ngcontact.drivers.user_mesh`).

    Parameters
    ----------
    mesh
        An ``ngsolve.Mesh`` with the regions ``rough`` and ``counter`` and the internal boundary
        ``interface`` between them, shared node for node (:mod:`ngcontact.macro.interface_form`).
    law
        An :class:`~ngcontact.laws.homogenized.InterfaceLaw` (e.g. :func:`ngcontact.cell_law`) or a normal
        law alone.
    rough, counter
        Region names of the rough body (paper ``D``) and the counter body.
    materials
        ``{region: ElasticLaw or {"E": ..., "nu": ...} or {"C": ...}}`` for both regions.
    interface
        Boundary name of the interface ``S_0``.
    setting
        ``plane_strain`` (2D default), ``axisymmetric`` (mesh ``(x, y)`` = ``(r, z)``) or ``3d``.
    supports, loads
        Lists of tables as a macro scene's ``[[supports]]`` (``boundary``, ``components``,
        ``displacement``) and ``[[loads]]`` (``boundary``, ``pressure``, ``traction``), on the mesh's
        boundary names.
    gap
        Macro normal gap ``g0`` (number or CoefficientFunction; ``< 0`` an interference).
    order
        Polynomial order of the displacement.
    solver, output
        Keys of a macro scene's ``[solver]`` and ``[output]`` sections (defaults as there).
    title
        The report's title.
    out
        Output directory: ``report.json``, ``report.html`` and the run's tables, figures and VTK files
        are written there, as ``ngcontact run --out`` writes them (checked before the solve).
    progress
        Optional callable receiving one line per stage.

    Returns
    -------
    (report, outcome)
        As :func:`solve`: the report (its ``results`` those of a macro run) and the outcome with the
        NGSolve objects.
    """
    from ngcontact.drivers import user_mesh
    from ngcontact.output.writer import check_output_dir, write_outputs
    if out is not None:
        check_output_dir(out)
    n = thread_count()
    clock = Clock(progress)
    with threads(n), progress_lines(clock):
        outcome, described, effects = user_mesh.run(
            mesh, law, rough=rough, counter=counter, materials=materials, interface=interface, setting=setting,
            supports=supports, loads=loads, gap=gap, order=order, solver=solver, output=output, title=title,
            clock=clock)
    report = build_report(kind="macro", title=title, scene=described, effects=effects, outcome=outcome,
                          timings=clock.total(), version=__version__, threads=n)
    if out is not None:
        write_outputs(out, report, outcome)
    return report, outcome


def level_report(scene) -> dict:
    """A level of an accuracy study run as ``ngcontact run`` runs a scene, its batches in this process: the
    report (module-level, so that a batch's worker can call it).  The kind's driver is imported first, so that
    the level's wall time is its run's, not the import's."""
    driver(scene)
    report, _ = solve(scene, workers=1)
    return report


def study_accuracy(path: str, levels: int | None = None, target: float | None = None,
                   progress: Callable[[str], None] | None = None, *, workers: int | None = None,
                   scheduler: str | None = None, batch_progress=None) -> tuple[dict, Outcome]:
    """The accuracy study of the scene file ``path`` (:mod:`ngcontact.drivers.study_accuracy`), as a report;
    no file I/O.

    The ladder (``levels`` per knob, default :data:`~ngcontact.scene.refinement_ladder.DEFAULT_LEVELS`) is
    stated to ``progress`` before anything runs; its levels are one batch of whole runs
    (:func:`level_report`), on ``workers`` / ``scheduler`` as in :func:`solve`.  ``target`` (a relative
    error in ``(0, 1)``, absolute for contact fractions, else relative) asks for the cheapest level meeting it.

    Raises
    ------
    SceneError
        The scene is invalid or of a kind the study does not refine, ``levels`` or ``target`` is out of
        range, or no knob of the scene gives enough admissible levels.
    """
    from ngcontact.scene import refinement_ladder as rl
    if target is not None and not 0 < target < 1:
        raise SceneError("--target", target, "an error in (0, 1) (contact fractions absolute, other quantities "
                         "relative), e.g. 0.01 for 1 %")
    scene = loader.load(path)
    ladder, dropped = rl.ladder(scene, loader.parsed(path), rl.DEFAULT_LEVELS if levels is None else levels)
    clock = Clock(progress)
    for knob in dict.fromkeys(lv.knob for lv in ladder):
        clock.note(f"ladder {knob} (unknowns over the scene's): " + "; ".join(
            lv.setting + ("" if lv.size is None else f" (~{lv.size:.2g})") for lv in ladder if lv.knob == knob))
    for line in dropped:
        clock.note(f"left out: {line}")
    distinct = len({lv.key for lv in ladder})
    clock.note(f"{distinct} distinct runs (the scene's own level is shared by its ladders)")
    own_key = rl.own_key(scene, loader.parsed(path))
    with batches(scene, workers, scheduler, batch_progress, start=True, note=progress, members=distinct) as ex:
        from ngcontact.drivers.study_accuracy import run_study
        outcome = run_study(scene, ladder, dropped, level_report, own_key=own_key, target=target, clock=clock)
    report = build_report(kind="accuracy-study", title=getattr(scene, "title", ""), scene=loader.as_dict(scene),
                          effects=loader.effects(scene), outcome=outcome, timings=clock.total(),
                          version=__version__, threads=1, compute=ex.describe())
    return report, outcome
