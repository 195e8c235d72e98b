"""How honest is the FE cell's error estimate? Its effectivity on shipped cells against converged values.

The FE cell estimates its error at the default tolerance (``FECell.refine_to(0.01, loads, required=False)``):
a flat 2D cell by meshes graded towards its contact edges checked by one order more
(``ngcontact.cell.fe.edge_grading``), any other cell by one order more on its mesh
(``ngcontact.cell.fe.second_discretization``).  The oracle of each is the same model converged on the
spectral cell (same layers, same penalty ``k_n``: the small-slope twin) on a fine grid.  For each cell, load
and quantity the script writes the value, the estimate, the true error against the oracle and their ratio,
the effectivity (issue 35 asks for it between 1 and 10); a true error at round-off (below ``FLOOR``) has
no effectivity.

    python scripts/fe_effectivity.py [OUT] [--publish]

Writes ``OUT/fe_effectivity.csv`` (default ``results/fe_effectivity``).
"""
from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.drivers.build import cell_loads, cell_solver, spectral_variant  # noqa: E402
from ngcontact.output.writer import write_csv  # noqa: E402
from ngcontact.scene.loader import load  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: shipped FE cells and the grid of their converged spectral twin
ORACLES = {"westergaard": 65536, "stem_grooves": 65536, "bisinusoid": 512}
#: a true error below this is round-off: no effectivity
FLOOR = 1e-10
KEYS = ("cell", "load", "quantity", "value", "reference", "estimate", "true_error", "effectivity", "how",
        "seconds")


def rows(name: str, grid: int) -> list[dict]:
    scene = load(os.path.join(ROOT, "geometries", "cells", f"{name}.toml"))
    loads = cell_loads(scene)
    reference = spectral_variant(scene, grid).sweep(loads)
    cell = cell_solver(scene)
    t0 = time.perf_counter()
    refined = cell.refine_to(0.01, loads, required=False)
    seconds = time.perf_counter() - t0
    out = []
    for k, (sol, estimate, ref) in enumerate(zip(refined.solutions, refined.estimates, reference)):
        for q in ("contact_fraction", "mean_closure"):
            v, r = float(sol.results[q]), float(ref.results[q])
            error = abs(v - r) if q == "contact_fraction" else abs(v - r) / abs(r)
            e = float(estimate[q])
            out.append({"cell": name, "load": k, "quantity": q, "value": v, "reference": r, "estimate": e,
                        "true_error": error, "effectivity": e / error if error > FLOOR else "",
                        "how": cell.default_refinement(), "seconds": seconds})
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "fe_effectivity"), help="output directory")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    data = []
    for name, grid in ORACLES.items():
        data += rows(name, grid)
        for d in data[-2:]:
            print(", ".join(f"{d[k]:.4g}" if isinstance(d[k], float) else str(d[k]) for k in KEYS), flush=True)
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, "fe_effectivity.csv")
    write_csv(csv_path, list(KEYS), [[d[k] for k in KEYS] for d in data])
    if args.publish:
        benchmark_doc.publish("fe_effectivity", "The FE cell's error estimate against the converged value",
                              csv_path, note="Shipped FE cells at the default tolerance 0.01: graded (flat 2D) or "
                              "compared with one order more (3D); the reference is the same model (layers, k_n) on "
                              "the spectral grid of the oracle's points. Contact fraction absolute, mean closure "
                              "relative. Issue 35 asks for effectivities between 1 and 10.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
