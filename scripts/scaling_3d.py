"""3D at scale: cost against size of a 3D cell and a 3D macro problem, direct and iterative; the bisinusoid aim.

Five measurements, one run, one CSV and one PNG:

1. **3D cell** (``geometries/cells/bisinusoid.toml``: order 2, the scene's
   pressure), refining ``interface_maxh``: the Newton solve of one load with
   ``solver.linear = "direct"`` (sparse Cholesky; up to ``--direct-max``
   dofs) and ``"iterative"`` (BDDC-preconditioned CG,
   :mod:`ngcontact.solvers.linear_solver`), started as ``ngcontact run``
   starts it: on the contact set of the spectral twin
   (:mod:`ngcontact.cell.spectral_start`), whose solve is timed with it.
2. **3D macro press fit** (two coaxial tubes, a quarter, interference 1e-3,
   a tabulated nonlinear normal law so that Newton iterates, 0.1 on the top),
   refining ``maxh`` at order 2, the same two solvers.
3. **Bisinusoid aim** (gap ``A (2 - cos 2 pi x - cos 2 pi y)``, ``A = 0.005``,
   two half-spaces ``E = 1, nu = 0.3``, mean pressures giving about 20 % and
   60 % contact): the spectral cell from 64^2 to 512^2 against Tamaas at
   1024^2 (the ``bench`` extra; skipped with a message without it): contact
   fraction against wall time.

4. **Accuracy aim** (issue 38: within 1 % of the converged contact fraction
   at ``p/p* = 0.005, 0.02, 0.05`` in at most 60 s each): the FE cell with
   exact contact on the bisinusoid against the converged spectral cell,
   its mesh refined along its spectral twin's contact edge (``edge`` rows,
   ``--accuracy-edges``, ``--accuracy-orders``) or, order 1, along the edge
   and in the bodies below and above the patch, the sizes scaled with the
   patch radius (``patch`` rows, ``--accuracy-patch``), each on the whole period and on its
   mirror-symmetric quarter side by side (column ``cell``, ``--accuracy-cells``); the sibling module
   ``bisinusoid_accuracy.py`` says what is solved.  Column
   ``relative_error``; the seconds include the twin, the meshing and the
   solve (threads: ``--accuracy-threads``), and each phase on its own.  The
   order-2 rows' extrapolations carry the estimate of the contact-edge ladder
   (:mod:`ngcontact.cell.fe.contact_edge_refinement`): the larger of the grid
   convergence index and the spectral twin's floor, each in its own column,
   and their effectivity against the converged value.
5. **The aim as a scene** (``scene``, ``bisinusoid_aim.py``): the same bisinusoid
   posed as a scene, one ``ngcontact run`` per load on one thread, its
   contact-edge ladder's contact fraction and estimate, wall and CPU seconds.

Parts 4 and 5 score their contact fractions against the one converged value
(``bisinusoid_accuracy.converged``), and so does ``--republish`` the kept rows.

Every solve of parts 1 and 2 runs in its own child process, so that its peak
memory (``VmHWM``) is its own.  Reported per solve: dofs, wall time of the
setup and solve (not the meshing), for a cell also the time of the
measurement ``ngcontact run`` makes after it (effective stiffness: a Schur
complement by the same linear-solver policy; stresses), Newton steps, CG
iterations, peak memory (measurement included), contact fraction; per
solver the exponent ``b`` of ``time ~ dofs^b`` fitted over the sizes.

With ``--republish CSV`` it measures nothing: it reads the measured rows of
an earlier run's ``scaling_3d.csv``, makes the rows derived from them again
(the edge-size extrapolations) and writes (and publishes) them as a run.
With ``--keep-rows CSV`` it measures as asked and keeps that earlier run's rows
above the new ones (a run adding rows to a published table, which ``--publish``
rewrites whole); the section says which rows are whose, and whether the
accuracy aim is met and by which row.  Either takes a folder holding a
``scaling_3d.csv`` too.  ``--publish`` keeps the published rows in the folder
docs/benchmarks/scaling_3d with ``measured_by.md``, the note of which commands
and commits measured them (:mod:`scaling_3d_rows`), so that the section is
published again, in any clone, by
``python scripts/scaling_3d.py --republish docs/benchmarks/scaling_3d --publish``.

With ``--breakdown INTERFACE_MAXH`` or ``--coarse INTERFACE_MAXH [--k-n K]`` it
runs instead one of the BDDC studies of :mod:`scaling_3d_bddc` (its own CSV, PNG and section).

Usage::

    python scripts/scaling_3d.py [OUT_DIR] [--quick] [--direct-max 45000] [--parts cell macro spectral accuracy scene]
                                 [--accuracy-edges [EDGE_MAXH ...]] [--accuracy-orders 1 2]
                                 [--accuracy-patch N_EDGE N_BODY DEPTH | --accuracy-no-patch]
                                 [--accuracy-patch-growth GROWTH] [--accuracy-cells quarter period]
                                 [--accuracy-threads N]
                                 [--solvers iterative direct] [--breakdown INTERFACE_MAXH]
                                 [--coarse INTERFACE_MAXH [--k-n K]] [--republish CSV|DIR] [--keep-rows CSV|DIR]

Writes ``scaling_3d.csv`` and ``scaling_3d.png`` into ``OUT_DIR`` (default
``results/scaling_3d``) and logs the tables and the fitted exponents.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import subprocess
import sys
import time

import numpy as np

from ngcontact.output.writer import write_csv

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)
from bisinusoid_accuracy import ACC_CELLS, ACC_EDGES, ACC_PATCH, QUICK_EDGES, REF_GRIDS, accuracy_aim  # noqa: E402
from bisinusoid_aim import aim_status, plot_aim, scene_rows  # noqa: E402
from scaling_3d_bddc import period_scene, study  # noqa: E402
from scaling_3d_rows import ARCHIVE, MEASURED, keep, measured, read_rows, with_extrapolations  # noqa: E402

log = logging.getLogger("scaling_3d")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# 0.021: 301k dofs (issue 13's 300k aim); 0.02 crashes Netgen's CSG mesher on this cell, 0.022 gives fewer dofs
# than 0.023
CELL_SIZES = (0.12, 0.08, 0.06, 0.045, 0.035, 0.025, 0.021, 0.016)
MACRO_SIZES = (0.3, 0.2, 0.14, 0.1, 0.075, 0.041)
QUICK_CELL, QUICK_MACRO = (0.16, 0.12), (0.35, 0.3)
AMPLITUDE, PRESSURES = 0.005, (0.00185, 0.0065)
SPECTRAL_GRIDS, TAMAAS_GRID = (64, 128, 256, 512), 1024
KEYS = ("part", "solver", "cell", "size", "ndof", "seconds", "cpu_seconds", "measure_seconds", "twin_seconds",
        "mesh_seconds", "solve_seconds", "newton_steps", "cg_iterations", "peak_memory_gb", "contact_fraction",
        "pressure", "relative_error", "estimate", "estimate_gci", "estimate_twin", "effectivity")


def peak_memory_gb() -> float:
    """This process's peak resident memory (``VmHWM``)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 2 ** 20
    return float("nan")


def cell_child(size: float, policy: str) -> dict:
    from ngcontact import runner
    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.drivers.build import build_cell, cell_loads, model_of, predictor_twin
    from ngcontact.solvers.linear_solver import LinearSolver
    scene = period_scene()
    cell = build_cell(scene, interface_maxh=size)
    with runner.threads(runner.thread_count()):   # as ngcontact run: task manager, BLAS on one thread
        t0 = time.perf_counter()
        # as ngcontact run: the first load starts from the spectral twin's contact set
        P = CellProblem(cell, model_of(scene), linear=LinearSolver(policy), predictor=predictor_twin(scene, size))
        first = cell_loads(scene)[0]
        sol = P.solve(first, first=True, measure=False)
        secs = time.perf_counter() - t0
        P.measure(first)                                # what ngcontact run reports: effective stiffness, stresses
        measure_secs = time.perf_counter() - t0 - secs
    return {"part": "cell", "solver": policy, "size": size, "ndof": P.ndof, "seconds": secs,
            "measure_seconds": measure_secs,
            "newton_steps": sol.iterations, "cg_iterations": sum(P.linear.iterations),
            "contact_fraction": sol.results["contact_fraction"], "pressure": sol.results["mean_pressure"]}


def macro_child(size: float, policy: str) -> dict:
    from ngcontact import runner
    from ngcontact.fem.materials import isotropic
    from ngcontact.geometry import bodies as gm
    from ngcontact.laws import homogenized as il
    from ngcontact.macro import macro_problem as M
    from ngcontact.solvers.linear_solver import LinearSolver
    g = gm.coaxial_3d(0.5, 1.0, 1.6, 1.0, maxh=size, order=2)
    law = il.InterfaceLaw(normal=il.TabulatedLaw(closure=(0.0, 5e-4, 2e-3), pressure=(0.0, 0.05, 0.5), kt=100.0))
    linear = LinearSolver(policy)
    with runner.threads(runner.thread_count()):   # as ngcontact run: task manager, BLAS on one thread
        t0 = time.perf_counter()
        sol = M.solve(M.MacroProblem(mesh=g.mesh, setting="3d", rough="inner", counter="outer",
                                     materials={"inner": isotropic(200.0, 0.3), "outer": isotropic(70.0, 0.25)},
                                     law=law, gap=-1e-3, order=2,
                                     supports=(M.Support(label="bottom"), M.Support(label="sym_x", components=("x",)),
                                               M.Support(label="sym_y", components=("y",))),
                                     loads=(M.Load(label="top", pressure=0.1),)), linear=linear)
        secs = time.perf_counter() - t0
    return {"part": "macro", "solver": policy, "size": size, "ndof": sol.gfu.space.ndof, "seconds": secs,
            "newton_steps": sol.history["newton_iterations"], "cg_iterations": sum(linear.iterations),
            "contact_fraction": "", "pressure": ""}


def child(argv: list[str]) -> None:
    part, size, policy = argv[0], float(argv[1]), argv[2]
    row = (cell_child if part == "cell" else macro_child)(size, policy)
    row["peak_memory_gb"] = peak_memory_gb()
    print(json.dumps(row))


def run_child(part: str, size: float, policy: str) -> dict | None:
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", part, str(size), policy],
                         capture_output=True, text=True)
    if out.returncode != 0:
        log.warning("%s %s at size %g failed: %s", part, policy, size, out.stderr.strip().splitlines()[-1:])
        return None
    row = json.loads(out.stdout.strip().splitlines()[-1])
    log.info("%-5s %-9s size %-6g ndof %8d: %7.1f s, %3d Newton, %5d CG, %.2f GB", part, policy, size, row["ndof"],
             row["seconds"], row["newton_steps"], row["cg_iterations"], row["peak_memory_gb"])
    return row


def fe_parts(quick: bool, direct_max: int, parts=("cell", "macro"), solvers=("iterative", "direct")) -> list[dict]:
    rows = []
    ladders = (("cell", QUICK_CELL if quick else CELL_SIZES), ("macro", QUICK_MACRO if quick else MACRO_SIZES))
    for part, sizes in ladders:
        if part not in parts:
            continue
        direct_on = True
        for size in sizes:
            for policy in solvers:
                if policy == "direct" and not direct_on:
                    continue
                row = run_child(part, size, policy)
                if row is None:
                    continue
                rows.append(row)
                if policy == "direct" and row["ndof"] > direct_max:
                    direct_on = False
    return rows


def spectral_aim(quick: bool) -> list[dict]:
    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
    from ngcontact.geometry.cell3d import bisinusoid_gap
    rows = []

    def gap(n):
        s = np.arange(n) / n
        return bisinusoid_gap(AMPLITUDE, 1.0, xy=(s[None, :], s[:, None]))

    for n in SPECTRAL_GRIDS[:2] if quick else SPECTRAL_GRIDS:
        for p in PRESSURES:
            t0 = time.perf_counter()
            cell = SpectralCell(dim=3, period=1.0, grid=n, rough=Layer(1.0, 0.3, 50.0), counter=Layer(1.0, 0.3, 50.0),
                                gap=gap(n), k_n=1.0, enforcement="exact")
            sol = cell.solve(cell_load(3, pressure=p))
            rows.append({"part": "bisinusoid", "solver": "ngcontact spectral", "size": n, "ndof": n * n,
                         "seconds": time.perf_counter() - t0, "newton_steps": "", "cg_iterations": sol.iterations,
                         "peak_memory_gb": "", "contact_fraction": sol.results["contact_fraction"], "pressure": p})
    try:
        import tamaas as tm
    except ImportError:
        log.warning("Tamaas is not installed (pip install '.[bench]'): the FFT peer is skipped")
        return rows
    tm.set_log_level(tm.LogLevel.error)
    n = 256 if quick else TAMAAS_GRID
    for p in PRESSURES:
        t0 = time.perf_counter()
        model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
        model.E, model.nu = 1.0 / (2 * (1 - 0.3 ** 2)), 0.0      # one half-space of the pair's E*
        solver = tm.PolonskyKeerRey(model, np.ascontiguousarray(-gap(n)), 1e-10)
        solver.max_iter = 100000
        solver.solve(p)
        tr = np.array(model.traction).reshape(n, n)
        rows.append({"part": "bisinusoid", "solver": "tamaas", "size": n, "ndof": n * n,
                     "seconds": time.perf_counter() - t0, "newton_steps": "", "cg_iterations": "",
                     "peak_memory_gb": "", "contact_fraction": float(np.mean(tr > 0)), "pressure": p})
    return rows


def exponent(rows: list[dict], part: str, solver: str) -> float | None:
    sel = [r for r in rows if r["part"] == part and r["solver"] == solver]
    if len(sel) < 2:
        return None
    b, _ = np.polyfit(np.log([r["ndof"] for r in sel]), np.log([r["seconds"] for r in sel]), 1)
    return float(b)


def plot(rows: list[dict], path: str) -> None:
    """One panel per part with rows in this table: cost against dofs of parts 1 and 2, the spectral cell
    against Tamaas, the aim (:func:`bisinusoid_aim.plot_aim`)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fe = [part for part in ("cell", "macro") if any(r["part"] == part for r in rows)]
    spectral = any(r["solver"] == "tamaas" for r in rows)
    aim = any(r["part"] in ("accuracy", "scene") for r in rows)
    n = max(len(fe) + spectral + aim, 1)
    fig, axes = plt.subplots(1, n, figsize=(5 * n, 4.2), squeeze=False)
    panels = iter(axes[0])
    for part, ax in zip(fe, panels):            # fe first: zip stops on it before taking a panel
        for solver, style in (("iterative", "o-"), ("direct", "s--")):
            sel = [r for r in rows if r["part"] == part and r["solver"] == solver]
            if sel:
                b = exponent(rows, part, solver)
                ax.loglog([r["ndof"] for r in sel], [r["seconds"] for r in sel], style,
                          label=f"{solver} (time ~ N^{b:.2f})" if b is not None else solver)
                measured = [r for r in sel if r.get("measure_seconds") not in (None, "")]
                if measured:
                    ax.loglog([r["ndof"] for r in measured], [r["measure_seconds"] for r in measured], style[0] + ":",
                              label=f"{solver}: measurement after the solve")
        ax.set_xlabel("dofs")
        ax.set_ylabel("wall time, setup and solve [s]")
        ax.set_title("3D cell (bisinusoid)" if part == "cell" else "3D macro press fit")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    if spectral:
        ax = next(panels)
        for p in PRESSURES:
            ref = [r for r in rows if r["part"] == "bisinusoid" and r["solver"] == "tamaas" and r["pressure"] == p]
            sel = [r for r in rows if r["part"] == "bisinusoid" and r["solver"] == "ngcontact spectral"
                   and r["pressure"] == p]
            if ref and sel:
                f0 = ref[0]["contact_fraction"]
                ax.loglog([r["seconds"] for r in sel], [max(abs(r["contact_fraction"] / f0 - 1), 1e-8) for r in sel],
                          "^-", label=f"spectral, p = {p:g} (Tamaas {TAMAAS_GRID}^2: {f0:.4f})")
        ax.axhline(5e-3, color="k", lw=0.8, ls=":", label="0.5 %")
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("contact fraction, relative to Tamaas 1024^2")
        ax.set_title("bisinusoid, 20 % and 60 % contact")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    if aim:
        plot_aim(next(panels), rows)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def measured_rows(args) -> list[dict]:
    """The rows of the parts asked for (``args.parts``), measured."""
    rows = fe_parts(args.quick, args.direct_max, args.parts, args.solvers)
    if "spectral" in args.parts:
        rows += spectral_aim(args.quick)
    if "accuracy" in args.parts:
        edges = args.accuracy_edges if args.accuracy_edges is not None else QUICK_EDGES if args.quick else ACC_EDGES
        rows += accuracy_aim(edges, tuple(args.accuracy_orders), None if args.accuracy_no_patch else
                             tuple(args.accuracy_patch), args.accuracy_threads, args.accuracy_patch_growth,
                             tuple(args.accuracy_cells))
    if "scene" in args.parts:
        rows += scene_rows(os.path.join(args.out, "scene"))
    return rows


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "--child":
        child(argv[1:])
        return 0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "scaling_3d"), help="output directory")
    ap.add_argument("--quick", action="store_true", help="two small sizes of each part (a smoke run)")
    ap.add_argument("--direct-max", type=int, default=45000,
                    help="no direct solves beyond the first size above this many dofs")
    ap.add_argument("--parts", nargs="+", choices=("cell", "macro", "spectral", "accuracy", "scene"),
                    default=("cell", "macro", "spectral", "accuracy", "scene"),
                    help="which of the five measurements to run (default: all)")
    ap.add_argument("--solvers", nargs="+", choices=("iterative", "direct"), default=("iterative", "direct"),
                    help="which linear solvers of parts 1 and 2 to run (default: both)")
    ap.add_argument("--breakdown", type=float, default=None, metavar="INTERFACE_MAXH",
                    help="instead: where an iterative cell solve of this interface mesh size spends its time")
    ap.add_argument("--coarse", type=float, default=None, metavar="INTERFACE_MAXH",
                    help="instead: BDDC's coarse problem on the converged cell of this interface mesh size, the "
                         "bubble term's gamma against the contact surface on the wirebasket")
    ap.add_argument("--accuracy-edges", type=float, nargs="*", default=None, metavar="EDGE_MAXH",
                    help="the edge element sizes of part 4's edge-refined rows (default 0.02 0.01; --quick: 0.02; "
                         "none: no such rows)")
    ap.add_argument("--accuracy-orders", type=int, nargs="+", default=(1,), choices=(1, 2),
                    help="the orders of part 4's edge-refined rows (2: on a linear trace; default 1)")
    ap.add_argument("--accuracy-patch", type=float, nargs=3, default=ACC_PATCH, metavar=("N_EDGE", "N_BODY", "DEPTH"),
                    help="part 4's patch-refined rows: edge a/N_EDGE, bodies a/N_BODY to DEPTH a, a the twin's patch "
                         "radius (default %s)" % " ".join(f"{v:g}" for v in ACC_PATCH))
    ap.add_argument("--accuracy-patch-growth", type=float, default=0.0, metavar="GROWTH",
                    help="part 4's patch-refined rows: the bodies' size a/N_BODY + GROWTH |z| at depth |z| "
                         "(default 0: a/N_BODY to DEPTH a)")
    ap.add_argument("--accuracy-no-patch", action="store_true", help="no patch-refined rows in part 4")
    ap.add_argument("--accuracy-cells", nargs="+", choices=ACC_CELLS, default=ACC_CELLS,
                    help="part 4's cells, side by side: the mirror-symmetric quarter, the whole period (default both)")
    ap.add_argument("--accuracy-threads", type=int, default=None,
                    help="threads of part 4's FE solves (default: as ngcontact run)")
    ap.add_argument("--k-n", type=float, default=None, help="with --coarse: the penalty k_n (default the scene's)")
    ap.add_argument("--republish", metavar="CSV|DIR", default=None,
                    help="instead of measuring: the rows an earlier run measured (its scaling_3d.csv, or a folder "
                         "holding one: docs/benchmarks/scaling_3d keeps the published rows), the rows derived from "
                         "them made again, written (and with --publish published) as a run's")
    ap.add_argument("--keep-rows", metavar="CSV|DIR", default=None,
                    help="the rows an earlier run measured (its scaling_3d.csv, or a folder holding one) kept above "
                         "those measured now, their derived rows made again: a run that adds rows to a published "
                         "table")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    if args.republish and args.keep_rows:
        ap.error("--republish measures nothing, --keep-rows keeps rows above those measured: give one of them")
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    if study(args):                     # --breakdown or --coarse: a BDDC study instead
        return 0
    kept = read_rows(args.republish or args.keep_rows) if args.republish or args.keep_rows else []
    new = [] if args.republish else measured(measured_rows(args))
    rows = with_extrapolations(kept + new)          # the derived rows last, made from every measured row
    os.makedirs(args.out, exist_ok=True)
    write_csv(os.path.join(args.out, "scaling_3d.csv"), list(KEYS), [[r.get(k, "") for k in KEYS] for r in rows])
    plot(rows, os.path.join(args.out, "scaling_3d.png"))
    fits = []
    for part in ("cell", "macro"):
        for solver in ("iterative", "direct"):
            b = exponent(rows, part, solver)
            if b is not None:
                log.info("%s, %s: time ~ dofs^%.2f", part, solver, b)
                fits.append(f"{part} {solver} `time ~ dofs^{b:.2f}`")
    log.info("wrote %s", os.path.join(args.out, "scaling_3d.csv"))
    if args.publish:
        keep(os.path.join(args.out, "scaling_3d.csv"), args.republish or args.keep_rows, len(kept), len(new))
        archive = os.path.relpath(ARCHIVE, os.path.join(ROOT, "docs"))
        benchmark_doc.publish("scaling_3d", "3D at scale: direct against iterative; the bisinusoid aim",
                              os.path.join(args.out, "scaling_3d.csv"),
                              note=("Rows measured by earlier runs (re-read with `--republish`; their "
                                    "timings, their machine's load), the extrapolated rows made again from them. "
                                    if args.republish else "") +
                                   (f"The first {len(kept)} rows were measured by an earlier run (its CSV kept "
                                    "with `--keep-rows`: its timings, its machine's load), the others by this "
                                    "one, the extrapolated rows made from all. " if args.keep_rows else "") +
                                   f"The rows are kept in `docs/{archive}/`; which commands measured them, at "
                                   f"which commits, on how many threads and under which load: "
                                   f"[{MEASURED}]({archive}/{MEASURED}). " + aim_status(rows) + " " +
                                   "Part `cell`: the 3D bisinusoid cell (order 2) refined, one load by sparse "
                                   "Cholesky (`direct`) and BDDC-CG (`iterative`), started as `ngcontact run` "
                                   "starts it; part `macro`: a 3D press fit of two tubes; part `spectral`: the "
                                   "spectral cell against Tamaas (skipped without the `bench` extra); part `accuracy`: "
                                   "the FE cell (exact) on the mesh refined along its spectral twin's contact edge "
                                   "(`edge-refined`, `size`: the edge's element size; order 1, or order 2 on a "
                                   "linear trace on S_C with rows `extrapolated`: Richardson in the edge size "
                                   "over the sizes listed, `estimate` its estimated relative error as the contact-"
                                   "edge ladder of `ngcontact run` makes it, the larger of `estimate_gci` (the "
                                   "grid convergence index of the extrapolation) and `estimate_twin` (the spectral "
                                   "twin's floor |q - q_N| + 2 |q_N - q_N/2|, N = 2048 whatever the finest edge "
                                   "size), `effectivity` = estimate / |relative_error|) or, order 1, "
                                   "along the edge and in the bodies below and above the patch (`patch-refined`, "
                                   "`size`: edge a/N_EDGE, bodies a/N_BODY to DEPTH a, a the twin's patch radius; "
                                   "`growth G`: the bodies' size a/N_BODY + G |z| at depth |z|), each on the whole "
                                   "period and on its mirror-symmetric quarter (`cell`: `period`, `quarter`: the "
                                   "same sizes, zero normal displacement on the quarter's mirror faces), "
                                   "per `pressure` = p/p* "
                                   "(p* = pi E* h, h = 0.01, E* = 1), `relative_error` of the contact fraction "
                                   f"against the spectral cell extrapolated from {REF_GRIDS[0]}^2 and "
                                   f"{REF_GRIDS[1]}^2, the kept rows' errors too (issue 38 aims "
                                   "at 1 % in 60 s; seconds: twin, meshing and solve, each on its own in "
                                   "`twin_seconds`, `mesh_seconds`, `solve_seconds`" + (
                                       f", {args.accuracy_threads} thread(s)" if args.accuracy_threads else "") +
                                   "); part `scene`: the bisinusoid posed as a scene, one `ngcontact run` per "
                                   "load on one thread, the contact fraction its contact-edge ladder reports "
                                   "(`size`: its levels), `estimate` its own (relative), `cpu_seconds` the run's "
                                   "CPU time, `seconds` its wall time; timings under the load of other jobs. "
                                   "Seconds of "
                                   "setup and solve, of the measurement after it, Newton steps, CG iterations, "
                                   "peak memory. Fitted: " + ("; ".join(fits) if fits else "none") + ".",
                              png=os.path.join(args.out, "scaling_3d.png"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
