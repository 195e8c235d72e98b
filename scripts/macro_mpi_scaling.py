"""The 3D press fit and the 3D femur on 1, 2 and 3 MPI ranks at growing sizes: time and peak memory per rank.

Scenes: the quarter of two coaxial tubes pressed together (interference
2 um, 5 MPa on the top; the scene of ``tests/distributed/test_mpi_macro.py``),
refined by ``discretization.maxh`` or, ``press_fit_refined``, made with ``maxh`` and split
uniformly ``discretization.refinements`` times (under MPI on the ranks, each
its own part; ``--refined MAXH:K``); the shipped 3D femur with its hip stem
(``geometries/femur_stem_3d.toml``, Coulomb friction), refined by dividing
``maxh`` and ``interface_maxh`` by a factor.  Both at order 2 (the press
fit at ``--order``) with ``solver.linear = "iterative"`` (BDDC-CG, what
runs distributed).

Each run is a fresh process (one rank) or ``mpiexec -n N`` (N ranks).
NGSolve distributes the mesh to ranks 1 .. N-1 (rank 0 makes the mesh,
coarse where the ranks refine it, distributes it and lets it go, holding no
element of the solve): 2 ranks are one part, 3 ranks two parts.  Rank 0
still holds BDDC's coarse problem, which NGSolve's parallel BDDC gathers and
factorizes there (the wirebasket: the vertices and the whole interface
surface's dofs, ``ngcontact.fem.elasticity.surface_wirebasket``; a higher
order puts fewer vertices under as many dofs).  Post-processing is reduced over the ranks
(:mod:`ngcontact.distributed.reduced_measures`) and the VTK file written in
pieces.  One process runs without its discretization error estimate (the
solves at the neighbouring orders, which a distributed run does not make),
so that both do the same work.  Per run: dofs, the work's wall time (the
stages from meshing to post-processing), every rank's peak
resident memory (``VmHWM`` at its exit) and the whole command's wall time
(with starting the interpreters); per rank also its memory by phase
(``rank_memory.Phases``: at the start, the largest within the mesh, the
assemblies, CG, the round-off floors, the solve, post-processing and
writing, and what the solve leaves), into ``OUT/macro_mpi_phases.csv``.
``--guard START_GB FLOOR_GB``: each run starts only with ``START_GB``
available (waiting and retrying, then giving up) and is ended once less
than ``FLOOR_GB`` is left (``rank_memory.MemoryGuard``).

The model of 64 ranks is on paper: memory of a rank holding a part grows
linearly with its dofs and rank 0's with the whole mesh's; both lines are
fitted to the measured distributed runs of the scene with the largest run and evaluated at 63 parts.  The
time is the measured time per dof of a part (of the fastest run at the
largest size) times the dofs of a part
(BDDC-CG's iteration count grows only slowly with the size; communication
across machines is not in the model).

    python scripts/macro_mpi_scaling.py [OUT] [--maxh 0.004 0.002 0.001] [--femur 1 1.5]
                                        [--refined MAXH:K ...] [--ranks 1 2 3] [--bddc JSON ...]
                                        [--order P] [--rank-threads T ...] [--guard START_GB FLOOR_GB]
                                        [--code LABEL]
                                        [--rows-from CSV|DIR ...] [--phases-from CSV ...]
                                        [--measured-by MD] [--publish]

``--bddc``: flags of NGSolve's BDDC to compare (``linear_solver.BDDC_FLAGS`` in each run's processes), each
run with each; per run also the time the ranks holding the mesh spend in BDDC's coarse solves.
``--rank-threads``: NGSolve's threads of each rank of a distributed run (``NGCONTACT_THREADS`` per rank; e.g.
``1 2``: rank 0, which holds no element, on one thread and the part on 2), recorded per rank in the
``threads`` column.  MPICH's settings (``MPIR_CVAR_...``) reach the ranks from the environment; name them in
``--code`` (e.g. ``--code 6f44d61+heavy_yield``).

Writes ``OUT/macro_mpi_scaling.csv``, ``OUT/macro_mpi_phases.csv``, ``OUT/macro_mpi_model.csv`` and ``.png``
(default ``results/macro_mpi_scaling``).  ``--rows-from``: no runs, the rows
of earlier ones (their CSV files, or a folder holding ``macro_mpi_scaling.csv``,
``macro_mpi_phases.csv`` and ``measured_by.md``, the Markdown note of how they
were measured; ``--measured-by``: a further such note).  ``--publish`` keeps
what it publishes in the folder ``macro_mpi_rows.ARCHIVE`` (docs/benchmarks/macro_mpi), so
that the sections are published again from it, in any clone, by
``--rows-from docs/benchmarks/macro_mpi --publish`` (a short command in their
stamp), each row's ``code`` naming the commit it measured.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)
from macro_mpi_rows import KEYS, MEASURED, PHASES, ROWS, inputs, keep, read_rows, read_table  # noqa: E402
from rank_memory import PHASE_KEYS, PHASE_TABLE_KEYS, MemoryGuard, Phases, phase_rows, phase_table  # noqa: E402

from ngcontact.output.writer import write_csv  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: NGSolve's timer of BDDC's coarse solve (the wirebasket's), as the ranks holding the mesh see it
COARSE_TIMER = "Apply BDDC preconditioner - wb solve"
MODEL_KEYS = ("ndof", "ranks", "dofs_per_part", "part_gb", "rank0_gb", "solve_s_estimate")
#: the sizes of the model of 64 ranks
MODEL_NDOF = (2e6, 1e7, 5e7, 1e8)

PRESS_FIT = """\
kind = "macro"
title = "3D press fit of two tubes, a quarter (MPI scaling)"
[materials.steel]
E = 210e9
nu = 0.3
[materials.bone]
E = 17e9
nu = 0.3
[bodies]
rough = "steel"
counter = "bone"
[geometry]
shape = "coaxial"
setting = "3d"
[geometry.dimensions]
a = 0.004
b = 0.008
c = 0.014
height = 0.01
[interface]
law = "linear"
kn = 1e13
kt = 1e12
gap = -2e-6
[[supports]]
boundary = "bottom"
[[supports]]
boundary = "sym_x"
components = ["x"]
[[supports]]
boundary = "sym_y"
components = ["y"]
[[loads]]
boundary = "top"
pressure = 5e6
[discretization]
order = {order}
maxh = {size}
refinements = {refinements}
max_elements = 3000000
[solver]
linear = "iterative"
"""


def femur(factor: float) -> str:
    """The shipped 3D femur with ``maxh`` and ``interface_maxh`` divided by ``factor``, solved by BDDC-CG."""
    with open(os.path.join(ROOT, "geometries", "femur_stem_3d.toml")) as fh:
        text = fh.read()
    for key in ("maxh", "interface_maxh"):
        text = re.sub(rf"^{key} = ([0-9.e-]+)", lambda m: f"{key} = {float(m.group(1)) / factor:g}", text,
                      flags=re.M)
    return text.replace("\nrtol = 1e-10\n", '\nrtol = 1e-10\nlinear = "iterative"\n')


SCENES = {"press_fit": lambda size, k, p: PRESS_FIT.format(size=size, refinements=0, order=p),
          "press_fit_refined": lambda size, k, p: PRESS_FIT.format(size=size, refinements=k, order=p),
          "femur": lambda size, k, p: femur(size)}


def _peak_mb() -> float:
    """This process's peak resident memory [MB] (``VmHWM`` of /proc/self/status)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1024.0
    return float("nan")


def child(scene: str, out: str, bddc: str = "") -> int:
    """One rank of a run: solve and write as ``ngcontact run`` does, without the discretization error
    estimate in one process (as under MPI), with BDDC's flags ``bddc`` (JSON; empty: the solver's); its
    peak memory and the time of BDDC's coarse solves into a file."""
    import ngsolve as ng

    from ngcontact import runner
    from ngcontact.solvers import linear_solver
    if bddc:
        linear_solver.BDDC_FLAGS.update(json.loads(bddc))
    from ngcontact.distributed.macro_run import accuracy_not_estimated
    from ngcontact.distributed.vtk_pieces import written
    from ngcontact.distributed.world import launched_rank
    from ngcontact.drivers import run_macro
    from ngcontact.output.writer import write_outputs
    run_macro.accuracy = lambda scene, sol, solve, balance, *rest: accuracy_not_estimated(scene, sol, balance)
    phases = Phases()
    phases.install()
    report, outcome = runner.solve(scene)
    phases.enter("write the outputs")
    written(outcome, lambda: write_outputs(out, report, outcome))
    phases.leave()
    coarse = sum(t["time"] for t in ng.Timers() if t["name"] == COARSE_TIMER)
    with open(f"{out}_peak_rank{launched_rank()}.txt", "w") as fh:
        fh.write(f"{_peak_mb()} {coarse}\n")
    with open(f"{out}_phases_rank{launched_rank()}.json", "w") as fh:
        json.dump(phases.table(), fh)
    return 0


def launch(child: list[str], ranks: int, rank_threads: tuple[int, ...] = ()) -> list[str]:
    """The command running ``child`` in one process or on ``ranks`` ranks (``mpiexec``); with
    ``rank_threads`` rank r runs on ``rank_threads[min(r, len - 1)]`` threads (``NGCONTACT_THREADS`` of
    each rank, by mpiexec's form for several programs)."""
    if ranks == 1:
        return child
    if not rank_threads:
        return ["mpiexec", "-n", str(ranks)] + child
    cmd = ["mpiexec"]
    for r in range(ranks):
        threads = rank_threads[min(r, len(rank_threads) - 1)]
        cmd += ([":"] if r else []) + ["-n", "1", "-env", "NGCONTACT_THREADS", str(threads)] + child
    return cmd


def measure(name: str, size: float, ranks: int, work: str, refinements: int = 0, bddc: str = "", order: int = 2,
            guard: MemoryGuard | None = None, code: str = "", rank_threads: tuple[int, ...] = ()) -> dict:
    """One run of scene ``name`` at ``size`` (refined ``refinements`` times, the press fit at ``order``) on
    ``ranks`` ranks, with BDDC's flags ``bddc`` (JSON), each rank on its ``rank_threads`` (:func:`launch`),
    under the memory ``guard`` if given; its ranks' memory by phase goes to ``OUT_phase_table.csv`` beside
    its output, labelled ``code``."""
    rank_threads = rank_threads if ranks > 1 else ()
    tag = f"{name}_{size:g}_k{refinements}_p{order}_r{ranks}" + \
        (f"_{re.sub('[^a-z0-9]+', '', bddc.lower())}" if bddc else "") + \
        (f"_t{'-'.join(map(str, rank_threads))}" if rank_threads else "")
    scene = os.path.join(work, f"{tag}.toml")
    with open(scene, "w") as fh:
        fh.write(SCENES[name](size, refinements, order))
    out = os.path.join(work, tag)
    cmd = launch([sys.executable, os.path.abspath(__file__), "--child", scene, out, bddc], ranks, rank_threads)
    t0 = time.perf_counter()
    if guard is None:
        subprocess.run(cmd, check=True, env=dict(os.environ, MPLBACKEND="Agg"))
    else:
        guard.run(cmd, env=dict(os.environ, MPLBACKEND="Agg"))
    wall = time.perf_counter() - t0
    with open(os.path.join(out, "report.json")) as fh:
        rep = json.load(fh)
    peaks, coarse = [], []
    for r in range(ranks):
        with open(f"{out}_peak_rank{r}.txt") as fh:
            peak, seconds = fh.read().split()
        peaks.append(round(float(peak), 1))
        coarse.append(float(seconds))
    phases = phase_rows(out, ranks)
    write_csv(f"{out}_phases.csv", list(PHASE_KEYS), [[p.get(k, "") for k in PHASE_KEYS] for p in phases])
    for p in phases:
        print(" ".join(f"{k}={p.get(k, '')}" for k in PHASE_KEYS), flush=True)
    table = phase_table(phases, peaks, {"code": code, "scene": name, "ndof": rep["ndof"], "order": order,
                                        "ranks": ranks})
    write_csv(f"{out}_phase_table.csv", list(PHASE_TABLE_KEYS), [[t[k] for k in PHASE_TABLE_KEYS] for t in table])
    stages = {k: v for k, v in rep["timings"].items() if k != "total"}
    parts = peaks[1:] if ranks > 1 else peaks
    return {"code": code, "scene": name, "size": size, "refinements": refinements,
            "order": order if name != "femur" else 2, "ranks": ranks,
            "threads": " ".join(str(rank_threads[min(r, len(rank_threads) - 1)]) for r in range(ranks))
            if rank_threads else rep.get("threads", ""),
            "bddc": bddc or "default",
            "ndof": rep["ndof"],
            "work_s": round(sum(stages.values()), 2), "wall_s": round(wall, 2),
            "newton": rep["solver"]["iterations"],
            "cg_iterations": sum(rep["solver"]["linear"].get("cg_iterations", [])), "coarse_s": round(max(coarse), 2),
            "peak_mb_rank0": peaks[0], "peak_mb_parts_max": max(parts),
            "peak_mb_each": " ".join(f"{p:g}" for p in peaks), "tag": tag}


def model(data: list[dict], ranks: int = 64) -> list[dict]:
    """What ``ranks`` ranks would need at :data:`MODEL_NDOF` (see the module's docstring)."""
    dist = [d for d in data if d["ranks"] > 1]
    def problem(d: dict) -> str:            # the press fit made finer by maxh or by refinements: one problem
        return d["scene"].removesuffix("_refined")
    scene = problem(max(dist, key=lambda d: d["ndof"])) if dist else ""
    dist = [d for d in dist if problem(d) == scene]
    if len({d["ndof"] for d in dist}) < 2:
        return []
    part = np.array([d["ndof"] / (d["ranks"] - 1) for d in dist])
    ndof = np.array([d["ndof"] for d in dist], dtype=float)
    a1, a0 = np.polyfit(part, [d["peak_mb_parts_max"] for d in dist], 1)
    b1, b0 = np.polyfit(ndof, [d["peak_mb_rank0"] for d in dist], 1)
    if a1 <= 0 or b1 <= 0:
        return []
    largest = max(d["ndof"] for d in dist)
    big = min((d for d in dist if d["ndof"] == largest), key=lambda d: d["work_s"])   # the least disturbed
    per_dof = big["work_s"] / (big["ndof"] / (big["ranks"] - 1))
    rows = []
    for n in MODEL_NDOF:
        p = n / (ranks - 1)
        rows.append({"ndof": int(n), "ranks": ranks, "dofs_per_part": int(p),
                     "part_gb": round((a0 + a1 * p) / 1024, 2), "rank0_gb": round((b0 + b1 * n) / 1024, 2),
                     "solve_s_estimate": round(per_dof * p, 1)})
    return rows


def plot(data: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    for (name, r), mark in zip(sorted({(d["scene"], d["ranks"]) for d in data}), "os^vD<>ph*"):
        rows = sorted((d for d in data if d["scene"] == name and d["ranks"] == r), key=lambda d: d["ndof"])
        n = [d["ndof"] for d in rows]
        ax.loglog(n, [d["work_s"] for d in rows], mark + "-", label=f"{name}, {r} rank(s)")
        bx.loglog(n, [d["peak_mb_parts_max"] for d in rows], mark + "-",
                  label=f"{name}, {r} rank(s): " + ("largest part" if r > 1 else "the process"))
        if r > 1:
            bx.loglog(n, [d["peak_mb_rank0"] for d in rows], mark + ":", label=f"{name}, {r} ranks: rank 0")
    ax.set_xlabel("dofs")
    ax.set_ylabel("work time [s] (without the order ladder)")
    bx.set_xlabel("dofs")
    bx.set_ylabel("peak memory per rank [MB]")
    ax.legend(fontsize=7)
    bx.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


NOTE = ("`ngcontact run` of the 3D press fit and the 3D femur (order 2 unless `order` says otherwise; BDDC-CG) "
        "in one process and under "
        "`mpiexec -n 2` and `-n 3`. Rank 0 makes the mesh (press_fit_refined: the coarse one, which the "
        "ranks refine uniformly, each its part), distributes it and lets it go, holding no element of the "
        "solve but BDDC's coarse problem (NGSolve's parallel BDDC factorizes it on rank 0), so 2 ranks "
        "are one part and 3 ranks two parts. "
        "`work_s`: the stages from meshing to post-processing (one process without its discretization error "
        "estimate, which a distributed run does not make either). `peak_mb_each`: every rank's peak resident "
        "memory, rank 0 first. `code`: the commit measured. `threads`: NGSolve's threads per rank (one process: "
        "the cores, 2, unless `NGCONTACT_THREADS` says otherwise; N ranks share them; several numbers: each "
        "rank's, rank 0 first, set apart; empty: not recorded). "
        "`bddc`: the flags of NGSolve's BDDC (`default`: none; its coarse problem, the vertices and the "
        "interface surface, factorized by a sparse Cholesky, on rank 0 under MPI); rows with other flags "
        "compare the coarse solves NGSolve offers at one size: `coarsetype` `local` (a Jacobi sweep instead "
        "of the coarse factorization, on every rank) and `inverse` `umfpack`. `coarse_s`: the seconds the "
        "ranks holding the mesh spend in BDDC's coarse solves (NGSolve's timer of the wirebasket solve: "
        "under MPI their wait for rank 0; empty where not recorded). "
        "Measured on 2 cores shared with other jobs (3 ranks oversubscribe them): times are indicative, "
        "memory is not affected; the rows of code `56148f8` on the machine with nothing else running (load "
        "about 1).")
PHASES_NOTE = ("Every rank's resident memory [MB] by phase of the runs above that recorded it (sampled every "
               "50 ms: NGSolve allocates in C++, out of Python's sight): at its start (the interpreter with "
               "NGSolve and MPI loaded), the largest within the mesh (made, distributed), the assemblies (the "
               "matrix and BDDC, built by its assembly), CG, the round-off floors of the Newton step, the whole "
               "solve, post-processing and writing the outputs (the VTK piece), what the solve leaves, and the "
               "peak (`VmHWM`). `code`: the commit measured (`183c603`: before the round-off floors were "
               "taken in blocks; they copied the absolute values of all the tangent's entries at once). "
               "What a part holds at its peak is the tangent and BDDC's local matrices (its harmonic "
               "extensions and interior solves) as the assembly builds them; the mesh, the geometry and the "
               "interface law's data are a few tens of MB, the solve's matrices are let go before "
               "post-processing and the VTK piece, and rank 0 holds the whole mesh only until it is "
               "distributed. Storing the symmetric tangent as its lower triangle (NGSolve's "
               "`symmetric_storage`) would halve the matrix and BDDC's local matrices, but NGSolve's parallel "
               "BDDC refuses it (`CumulationOperator::Mult called, but y is not distributed` in CG's first "
               "preconditioner application on 2 ranks), so it is not used. With 2 ranks the part holds every "
               "element and the serial peak less the coarse factorization on rank 0; 3 ranks (2 parts, "
               "oversubscribing the 2 cores) show what distributing the elements gives.")
MODEL_NOTE = ("On paper, from the distributed runs above of the scene with the largest run (the press fit): the "
              "peak memory of the largest part fitted as a line in its dofs, rank 0's as a line in the whole "
              "mesh's dofs (BDDC's coarse problem, gathered there, grows with the whole mesh), both evaluated "
              "for 64 ranks (63 parts); "
              "the time is the work time per dof of a part of the fastest run at the largest size (the one "
              "least slowed by other jobs) times the dofs of a part (BDDC-CG "
              "iterations grow slowly with the size; communication across machines is not modelled). Rank 0 "
              "grows with the whole problem and is the limit: a coarse solve distributed over the ranks would "
              "remove it (NGSolve's own, MUMPS or hypre, is not built into its wheels, and its AMG of the "
              "coarse problem, `coarsetype` `h1amg`, refuses a distributed matrix). Its line is fitted to sizes "
              "close together and understates large runs, whose coarse factorization grows faster than linearly "
              f"(the attempt at 2M dofs in [{MEASURED}](benchmarks/macro_mpi/{MEASURED})).")


def write_and_publish(args, data: list[dict], work: str) -> None:
    """The CSV files and the plot of ``data`` (and the phase tables of its runs) under ``args.out``; with
    ``args.publish`` their sections of docs/benchmarks.md."""
    csv_path = os.path.join(args.out, "macro_mpi_scaling.csv")
    write_csv(csv_path, list(KEYS), [[d[k] for k in KEYS] for d in data])
    phases_path = os.path.join(args.out, "macro_mpi_phases.csv")
    tables = args.phases_from + [os.path.join(work, f"{d['tag']}_phase_table.csv") for d in data if d.get("tag")]
    write_csv(phases_path, list(PHASE_TABLE_KEYS), [[t[k] for k in PHASE_TABLE_KEYS] for path in tables
                                                     for t in read_table(path)])
    default = [d for d in data if d["bddc"] == "default"]     # the other flags' rows compare the coarse solve
    rows = model([d for d in default if int(d["order"]) == 2])    # the model: the order-2 runs' lines
    model_path = os.path.join(args.out, "macro_mpi_model.csv")
    write_csv(model_path, list(MODEL_KEYS), [[m[k] for k in MODEL_KEYS] for m in rows])
    png = os.path.join(args.out, "macro_mpi_scaling.png")
    plot(default, png)
    for m in rows:
        print(" ".join(f"{k}={m[k]}" for k in MODEL_KEYS))
    if args.publish:
        notes = args.notes + ([args.measured_by] if args.measured_by else [])
        keep(csv_path, phases_path if tables else None, notes)
        measured = (f" How the rows of each `code` were measured, and what they show: "
                    f"[{MEASURED}](benchmarks/macro_mpi/{MEASURED})." if notes else "")
        benchmark_doc.publish("macro_mpi_scaling", "The 3D press fit and femur on 1, 2 and 3 MPI ranks", csv_path,
                              note=NOTE + measured, png=png)
        if tables:
            benchmark_doc.publish("macro_mpi_phases", "Where a rank's memory goes: its phases", phases_path,
                                  note=PHASES_NOTE)
        benchmark_doc.publish("macro_mpi_model", "What 64 MPI ranks would need (a paper model)", model_path,
                              note=MODEL_NOTE)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--child"]:
        return child(*argv[1:4])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "macro_mpi_scaling"), help="output directory")
    ap.add_argument("--maxh", type=float, nargs="*", default=[0.004, 0.002, 0.001], help="press fit mesh sizes [m]")
    ap.add_argument("--femur", type=float, nargs="*", default=[1.0, 1.5], help="femur refinement factors")
    ap.add_argument("--refined", nargs="*", default=[], metavar="MAXH:K",
                    help="press fit meshes made with MAXH and refined K times uniformly (on the ranks under MPI)")
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 3], help="numbers of MPI ranks")
    ap.add_argument("--bddc", nargs="+", default=[""], metavar="JSON",
                    help='flags of NGSolve\'s BDDC to compare, each run with each (e.g. \'{"inverse": "umfpack"}\'; '
                         '"": the solver\'s)')
    ap.add_argument("--order", type=int, default=2, help="the press fit's polynomial order")
    ap.add_argument("--rank-threads", type=int, nargs="+", default=[], metavar="T",
                    help="runs on several ranks: rank r on the r-th T threads (the last for the rest; e.g. 1 2: "
                         "rank 0 on one, the parts on 2), instead of the cores shared evenly")
    ap.add_argument("--guard", type=float, nargs=2, default=None, metavar=("START_GB", "FLOOR_GB"),
                    help="start each run only with START_GB available (MemAvailable; waits and retries, then gives "
                         "up) and end it once less than FLOOR_GB is left (a large run on a shared machine)")
    ap.add_argument("--code", default="", help="the label of the code measured in the phase table (default: the "
                    "commit)")
    ap.add_argument("--phases-from", nargs="+", default=[], metavar="CSV",
                    help="the phase tables (RUN_phase_table.csv) of earlier runs to publish with these runs'")
    ap.add_argument("--rows-from", nargs="+", default=[], metavar="CSV|DIR",
                    help="no runs: the rows of these CSV files of earlier runs (e.g. a large size run apart), or "
                         f"of folders holding {ROWS}, {PHASES} and {MEASURED} (e.g. docs/benchmarks/macro_mpi)")
    ap.add_argument("--measured-by", default="", metavar="MD",
                    help="with --rows-from: a Markdown file saying how its CSV files' rows were measured, kept with "
                         "the folders' notes")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    if any(t < 1 for t in args.rank_threads):
        ap.error(f"--rank-threads {' '.join(map(str, args.rank_threads))}: each rank's threads, integers >= 1")
    args.code = args.code or benchmark_doc.git_commit()
    work = os.path.abspath(os.path.join(args.out, "runs"))
    os.makedirs(work, exist_ok=True)
    runs = [("press_fit", h, 0) for h in args.maxh] + [("femur", f, 0) for f in args.femur] + \
        [("press_fit_refined", float(r.split(":")[0]), int(r.split(":")[1])) for r in args.refined]
    rows_from, phases_from, args.notes = inputs(args.rows_from)
    args.phases_from = phases_from + args.phases_from
    data = [row for path in rows_from for row in read_rows(path)]
    for name, size, k in ([] if args.rows_from else runs):
        for r, flags in ((r, f) for r in args.ranks for f in args.bddc):
            guard = MemoryGuard(*args.guard) if args.guard else None
            try:
                data.append(measure(name, size, r, work, k, flags, args.order, guard, args.code,
                                    tuple(args.rank_threads)))
            except RuntimeError as exc:            # the memory guard did not start or ended the run
                print(f"{name} {size:g} refined {k} on {r} rank(s): {exc}", flush=True)
                continue
            print(" ".join(f"{k}={data[-1][k]}" for k in KEYS), flush=True)
    write_and_publish(args, data, work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
