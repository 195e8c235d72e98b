"""A measured scan read from its X3P file against the same heights as .npy, a finer grid and surfaces like it.

The shipped scene ``geometries/cells/measured_scan.toml`` (a profilometer's scan in X3P, detrended and
mirrored into a period of 200 um; spectral cell, exact non-penetration, steel) is solved

* as shipped (the scene refines from 32 points to the default tolerance), but on the map's own 128 x 128 grid
  alone, the map read from the X3P file through SurfaceTopography;
* with the same periodic heights given as ``.npy`` in the package's layout (the map the X3P route built,
  saved): the two must agree to round-off;
* on finer spectral grids alone (``discretization.grid`` 256 and 512, no estimate: the bilinear interpolant of
  the map, the surface the cell stands for), towards the converged value of that surface;
* as the class of surfaces like it (``measured_scan_ensemble.toml``: random surfaces with the scan's
  spectrum), the mean and 95 % half-width of the contact fraction over its members.

    python scripts/measured_topography.py [OUT] [--publish]

Writes ``OUT/measured_topography.csv`` and ``.png`` (default ``results/measured_topography``); needs
SurfaceTopography (``pip install ".[topography]"``).
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.drivers.cell_gap import height_map  # noqa: E402
from ngcontact.output.writer import write_csv  # noqa: E402
from ngcontact.runner import solve  # noqa: E402
from ngcontact.scene import loader  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "geometries", "cells", "measured_scan.toml")
ENSEMBLE = os.path.join(ROOT, "geometries", "cells", "measured_scan_ensemble.toml")
GRIDS = (256, 512)
#: the periodized map's own grid, on which the X3P and .npy routes are compared
OWN_GRID = 128
KEYS = ("pressure", "cf_x3p", "cf_npy", "cf_difference", "closure_relative_difference",
        *(f"cf_grid{n}" for n in GRIDS), "cf_class_mean", "cf_class_half_width")


def _loads(path: str) -> list[dict]:
    report, _ = solve(path, workers=1)
    return report["results"]["loads"]


def _variant(text: str, where: str, name: str) -> str:
    """Write the scene text ``text`` as ``where/name`` and return its path (relative files resolved to ROOT)."""
    data = os.path.join(ROOT, "geometries", "cells", "data")
    path = os.path.join(where, name)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text.replace('"data/', f'"{data}/'))
    return path


def on_grid(text: str, grid: int) -> str:
    """The scene ``text`` solved on ``grid`` points per direction alone (its refinement's first grid replaced,
    no estimate)."""
    return re.sub(r'(?m)^grid = .*$', f'grid = {grid}\nestimate = "off"', text, count=1)


def rows() -> list[dict]:
    text = open(SCENE, encoding="utf-8").read()
    with tempfile.TemporaryDirectory() as tmp:
        x3p = _loads(_variant(on_grid(text, OWN_GRID), tmp, "x3p.toml"))
        np.save(os.path.join(tmp, "map.npy"), height_map(loader.load(SCENE)))
        npy_text = re.sub(r'(?m)^(file|detrend|periodize) = .*$', "", text).replace(
            'profile = "height_map"', f'profile = "height_map"\nfile = "{tmp}/map.npy"')
        npy = _loads(_variant(on_grid(npy_text, OWN_GRID), tmp, "npy.toml"))
        finer = {n: _loads(_variant(on_grid(text, n), tmp, f"grid{n}.toml")) for n in GRIDS}
    report, _ = solve(ENSEMBLE, workers=1)
    band = report["results"]["loads"]
    out = []
    for k, (a, b) in enumerate(zip(x3p, npy)):
        row = {"pressure": a["transmitted_pressure"], "cf_x3p": a["contact_fraction"], "cf_npy": b["contact_fraction"],
               "cf_difference": abs(a["contact_fraction"] - b["contact_fraction"]),
               "closure_relative_difference": abs(a["mean_closure"] - b["mean_closure"]) / abs(b["mean_closure"]),
               "cf_class_mean": band[k]["contact_fraction"]["mean"],
               "cf_class_half_width": band[k]["contact_fraction"]["half_width"]}
        row.update({f"cf_grid{n}": finer[n][k]["contact_fraction"] for n in GRIDS})
        out.append(row)
    return out


def plot(data: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    p = np.array([d["pressure"] for d in data])
    fig, ax = plt.subplots(figsize=(6, 4))
    mean = np.array([d["cf_class_mean"] for d in data])
    half = np.array([d["cf_class_half_width"] for d in data])
    ax.fill_between(p, mean - half, mean + half, color="C2", alpha=0.3, label="surfaces like it: 95 % band")
    ax.plot(p, mean, "-", color="C2", label="surfaces like it: mean")
    ax.plot(p, [d["cf_x3p"] for d in data], "o", ms=8, mfc="none", label="X3P, own grid 128")
    ax.plot(p, [d["cf_npy"] for d in data], "x", ms=8, label=".npy, same heights")
    for n in GRIDS:
        ax.plot(p, [d[f"cf_grid{n}"] for d in data], "s--", ms=4, label=f"X3P, grid {n}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("mean pressure [Pa]")
    ax.set_ylabel("contact fraction")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "measured_topography"), help="output directory")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    data = rows()
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, "measured_topography.csv")
    png = os.path.join(args.out, "measured_topography.png")
    write_csv(csv_path, list(KEYS), [[d[k] for k in KEYS] for d in data])
    plot(data, png)
    print(f"wrote {csv_path}")
    if args.publish:
        benchmark_doc.publish(
            "measured_topography", "A measured scan (X3P) against .npy, finer grids and surfaces like it", csv_path,
            note="`geometries/cells/measured_scan.toml` per pressure: the contact fraction from the X3P file "
                 "(`cf_x3p`, the map's own 128 x 128 grid) and from the same periodic heights as `.npy` "
                 "(`cf_npy`), their difference and the relative difference of the mean closure (round-off "
                 "expected); the same scene on finer spectral grids (the bilinear interpolant of the map); and the "
                 "contact fraction of the class of surfaces with the scan's spectrum "
                 "(`measured_scan_ensemble.toml`, 8 members): mean and 95 % half-width.", png=png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
