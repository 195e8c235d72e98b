"""Westergaard's sinusoid: this package's cell solver and an FFT half-space solver side by side.

The benchmark of the exact-contact issue: the flat cell with the initial gap
``g = 2h sin^2(pi x)`` (``h = 0.01``, period 1, both bodies ``E = 1``,
``nu = 0.3``, so ``E* = 1 / (2 (1 - nu^2))``) under the four mean pressures
``p/p* = 0.05, 0.2, 0.5, 0.8`` with ``p* = pi E* h`` (Westergaard 1939;
:mod:`ngcontact.verification.westergaard`).  For every setting the four
loads are solved in one run and timed together (wall time on the machine's
cores), and two errors are recorded against the closed form:

* the worst relative error of the contact fraction over the four loads;
* the worst relative L2 error of the contact pressure over the four loads.

This package, spectral: the small-slope cell of two layers ``DEPTH`` thick
solved on a grid with FFTs and exact contact
(:mod:`ngcontact.cell.spectral.layered_cell`), from ``N = 2^10`` to ``2^16`` points,
the contact edges placed between grid points; and the same refined from
``N = 2^10`` to the tolerances 1e-4, 1e-5, 1e-6 (the refinement of
``geometries/cells/westergaard_exact.toml``), every level timed.

This package, FE: the FE cell of :class:`ngcontact.cell.fe.cell_problem.CellProblem`
(bodies 2 periods deep, so that their finite depth changes the half-space
answer by less than 1e-10) over a ladder of orders, interface mesh sizes and
penalties, on fixed meshes and on meshes graded towards the contact edges to
a tolerance (``discretization.tolerance``), with the penalty and with exact
contact (``contact.enforcement = "exact"``: node-to-node, the pressure the
multiplier); the contact fraction is the
package's own measure and the pressure is the penalty pressure at the
contact term's quadrature (exact: the multiplier's interpolant).  The penalty is part of the package's model (the
paper's Winkler layer): its own shift of the answer is in the error.  The
graded penalty rows are run twice: on their own (the FE cost alone), and as
``ngcontact run`` runs them, each load's first mesh seeded with the contact
edges of the cell's spectral twin and every level started from the twin
(:mod:`ngcontact.cell.fe.edge_grading`; the twin's solves in the time).

The peer: Tamaas (the ``bench`` extra, ``pip install ".[bench]"``), the
Polonsky-Keer-Rey FFT solver on one elastic half-space against a rigid
sinusoid of the same ``p/p*`` (Westergaard's answer depends on ``p/p*``
only), from ``N = 2^10`` grid points upwards until the worst fraction error
passes 1e-5 or a run takes more than 60 s.  Its contact fraction is the
share of grid points with positive pressure.  Without Tamaas the peer is
skipped with a message.

Writes ``westergaard_vs_fft.csv`` and ``westergaard_vs_fft.png`` (work
against precision of both, contact fraction and pressure) into the output
directory (default ``results/westergaard_vs_fft``) and logs the table.

Usage::

    python scripts/westergaard_vs_fft.py [OUT_DIR] [--quick]
"""
from __future__ import annotations

import argparse
import logging
import math
import os
import sys
import time
from dataclasses import replace

import numpy as np
import ngsolve as ng
from ngcontact import runner

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.edge_grading import graded_flat_cell, solve_to_tolerance
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral_start import SpectralStart, twin_edges
from ngcontact.cell.spectral.refinement import sweep_to_tolerance
from ngcontact.errors import ConvergenceError
from ngcontact.fem.materials import isotropic
from ngcontact.output.writer import write_csv
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import (westergaard_contact_fraction, westergaard_p_star,
                                                westergaard_pressure)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

log = logging.getLogger("westergaard_vs_fft")

H_GAP, NU, DEPTH = 0.01, 0.3, 2.0
RATIOS = (0.05, 0.2, 0.5, 0.8)
#: (order, interface_maxh, k_n / E, tolerance or None, enforcement) of this package's ladder: fixed
#: meshes, then meshes graded towards the contact edges to a tolerance; the penalty, then exact contact
#: (k_n its augmentation)
LADDER = ((2, 0.02, 1e3, None, "penalty"), (3, 0.01, 1e3, None, "penalty"), (3, 0.005, 1e3, None, "penalty"),
          (4, 0.005, 1e4, None, "penalty"), (2, 0.02, 1e4, 1e-3, "penalty"), (3, 0.02, 1e6, 1e-3, "penalty"),
          (3, 0.02, 1e6, 1e-4, "penalty"), (3, 0.02, 1e6, 3e-5, "penalty"),
          (3, 0.01, 1e5, None, "exact"), (3, 0.005, 1e5, None, "exact"), (3, 0.02, 1e5, 1e-4, "exact"))
QUICK_LADDER = (LADDER[0], LADDER[4], LADDER[8])
#: (order, interface_maxh, k_n / E, tolerance) of the graded penalty rows run as ``ngcontact run`` runs them: each
#: load's first mesh seeded with the spectral twin's edges, every level started from the twin
TWIN_LADDER = ((3, 0.02, 1e6, 1e-3), (3, 0.02, 1e6, 1e-4), (3, 0.02, 1e6, 3e-5))
#: the twin's grid (``ngcontact.drivers.build.TWIN_GRID``'s bound for 2D cells, which a graded solve takes)
TWIN_POINTS = 8192
FFT_START, FFT_TARGET, FFT_BUDGET = 2 ** 10, 1e-5, 60.0
#: grids of the spectral cell (exact contact, layers DEPTH thick)
SPECTRAL_GRIDS = tuple(2 ** k for k in range(10, 17))
#: tolerances of the spectral cell refined from the first grid (discretization.tolerance)
SPECTRAL_TOLERANCES = (1e-4, 1e-5, 1e-6)
KEYS = ("solver", "setting", "ndof", "worst_fraction_error", "worst_pressure_error", "seconds",
        "iterations_per_load")


def _exact_pressure_cf(p: float, pstar: float):
    """Westergaard's pressure as a CoefficientFunction of ``x`` (contact centred at ``x = 0``)."""
    sa = p / pstar
    s = ng.sin(math.pi * ng.x) ** 2
    return 2.0 * p * ng.sqrt(ng.cos(math.pi * ng.x) ** 2) * ng.sqrt(ng.IfPos(sa - s, sa - s, 0.0)) / sa


def ours(order: int, ih: float, kn: float, tolerance: float | None = None, enforcement: str = "penalty",
         twin: bool = False) -> dict:
    """The four loads on FE cells; errors and wall time.

    The first load starts from the rigid predictor, not from the spectral
    predictor (``ngcontact run``'s start for this small-slope cell): its twin
    is the spectral cell these rows are compared with, and the FE rows keep
    their cost their own.  With ``twin`` (and a tolerance) the rows are
    ``ngcontact run``'s: the penalty twin on ``TWIN_POINTS`` points seeds each
    load's first graded mesh with its contact edges and starts every level
    (:mod:`ngcontact.cell.fe.edge_grading`), its solves in the time.

    Without ``tolerance``: one mesh, the loads continued from one another.
    With it: each load on its own meshes, graded towards its contact edges
    until the estimate meets the tolerance (:mod:`ngcontact.cell.fe.edge_grading`).
    """
    pstar = westergaard_p_star(e_star(1.0, NU, 1.0, NU), H_GAP, 1.0)
    law = isotropic(1.0, NU)
    model = CellModel(rough=law, counter=law, k_n=kn, gap=2 * H_GAP * ng.sin(math.pi * ng.x) ** 2, order=order,
                      enforcement=enforcement)

    t0 = time.perf_counter()
    spectral_twin = None
    if twin:
        x = np.arange(TWIN_POINTS) / TWIN_POINTS
        spectral_twin = SpectralCell(dim=2, period=1.0, grid=TWIN_POINTS, rough=Layer(1.0, NU, DEPTH),
                                     counter=Layer(1.0, NU, DEPTH), gap=2 * H_GAP * np.sin(np.pi * x) ** 2, k_n=kn,
                                     enforcement="penalty", tol=1e-8)

    def make_problem(vertices, p):
        cell = graded_flat_cell(1.0, DEPTH, DEPTH, maxh=0.3, interface_maxh=ih, order=p, vertices=vertices)
        return CellProblem(cell, replace(model, order=p), max_iter=100,
                           predictor=None if spectral_twin is None else SpectralStart(spectral_twin))

    fractions, pressures, steps, ndof = [], [], [], 0
    with runner.threads(runner.thread_count()):   # as ngcontact run: task manager, BLAS on one thread
        P = make_problem([], order)
        for k, r in enumerate(RATIOS):
            load = cell_load(2, pressure=r * pstar)
            if tolerance is None:
                sol = P.solve(load, first=(k == 0), measure=False)
            else:
                seed = twin_edges(spectral_twin, load) if spectral_twin is not None else None
                graded = solve_to_tolerance(make_problem, load, tolerance, ih, 1.0, order, seed=seed)
                P, sol = graded.problem, graded.solution
            fractions.append(sol.results["contact_fraction"])
            steps.append(sol.iterations if tolerance is None else sum(h["newton_iterations"] for h in graded.history))
            ndof = max(ndof, P.ndof)
            exact = _exact_pressure_cf(r * pstar, pstar)
            o = P.contact_order
            err = ng.Integrate((P.pressure - exact) ** 2, P.mesh, definedon=P.mesh.Boundaries("contact"), order=o)
            ref = ng.Integrate(exact ** 2, P.mesh, definedon=P.mesh.Boundaries("contact"), order=o)
            pressures.append(math.sqrt(max(err, 0.0) / ref))
    secs = time.perf_counter() - t0
    ferr = max(abs(f - westergaard_contact_fraction(r * pstar, pstar)) / westergaard_contact_fraction(r * pstar, pstar)
               for f, r in zip(fractions, RATIOS))
    setting = f"order {order}, interface_maxh {ih:g}, k_n {kn:g} E"
    if tolerance is not None:
        setting += f", graded to tolerance {tolerance:g}"
    if twin:
        setting += ", seeded by the spectral twin"
    return {"solver": "ngcontact" if enforcement == "penalty" else "ngcontact exact", "setting": setting,
            "ndof": ndof, "worst_fraction_error": ferr,
            "worst_pressure_error": max(pressures), "seconds": secs,
            "iterations_per_load": " ".join(str(s) for s in steps)}


def _westergaard_cell(n: int) -> SpectralCell:
    x = np.arange(n) / n
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, DEPTH), counter=Layer(1.0, NU, DEPTH),
                        gap=2 * H_GAP * np.sin(np.pi * x) ** 2, k_n=1.0, enforcement="exact")


def _spectral_errors(n: int, sols, pstar: float) -> tuple[float, float]:
    """Worst relative fraction and pressure errors of a spectral sweep on ``n`` points."""
    x = np.arange(n) / n
    xc = np.where(x > 0.5, x - 1.0, x)
    ferr = perr = 0.0
    for r, sol in zip(RATIOS, sols):
        exact_f = westergaard_contact_fraction(r * pstar, pstar)
        ferr = max(ferr, abs(sol.results["contact_fraction"] - exact_f) / exact_f)
        pe = westergaard_pressure(xc, r * pstar, pstar, 1.0)
        perr = max(perr, float(np.linalg.norm(sol.fields["pressure"] - pe) / np.linalg.norm(pe)))
    return ferr, perr


def spectral(n: int) -> dict:
    """The four loads on the spectral cell of ``n`` grid points (exact contact); errors and wall time."""
    pstar = westergaard_p_star(e_star(1.0, NU, 1.0, NU), H_GAP, 1.0)
    t0 = time.perf_counter()
    cell = _westergaard_cell(n)
    sols = cell.sweep([cell_load(2, pressure=r * pstar) for r in RATIOS])
    secs = time.perf_counter() - t0
    ferr, perr = _spectral_errors(n, sols, pstar)
    return {"solver": "ngcontact spectral", "setting": f"N = {n}, exact", "ndof": n, "worst_fraction_error": ferr,
            "worst_pressure_error": perr, "seconds": secs,
            "iterations_per_load": " ".join(str(s.iterations) for s in sols)}


def spectral_to_tolerance(tolerance: float) -> dict:
    """The four loads on the spectral cell refined from ``N = 2^10`` until the estimate meets ``tolerance``.

    The refinement of the scene ``geometries/cells/westergaard_exact.toml``
    (:mod:`ngcontact.cell.spectral.refinement`), called directly: where the 2D stiffness ends at its cap the
    sweep of the other quantities is timed, which a scene stating the tolerance would refuse (exit 3); the
    time includes every level.
    """
    pstar = westergaard_p_star(e_star(1.0, NU, 1.0, NU), H_GAP, 1.0)
    t0 = time.perf_counter()
    refined = sweep_to_tolerance(_westergaard_cell, [cell_load(2, pressure=r * pstar) for r in RATIOS], tolerance,
                                 SPECTRAL_GRIDS[0], 2, 2 ** 24)
    secs = time.perf_counter() - t0
    n = refined.cell.grid
    ferr, perr = _spectral_errors(n, refined.solutions, pstar)
    grids = " -> ".join(str(h["grid"]) for h in refined.history)
    return {"solver": "ngcontact spectral", "setting": f"to tolerance {tolerance:g} (N = {grids}), exact",
            "ndof": n, "worst_fraction_error": ferr, "worst_pressure_error": perr, "seconds": secs,
            "iterations_per_load": " ".join(str(s.iterations) for s in refined.solutions)}


def tamaas_available() -> bool:
    try:
        import tamaas  # noqa: F401
    except ImportError:
        return False
    return True


def fft(n: int) -> dict:
    """Tamaas on ``n`` grid points, the four loads; errors and wall time."""
    import tamaas as tm

    tm.set_log_level(tm.LogLevel.error)
    t0 = time.perf_counter()
    model = tm.ModelFactory.createModel(tm.model_type.basic_1d, [1.0], [n])
    model.E, model.nu = 1.0, 0.0          # E* = E / (1 - nu^2) = 1 against a rigid surface
    pstar = math.pi * 1.0 * H_GAP          # p* = pi E* h / lambda
    x = np.arange(n) / n
    surface = -2.0 * H_GAP * np.sin(np.pi * x) ** 2
    solver = tm.PolonskyKeerRey(model, surface, 1e-12)
    ferr, perr, iters = 0.0, 0.0, []
    for r in RATIOS:
        solver.solve(r * pstar)
        p = np.asarray(model.traction).ravel()
        exact_f = westergaard_contact_fraction(r * pstar, pstar)
        ferr = max(ferr, abs(np.mean(p > 0) - exact_f) / exact_f)
        pe = westergaard_pressure(x, r * pstar, pstar, 1.0)
        perr = max(perr, float(np.sqrt(np.mean((p - pe) ** 2) / np.mean(pe ** 2))))
        iters.append("-")
    secs = time.perf_counter() - t0
    return {"solver": "tamaas", "setting": f"N = {n}", "ndof": n, "worst_fraction_error": ferr,
            "worst_pressure_error": perr, "seconds": secs, "iterations_per_load": " ".join(iters)}


def run(quick: bool = False) -> list[dict]:
    rows = []
    for order, ih, kn, tol, enforcement in (QUICK_LADDER if quick else LADDER):
        try:
            rows.append(ours(order, ih, kn, tol, enforcement))
        except ConvergenceError as exc:  # a tolerance out of reach is a figure too, not a crash
            log.warning("ngcontact order %d, k_n %g, tolerance %s: %s", order, kn, tol, exc)
            continue
        log.info("%s", _fmt(rows[-1]))
    for order, ih, kn, tol in TWIN_LADDER[:1] if quick else TWIN_LADDER:
        try:
            rows.append(ours(order, ih, kn, tol, twin=True))
        except ConvergenceError as exc:
            log.warning("ngcontact order %d, k_n %g, tolerance %s, seeded: %s", order, kn, tol, exc)
            continue
        log.info("%s", _fmt(rows[-1]))
    for n in SPECTRAL_GRIDS[:2] if quick else SPECTRAL_GRIDS:
        rows.append(spectral(n))
        log.info("%s", _fmt(rows[-1]))
    for tol in SPECTRAL_TOLERANCES[:1] if quick else SPECTRAL_TOLERANCES:
        rows.append(spectral_to_tolerance(tol))
        log.info("%s", _fmt(rows[-1]))
    if not tamaas_available():
        log.warning("Tamaas is not installed (pip install '.[bench]'): the FFT peer is skipped")
        return rows
    n = FFT_START
    while True:
        rows.append(fft(n))
        log.info("%s", _fmt(rows[-1]))
        last = rows[-1]
        if last["worst_fraction_error"] <= FFT_TARGET or last["seconds"] > FFT_BUDGET or (quick and n >= 2 ** 12):
            break
        n *= 2
    return rows


def _fmt(r: dict) -> str:
    return (f"{r['solver']:9s} {r['setting']:40s} ndof={r['ndof']:<7d} "
            f"fraction err={r['worst_fraction_error']:.2e} pressure err={r['worst_pressure_error']:.2e} "
            f"t={r['seconds']:.2f}s Newton/load={r['iterations_per_load']}")


def time_at(rows: list[dict], solver: str, target: float) -> float | None:
    """Shortest wall time of ``solver`` whose worst fraction error is at most ``target``."""
    times = [r["seconds"] for r in rows if r["solver"] == solver and r["worst_fraction_error"] <= target]
    return min(times) if times else None


def plot(rows: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key, title in zip(axes, ("worst_fraction_error", "worst_pressure_error"),
                              ("contact fraction", "pressure (relative L2)")):
        series = (("ngcontact, fixed meshes", "o-",
                   lambda r: r["solver"] == "ngcontact" and "graded" not in r["setting"]),
                  ("ngcontact, graded to a tolerance", "D-",
                   lambda r: r["solver"] == "ngcontact" and "graded" in r["setting"] and "twin" not in r["setting"]),
                  ("ngcontact, graded, seeded by the spectral twin", "P-",
                   lambda r: r["solver"] == "ngcontact" and "twin" in r["setting"]),
                  ("ngcontact, FE exact contact", "v-", lambda r: r["solver"] == "ngcontact exact"),
                  ("ngcontact, spectral cell (exact)", "^-", lambda r: r["solver"] == "ngcontact spectral"),
                  ("tamaas (FFT)", "s--", lambda r: r["solver"] == "tamaas"))
        for label, style, take in series:
            sel = [r for r in rows if take(r)]
            if sel:
                ax.loglog([r["seconds"] for r in sel], [max(r[key], 1e-16) for r in sel], style, label=label)
        ax.set_xlabel("wall time, four loads [s]")
        ax.set_ylabel("worst relative error over the four loads")
        ax.set_title(f"Westergaard: {title}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "westergaard_vs_fft"),
                    help="output directory")
    ap.add_argument("--quick", action="store_true", help="two settings of each solver only (a smoke run)")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    for quiet in ("ngcontact.cell.fe.edge_grading", "ngcontact.solvers.newton"):
        logging.getLogger(quiet).setLevel(logging.WARNING)
    rows = run(quick=args.quick)
    os.makedirs(args.out, exist_ok=True)
    write_csv(os.path.join(args.out, "westergaard_vs_fft.csv"), list(KEYS), [[r[k] for k in KEYS] for r in rows])
    plot(rows, os.path.join(args.out, "westergaard_vs_fft.png"))
    reached = []
    for target in (1e-4, 1e-5, 1e-6):
        times = {name: time_at(rows, name, target)
                 for name in ("ngcontact", "ngcontact exact", "ngcontact spectral", "tamaas")}
        log.info("time to a worst fraction error <= %g: %s", target, ", ".join(
            f"{name} {t:.2f} s" if t is not None else f"{name} not reached" for name, t in times.items()))
        reached.append(f"{target:g}: " + ", ".join(f"{name} {t:.3g} s" if t is not None else f"{name} not reached"
                                                  for name, t in times.items()))
    log.info("wrote %s", os.path.join(args.out, "westergaard_vs_fft.csv"))
    if args.publish:
        benchmark_doc.publish("westergaard_vs_fft", "Westergaard's sinusoid: this package beside an FFT half-space "
                              "solver", os.path.join(args.out, "westergaard_vs_fft.csv"),
                              note="Four mean pressures solved in one run per setting: the worst relative errors "
                                   "of the contact fraction and of the pressure (L2) against the closed form, "
                                   "wall seconds, iterations per load. Time to a worst fraction error of "
                                   + "; ".join(reached) + ".",
                              png=os.path.join(args.out, "westergaard_vs_fft.png"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
