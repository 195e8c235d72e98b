"""Exact contact on the 3D FE cell, checked two ways: Westergaard's waves in 3D and the spectral cell.

Two measurements, one run, one CSV and one PNG:

1. **Westergaard's waves in a 3D cell.**  The gap ``2h sin^2(pi x)``
   (``h = 0.01``, period 1) does not depend on ``y``, so the 3D cell is in
   plane strain and its contact fraction is Westergaard's (ngcontact.verification.westergaard).
   Bodies 1 deep, ``E = 1``, ``nu = 0.3``, loads ``p/p* = 0.2, 0.8``,
   refining the interface mesh and with it the bodies' (``maxh`` twice the
   interface's: order-1 bodies kept coarse stall the error at 5-6 %): exact enforcement at order 1 (what is built
   in 3D, ``ngcontact.cell.fe.contact_multiplier``; augmentation
   ``k_n = 100 E/h``) beside the penalty ``k_n = 1000 E/h`` at order 1, and
   at order 2 on the two coarser meshes (its contact set read from the
   penetration at quadrature points).  Reported: relative error of the
   contact fraction, Newton steps, Uzawa passes, dofs, wall time.
2. **Bisinusoid against the spectral cell.**  The shipped
   ``geometries/cells/bisinusoid.toml`` (layers 0.6 thick, one pressure)
   with ``contact.enforcement = "exact"`` at order 1: the FE cell over a
   ladder of interface mesh sizes, the bodies' ``maxh`` twice that (the
   linear-solver policy of the scene: BDDC-CG from 20k dofs on), and the
   spectral cell of the same layers at ``512^2``, both exact: contact
   fraction and mean closure.  The two discretize the same
   small-slope problem, so they must meet as the FE mesh is refined.

Usage::

    python scripts/exact_fe_3d.py [OUT_DIR] [--quick] [--wave-sizes H ...] [--bis-sizes H ...]

``--wave-sizes`` and ``--bis-sizes`` replace the interface mesh sizes of the
two parts (a shorter ladder for a loaded machine); the published note names
the sizes that were run.

Writes ``exact_fe_3d.csv`` and ``exact_fe_3d.png`` into ``OUT_DIR`` (default
``results/exact_fe_3d``) and logs the tables.
"""
from __future__ import annotations

import argparse
import logging
import math
import os
import sys
import time
from dataclasses import replace


sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from spectral_vs_fft import (  # noqa: E402  (the sibling script draws both)
    fe_against_spectral_panel, finish, run_variant, start_logging, write_study)
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

log = logging.getLogger("exact_fe_3d")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
H, NU, RATIOS = 0.01, 0.3, (0.2, 0.8)
WAVE_SIZES, QUICK_WAVE = (0.1, 0.07, 0.05, 0.035), (0.1,)
BIS_SIZES, QUICK_BIS = (0.08, 0.05, 0.035, 0.025), (0.08,)
KEYS = ("part", "method", "setting", "ndof", "load", "contact_fraction", "reference", "relative_error",
        "mean_closure", "newton_steps", "uzawa_passes", "seconds")


def waves(sizes) -> list[dict]:
    import ngsolve as ng
    from ngcontact import runner
    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
    from ngcontact.fem.materials import isotropic
    from ngcontact.geometry.cell3d import flat_cell3d
    from ngcontact.solvers.linear_solver import LinearSolver
    from ngcontact.verification.moduli import e_star
    from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star
    pstar = westergaard_p_star(e_star(1.0, NU, 1.0, NU), H, 1.0)
    law = isotropic(1.0, NU)
    rows = []
    for n, ih in enumerate(sizes):
        cell = flat_cell3d(maxh=2 * ih, interface_maxh=ih, h_rough=1.0, h_counter=1.0)
        methods = (("exact", 1, 1e2), ("penalty", 1, 1e3)) + ((("penalty", 2, 1e3),) if n < 2 else ())
        for method, order, k_factor in methods:
            model = CellModel(rough=law, counter=law, k_n=k_factor / ih, gap=2 * H * ng.sin(math.pi * ng.x) ** 2,
                              order=order, enforcement=method)
            with runner.threads(runner.thread_count()):
                P = CellProblem(cell, model, linear=LinearSolver("auto"))
                for k, r in enumerate(RATIOS):
                    t0 = time.perf_counter()
                    sol = P.solve(cell_load(3, pressure=r * pstar), first=(k == 0), measure=False)
                    secs = time.perf_counter() - t0
                    ref = westergaard_contact_fraction(r, 1.0)
                    f = sol.results["contact_fraction"]
                    rows.append({"part": "waves", "method": f"{method} order {order}",
                                 "setting": f"order {order}, interface_maxh {ih}",
                                 "ndof": P.ndof, "load": r, "contact_fraction": f, "reference": ref,
                                 "relative_error": f / ref - 1.0, "mean_closure": "",
                                 "newton_steps": sol.iterations,
                                 "uzawa_passes": sol.newton[-1].get("uzawa_iterations", ""), "seconds": secs})
                    log.info("waves %-8s p %d h %-5g ndof %7d p/p* %.1f: fraction %.5f (Westergaard %.5f, %+.2e), "
                             "%d Newton, %.1f s", method, order, ih, P.ndof, r, f, ref, f / ref - 1.0,
                             sol.iterations, secs)
    return rows


def bisinusoid(sizes) -> list[dict]:
    from ngcontact.scene.loader import load
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    exact = replace(scene.contact, enforcement="exact")
    settings = [("spectral", replace(scene.discretization, method="spectral", grid=512))]
    settings += [("fe", replace(scene.discretization, order=1, maxh=2 * h, interface_maxh=h)) for h in sizes]
    rows = []
    for method, disc in settings:
        out, load0, secs = run_variant(scene, contact=exact, discretization=disc)
        newton = out.solver.get("iterations", "")
        rows.append({"part": "bisinusoid", "method": f"{method} exact",
                     "setting": f"grid {disc.grid}" if method == "spectral" else
                     f"order {disc.order}, interface_maxh {disc.interface_maxh}",
                     "ndof": out.ndof, "load": load0["mean_pressure"], "contact_fraction": load0["contact_fraction"],
                     "reference": "", "relative_error": "", "mean_closure": load0["mean_closure"],
                     "newton_steps": newton if method == "fe" else "", "uzawa_passes": "", "seconds": secs})
        log.info("bisinusoid %-36s ndof %8d: fraction %.5f, closure %.8f (%.1f s)", rows[-1]["setting"], out.ndof,
                 load0["contact_fraction"], load0["mean_closure"], secs)
    spectral = rows[0]
    for r in rows[1:]:
        r["reference"] = spectral["contact_fraction"]
        r["relative_error"] = r["contact_fraction"] / spectral["contact_fraction"] - 1.0
    return rows


def plot(rows: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for method, style in (("exact order 1", "o-"), ("penalty order 1", "s--"), ("penalty order 2", "^:")):
        for r0 in RATIOS:
            sel = [r for r in rows if r["part"] == "waves" and r["method"] == method and r["load"] == r0]
            if sel:
                axes[0].loglog([r["ndof"] for r in sel], [abs(r["relative_error"]) for r in sel], style,
                               label=f"{method}, p/p* = {r0}")
    axes[0].set(xlabel="dofs", ylabel="|contact fraction / Westergaard - 1|", title="3D cell, Westergaard's waves")
    bis = [r for r in rows if r["part"] == "bisinusoid"]
    fe_against_spectral_panel(axes[1], [(r["ndof"], r["contact_fraction"]) for r in bis if r["method"] == "fe exact"],
                              [(r["setting"], r["contact_fraction"]) for r in bis if r["method"] == "spectral exact"],
                              " exact")
    finish(fig, axes, path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "exact_fe_3d"), help="output directory")
    ap.add_argument("--quick", action="store_true", help="the coarsest size of each part only (a smoke run)")
    ap.add_argument("--wave-sizes", type=float, nargs="+", metavar="H",
                    help=f"interface mesh sizes of the waves part (default {' '.join(map(str, WAVE_SIZES))})")
    ap.add_argument("--bis-sizes", type=float, nargs="+", metavar="H",
                    help=f"interface mesh sizes of the bisinusoid part (default {' '.join(map(str, BIS_SIZES))})")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    start_logging("ngcontact.cell.fe.contact_multiplier")
    wave_sizes = args.wave_sizes or (QUICK_WAVE if args.quick else WAVE_SIZES)
    bis_sizes = args.bis_sizes or (QUICK_BIS if args.quick else BIS_SIZES)
    rows = waves(wave_sizes) + bisinusoid(bis_sizes)
    write_study(args.out, "exact_fe_3d", KEYS, rows, plot)
    if args.publish:
        benchmark_doc.publish("exact_fe_3d", "Exact contact on the 3D FE cell",
                              os.path.join(args.out, "exact_fe_3d.csv"),
                              note="Part `waves`: Westergaard's waves in a 3D cell, exact enforcement at order 1 "
                                   "beside the penalty, relative error of the contact fraction against the "
                                   "closed form; part `bisinusoid`: the FE cell with exact enforcement against "
                                   "the spectral cell at 512^2. Newton steps, Uzawa passes, seconds. "
                                   f"Interface mesh sizes run: waves {', '.join(map(str, wave_sizes))}; "
                                   f"bisinusoid {', '.join(map(str, bis_sizes))} (the full ladders: "
                                   f"{', '.join(map(str, WAVE_SIZES))}; {', '.join(map(str, BIS_SIZES))}).",
                              png=os.path.join(args.out, "exact_fe_3d.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
