"""The press fit read from a STEP file against Lame's closed form and the built-in coaxial shape, by mesh size.

``geometries/macro/press_fit_step.toml`` (a quarter hub on a tube, two
unnamed solids in mm, both ends held in z: plane strain) solved at several
mesh sizes; for each the mean interface pressure of the STEP geometry, its
error against Lame's pressure with the interface compliance ``1/kn`` in series
(:func:`ngcontact.verification.lame.lame_press_fit_pressure`), the same
scene on the built-in ``coaxial`` 3D shape and the two's difference, the
degrees of freedom and the time to read, mesh and solve the STEP model.

    python scripts/press_fit_step_vs_lame.py [OUT] [--publish]

Writes ``OUT/press_fit_step.csv`` and ``.png`` (default ``results/press_fit_step``).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import tomllib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.drivers import run_macro as RM  # noqa: E402
from ngcontact.macro import macro_measures as MM  # noqa: E402
from ngcontact.output.writer import write_csv  # noqa: E402
from ngcontact.scene import loader  # noqa: E402
from ngcontact.verification.lame import lame_press_fit_pressure  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "geometries", "macro", "press_fit_step.toml")
A, B, C, HEIGHT = 0.005, 0.03, 0.075, 0.02
SIZES = (0.015, 0.01, 0.008, 0.006)      # maxh [m]; the interface gets 3/4 of it
KEYS = ("maxh", "ndof", "p_step", "error_step", "p_coaxial", "step_vs_coaxial", "seconds_step")


def solved(scene, maxh: float) -> tuple[float, int, float]:
    """(mean pressure, dofs, seconds) of ``scene`` at mesh size ``maxh``."""
    start = time.perf_counter()
    geometry = RM.build_geometry(scene, maxh=maxh, interface_maxh=0.75 * maxh)
    problem, _ = RM.problem_of(scene, geometry)
    sol = RM.solve_scene(scene, problem)
    return MM.mean_pressure(sol), sol.ndof, time.perf_counter() - start


def rows() -> list[dict]:
    scene = loader.load(SCENE)
    with open(SCENE, "rb") as fh:
        data = tomllib.load(fh)
    data["geometry"] = {"shape": "coaxial", "setting": "3d",
                        "dimensions": {"a": A, "b": B, "c": C, "height": HEIGHT}}
    builtin = loader.from_dict(data, base_dir=os.path.dirname(SCENE))
    m = {k: scene.materials[v] for k, v in (("in", scene.bodies.rough), ("out", scene.bodies.counter))}
    lame = lame_press_fit_pressure(A, B, C, m["in"].E, m["in"].nu, m["out"].E, m["out"].nu,
                                   interference=-scene.interface.gap, k_n=scene.interface.kn)
    out = []
    for h in SIZES:
        p, ndof, seconds = solved(scene, h)
        q = solved(builtin, h)[0]
        out.append({"maxh": h, "ndof": ndof, "p_step": p, "error_step": p / lame - 1, "p_coaxial": q,
                    "step_vs_coaxial": p / q - 1, "seconds_step": seconds})
    return out


def plot(data: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.loglog([d["ndof"] for d in data], [abs(d["error_step"]) for d in data], "o-", label="STEP vs Lame")
    ax.loglog([d["ndof"] for d in data], [abs(d["step_vs_coaxial"]) for d in data], "s--",
              label="STEP vs built-in coaxial")
    ax.axhline(5e-3, color="0.6", lw=0.8, label="aim vs Lame: 0.5 %")
    ax.set_xlabel("degrees of freedom")
    ax.set_ylabel("relative difference of the mean pressure")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "press_fit_step"), help="output directory")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    data = rows()
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, "press_fit_step.csv")
    write_csv(csv_path, list(KEYS), [[d[k] for k in KEYS] for d in data])
    plot(data, os.path.join(args.out, "press_fit_step.png"))
    if args.publish:
        benchmark_doc.publish("press_fit_step", "The press fit from a STEP file against Lame and the built-in shape",
                              csv_path, note="`geometries/macro/press_fit_step.toml` at order 2, interface mesh "
                              "size 3/4 of maxh; Lame's plane-strain pressure with 1/kn in series is "
                              "27.0616 MPa. Issue 37 asks for 0.5 % against Lame and 1e-4 against the built-in "
                              "coaxial shape; seconds_step: reading, meshing and solving the STEP model.",
                              png=os.path.join(args.out, "press_fit_step.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
