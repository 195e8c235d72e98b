"""Write the STEP file of the shipped press-fit scene: a quarter hub on a quarter tube, two solids, in mm.

The tube (bore 5 mm, outer radius 30 mm) and the hub (bore 30 mm, outer
radius 75 mm), 20 mm high, axis ``z``, cut to ``x, y >= 0``, written as two
separate solids that touch along ``r = 30 mm``, with no face names, as a CAD
system exports an assembly (``geometries/macro/press_fit_step.toml`` reads it;
the interference is the scene's negative ``interface.gap``).

    python scripts/press_fit_step.py [OUT]

Default ``OUT``: ``geometries/macro/data/press_fit_quarter.step``.
"""
from __future__ import annotations

import argparse
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BORE, INTERFACE, OUTER, HEIGHT = 5.0, 30.0, 75.0, 20.0


def quarter_hub_and_tube():
    """The two solids (tube, hub), in millimetres."""
    from netgen.occ import Box, Cylinder, Pnt, Z

    quarter = Box(Pnt(0, 0, 0), Pnt(2 * OUTER, 2 * OUTER, HEIGHT))

    def cylinder(r):
        return Cylinder(Pnt(0, 0, 0), Z, r=r, h=HEIGHT)

    tube = (cylinder(INTERFACE) - cylinder(BORE)) * quarter
    hub = (cylinder(OUTER) - cylinder(INTERFACE)) * quarter
    return tube, hub


def main() -> int:
    from netgen.occ import Compound

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out", nargs="?", default=os.path.join(ROOT, "geometries", "macro", "data",
                                                          "press_fit_quarter.step"))
    args = p.parse_args()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    Compound(list(quarter_hub_and_tube())).WriteStep(args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
