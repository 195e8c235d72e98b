"""Sliding ratio tau / p of a sawtooth interface: resolved against the homogenized macro laws (issue 14).

Two blocks meet along a symmetric sawtooth (faces at 20 degrees, period eps = L / N) with micro Coulomb
friction mu = 0.3 and a penalty; the upper face is pressed with p and displaced along x far enough for the
whole interface to slide.  The sliding ratio tau / p = (x reaction of the displaced face) / (p L) is the
largest shear the interface carries at that pressure; rigid wedge mechanics gives
(tan 20 + mu) / (1 - mu tan 20) = 0.7454.  Compared:

* ``resolved``: the sawtooth meshed with N periods;
* ``from_cell``: the two-scale macro scene with ``interface.friction = "from_cell"``: the cell's tabulated
  shear (:mod:`ngcontact.coupling.shear_table`) is the macro law's tangential part;
* ``hand_mu``: the same two-scale scene with the hand-set ``mu0 = mu`` (``interface.friction = "given"``);
* ``bundle_mu0``: the cell's direction bundle with the friction of eqs. 42-43 (``from_cell`` without
  ``[two_scale]``; in 2D exactly ``mu0 = mu``).

Writes ``sawtooth_shear.csv`` and ``sawtooth_shear.png`` into the output directory (default
``results/sawtooth_shear``) and prints the table with the wall time of each run.

Usage::

    python scripts/sawtooth_shear.py [OUT_DIR] [N ...] [--publish]

A second top displacement (0.002) leaves part of the interface sticking: there the tabulated curve
below the plateau matters, and the resolved ratio depends on eps.
"""
from __future__ import annotations

import argparse
import csv
import math
import os
from functools import partial
import sys
import tempfile
import time

from ngcontact.drivers import run_macro as RM
from ngcontact.drivers import run_resolved as drv
from ngcontact.drivers import run_two_scale as R2
from ngcontact.fem.reaction import boundary_reaction
from ngcontact.scene.loader import from_dict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)


P, U, MU, ANGLE, L = 1e-3, 0.02, 0.3, 20.0, 1.0
CELL = f"""kind = "cell"
title = "symmetric sawtooth at its physical period 1/8, Coulomb friction"
[materials.s]
E = 1.0
nu = 0.3
[bodies]
rough = "s"
counter = "s"
[geometry]
profile = "triangular"
arrangement = "conforming"
period = 0.125
h_rough = 0.125
h_counter = 0.125
angles = [{ANGLE}, {ANGLE}]
[contact]
k_n = 1000.0
friction = "coulomb"
mu = {MU}
w = 1e-5
[load]
pressure = [{P}]
[discretization]
order = 2
maxh = 0.03
interface_maxh = 0.0125
"""
MATERIALS = {"s": {"E": 1.0, "nu": 0.3}}


def resolved_ratio(base: str, periods: int, u: float = U) -> float:
    scene = from_dict({"kind": "direct", "materials": MATERIALS, "bodies": {"rough": "s", "counter": "s"},
                       "geometry": {"cell": "saw.toml", "periods": periods, "length": L, "h_rough": 0.5,
                                    "h_counter": 0.5},
                       "supports": [{"boundary": "bottom"},
                                    {"boundary": "top", "components": ["x"], "displacement": [u]}],
                       "loads": [{"boundary": "top", "pressure": P}],
                       "discretization": {"order": 2, "maxh": 0.1, "elements_per_period": 6}}, base_dir=base)
    sol = drv.solve_scene(scene, drv.problem_of(scene, drv.build_resolved(scene, periods)))
    return abs(drv.reactions(scene, sol)["top"]["x"]) / (P * L)


def macro_scene(base: str, interface: dict, two_scale: bool, u: float = U):
    data = {"kind": "macro", "materials": MATERIALS, "bodies": {"rough": "s", "counter": "s"},
            "geometry": {"shape": "block", "setting": "plane_strain",
                         "dimensions": {"length": L, "h_block": 0.5, "h_base": 0.5}},
            "interface": {"huber_width": 1e-5, **interface},
            "supports": [{"boundary": "bottom"}, {"boundary": "top", "components": ["x"], "displacement": [u]}],
            "loads": [{"boundary": "top", "pressure": P}],
            "discretization": {"order": 2, "maxh": 0.05}}
    if two_scale:
        data["two_scale"] = {"cell": "saw.toml", "tol": 1e-9, "table_tol": 0.05}
    return from_dict(data, base_dir=base)


def macro_ratio(scene, cache: str):
    geo = RM.build_geometry(scene)
    problem, _ = RM.problem_of(scene, geo)
    res = None
    if scene.two_scale is None:
        sol = RM.solve_scene(scene, problem)
    else:
        sol, res = R2.couple(scene, problem, partial(RM.solve_scene, scene),
                             map_tasks=lambda f, xs: [f(x) for x in xs], cache_dir=cache,
                             shear_map=lambda f, xs: [f(x) for x in xs])
    rough = problem.rough
    r = boundary_reaction(problem.mesh, problem.setting, problem.materials[rough], sol.u_rough, rough, "top",
                          problem.order)
    return abs(r["x"]) / (P * L), res


def serial(task, items):
    return [task(x) for x in items]


def wedge_ratio() -> float:
    t = math.tan(math.radians(ANGLE))
    return (t + MU) / (1 - MU * t)


def write_cell(base: str) -> None:
    with open(os.path.join(base, "saw.toml"), "w") as fh:
        fh.write(CELL)


#: top displacements: the whole interface slides (the test's case), and part of it still sticks
DISPLACEMENTS = (U, 0.002)
VARIANTS = {"from_cell": ({"law": "linear", "kn": 1000.0, "friction": "from_cell"}, True),
            "hand_mu": ({"law": "linear", "kn": 1000.0, "mu": MU}, True),
            "bundle_mu0": ({"cell": "saw.toml", "friction": "from_cell"}, False)}


def main(out: str, periods: list[int], publish: bool = False) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(out, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as base:
        write_cell(base)
        cache = os.path.join(base, "cache")
        for u in DISPLACEMENTS:
            for N in periods:
                t0 = time.perf_counter()
                rows.append({"case": "resolved", "N": N, "u": u, "ratio": resolved_ratio(base, N, u),
                             "seconds": time.perf_counter() - t0, "cell_solves": 0})
        for u in DISPLACEMENTS:
            for name, (interface, two_scale) in VARIANTS.items():
                t0 = time.perf_counter()
                ratio, res = macro_ratio(macro_scene(base, interface, two_scale, u), cache)
                rows.append({"case": name, "N": 0, "u": u, "ratio": ratio, "seconds": time.perf_counter() - t0,
                             "cell_solves": res["cell_solves"] if res else 0,
                             **({"shear_rows": res["shear_table"]["rows"], "shear_nodes": res["shear_table"]["nodes"],
                                 "shear_jump_error": res["shear_table"]["jump_error_estimate"],
                                 "shear_pressure_error": res["shear_table"]["pressure_error_estimate"],
                                 "macro_solves": res["macro_solves"]} if res and "shear_table" in res else {})})
    for r in rows:
        ref = [q for q in rows if q["case"] == "resolved" and q["u"] == r["u"]][-1]["ratio"]
        r["relative_error"] = abs(r["ratio"] - ref) / ref
    keys = sorted({k for r in rows for k in r}, key=lambda k: (k not in ("case", "u", "N", "ratio"), k))
    with open(os.path.join(out, "sawtooth_shear.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, keys)
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        print("  ".join(f"{k}={r[k]:.6g}" if isinstance(r.get(k), float) else f"{k}={r.get(k)}" for k in keys))
    print(f"wedge {wedge_ratio():.6f}")
    fig, axes = plt.subplots(1, len(DISPLACEMENTS), figsize=(5 * len(DISPLACEMENTS), 3.5), squeeze=False)
    for ax, u in zip(axes[0], DISPLACEMENTS):
        res_rows = [r for r in rows if r["case"] == "resolved" and r["u"] == u]
        ax.plot([1 / r["N"] for r in res_rows], [r["ratio"] for r in res_rows], "ko-", label="resolved")
        for r, style in zip([r for r in rows if r["case"] != "resolved" and r["u"] == u], ("C0--", "C1:", "C2-.")):
            ax.axhline(r["ratio"], color=style[:2], linestyle=style[2:], label=r["case"])
        ax.axhline(wedge_ratio(), color="0.6", linewidth=0.8, label="rigid wedge")
        ax.set_xlabel("eps / L")
        ax.set_ylabel("tau / p")
        ax.set_title(f"top displaced by {u:g}", fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "sawtooth_shear.png"), dpi=120)
    if publish:
        benchmark_doc.publish("sawtooth_shear", "Sawtooth interface: sliding ratio tau / p, resolved against "
                              "homogenized", os.path.join(out, "sawtooth_shear.csv"),
                              note=f"Faces at 20 degrees, micro Coulomb friction; the rigid wedge gives "
                                   f"{wedge_ratio():.6f}. `resolved` with N periods; `from_cell` the two-scale "
                                   "scene with the cell's tabulated shear; `hand_mu` the same with the hand-set "
                                   "mu0 = mu; `bundle_mu0` the direction bundle with the friction of eqs. 42-43. "
                                   "`relative_error` against the finest resolved run at the same displacement.",
                              png=os.path.join(out, "sawtooth_shear.png"))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "sawtooth_shear"), help="output directory")
    ap.add_argument("periods", nargs="*", type=int, default=[8, 16, 32], help="numbers of periods resolved")
    ap.add_argument("--publish", action="store_true", help="write the section of docs/benchmarks.md")
    a = ap.parse_args()
    main(a.out, a.periods, publish=a.publish)
