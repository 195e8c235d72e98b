"""CalculiX against this package: two blocks pressed and sheared through the same exported interface law.

The client check of issue 16 (:mod:`ngcontact.export.calculix_check`): the law
of ``geometries/macro/sinusoid_gap_cell.toml`` (one cell unit = 0.1 mm) is
exported for ccx and as JSON; a steel block 20 x 5 mm on a base 20 x 5 mm
(plane strain, base clamped) is moved at its top by 2 um down and 0.5 um
sideways, once in ccx (a C3D8I slab ``nx`` elements long and ``nx / 4`` high
per body, node-to-face contact with the exported ``*SURFACE INTERACTION``)
and once by this package (order-2 triangles of size ``2 L / nx``, the law
read back from the JSON file).  The press lies inside the law's nonlinear
(kinked) range; the friction coefficient 0.3 keeps ccx's interface sticking,
where its stick slope is the law's ``k_t0``.

Compared: the reaction force on the top (both components, per metre), the
mean contact pressure, the pressure at the centre and its largest value, the
shear at the centre; with both codes' wall times (ccx on one thread).  Wall
times measured on a busy machine are noisy: rerun quietly before quoting them.

Writes ``calculix_comparison.csv`` (level, quantity, unit, both values, the
relative difference, both run times) and ``calculix_comparison.png``
(pressure and shear along the interface from both codes at the finest level;
relative differences by level) into the output directory (default
``results/calculix_comparison``) and prints the table.

Usage::

    python scripts/calculix_comparison.py [OUT_DIR] [--levels 20 40 80]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ngcontact.export.calculix_check import compare  # noqa: E402
from ngcontact.export.calculix_model import Blocks, ccx_path  # noqa: E402
from ngcontact.output.writer import write_csv  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CELL = os.path.join(ROOT, "geometries", "macro", "sinusoid_gap_cell.toml")
HEADER = ["nx", "quantity", "unit", "ngcontact", "ccx", "relative_difference", "ngcontact_seconds", "ccx_seconds"]


def blocks(nx: int) -> Blocks:
    return Blocks(length=0.02, h_block=0.005, h_base=0.005, E=210e9, nu=0.3, nx=nx, ny_block=max(nx // 4, 2),
                  ny_base=max(nx // 4, 2), press=2e-6, shear=0.5e-6)


def plot(path: str, results: dict[int, dict]) -> None:
    finest = results[max(results)]
    cx = finest["ccx"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    prof = finest["profile"]
    ax1.plot(prof["x"] * 1e3, prof["pressure"] / 1e6, "-", label="ngcontact pressure")
    ax1.plot(cx["x"] * 1e3, cx["pressure"] / 1e6, "o", ms=3, label="ccx pressure")
    ax1.plot(prof["x"] * 1e3, np.abs(prof["shear"]) / 1e6, "-", label="ngcontact |shear|")
    ax1.plot(cx["x"] * 1e3, np.abs(cx["shear"]) / 1e6, "s", ms=3, label="ccx |shear|")
    ax1.set_xlabel("x [mm]")
    ax1.set_ylabel("contact stress [MPa]")
    ax1.set_title(f"interface, nx = {max(results)}")
    ax1.legend(fontsize=8)
    names = [row[0] for row in finest["rows"]]
    width = 0.8 / len(results)
    for k, (nx, r) in enumerate(sorted(results.items())):
        diffs = [max(row[4], 1e-16) for row in r["rows"]]
        ax2.bar(np.arange(len(names)) + k * width, diffs, width,
                label=f"nx = {nx}: ngcontact {r['seconds']['ngcontact']:.1f} s, ccx {r['seconds']['ccx']:.1f} s")
    ax2.axhline(0.01, color="k", ls="--", lw=1, label="1 %")
    ax2.set_yscale("log")
    ax2.set_xticks(np.arange(len(names)) + 0.4 - width / 2, names, rotation=30, ha="right", fontsize=8)
    ax2.set_ylabel("|ngcontact - ccx| / |ccx|")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "calculix_comparison"),
                    help="output directory")
    ap.add_argument("--levels", type=int, nargs="+", default=[20, 40, 80], metavar="NX",
                    help="ccx elements along the interface (ngcontact: element size 2 L / NX)")
    args = ap.parse_args(argv)
    if ccx_path() is None:
        print("calculix_comparison: ccx is not on PATH (Debian package calculix-ccx)", file=sys.stderr)
        return 1
    os.makedirs(args.out, exist_ok=True)
    results, table = {}, []
    with tempfile.TemporaryDirectory() as work:
        for nx in args.levels:
            r = compare(CELL, os.path.join(work, f"nx{nx}"), blocks(nx), length_unit=1e-4, mu=0.3, p_max=1e8)
            results[nx] = r
            for name, unit, ours, theirs, diff in r["rows"]:
                table.append([nx, name, unit, ours, theirs, diff, r["seconds"]["ngcontact"], r["seconds"]["ccx"]])
                print(f"nx {nx:4d}  {name:28s} {ours:14.6g} {theirs:14.6g} {diff:10.2e} {unit}")
            print(f"nx {nx:4d}  run time: ngcontact {r['seconds']['ngcontact']:.2f} s ({r['ndof']} dofs), "
                  f"ccx {r['seconds']['ccx']:.2f} s; ccx stick ratio max |tau|/(mu p) = {r['stick']:.3f}")
    write_csv(os.path.join(args.out, "calculix_comparison.csv"), HEADER, table)
    plot(os.path.join(args.out, "calculix_comparison.png"), results)
    print(f"wrote {args.out}/calculix_comparison.csv and .png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
