"""Write the STEP file of the femur scene's section: the stem and the bone as two faces in ``z = 0``, in mm.

The axisymmetric section ``(r, z)`` = ``(x, y)`` of ``geometries/femur_stem.toml`` (its
``[geometry.dimensions]``): the stem from its tip to its top, the bone from the clamped base to its top
around the stem and the empty canal below the tip, written as two separate faces with no names, as a CAD
system exports a section.  ``geometries/macro/femur_stem_step.toml`` reads it; its peak interface pressure
is the built-in shape's (``tests/macro/test_press_fit_step.py``).

    python scripts/femur_stem_step.py [OUT]

Default ``OUT``: ``geometries/macro/data/femur_stem_section.step``.
"""
from __future__ import annotations

import argparse
import os
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "geometries", "femur_stem.toml")


def stem_and_bone(dims: dict, unit: float = 1e-3):
    """The stem's and the bone's faces of the section with the scene's ``dims`` [m], in units of ``unit``."""
    from netgen.occ import WorkPlane

    d = {k: v / unit for k, v in dims.items()}

    def face(points):
        wp = WorkPlane().MoveTo(*points[0])
        for p in points[1:]:
            wp = wp.LineTo(*p)
        return wp.Close().Face()

    stem = face([(0.0, d["z_tip"]), (d["r_tip"], d["z_tip"]), (d["r_stem"], d["z_corner"]),
                 (d["r_stem"], d["z_stem_top"]), (0.0, d["z_stem_top"])])
    bone = face([(d["r_tip"], 0.0), (d["r_bone"], 0.0), (d["r_bone"], d["z_bone_top"]),
                 (d["r_stem"], d["z_bone_top"]), (d["r_stem"], d["z_corner"]), (d["r_tip"], d["z_tip"])])
    return stem, bone


def main() -> int:
    from netgen.occ import Compound

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?", default=os.path.join(ROOT, "geometries", "macro", "data",
                                                          "femur_stem_section.step"))
    args = p.parse_args()
    with open(SCENE, "rb") as fh:
        dims = tomllib.load(fh)["geometry"]["dimensions"]
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    Compound(list(stem_and_bone(dims))).WriteStep(args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
