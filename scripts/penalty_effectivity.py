"""A penalty's estimate against the converged value of the same penalty model, on random profiles and Westergaard.

The 2D spectral cell with the Winkler layer of eq. 65 (``contact.enforcement = "penalty"``) refined to the
tolerances 1e-2, 1e-3 and 1e-4 as a run does, for ``k_n`` = 1e3, 1e4 and 1e5 (``E = 1``, ``nu = 0.3``, layers
of depth 1, so the penalty's length ``lambda = E*/k_n`` is 5.5e-4, 5.5e-5 and 5.5e-6 of the period): Westergaard's
sinusoid at three loads and the random 64-sample profiles of seeds 5 and 11 (those of
``scripts/spectral_effectivity.py``, whose rows and columns this script shares).  The true error of each
reported quantity is against the same penalty model on the grid of :func:`reference_grid` (at least 2^17
points, a step at most a third of ``lambda``, so that the reference has passed the change of regime where the
grid comes to resolve the penalty's zone); ``reference_change`` is that grid's own change from half as many
points, and a row whose true error lies below it is not judged (its effectivity measures the reference).  The
penalty's edges hold a floor of ``lambda ln(P / lambda)`` times a constant calibrated on Westergaard's sinusoid
alone (``ngcontact.cell.spectral.contact_edges``): this study is its check on maps it was not calibrated on.
The penalty's own share of the answer (the same quantity at the exact limit) is reported apart by a run and
is not part of these estimates.  Issue 35 asks for effectivities between 1 and 10.

    MPLBACKEND=Agg python scripts/penalty_effectivity.py results/penalty_effectivity --publish
"""
from __future__ import annotations

import argparse
import os
import sys
from functools import partial

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)
from spectral_effectivity import (KEYS, NU, Oracle, judged, oracle_rows, plot, random_profile_gap,  # noqa: E402
                                  westergaard_gap)

from ngcontact.output.writer import write_csv  # noqa: E402

PENALTIES = (1e3, 1e4, 1e5)
TOLERANCES = (1e-2, 1e-3, 1e-4)
#: the fewest points of a reference grid
REFERENCE = 2 ** 17
#: a reference's step is at most this share of the penalty's length ``lambda``
REFERENCE_STEP = 1 / 3
#: the plane-strain modulus of the two bodies together (``1/E* = 2 (1 - nu^2) / E``, ``E = 1``)
E_STAR = 1.0 / (2 * (1 - NU ** 2))
#: the largest grid a refinement may reach here
LARGEST = 2 ** 14


def oracles(penalties=PENALTIES) -> tuple[Oracle, ...]:
    """Westergaard's sinusoid and the random profiles of seeds 5 and 11 under each penalty of ``penalties``."""
    shapes = (("westergaard", westergaard_gap, (0.000863, 0.00345, 0.00863)),
              ("random_2d", random_profile_gap, (0.001, 0.003, 0.01)),
              ("random_2d_seed11", partial(random_profile_gap, seed=11), (0.001, 0.003, 0.01)))
    return tuple(Oracle(f"{name} k_n={k_n:g}", 2, gap, loads, 64, LARGEST, reference_grid(k_n), k_n=k_n,
                        enforcement="penalty") for k_n in penalties for name, gap, loads in shapes)


def reference_grid(k_n: float) -> int:
    """The points of the reference grid under the penalty ``k_n``: a power of two, at least :data:`REFERENCE`,
    whose step (period 1) is at most :data:`REFERENCE_STEP` of ``lambda = E*/k_n``."""
    lam = E_STAR / k_n
    return max(REFERENCE, 2 ** int(np.ceil(np.log2(1.0 / (REFERENCE_STEP * lam)))))


def summarize(data: list[dict]) -> str:
    """The study's outcome in words: per penalty the range of the judged rows' effectivity, and every row
    outside [1, 10]."""
    parts = []
    for k_n in sorted({d["k_n"] for d in data}):
        rows = [d for d in data if d["k_n"] == k_n]
        kept = [d for d in rows if judged(d)]
        effs = np.array([d["effectivity"] for d in kept])
        below = [d for d in kept if d["effectivity"] < 1]
        above = [d for d in kept if d["effectivity"] > 10]
        text = f"k_n = {k_n:g}: {len(rows)} rows, {len(kept)} judged"
        if len(effs):
            text += (f", effectivity {effs.min():.3g} to {effs.max():.3g}, {len(below)} below 1"
                     + "".join(f" ({d['oracle']} {d['tolerance']:g} load {d['load']} {d['quantity']} "
                               f"{d['effectivity']:.3g})" for d in below)
                     + f", {len(above)} above 10 ({sum(d['by_chance'] for d in above)} of them by chance)")
        parts.append(text)
    return "; ".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "penalty_effectivity"), help="output directory")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    data = []
    for oracle in oracles():
        for row in oracle_rows(oracle, TOLERANCES):
            row["k_n"] = oracle.k_n
            data.append(row)
        print(f"{oracle.name}: {sum(1 for d in data if d['oracle'] == oracle.name)} rows", flush=True)
    os.makedirs(args.out, exist_ok=True)
    keys = ("k_n",) + KEYS
    csv_path = os.path.join(args.out, "penalty_effectivity.csv")
    write_csv(csv_path, list(keys), [[d[k] for k in keys] for d in data])
    plot(data, os.path.join(args.out, "penalty_effectivity.png"), oracles())
    summary = summarize(data)
    print(summary)
    if args.publish:
        benchmark_doc.publish("penalty_effectivity", "A penalty's estimate on random profiles and Westergaard",
                              csv_path, note=__doc__.split("\n\n")[1].replace("\n", " ")
                              + " Columns as in the spectral refinement's section above; `judged`: the true "
                              f"error above `reference_change`. {summary}.",
                              png=os.path.join(args.out, "penalty_effectivity.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
