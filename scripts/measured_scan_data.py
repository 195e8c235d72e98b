"""Write the shipped measured scan ``geometries/cells/data/ground_scan.x3p`` (reproducibly).

A stand-in for a profilometer's scan of a ground steel face: 64 x 64 points over 100 um x 100 um, heights
in metres in the file (X3P), not periodic, tilted and slightly curved as a real scan is.  Its roughness is a
window of a self-affine surface (Hurst exponent 0.8, rms slope 0.05 over the 200 um period it is cut
from, roll-off 50 um, seed 7: :func:`ngcontact.geometry.random_surface.self_affine`), so the window does not
close on itself; the instrument's tilt is ``2e-2`` along ``x`` and ``-1e-2`` along ``y`` and its form a
bowl of 0.5 um sag across the scan.  The scene ``geometries/cells/measured_scan.toml`` removes tilt and
form (``detrend = "curvature"``) and mirrors the scan into a period of 200 um (``periodize = "mirror"``).

    python scripts/measured_scan_data.py [--check]

``--check`` writes to a temporary file and compares its bytes with the shipped one (exit 1 if they differ).
"""
from __future__ import annotations

import argparse
import filecmp
import os
import sys
import tempfile

import numpy as np

from ngcontact.geometry.random_surface import self_affine
from ngcontact.geometry.x3p import write_x3p

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TARGET = os.path.join(ROOT, "geometries", "cells", "data", "ground_scan.x3p")
#: points per direction of the scan, its physical size and that of the surface it is cut from (metres)
POINTS, SIZE = 64, 100e-6
TILT = (2e-2, -1e-2)
SAG = 0.5e-6


def scan_heights() -> np.ndarray:
    """The scan's heights ``[y, x]`` in metres (module docstring)."""
    surface = self_affine(grid=2 * POINTS, period=2 * SIZE, hurst=0.8, rms_slope=0.05, rolloff=SIZE / 2, seed=7)
    z = surface[:POINTS, :POINTS]
    s = SIZE * np.arange(POINTS) / POINTS
    x, y = s[None, :], s[:, None]
    r2 = ((x - SIZE / 2) ** 2 + (y - SIZE / 2) ** 2) / (SIZE / 2) ** 2
    return z + TILT[0] * x + TILT[1] * y + SAG * r2


def write(path: str) -> None:
    write_x3p(path, scan_heights(), (SIZE / POINTS, SIZE / POINTS), model="scripts/measured_scan_data.py",
              comment="stand-in for a ground steel face: self-affine window, tilted and curved, not periodic")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with the shipped file instead of writing it")
    args = ap.parse_args(argv)
    if not args.check:
        write(TARGET)
        print(f"wrote {os.path.relpath(TARGET, ROOT)}")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        fresh = os.path.join(tmp, "ground_scan.x3p")
        write(fresh)
        same = filecmp.cmp(fresh, TARGET, shallow=False)
    print("the shipped scan is reproduced" if same else "the shipped scan differs from the script's")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
