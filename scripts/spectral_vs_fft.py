"""The spectral small-slope cell beside an FFT half-space solver and beside the FE cell.

Four measurements, one run, one CSV and one PNG:

1. **Half-space limit against Tamaas** (the ``bench`` extra; skipped with a
   message without it).  A random self-affine surface (Hurst exponent 0.8,
   RMS slope 0.1, roll-off at a quarter period, cut-off at 1/64 of the
   period; :func:`ngcontact.geometry.random_surface.self_affine`, seed 7),
   drawn once on the finest grid and sampled on every coarser one (its
   spectrum ends below their Nyquist wave number, so it is the same surface),
   pressed by one mean pressure.  This package: two identical layers 50
   periods thick (``E = 1``, ``nu = 0.3``: a half-space pair of
   ``E* = E / (2 (1 - nu^2))``), exact contact.  Tamaas: its
   Polonsky-Keer-Rey solver on one half-space of the same ``E*`` against
   the rigid surface.  Both with the same tolerance on the same grid from
   128^2 to 1024^2: contact fraction (share of grid points in contact),
   relative L2 difference of the pressure fields, iterations and wall time.
2. **FE cell against the spectral cell** on the shipped bisinusoid
   (``geometries/cells/bisinusoid.toml``: finite layers 0.6 thick, the
   penalty of the scene): the FE cell over a ladder of interface mesh sizes,
   each solved on the mesh its row names (``discretization.estimate =
   "estimate"``: not refined towards the default tolerance), its contact
   fraction's error estimate (one order more on the same mesh) beside its
   true error against the spectral cell at 512^2 (its own change from 256^2
   as its estimate); contact fraction, mean closure and the far-face
   stiffness.
3. **Issue 38's random map against Tamaas** (skipped without the ``bench``
   extra for Tamaas' rows): the random 64 x 64 map of
   ``scripts/random_map_accuracy.py`` (issue 35's cell), its bilinear
   interpolant sampled on ``MAP_GRID``^2 (1024^2), the same two thick layers
   as part 1 (the half-space pair Tamaas solves), the three mean pressures of
   that script, each load started from the previous one's pressure (as
   ``SpectralCell.sweep`` runs a scene's loads; the first load's time holds the cell's set-up).  Tamaas:
   ``PolonskyKeerRey`` on the same samples, one model per load.  Both stop at
   ``TOL``, each by its own rule: ours the largest complementarity violation
   of the gap relative to its peak-to-valley height
   (:mod:`ngcontact.solvers.constrained_cg`), Tamaas' a relative residual of
   its own; the contact fractions and the relative L2 difference of the
   pressure fields show both answers are the same to far below the
   discretization.  Per load: contact fraction, CG steps (ours), seconds.
4. **Dissimilar finite layers** (``E = 1, 3``, ``nu = 0.3, 0.25``, 0.5 and
   0.3 thick) on the same surface: frictionless at 1024^2, and with exact
   Coulomb friction (``mu = 0.5``) under a mean shear of 0.2 times the
   pressure at 512^2 (the frictional solver's steps and time at each grid are
   measured by ``scripts/spectral_friction_speed.py``): wall time and peak
   memory of the whole process (each run in a child process).

Part 3's threads: ours the run's (``NGCONTACT_THREADS``, else every core), Tamaas' its OpenMP default (every
core).

Usage::

    python scripts/spectral_vs_fft.py [OUT_DIR] [--quick] [--fe-sizes 0.12 0.08 0.06] [--random-map-only]

``--quick`` runs parts 1 and 2 on small grids and part 3 on 256^2; ``--random-map-only`` runs part 3 alone
(its rows, CSV and PNG; ``--publish`` is refused with it, so that the published table stays whole).

Writes ``spectral_vs_fft.csv`` and ``spectral_vs_fft.png`` into ``OUT_DIR``
(default ``results/spectral_vs_fft``) and logs the tables.
"""
from __future__ import annotations

import argparse
import json
import logging
import os
import resource
import subprocess
import sys
import time
from dataclasses import replace

import numpy as np

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.geometry.random_surface import self_affine
from ngcontact.output.writer import write_csv

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

log = logging.getLogger("spectral_vs_fft")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
E, NU, THICK = 1.0, 0.3, 50.0
E_STAR = E / (2 * (1 - NU ** 2))
SLOPE, HURST, SEED = 0.1, 0.8, 7
PRESSURE = 0.05 * E_STAR * SLOPE          # about 10 % contact (Persson: fraction ~ 2 p / (E* slope))
MU, SHEAR = 0.5, 0.2                      # part 3 with friction: Coulomb mu, mean shear / mean pressure
FRICTION_GRID = 512                       # part 3 with friction (1024^2 takes over 10 minutes: see the note)
GRIDS, FINEST = (128, 256, 512, 1024), 1024
MAP_GRID, MAP_GRID_QUICK = 1024, 256        # part 3: the random map's grid (issue 38: 1024^2)
SPECTRAL_GRID, SPECTRAL_GRID_QUICK = 512, 128  # part 2: the spectral reference's grid
TOL = 1e-10
KEYS = ("part", "solver", "setting", "grid_or_ndof", "contact_fraction", "estimate", "true_error",
        "pressure_l2_difference", "mean_closure", "stiffness", "iterations", "seconds", "peak_memory_gb")


def surface(n: int) -> np.ndarray:
    """The benchmark surface on an ``n x n`` grid (sampled from the finest grid)."""
    z = self_affine(dim=3, grid=FINEST, hurst=HURST, rms_slope=SLOPE, rolloff=0.25, cutoff=1 / 64, seed=SEED)
    step = FINEST // n
    return z[::step, ::step]


def ours(z: np.ndarray, rough=None, counter=None, friction=None, shear=None) -> tuple[dict, np.ndarray]:
    n = z.shape[0]
    t0 = time.perf_counter()
    cell = SpectralCell(dim=3, period=1.0, grid=n, rough=rough or Layer(E, NU, THICK),
                        counter=counter or Layer(E, NU, THICK), gap=z.max() - z, k_n=1.0, enforcement="exact",
                        tol=TOL, friction=friction, max_iter=100000)
    sol = cell.solve(cell_load(3, pressure=PRESSURE, shear=shear))
    secs = time.perf_counter() - t0
    r = sol.results
    # the share of grid points in contact, as Tamaas reports it (``contact_fraction`` locates the edges between points)
    return ({"solver": "ngcontact spectral", "grid_or_ndof": n, "contact_fraction": r["contact_fraction_grid"],
             "mean_closure": r["mean_closure"], "stiffness": r["effective_stiffness"]["total"][0][0],
             "iterations": sol.iterations, "seconds": secs}, sol.fields["pressure"])


def tamaas_available() -> bool:
    try:
        import tamaas  # noqa: F401
    except ImportError:
        return False
    return True


def tamaas(z: np.ndarray) -> tuple[dict, np.ndarray]:
    import tamaas as tm
    tm.set_log_level(tm.LogLevel.error)
    n = z.shape[0]
    t0 = time.perf_counter()
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
    model.E, model.nu = E_STAR, 0.0          # one half-space of E / (1 - nu^2) = E* against a rigid surface
    solver = tm.PolonskyKeerRey(model, np.ascontiguousarray(z), TOL)
    solver.max_iter = 100000
    solver.solve(PRESSURE)
    p = np.array(model.traction).reshape(n, n)
    secs = time.perf_counter() - t0
    return ({"solver": "tamaas", "grid_or_ndof": n, "contact_fraction": float(np.mean(p > 0)),
             "iterations": "", "seconds": secs}, p)


def half_space(quick: bool) -> list[dict]:
    rows = []
    have = tamaas_available()
    if not have:
        log.warning("Tamaas is not installed (pip install '.[bench]'): the FFT peer is skipped")
    for n in (GRIDS[:2] if quick else GRIDS):
        z = surface(n)
        a, pa = ours(z)
        a.update(part="half_space", setting=f"{n}^2, exact, tol {TOL:g}")
        rows.append(a)
        if have:
            b, pb = tamaas(z)
            diff = float(np.linalg.norm(pa - pb) / np.linalg.norm(pb))
            b.update(part="half_space", setting=f"{n}^2, tol {TOL:g}", pressure_l2_difference=diff)
            a["pressure_l2_difference"] = diff
            rows.append(b)
            log.info("%4d^2: fraction ours %.6f tamaas %.6f (diff %.1e), pressure L2 diff %.1e, time ours %.2f s "
                     "(%d CG steps) tamaas %.2f s", n, a["contact_fraction"], b["contact_fraction"],
                     abs(a["contact_fraction"] - b["contact_fraction"]), diff, a["seconds"], a["iterations"],
                     b["seconds"])
        else:
            log.info("%4d^2: fraction ours %.6f, %.2f s (%d CG steps)", n, a["contact_fraction"], a["seconds"],
                     a["iterations"])
    return rows


def random_map(quick: bool) -> list[dict]:
    """Part 3: the random 64 x 64 map on ``MAP_GRID``^2, three loads, ours and Tamaas' (module docstring)."""
    import random_map_accuracy as rma
    n = MAP_GRID_QUICK if quick else MAP_GRID
    g0 = rma.map_gap(n)
    setting = f"{n}^2, map {rma.SAMPLES}^2 bilinear, exact, tol {TOL:g}"
    t0 = time.perf_counter()
    cell = SpectralCell(dim=3, period=1.0, grid=n, rough=Layer(E, NU, THICK), counter=Layer(E, NU, THICK), gap=g0,
                        k_n=1.0, enforcement="exact", tol=TOL, max_iter=100000)
    ends: list[float] = []
    sols: list = []
    for p in rma.PRESSURES:  # as SpectralCell.sweep: each load from the previous one's pressure, timed one by one
        sols.append(cell.solve(cell_load(3, pressure=p), start=sols[-1].fields["pressure"] if sols else None))
        ends.append(time.perf_counter())
    rows = []
    for k, (p, sol, end) in enumerate(zip(rma.PRESSURES, sols, ends)):
        r = sol.results
        rows.append({"part": "random_map", "solver": "ngcontact spectral", "setting": f"{setting}, p = {p}",
                     "grid_or_ndof": n, "contact_fraction": r["contact_fraction_grid"],
                     "mean_closure": r["mean_closure"], "iterations": sol.iterations,
                     "seconds": end - (ends[k - 1] if k else t0)})
    if not tamaas_available():
        log.warning("random map: Tamaas is not installed (pip install '.[bench]'): its rows are skipped")
        return rows
    import tamaas as tm
    tm.set_log_level(tm.LogLevel.error)
    surface = np.ascontiguousarray(-g0)
    for row, p, sol in zip(list(rows), rma.PRESSURES, sols):
        t0 = time.perf_counter()
        model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [n, n])
        model.E, model.nu = E_STAR, 0.0          # one half-space of E / (1 - nu^2) = E* against a rigid surface
        solver = tm.PolonskyKeerRey(model, surface, TOL)
        solver.max_iter = 100000
        solver.solve(p)
        pt = np.array(model.traction).reshape(n, n)
        secs = time.perf_counter() - t0
        pa = sol.fields["pressure"]
        diff = float(np.linalg.norm(pa - pt) / np.linalg.norm(pt))
        row["pressure_l2_difference"] = diff
        rows.append({"part": "random_map", "solver": "tamaas", "setting": f"{n}^2, tol {TOL:g}, p = {p}",
                     "grid_or_ndof": n, "contact_fraction": float(np.mean(pt > 0)), "pressure_l2_difference": diff,
                     "iterations": "", "seconds": secs})
    log.info("random map %d^2, three loads: ours %.2f s (%s CG steps), tamaas %.2f s: ratio %.3g", n,
             random_map_seconds(rows, "ngcontact spectral"), "/".join(str(s.iterations) for s in sols),
             random_map_seconds(rows, "tamaas"), random_map_ratio(rows))
    return rows


def random_map_seconds(rows: list[dict], solver: str) -> float:
    """Part 3's seconds of ``solver`` over the three loads."""
    return sum(r["seconds"] for r in rows if r["part"] == "random_map" and r["solver"] == solver)


def random_map_ratio(rows: list[dict]) -> float:
    """Part 3's Tamaas seconds over ours (above 1: ours faster)."""
    return random_map_seconds(rows, "tamaas") / random_map_seconds(rows, "ngcontact spectral")


def random_map_note(rows: list[dict]) -> str:
    """The published sentence on part 3: the times, the ratio and issue 38's aim (<= 15 s)."""
    mine = [r for r in rows if r["part"] == "random_map" and r["solver"] == "ngcontact spectral"]
    if not mine:
        return ""
    ours_s = random_map_seconds(rows, "ngcontact spectral")
    text = (f"Part 3 (random map, {mine[0]['grid_or_ndof']}^2, three loads): ours {ours_s:.3g} s "
            f"({'/'.join(str(r['iterations']) for r in mine)} CG steps), issue 38's aim <= 15 s "
            f"{'met' if ours_s <= 15 else 'not met'}")
    if not any(r["part"] == "random_map" and r["solver"] == "tamaas" for r in rows):
        return text + "; Tamaas skipped: not importable here."
    diffs = ", ".join(f"{r['pressure_l2_difference']:.2g}" for r in mine)
    return (text + f"; Tamaas' PolonskyKeerRey {random_map_seconds(rows, 'tamaas'):.3g} s at the same grid and "
            f"tolerance: ratio {random_map_ratio(rows):.3g} (Tamaas / ours); pressure L2 differences {diffs}.")


def run_variant(scene, **changes):
    """``ngcontact run`` of ``scene`` with its fields replaced (the scene's folder kept): ``(outcome, first
    load's results, wall seconds)``."""
    from ngcontact.drivers import run_cell
    from ngcontact.output.report import Clock
    sc = replace(scene, **changes)
    object.__setattr__(sc, "base_dir", scene.base_dir)
    t0 = time.perf_counter()
    out = run_cell.run(sc, Clock())
    return out, out.results["loads"][0], time.perf_counter() - t0


def fe_against_spectral(sizes, quick: bool) -> list[dict]:
    """Part 2 (module docstring), each row the discretization it names: FE ``estimate = "estimate"`` (one order
    more, :mod:`ngcontact.cell.fe.saturation`; the default refinement had solved 0.12 and 0.06 alike on 38,826
    dofs), the spectral cell ``estimate = "off"`` on ``G``^2 and ``(G/2)``^2, ``G``^2 the reference."""
    from ngcontact.scene.loader import load
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    grid = SPECTRAL_GRID_QUICK if quick else SPECTRAL_GRID
    fractions = {}
    for n in (grid // 2, grid):
        out, load0, secs = run_variant(scene, discretization=replace(scene.discretization, method="spectral", grid=n,
                                                                     estimate="off"))
        fractions[n] = load0["contact_fraction"]
    reference = fractions[grid]
    rows = [{"part": "bisinusoid", "solver": "ngcontact spectral", "setting": f"grid {grid}", "grid_or_ndof": out.ndof,
             "contact_fraction": reference, "estimate": abs(reference - fractions[grid // 2]),
             "mean_closure": load0["mean_closure"], "stiffness": load0["effective_stiffness"]["total"][-1][-1],
             "iterations": out.solver["iterations"], "seconds": secs}]
    log.info("bisinusoid spectral %d^2: fraction %.5f (change from %d^2: %.2g; %.1f s)", grid, reference, grid // 2,
             rows[0]["estimate"], secs)
    for h in sizes:
        out, load0, secs = run_variant(scene, discretization=replace(scene.discretization, interface_maxh=h,
                                                                     estimate="estimate"))
        estimate = load0.get("error_estimate", {}).get("contact_fraction")
        rows.append({"part": "bisinusoid", "solver": "ngcontact fe",
                     "setting": f"order {scene.discretization.order}, interface_maxh {h:g}, one order more",
                     "grid_or_ndof": out.ndof, "contact_fraction": load0["contact_fraction"],
                     "estimate": "" if estimate is None else estimate,
                     "true_error": abs(load0["contact_fraction"] - reference),
                     "mean_closure": load0["mean_closure"], "stiffness": load0["effective_stiffness"]["total"][-1][-1],
                     "iterations": out.solver["iterations"], "seconds": secs})
        log.info("bisinusoid %-40s ndof %8d: fraction %.5f, estimate %s, true error %.2g (%.1f s)",
                 rows[-1]["setting"], out.ndof, load0["contact_fraction"],
                 "none" if estimate is None else f"{estimate:.2g}", rows[-1]["true_error"], secs)
    return rows


def peak_memory_gb() -> float:
    """This process's peak resident memory (``VmHWM``: unlike ``ru_maxrss`` it does not carry over, through
    ``exec``, the size of the parent that forked the child)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 2 ** 20
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20


def dissimilar_child(friction: bool) -> None:
    """Part 3 in this (child) process: print its row as JSON."""
    from ngcontact.laws.friction import Coulomb
    n = FRICTION_GRID if friction else FINEST
    z = surface(n)
    fr = Coulomb(w=1e-6, mu=MU) if friction else None
    row, _ = ours(z, rough=Layer(1.0, 0.3, 0.5), counter=Layer(3.0, 0.25, 0.3), friction=fr,
                  shear=(SHEAR * PRESSURE, 0.0) if friction else None)
    row.update(part="dissimilar", setting=f"{n}^2, E 1 / 3, h 0.5 / 0.3, exact" + (
               f", Coulomb mu {MU}, shear {SHEAR} p" if friction else ", frictionless"),
               peak_memory_gb=peak_memory_gb())
    print(json.dumps(row))


def dissimilar() -> list[dict]:
    rows = []
    for flag in ("--dissimilar-child", "--dissimilar-friction-child"):
        out = subprocess.run([sys.executable, os.path.abspath(__file__), flag], check=True, capture_output=True,
                             text=True)
        rows.append(json.loads(out.stdout.strip().splitlines()[-1]))
        log.info("%s: %.2f s, %d iterations, peak memory %.2f GB, fraction %.5f", rows[-1]["setting"],
                 rows[-1]["seconds"], rows[-1]["iterations"], rows[-1]["peak_memory_gb"], rows[-1]["contact_fraction"])
    return rows


def plot(rows: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(18, 4))
    hs = [r for r in rows if r["part"] == "half_space"]
    for solver, style in (("ngcontact spectral", "o-"), ("tamaas", "s--")):
        sel = [r for r in hs if r["solver"] == solver]
        if sel:
            axes[0].semilogx([r["grid_or_ndof"] for r in sel], [r["contact_fraction"] for r in sel], style,
                             label=solver, base=2)
            axes[1].loglog([r["grid_or_ndof"] for r in sel], [r["seconds"] for r in sel], style, label=solver,
                           base=2)
    axes[0].set(xlabel="grid points per direction", ylabel="contact fraction", title="half-space limit: fraction")
    axes[1].set(xlabel="grid points per direction", ylabel="wall time [s]", title="half-space limit: time")
    bis = [r for r in rows if r["part"] == "bisinusoid"]
    fe = [(r["grid_or_ndof"], r["contact_fraction"]) for r in bis if r["solver"] == "ngcontact fe"]
    spectral = [(r["setting"], r["contact_fraction"]) for r in bis if r["solver"] == "ngcontact spectral"]
    estimates = [r["estimate"] if r.get("estimate") != "" else 0.0 for r in bis if r["solver"] == "ngcontact fe"]
    fe_against_spectral_panel(axes[2], fe, spectral, "", estimates)
    random_map_panel(axes[3], rows)
    finish(fig, axes, path)


def random_map_panel(ax, rows: list[dict]) -> None:
    """Part 3: seconds per load, ours beside Tamaas'."""
    pressures: list[str] = []
    for k, (solver, color) in enumerate((("ngcontact spectral", "C0"), ("tamaas", "C1"))):
        sel = [r for r in rows if r["part"] == "random_map" and r["solver"] == solver]
        if sel:
            ax.bar(np.arange(len(sel)) + 0.4 * k, [r["seconds"] for r in sel], 0.4, color=color,
                   label=f"{solver}: {sum(r['seconds'] for r in sel):.3g} s")
            pressures = pressures or [str(r["setting"]).split("p = ")[-1] for r in sel]
    ax.set_xticks(np.arange(len(pressures)) + 0.2, pressures)
    ax.set(xlabel="mean pressure", ylabel="wall time [s]", title="random 64^2 map on 1024^2: time per load")


def fe_against_spectral_panel(ax, fe: list[tuple[int, float]], spectral: list[tuple[str, float]], what: str,
                              estimates: list[float] | None = None) -> None:
    """The bisinusoid's contact fraction: FE ``(dofs, fraction)`` against the spectral cell's ``(setting, fraction)``
    as lines; ``what`` names the enforcement (empty: the scene's); ``estimates``: the FE values' estimated errors,
    drawn as error bars."""
    if fe:
        ax.errorbar([d for d, _ in fe], [f for _, f in fe], yerr=estimates, fmt="o-", capsize=3,
                    label=f"FE cell{what}" + (" (bars: its estimate)" if estimates else ""))
        ax.set_xscale("log")
    for setting, f in spectral:
        ax.axhline(f, color="k", ls="--", label=f"spectral{what}, {setting}")
    ax.set(xlabel="FE dofs", ylabel="contact fraction", title=f"bisinusoid: FE{what} against spectral{what}")


def finish(fig, axes, path: str) -> None:
    """Grid and legend on every panel; the figure saved to ``path`` and closed."""
    import matplotlib.pyplot as plt
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


QUIET = ("ngcontact.cell.spectral.layered_cell", "ngcontact.solvers.newton", "ngcontact.drivers.run_cell",
         "ngcontact.cell.fe.cell_problem")


def start_logging(*more: str) -> None:
    """The study's progress on the terminal; the solvers' own lines (``QUIET`` and ``more``) left out."""
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    for quiet in QUIET + more:
        logging.getLogger(quiet).setLevel(logging.WARNING)


def write_study(out: str, name: str, keys, rows: list[dict], draw) -> None:
    """``OUT/NAME.csv`` (the columns ``keys``) and ``OUT/NAME.png`` (``draw(rows, path)``)."""
    os.makedirs(out, exist_ok=True)
    write_csv(os.path.join(out, f"{name}.csv"), list(keys), [[r.get(k, "") for k in keys] for r in rows])
    draw(rows, os.path.join(out, f"{name}.png"))
    log.info("wrote %s", os.path.join(out, f"{name}.csv"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "spectral_vs_fft"), help="output directory")
    ap.add_argument("--quick", action="store_true", help="small grids and one FE size (a smoke run)")
    ap.add_argument("--fe-sizes", type=float, nargs="*", default=None,
                    help="FE interface mesh sizes of part 2 (default 0.12 0.08 0.06)")
    ap.add_argument("--random-map-only", action="store_true", help="part 3 alone (issue 38's random map)")
    ap.add_argument("--dissimilar-child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--dissimilar-friction-child", action="store_true", help=argparse.SUPPRESS)
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    if args.dissimilar_child or args.dissimilar_friction_child:
        dissimilar_child(friction=args.dissimilar_friction_child)
        return 0
    start_logging()
    sizes = args.fe_sizes if args.fe_sizes is not None else ([0.12] if args.quick else [0.12, 0.08, 0.06])
    if args.random_map_only and args.publish:
        print("error: --publish with --random-map-only: the published table needs every part (allowed: one of "
              "the two)", file=sys.stderr)
        return 2
    if args.random_map_only:
        rows = random_map(args.quick)
    else:
        rows = half_space(args.quick) + fe_against_spectral(sizes, args.quick) + random_map(args.quick)
    if not args.quick and not args.random_map_only:
        rows += dissimilar()
    write_study(args.out, "spectral_vs_fft", KEYS, rows, plot)
    if args.publish:
        benchmark_doc.publish("spectral_vs_fft", "The spectral cell beside an FFT half-space solver and the FE cell",
                              os.path.join(args.out, "spectral_vs_fft.csv"),
                              note="Part 1: a random self-affine surface on two thick layers against Tamaas' "
                                   "half-space solver (skipped without the `bench` extra); part 2: the FE cell "
                                   "against the spectral cell on the bisinusoid, each FE row solved on the "
                                   "interface mesh it names (`discretization.estimate = 'estimate'`: not "
                                   "refined), `estimate` its contact fraction's error estimate (one order more on "
                                   "the same mesh, the change over 1 - 0.75), `true_error` its distance to the "
                                   "spectral row (absolute; the spectral row's `estimate`: its change from the "
                                   "grid of half its points); part 3 (`random_map`): issue "
                                   "38's random 64 x 64 map, bilinear on 1024^2, three loads, ours and Tamaas' "
                                   "at the same grid and tolerance (each by its own stopping rule; seconds per "
                                   "load); part 4: dissimilar finite layers, frictionless and with Coulomb "
                                   "friction. Contact fraction, pressure difference, mean closure, stiffness, "
                                   "iterations, seconds, peak memory. Timings on a 2-core machine shared with "
                                   "other jobs. " + random_map_note(rows),
                              png=os.path.join(args.out, "spectral_vs_fft.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
