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
shear at the centre.

Second model, a plane-strain press fit: two steel tubes (radii 10, 20, 30
mm, a quarter, cuts held normally) with the same cell's law and a radial
interference of 3 um, the macro gap ``g0`` the law is exported with (ccx:
the table shifted by ``g0``); ccx on a slab of ``nx`` elements along the
arc and ``nx / 4`` through each wall, this package on curved order-2
triangles of size ``2 (c - a) / (nx / 2)``.  Compared: the outer tube's hoop
force on its cut, the radial displacements of mantle and bore at 45
degrees, the contact pressure at 45 degrees and its mean over the arc.

Both codes' wall times are recorded (ccx on one thread; this package from
reading the scene to the measured solution, on the machine's cores; the
discretizations differ, so the times say what each took, not which is
faster at equal accuracy).  Wall times measured on a busy machine are noisy:
rerun quietly before quoting them.

Writes ``calculix_comparison.csv`` (model, level, quantity, unit, both
values, the relative difference, both run times) and
``calculix_comparison.png`` (the contact stresses from both codes at the
finest level of each model; relative differences by level) into the output
directory (default ``results/calculix_comparison``) and prints the table.

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

from ngcontact.export.calculix_check import compare, compare_press_fit  # noqa: E402
from ngcontact.verification.calculix_model import Blocks, PressFit, ccx_path  # noqa: E402
from ngcontact.output.writer import write_csv  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CELL = os.path.join(ROOT, "geometries", "macro", "sinusoid_gap_cell.toml")
HEADER = ["model", "nx", "quantity", "unit", "ngcontact", "ccx", "relative_difference", "ngcontact_seconds",
          "ccx_seconds"]


def blocks(nx: int) -> Blocks:
    return Blocks(length=0.02, h_block=0.005, h_base=0.005, E=210e9, nu=0.3, nx=nx, ny_block=max(nx // 4, 2),
                  ny_base=max(nx // 4, 2), press=2e-6, shear=0.5e-6)


def press_fit(nx: int) -> PressFit:
    return PressFit(a=0.01, b=0.02, c=0.03, E=210e9, nu=0.3, n_theta=nx, n_inner=max(nx // 4, 2),
                    n_outer=max(nx // 4, 2))


def plot(path: str, results: dict[int, dict], fits: dict[int, dict]) -> None:
    finest = results[max(results)]
    cx = finest["ccx"]
    fig, (ax1, ax3, ax2) = plt.subplots(1, 3, figsize=(17, 4.8))
    prof = finest["profile"]
    ax1.plot(prof["x"] * 1e3, prof["pressure"] / 1e6, "-", label="ngcontact pressure")
    ax1.plot(cx["x"] * 1e3, cx["pressure"] / 1e6, "o", ms=3, label="ccx pressure")
    ax1.plot(prof["x"] * 1e3, np.abs(prof["shear"]) / 1e6, "-", label="ngcontact |shear|")
    ax1.plot(cx["x"] * 1e3, np.abs(cx["shear"]) / 1e6, "s", ms=3, label="ccx |shear|")
    ax1.set_xlabel("x [mm]")
    ax1.set_ylabel("contact stress [MPa]")
    ax1.set_title(f"interface, nx = {max(results)}")
    ax1.legend(fontsize=8)
    fit = fits[max(fits)]
    ax3.plot(np.degrees(fit["profile"]["theta"]), fit["profile"]["pressure"] / 1e6, "-", label="ngcontact")
    ax3.plot(np.degrees(fit["ccx"]["theta"]), fit["ccx"]["pressure"] / 1e6, "o", ms=3, label="ccx")
    ax3.set_xlabel("angle [degrees]")
    ax3.set_ylabel("contact pressure [MPa]")
    ax3.set_title(f"press fit, nx = {max(fits)}")
    ax3.legend(fontsize=8)
    names = [f"blocks: {row[0]}" for row in finest["rows"]] + [f"press fit: {row[0]}" for row in fit["rows"]]
    width = 0.8 / len(results)
    for k, nx in enumerate(sorted(results)):
        r, f = results[nx], fits[nx]
        diffs = [max(row[4], 1e-16) for row in r["rows"] + f["rows"]]
        ax2.bar(np.arange(len(names)) + k * width, diffs, width,
                label=f"nx = {nx}: ngcontact {r['seconds']['ngcontact']:.1f} + {f['seconds']['ngcontact']:.1f} s, "
                      f"ccx {r['seconds']['ccx']:.1f} + {f['seconds']['ccx']:.1f} s")
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
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    if ccx_path() is None:
        print("calculix_comparison: ccx is not on PATH (Debian package calculix-ccx)", file=sys.stderr)
        return 1
    os.makedirs(args.out, exist_ok=True)
    results, fits, table = {}, {}, []
    with tempfile.TemporaryDirectory() as work:
        for nx in args.levels:
            r = compare(CELL, os.path.join(work, f"blocks{nx}"), blocks(nx), length_unit=1e-4, mu=0.3, p_max=1e8)
            f = compare_press_fit(CELL, os.path.join(work, f"fit{nx}"), press_fit(nx), length_unit=1e-4,
                                  gap=-3e-6, p_max=1e8)
            results[nx], fits[nx] = r, f
            for model, res in (("blocks", r), ("press fit", f)):
                for name, unit, ours, theirs, diff in res["rows"]:
                    table.append([model, nx, name, unit, ours, theirs, diff, res["seconds"]["ngcontact"],
                                  res["seconds"]["ccx"]])
                    print(f"{model:9s} nx {nx:3d}  {name:30s} {ours:14.6g} {theirs:14.6g} {diff:10.2e} {unit}")
                print(f"{model:9s} nx {nx:3d}  run time: ngcontact {res['seconds']['ngcontact']:.2f} s "
                      f"({res['ndof']} dofs), ccx {res['seconds']['ccx']:.2f} s")
            print(f"blocks    nx {nx:3d}  ccx stick ratio max |tau|/(mu p) = {r['stick']:.3f}")
    write_csv(os.path.join(args.out, "calculix_comparison.csv"), HEADER, table)
    plot(os.path.join(args.out, "calculix_comparison.png"), results, fits)
    print(f"wrote {args.out}/calculix_comparison.csv and .png")
    if args.publish:
        benchmark_doc.publish("calculix_comparison", "CalculiX against this package (exported interface law)",
                              os.path.join(args.out, "calculix_comparison.csv"),
                              note="Two blocks pressed and sheared, and a press fit of two tubes, through the "
                                   "exported law of `geometries/macro/sinusoid_gap_cell.toml`: each quantity from "
                                   "both codes, their relative difference, and each code's run time in seconds "
                                   "(the discretizations differ: the times say what each took, not which is "
                                   "faster at equal accuracy).",
                              png=os.path.join(args.out, "calculix_comparison.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
