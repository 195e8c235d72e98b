"""What accuracy costs in time: work-precision of the manufactured elasticity problem.

For the manufactured plane-strain and axisymmetric problems of
:mod:`ngcontact.verification.manufactured` it measures the L2 and H1-seminorm errors
against the wall time of one solve (mesh, assembly, sparse direct solve;
the error evaluation is not counted) under

* h-refinement: orders 1..4, nested levels ``h = maxh / 2^k``;
* p-refinement: orders 1..8 on one fixed mesh.

Writes ``work_precision.csv`` and ``work_precision.png`` into the output
directory (default ``results/work_precision_elasticity``) and logs the table.

Usage::

    python scripts/work_precision_elasticity.py [--out DIR] [--settings plane_strain axisymmetric]
"""
from __future__ import annotations

import argparse
import logging
import os
import sys

from ngcontact.verification import manufactured
from ngcontact.verification import rates as studies
from ngcontact.fem.materials import isotropic
from ngcontact.output.writer import write_csv

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

log = logging.getLogger("work_precision_elasticity")

MAXH = 0.25
H_ORDERS = (1, 2, 3, 4)
H_LEVELS = (1, 2, 3, 4)
P_ORDERS = (1, 2, 3, 4, 5, 6, 7, 8)
P_LEVEL = 1
LAWS = {"body": isotropic(210e9, 0.3)}
KEYS = ("setting", "study", "order", "level", "h", "ndof", "l2", "h1", "solve_seconds")


def study(setting: str) -> list[dict]:
    """h- and p-refinement rows of one setting."""
    level = manufactured.level_runner(setting, LAWS, MAXH)
    level(1, 0)  # warm-up: first use of the mesher and the solver
    rows = [dict(r, study="h") for r in studies.h_refinement(level, setting=setting, orders=H_ORDERS,
                                                              maxh=MAXH, refinements=H_LEVELS)]
    rows += [dict(r, study="p") for r in studies.p_refinement(level, setting=setting, orders=P_ORDERS,
                                                               maxh=MAXH, refinement=P_LEVEL)]
    return rows


def plot(rows: list[dict], path: str) -> None:
    """Error against solve time, one panel per setting and norm."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    settings = sorted({r["setting"] for r in rows})
    fig, axes = plt.subplots(len(settings), 2, figsize=(10, 4 * len(settings)), squeeze=False,
                             constrained_layout=True)
    for i, setting in enumerate(settings):
        for j, (norm, label) in enumerate((("l2", "L2 error"), ("h1", "H1-seminorm error"))):
            ax = axes[i][j]
            for p in H_ORDERS:
                sel = [r for r in rows if r["setting"] == setting and r["study"] == "h" and r["order"] == p]
                ax.loglog([r["solve_seconds"] for r in sel], [r[norm] for r in sel], "o-",
                          label=f"h-refinement, p = {p}")
            sel = [r for r in rows if r["setting"] == setting and r["study"] == "p"]
            ax.loglog([r["solve_seconds"] for r in sel], [r[norm] for r in sel], "k^--",
                      label=f"p-refinement, p = {P_ORDERS[0]}..{P_ORDERS[-1]}, h = {MAXH / 2 ** P_LEVEL:g}")
            ax.set_xlabel("wall time of one solve [s]")
            ax.set_ylabel(label)
            ax.set_title(setting)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def format_table(rows: list[dict]) -> str:
    lines = ["| setting | study | p | h | ndof | L2 error | H1 error | solve time [s] |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['setting']} | {r['study']} | {r['order']} | {r['h']:.5f} | {r['ndof']} | "
                     f"{r['l2']:.3e} | {r['h1']:.3e} | {r['solve_seconds']:.3f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=os.path.join("results", "work_precision_elasticity"),
                        help="output directory (default: %(default)s)")
    parser.add_argument("--settings", nargs="+", default=["plane_strain", "axisymmetric"],
                        choices=["plane_strain", "axisymmetric"], help="settings to study")
    benchmark_doc.add_flag(parser)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for setting in args.settings:
        rows += study(setting)
    write_csv(os.path.join(args.out, "work_precision.csv"), list(KEYS), [[r[k] for k in KEYS] for r in rows])
    plot(rows, os.path.join(args.out, "work_precision.png"))
    log.info("%s", format_table(rows))
    log.info("wrote %s", os.path.join(args.out, "work_precision.{csv,png}"))
    if args.publish:
        benchmark_doc.publish("work_precision_elasticity", "Work-precision of the manufactured elasticity problem",
                              os.path.join(args.out, "work_precision.csv"),
                              note="The manufactured plane-strain and axisymmetric problems: L2 and H1-seminorm "
                                   "errors against the wall seconds of one solve (mesh, assembly, sparse direct "
                                   "solve), under h-refinement (orders 1 to 4) and p-refinement (orders 1 to 8).",
                              png=os.path.join(args.out, "work_precision.png"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
