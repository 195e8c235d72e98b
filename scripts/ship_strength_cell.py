"""Ship the main job's strength cell with the package: its entry in ``ngcontact/data/strength_cells``.

The main job, ``ngcontact run geometries/femur_stem.toml``, checks the strength of the stem's coating with
the hip-hills cell (``geometries/cells/hip_hills.toml``); on a machine whose cache has never seen it,
meshing that cell and factorizing its stiffness cost more than the macro solve.  This script computes the
cell's entry (mesh and fixed-set corrector states, :mod:`ngcontact.drivers.strength_cell`) and writes it
where the package looks first, under the key the current code computes, removing the entries of other keys
there.  Run it again whenever ``tests/drivers/test_strength_cell.py`` says the shipped key is stale (the
cell, its discretization or the code that computes it changed).

    python scripts/ship_strength_cell.py            # write the entry
    python scripts/ship_strength_cell.py --check    # exit 1 when the shipped entry is not the current key's
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "geometries" / "femur_stem.toml"
#: the macro frame's dimension of each setting (the interface law's directions)
DIM = {"plane_strain": 2, "axisymmetric": 2, "3d": 3}


def main_job_cell():
    """``(cell scene, k_t, key)`` of the main job's strength cell as the current code computes them."""
    from ngcontact.drivers import strength_cell as SC
    from ngcontact.drivers.run_macro import interface_law_of
    from ngcontact.drivers.run_strength import strength_cell
    from ngcontact.scene.loader import load

    scene = load(str(SCENE))
    law, _ = interface_law_of(scene, DIM[scene.geometry.setting])
    _, cs, kt = strength_cell(scene, law)
    return cs, kt, SC.recovery_key(cs, kt)


def shipped() -> list[str]:
    """The file names of the shipped entries."""
    from ngcontact.drivers.strength_cell import SHIPPED
    return sorted(f for f in os.listdir(SHIPPED) if f.endswith(".npz")) if os.path.isdir(SHIPPED) else []


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true", help="only compare the shipped key with the current one")
    args = parser.parse_args()
    from ngcontact.drivers import strength_cell as SC

    cs, kt, key = main_job_cell()
    if args.check:
        ok = shipped() == [f"{key}.npz"]
        print(f"shipped {shipped()}, current key {key}: {'up to date' if ok else 'stale'}")
        return 0 if ok else 1
    _, _, arrays = SC.compute_entry(cs, kt)
    if arrays is None:
        print("the main job's strength cell has curved elements: a mesh file cannot keep them", file=sys.stderr)
        return 2
    os.makedirs(SC.SHIPPED, exist_ok=True)
    for name in shipped():
        if name != f"{key}.npz":
            os.remove(os.path.join(SC.SHIPPED, name))
    SC.write_entry(key, arrays, SC.SHIPPED)
    path = os.path.join(SC.SHIPPED, f"{key}.npz")
    os.chmod(path, 0o644)   # package data, readable by all (the cache writes its entries private)
    print(f"wrote {os.path.relpath(path, ROOT)}: {os.path.getsize(path) / 1e3:.0f} kB "
          f"(states {arrays['states'].shape}, mesh file {arrays['mesh'].size / 1e3:.0f} kB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
