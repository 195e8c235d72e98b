"""What accuracy costs in time for the cell problem: two work-precision studies.

1. Westergaard contact fraction (:mod:`ngcontact.verification.westergaard`): flat cell, gap
   ``2h sin^2(pi x)`` with ``h = 0.01``, ``E = 1``, ``nu = 0.3``, one load
   ``p/p* = 0.2`` (exact fraction ``(2/pi) asin(sqrt(0.2))``).  The error
   contains the penalty error (``O(1/k_n)``) as well as the discretization
   error; both ``k_n`` values of ``KN_VALUES`` are run.  Time: mesh, setup
   and the Newton solve (rigid predictor, exact line search), without the
   post-processing of :meth:`ngcontact.cell.fe.cell_problem.CellProblem.measure`.
2. Example 27 ``k_t0`` of the semicircular valley (radius 0.3, unit period,
   conforming, ``k_n = 1``): exact ``a pi / 2``; purely geometric (paper
   eq. 34), time = meshing + surface integral.

Both under h-refinement (interface mesh halved at fixed order) and
p-refinement (order raised on a fixed mesh).  The levels are independent
solves: one batch on ``--workers N`` local processes (default 1); each is
timed inside its worker on one NGSolve thread, so the figures do not depend
on N, only the study's wall time does.  Writes ``work_precision.csv``
and ``work_precision.png`` into the output directory (default
``results/work_precision_cell``) and logs the table.

Usage::

    python scripts/work_precision_cell.py [OUT_DIR] [--workers N]
"""
from __future__ import annotations

import argparse
import logging
import math
import os
import sys
import time

import ngsolve as ng

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.geometry import profiles
from ngcontact.geometry.cell2d import flat_cell
from ngcontact.cell.coefficients import coefficients
from ngcontact.fem.materials import isotropic
from ngcontact.output.writer import write_csv
from ngcontact.parallel import executor
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

log = logging.getLogger("work_precision_cell")

H_GAP, NU, RATIO = 0.01, 0.3, 0.2
KN_VALUES = (1e3, 1e4)
WG_H = {"order": 2, "interface_maxh": (0.04, 0.02, 0.01, 0.005)}
WG_P = {"interface_maxh": 0.02, "orders": (1, 2, 3, 4, 5)}
SC_RADIUS = 0.3
SC_H = {"order": 2, "interface_maxh": (0.1, 0.05, 0.025, 0.0125)}
SC_P = {"interface_maxh": 0.1, "orders": (1, 2, 3, 4, 5, 6)}
KEYS = ("quantity", "study", "k_n", "order", "interface_maxh", "ndof", "value", "exact",
        "rel_error", "seconds", "newton_iterations")


def westergaard(order: int, ih: float, kn: float) -> dict:
    """One Westergaard solve at ``p/p* = RATIO``; error of the contact fraction."""
    pstar = westergaard_p_star(e_star(1.0, NU, 1.0, NU), H_GAP, 1.0)
    exact = westergaard_contact_fraction(RATIO * pstar, pstar)
    t0 = time.perf_counter()
    cell = flat_cell(maxh=0.3, interface_maxh=ih, order=order)
    law = isotropic(1.0, NU)
    gap = 2 * H_GAP * ng.sin(math.pi * ng.x) ** 2
    P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=kn, gap=gap, order=order),
                    max_iter=60)
    sol = P.solve(cell_load(2, pressure=RATIO * pstar), first=True, measure=False)
    secs = time.perf_counter() - t0
    value = sol.results["contact_fraction"]
    return {"quantity": "westergaard_contact_fraction", "k_n": kn, "order": order,
            "interface_maxh": ih, "ndof": P.ndof, "value": value, "exact": exact,
            "rel_error": abs(value - exact) / exact, "seconds": secs,
            "newton_iterations": sol.iterations}


def semicircle_kt(order: int, ih: float) -> dict:
    """Example 27: ``k_t0`` of the whole surface of the semicircular valley."""
    exact = SC_RADIUS * math.pi / 2
    t0 = time.perf_counter()
    cell = profiles.profile_cell(profiles.semicircular_valley(SC_RADIUS, 1.0), arrangement="conforming",
                                 h_rough=1.0, h_counter=1.0, maxh=0.3, interface_maxh=ih, order=order)
    value = coefficients(cell, kn=1.0).k_t
    secs = time.perf_counter() - t0
    return {"quantity": "semicircle_k_t0", "k_n": 1.0, "order": order, "interface_maxh": ih,
            "ndof": 0, "value": value, "exact": exact, "rel_error": abs(value - exact) / exact,
            "seconds": secs, "newton_iterations": 0}


def level(job: tuple) -> dict:
    """One level of either study as a member of a batch (:mod:`ngcontact.parallel.executor`)."""
    study, quantity, args = job
    return {"study": study, **(westergaard(*args) if quantity == "westergaard" else semicircle_kt(*args))}


def run(workers: int = 1) -> list[dict]:
    jobs = []
    for kn in KN_VALUES:
        jobs += [("h", "westergaard", (WG_H["order"], ih, kn)) for ih in WG_H["interface_maxh"]]
        jobs += [("p", "westergaard", (order, WG_P["interface_maxh"], kn)) for order in WG_P["orders"]]
    jobs += [("h", "semicircle", (SC_H["order"], ih)) for ih in SC_H["interface_maxh"]]
    jobs += [("p", "semicircle", (order, SC_P["interface_maxh"])) for order in SC_P["orders"]]
    names = [f"{quantity} {study} {args}" for study, quantity, args in jobs]
    with executor.use(executor.make(workers)) as ex:
        ex.start()
        rows = ex.map(level, jobs, names, label="work-precision levels")
    for r in rows:
        log.info("%s", _fmt(r))
    return rows


def _fmt(r: dict) -> str:
    return (f"{r['quantity']:30s} {r['study']} k_n={r['k_n']:<7g} p={r['order']} "
            f"h={r['interface_maxh']:<7g} ndof={r['ndof']:<6d} err={r['rel_error']:.3e} "
            f"t={r['seconds']:.2f}s it={r['newton_iterations']}")


def plot(rows: list[dict], path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, q in zip(axes, ("westergaard_contact_fraction", "semicircle_k_t0")):
        groups = sorted({(r["study"], r["k_n"]) for r in rows if r["quantity"] == q})
        for study, kn in groups:
            sel = [r for r in rows if r["quantity"] == q and r["study"] == study and r["k_n"] == kn]
            ax.loglog([r["seconds"] for r in sel], [max(r["rel_error"], 1e-16) for r in sel], "o-",
                      label=f"{study}-refinement" + (f", k_n={kn:g}" if q.startswith("west") else ""))
        ax.set_xlabel("wall time [s]")
        ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide on short time ranges
        ax.set_ylabel("relative error")
        ax.set_title(q)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "work_precision_cell"),
                    help="output directory")
    ap.add_argument("--workers", type=int, default=1, help="local worker processes for the levels")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    os.makedirs(args.out, exist_ok=True)
    rows = run(args.workers)
    write_csv(os.path.join(args.out, "work_precision.csv"), KEYS, [[r[k] for k in KEYS] for r in rows])
    plot(rows, os.path.join(args.out, "work_precision.png"))
    log.info("wrote %s", args.out)
    if args.publish:
        benchmark_doc.publish("work_precision_cell", "Work-precision of the cell problem",
                              os.path.join(args.out, "work_precision.csv"),
                              note="Westergaard's contact fraction at `p/p* = 0.2` (penalty and discretization "
                                   "error, both `k_n`) and Example 27's `k_t0` of the semicircular valley, under "
                                   "h- and p-refinement: value, exact value, relative error, seconds of one "
                                   "level timed inside its worker on one NGSolve thread, Newton steps.",
                              png=os.path.join(args.out, "work_precision.png"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
