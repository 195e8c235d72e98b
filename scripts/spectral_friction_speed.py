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
* **halfspace**: the peer's problem, Tamaas' frictional solvers against ours: the same map, ``mu``, mean pressure
  ``p0`` and shear ``0.2 p0`` on an elastic half-space (``E = 1``, ``nu = 0.3``) under a rigid surface
  (:mod:`tamaas_coulomb`, which says how the problem is posed alike and why the discretizations differ on the
  Nyquist modes only).  Rows: ours (``current``, on the run's threads, and ``current 1 thread``, as Tamaas' serial
  build) and each Tamaas solver.  Tamaas' own stopping measure does not vanish at the classical Coulomb
  solution, so every solution is judged by ours (``residual``: the proximal fixed-point residual of the cell,
  each code's own operator), and each Tamaas solver is run for a fixed number of steps, more in each new run
  (:func:`tamaas_coulomb.next_steps`), until that residual meets ``TOL`` (``attempts``: steps:residual of every
  run; the row is the last run).  A solver that stalls or would exceed ``--tamaas-budget`` seconds stops there and
  is not run on the larger grids.  ``stick_fraction``: pressed and sticking points; ``traction_difference``: the
  L2 distance of the tractions to ours (``current``) on the grid, relative to their norm.

Each run is a child process, so its peak resident memory is its own.  ``steps``
counts CG steps (frictionless, summed over the loads) or operator applications
(friction: every application of the 3-component operator, the frictionless start's one-component CG
steps not included; Tamaas: its iterations).  Without Tamaas the halfspace case runs ours alone, and the log and
the published note say why (:func:`tamaas_reason`).

Usage::

    python scripts/spectral_friction_speed.py [OUT_DIR] [--grids 256 512 1024] [--old-max-grid 512]
        [--coulomb-max-grid 1024] [--cases frictionless coulomb halfspace] [--tamaas-max-grid 512]
        [--tamaas-first 500] [--tamaas-budget 900] [--publish]

``--old-max-grid``: the largest grid on which the former frictional solver is
run (it needs thousands of steps beyond it); ``--coulomb-max-grid``: the same
for the current one; ``--cases``: the cases run (default all); ``--tamaas-max-grid``: the largest grid of the
Tamaas rows; ``--tamaas-first``: the steps of a Tamaas solver's first run; ``--tamaas-budget``: the longest run
(seconds, estimated from the previous run's) a Tamaas solver is given.
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
import tamaas_coulomb  # noqa: E402  (the sibling module poses the peer's problem)

log = logging.getLogger("spectral_friction_speed")
FINEST = 1024
P0 = 0.05 * 1.0 / (2 * (1 - 0.3 ** 2)) * 0.1
MU, SHEAR, TOL = 0.5, 0.2, 1e-10
#: the half-space of the halfspace case
HALF_E, HALF_NU = 1.0, 0.3
CASES = ("frictionless", "coulomb", "halfspace")
KEYS = ("case", "grid", "solver", "steps", "seconds", "peak_memory_gb", "contact_fraction", "slip_fraction",
        "stick_fraction", "residual", "traction_difference", "attempts")


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


def child_halfspace(n: int, solver: str, steps: int, fields: str) -> dict:
    """One run of the halfspace case in this process: ours (``current``) or Tamaas' (``tamaas <Name>``); the
    tractions saved to ``fields`` (``.npy``, our layout)."""
    z = surface(n)
    pressure, shear = P0, SHEAR * P0
    if solver.startswith("tamaas "):
        t, grad, secs = tamaas_coulomb.run_tamaas(solver.split()[1], z, HALF_E, HALF_NU, MU, pressure, shear, steps)
        peak, iterations = peak_memory_gb(), steps
        cell = tamaas_coulomb.halfspace_cell(z, HALF_E, HALF_NU, MU, TOL)
    else:
        import scipy.fft  # noqa: F401  (imported before the clock starts, as Tamaas is)
        from ngcontact.cell.cell_load import cell_load
        from ngcontact.cell.spectral import layered_cell  # noqa: F401
        t0 = time.perf_counter()
        cell = tamaas_coulomb.halfspace_cell(z, HALF_E, HALF_NU, MU, TOL)
        sol = cell.solve(cell_load(3, pressure=pressure, shear=(shear, 0.0)))
        secs, peak, iterations = time.perf_counter() - t0, peak_memory_gb(), sol.iterations
        t = np.concatenate([sol.fields["shear"], sol.fields["pressure"][None]])
    apply, L, _ = cell.traction_operator((False, False, False))
    if not solver.startswith("tamaas "):
        grad = apply(t)
        grad[2] += cell.g0
    np.save(fields, t)
    contact, stick = tamaas_coulomb.fractions(t, MU)
    return {"case": "halfspace", "grid": n, "solver": solver, "steps": iterations, "seconds": secs,
            "peak_memory_gb": peak, "contact_fraction": contact, "slip_fraction": contact - stick,
            "stick_fraction": stick,
            "residual": tamaas_coulomb.fixed_point_residual(t, grad, L, cell.gscale, MU, pressure, shear)}


def run_child(case: str, n: int, solver: str, steps: int = 0, fields: str = "", threads: str | None = None) -> dict:
    env = dict(os.environ, **({} if threads is None else {"NGCONTACT_THREADS": threads}))
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", case, str(n), solver,
                          "--steps", str(steps), "--fields", fields], check=True, capture_output=True, text=True,
                         env=env)
    # the last line that is JSON: a peer's own output may follow ours
    row = json.loads(next(line for line in reversed(out.stdout.splitlines()) if line.startswith("{")))
    log.info("%-12s %5d^2 %-24s %6d steps %8.2f s %6.2f GB%s", case, n, solver, row["steps"], row["seconds"],
             row["peak_memory_gb"], f"  residual {row['residual']:.2e}" if "residual" in row else "")
    return row


def run_halfspace(n: int, out: str, reason: str | None, args, dropped: set[str]) -> list[dict]:
    """The halfspace rows of grid ``n``: ours, then each Tamaas solver not ``dropped`` (on a smaller grid), run until
    our residual meets ``TOL`` (module docstring); the solvers that do not reach it join ``dropped``."""
    folder = os.path.join(out, "fields")
    os.makedirs(folder, exist_ok=True)

    def path(solver: str) -> str:
        return os.path.join(folder, f"halfspace_{n}_{solver.replace(' ', '_')}.npy")
    rows = [run_child("halfspace", n, "current", fields=path("current")),
            run_child("halfspace", n, "current 1 thread", fields=path("current 1 thread"), threads="1")]
    for name in tamaas_coulomb.SOLVERS if reason is None and n <= args.tamaas_max_grid else ():
        if name in dropped:
            log.info("halfspace %5d^2 tamaas %s: not run (did not reach the tolerance on a smaller grid)", n, name)
            continue
        solver, row = f"tamaas {name}", None
        attempts: list[tuple[int, float]] = []
        while (steps := tamaas_coulomb.next_steps(attempts, TOL, args.tamaas_first)) is not None:
            if row is not None and steps * row["seconds"] / row["steps"] > args.tamaas_budget:
                log.info("halfspace %5d^2 %s: %d steps would exceed --tamaas-budget %g s", n, solver, steps,
                         args.tamaas_budget)
                break
            row = run_child("halfspace", n, solver, steps, path(solver))
            attempts.append((steps, row["residual"]))
        assert row is not None
        row["attempts"] = " ".join(f"{k}:{r:.2g}" for k, r in attempts)
        if row["residual"] > TOL:
            dropped.add(name)
        rows.append(row)
    ours = np.load(path("current"))
    for row in rows:
        row["traction_difference"] = tamaas_coulomb.traction_difference(np.load(path(row["solver"])), ours)
    reached = [r for r in rows[2:] if r["residual"] <= TOL]
    if reached:
        best = min(reached, key=lambda r: r["seconds"])
        log.info("halfspace %5d^2: ours %.2f s (1 thread %.2f s), Tamaas' fastest at the tolerance (%s) %.2f s: "
                 "%.1f (%.1f) times ours", n, rows[0]["seconds"], rows[1]["seconds"], best["solver"], best["seconds"],
                 best["seconds"] / rows[0]["seconds"], best["seconds"] / rows[1]["seconds"])
    return rows


def tamaas_reason() -> str | None:
    """Why Tamaas' frictional solvers are not run (``None``: they are, in the halfspace case)."""
    try:
        import tamaas  # noqa: F401
    except ImportError:
        return "Tamaas is not installed (pip install '.[bench]')"
    return None


def tamaas_version() -> str:
    import tamaas
    return str(tamaas.__version__)


def plot(rows: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for ax, key in zip(axes, ("steps", "seconds", "peak_memory_gb")):
        for case, solver in dict.fromkeys((r["case"], r["solver"]) for r in rows):
            pts = sorted((r["grid"], r[key]) for r in rows if r["case"] == case and r["solver"] == solver)
            style = "o--" if solver == "former" else "^:" if solver.startswith("tamaas") else "s-"
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
        "spectral_friction_speed", "Spectral cell: frictionless and Coulomb solvers, former, current and Tamaas'",
        csv_path,
        note="Random self-affine map between dissimilar finite layers, exact contact, tolerance 1e-10. "
             "frictionless: three loads (p0/4, p0, 4 p0), steps summed; coulomb: exact Coulomb mu = 0.5 under "
             "p0 and a mean shear 0.2 p0, steps = applications of the 3-component operator (two FFT pairs per "
             "Krylov step with its preconditioner). former: plain constrained CG and accelerated proximal "
             "gradients; current: preconditioned constrained CG and the active-set method (Coulomb: semismooth "
             "Newton steps of the coupled law by preconditioned GMRES, the Anderson-accelerated fixed point of "
             "Tresca problems as fallback; the Krylov vectors held on the support of the free directions, the "
             "pressed, sticking and slipping points, so that beside the FFTs a Krylov step costs little). Timings "
             "taken on 2 cores shared with other jobs: compare rows of one run, not absolute seconds; the step "
             "counts do not depend on the load. halfspace: the same map, mu, p0 and shear on an elastic "
             "half-space (E = 1, nu = 0.3, a layer of 4 periods) under a rigid surface, the problem of Tamaas' "
             "frictional solvers (scripts/tamaas_coulomb.py says how it is posed alike); current 1 thread: ours on "
             "one thread, as Tamaas' serial build. Tamaas' own error measure does not vanish at the classical "
             "Coulomb solution (PolonskyKeerTan's levels off at 4e-8 on 64^2 while the traction has converged to "
             "round-off), so every solution is judged by ours: residual = max |t - prox(t - (K t + b)/L)| L / "
             "ptp(g0), the cell's stopping measure, K t from each code's own operator. Each Tamaas solver (default "
             "parameters) is run for a fixed number of steps, more in each new run (attempts: steps:residual), "
             "until that residual is <= 1e-10; the row is its last run, its seconds those of that run alone. A "
             "solver that stalls (doubling its steps does not halve the residual) stops there and is not run on the "
             "larger grids. stick_fraction: pressed and sticking points (|q| < mu p (1 - 1e-6)); "
             "traction_difference: L2 distance of the tractions to ours (current) relative to their norm, at "
             "least the discretizations' difference on the Nyquist modes (ours zeroes the normal/tangential "
             "coupling there, Tamaas takes k = -N/2), about 1e-3; on Tamaas' own operator the two converged "
             "solutions agree to 1e-11 (tests/cell/test_tamaas_coulomb.py). " + only +
             "Aims (issue 38): Coulomb at 1024^2 <= 30 s and <= 2 GB, frictionless three loads <= 15 s; at 512^2 "
             "no slower than Tamaas' fastest frictional solver at the same tolerance. "
             f"Peer: {reason or 'Tamaas ' + tamaas_version() + ' (the halfspace rows)'}.",
        png=png, command=command)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "spectral_friction_speed"))
    ap.add_argument("--grids", type=int, nargs="+", default=[256, 512, 1024])
    ap.add_argument("--old-max-grid", type=int, default=512)
    ap.add_argument("--coulomb-max-grid", type=int, default=FINEST)
    ap.add_argument("--cases", nargs="+", choices=CASES, default=list(CASES))
    ap.add_argument("--tamaas-max-grid", type=int, default=512)
    ap.add_argument("--tamaas-first", type=int, default=500)
    ap.add_argument("--tamaas-budget", type=float, default=900.0)
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    ap.add_argument("--steps", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--fields", default="", help=argparse.SUPPRESS)
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    if args.tamaas_first < 1:
        ap.error(f"--tamaas-first {args.tamaas_first}: the steps of a first run must be >= 1")
    if not args.tamaas_budget > 0:
        ap.error(f"--tamaas-budget {args.tamaas_budget}: the seconds of a run must be > 0")
    if args.child:
        case, n, solver = args.child[0], int(args.child[1]), args.child[2]
        row = child_halfspace(n, solver, args.steps, args.fields) if case == "halfspace" else child(case, n, solver)
        print(json.dumps(row), flush=True)
        return 0
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    rows: list[dict] = []
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, "spectral_friction_speed.csv")
    reason = tamaas_reason()
    if reason:
        log.warning("peer skipped: %s", reason)
    dropped: set[str] = set()
    for n in args.grids:
        for case in args.cases:
            if case == "halfspace":
                rows += run_halfspace(n, args.out, reason, args, dropped)
                write_csv(csv_path, list(KEYS), [[r.get(k, "") for k in KEYS] for r in rows])
                continue
            for solver in ("former", "current"):
                if case == "coulomb" and n > (args.old_max_grid if solver == "former" else args.coulomb_max_grid):
                    log.info("coulomb %d^2 %s: skipped (above --old-max-grid %d or --coulomb-max-grid %d)", n, solver,
                             args.old_max_grid, args.coulomb_max_grid)
                    continue
                rows.append(run_child(case, n, solver))
                write_csv(csv_path, list(KEYS), [[r.get(k, "") for k in KEYS] for r in rows])    # partial results
    png = os.path.join(args.out, "spectral_friction_speed.png")
    plot(rows, png)
    if args.publish:
        publish(csv_path, png, reason, args.cases)
    return 0


if __name__ == "__main__":
    sys.exit(main())
