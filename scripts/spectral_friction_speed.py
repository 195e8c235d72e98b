"""Steps, seconds and peak memory of the spectral cell's solvers, former and current, on a random map.

The surface: a random self-affine height map (Hurst exponent 0.8, RMS slope
0.1, roll-off at a quarter period, cut-off at 1/64 of the period, seed 7;
:func:`ngcontact.geometry.random_surface.self_affine`) drawn on 1024^2 and
sampled on the coarser grids, between dissimilar finite layers (``E = 1, 3``,
``nu = 0.3, 0.25``, 0.5 and 0.3 thick), exact contact, tolerance 1e-10.

* **frictionless**: three mean pressures (1/4, 1 and 4 times ``p0 = 0.05 E* 0.1``), each from no start; the
  former solver is the plain constrained CG, the current one the CG preconditioned by the inverse compliance on
  the contact set (:mod:`ngcontact.solvers.constrained_cg`).
* **coulomb**: exact Coulomb friction (``mu = 0.5``) under the pressure ``p0`` and a mean shear ``0.2 p0``; the
  former solver is accelerated proximal gradients (:mod:`ngcontact.solvers.projected_gradient`), the current one
  the active-set method (:mod:`ngcontact.solvers.active_set_newton`: semismooth Newton steps of the coupled law,
  each a GMRES solve preconditioned by the split inverse compliance, with the Anderson-accelerated fixed point of
  Tresca problems as its fallback).

Each run is a child process, so its peak resident memory is its own.  ``steps``
counts CG steps (frictionless, summed over the loads) or operator applications
(friction: every application of the 3-component operator, the frictionless start's one-component CG
steps not included).  Tamaas' frictional solvers are not run: the log and the
published note say why (the ``bench`` extra missing, or the rows not written
yet: Tamaas solves one half-space against a rigid surface, not two finite
layers, so only its steps and time would compare).

Usage::

    python scripts/spectral_friction_speed.py [OUT_DIR] [--grids 256 512 1024] [--old-max-grid 512]
        [--coulomb-max-grid 1024] [--cases frictionless coulomb] [--publish]

``--old-max-grid``: the largest grid on which the former frictional solver is
run (it needs thousands of steps beyond it); ``--coulomb-max-grid``: the same
for the current one; ``--cases``: the cases run (default both).
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

log = logging.getLogger("spectral_friction_speed")
FINEST = 1024
P0 = 0.05 * 1.0 / (2 * (1 - 0.3 ** 2)) * 0.1
MU, SHEAR, TOL = 0.5, 0.2, 1e-10
CASES = ("frictionless", "coulomb")
KEYS = ("case", "grid", "solver", "steps", "seconds", "peak_memory_gb", "contact_fraction", "slip_fraction")


def surface(n: int) -> np.ndarray:
    from ngcontact.geometry.random_surface import self_affine
    z = self_affine(dim=3, grid=FINEST, hurst=0.8, rms_slope=0.1, rolloff=0.25, cutoff=1 / 64, seed=7)
    return z[::FINEST // n, ::FINEST // n]


def peak_memory_gb() -> float:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 2 ** 20
    return float("nan")


def child(case: str, n: int, solver: str) -> dict:
    """One run in this process."""
    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
    from ngcontact.laws.friction import Coulomb
    z = surface(n)
    t0 = time.perf_counter()
    cell = SpectralCell(dim=3, period=1.0, grid=n, rough=Layer(1.0, 0.3, 0.5), counter=Layer(3.0, 0.25, 0.3),
                        gap=z.max() - z, k_n=1.0, enforcement="exact", tol=TOL, max_iter=100000,
                        friction=Coulomb(w=None, mu=MU) if case == "coulomb" else None)
    cell.preconditioned = solver == "current"
    cell.friction_method = "active_set" if solver == "current" else "proximal"
    if case == "coulomb":
        sols = [cell.solve(cell_load(3, pressure=P0, shear=(SHEAR * P0, 0.0)))]
    else:
        sols = [cell.solve(cell_load(3, pressure=f * P0)) for f in (0.25, 1.0, 4.0)]
    secs = time.perf_counter() - t0
    r = sols[-1].results
    return {"case": case, "grid": n, "solver": solver, "steps": sum(s.iterations for s in sols), "seconds": secs,
            "peak_memory_gb": peak_memory_gb(), "contact_fraction": r["contact_fraction"],
            "slip_fraction": r.get("slip_fraction", "")}


def run_child(case: str, n: int, solver: str) -> dict:
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", case, str(n), solver], check=True,
                         capture_output=True, text=True)
    row = json.loads(out.stdout.strip().splitlines()[-1])
    log.info("%-12s %5d^2 %-8s %6d steps %8.2f s %6.2f GB", case, n, solver, row["steps"], row["seconds"],
             row["peak_memory_gb"])
    return row


def tamaas_reason() -> str | None:
    """Why Tamaas' frictional solver is not run (``None``: it is)."""
    try:
        import tamaas  # noqa: F401
    except ImportError:
        return "Tamaas is not installed (pip install '.[bench]')"
    return ("this script does not run Tamaas' frictional solvers yet (they take one half-space against a rigid "
            "surface, not two finite layers: only steps and time would compare)")


def plot(rows: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for ax, key in zip(axes, ("steps", "seconds", "peak_memory_gb")):
        for case in ("frictionless", "coulomb"):
            for solver, style in (("former", "o--"), ("current", "s-")):
                pts = sorted((r["grid"], r[key]) for r in rows if r["case"] == case and r["solver"] == solver)
                if pts:
                    ax.loglog(*zip(*pts), style, label=f"{case}, {solver}")
        ax.set_xlabel("grid points per direction")
        ax.set_ylabel(key.replace("_", " "))
    axes[1].axhline(30, color="0.6", lw=0.8)
    axes[1].axhline(15, color="0.8", lw=0.8)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def publish(csv_path: str, png: str, reason: str | None, cases=CASES, command: str | None = None) -> None:
    """This study's section of ``docs/benchmarks.md`` from its CSV and PNG."""
    only = "" if set(cases) == set(CASES) else f"Only the {', '.join(cases)} rows were run this time. "
    benchmark_doc.publish(
        "spectral_friction_speed", "Spectral cell: frictionless and Coulomb solvers, former and current", csv_path,
        note="Random self-affine map between dissimilar finite layers, exact contact, tolerance 1e-10. "
             "frictionless: three loads (p0/4, p0, 4 p0), steps summed; coulomb: exact Coulomb mu = 0.5 under "
             "p0 and a mean shear 0.2 p0, steps = applications of the 3-component operator (two FFT pairs per "
             "Krylov step with its preconditioner). former: plain constrained CG and accelerated proximal "
             "gradients; current: preconditioned constrained CG and the active-set method (Coulomb: semismooth "
             "Newton steps of the coupled law by preconditioned GMRES, the Anderson-accelerated fixed point of "
             "Tresca problems as fallback; the Krylov vectors held on the support of the free directions, the "
             "pressed, sticking and slipping points, so that beside the FFTs a Krylov step costs little). Timings "
             "taken on 2 cores shared with other jobs: compare rows of one run, not absolute seconds; the step "
             "counts do not depend on the load. " + only +
             "Aims (issue 38): Coulomb at 1024^2 <= 30 s and <= 2 GB, frictionless three loads <= 15 s. "
             f"Peer: {reason or 'Tamaas run'}.",
        png=png, command=command)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "spectral_friction_speed"))
    ap.add_argument("--grids", type=int, nargs="+", default=[256, 512, 1024])
    ap.add_argument("--old-max-grid", type=int, default=512)
    ap.add_argument("--coulomb-max-grid", type=int, default=FINEST)
    ap.add_argument("--cases", nargs="+", choices=CASES, default=list(CASES))
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child[0], int(args.child[1]), args.child[2])))
        return 0
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    rows: list[dict] = []
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, "spectral_friction_speed.csv")
    for n in args.grids:
        for case in args.cases:
            for solver in ("former", "current"):
                if case == "coulomb" and n > (args.old_max_grid if solver == "former" else args.coulomb_max_grid):
                    log.info("coulomb %d^2 %s: skipped (above --old-max-grid %d or --coulomb-max-grid %d)", n, solver,
                             args.old_max_grid, args.coulomb_max_grid)
                    continue
                rows.append(run_child(case, n, solver))
                write_csv(csv_path, list(KEYS), [[r[k] for k in KEYS] for r in rows])    # partial results survive
    reason = tamaas_reason()
    if reason:
        log.warning("peer skipped: %s", reason)
    png = os.path.join(args.out, "spectral_friction_speed.png")
    plot(rows, png)
    if args.publish:
        publish(csv_path, png, reason, args.cases)
    return 0


if __name__ == "__main__":
    sys.exit(main())
