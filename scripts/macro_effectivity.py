"""How honest is the macro error estimate? Its effectivity on Lame's press fit and on the femur.

Every macro run reports its headline quantities with a discretization error estimated from the orders
one below and above on the same mesh (:mod:`ngcontact.macro.discretization_error`).  The oracles:

* Lame's press fit of two tubes through a linear Winkler interface (plane strain quarter, the
  compliances in series, :mod:`ngcontact.verification.lame`): the pressure, the resultant of the
  quarter's interface (``p b`` per component) and the largest von Mises and Tresca stress of each tube
  (at its bore) in closed form, at orders 1 to 4 on one coarse mesh curved at the order (straight-sided
  at order 1, whose neighbours are solved on it curved at order 2);
* the femur / hip-stem scene (``geometries/femur_stem.toml``, order 3) against the converged reference of
  :mod:`ngcontact.drivers.macro_reference`: order 4 on its mesh sizes divided by 4, the elements where the
  balls' circles cross the interface refined five times, the maxima away taken as suprema (a lattice of 24
  intervals per element edge reaching the faces, 65536 points per circle) and the safety factor at 21
  points per interface element; its own uncertainty (column ``reference_uncertainty``) is its difference to
  the same rule on the mesh sizes halved plus its sampling step (skipped with ``--quick``).

Each stress maximum's estimate is the default run's: the order ladder judged by
:mod:`ngcontact.macro.singular_maxima`, which reports a maximum with no converged value (a closed end of
the interface, a singular corner) without an estimate.

For each quantity: the value, the estimate, the true error and their ratio, the effectivity (issue 35
asks for it between 1 and 10).  Then the refinement towards ``discretization.tolerance``
(:mod:`ngcontact.drivers.macro_refinement`) on the same press fit as a scene of order 1, per tolerance:
the order that met it (or the last one tried, out of reach), the mesh levels refined after it, its
elements and unknowns, the largest estimated and the largest true relative error over the headline
quantities and the smallest effectivity (over the quantities whose true error exceeds round-off).  Usage::

    python scripts/macro_effectivity.py [OUT] [--quick] [--refinement-only] [--publish]

Writes ``OUT/macro_effectivity.csv``, ``.png`` and ``OUT/macro_refinement.csv``, ``.png`` (the levels of
the run to the smallest tolerance; default ``results/macro_effectivity``).
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.drivers import macro_accuracy as MA  # noqa: E402
from ngcontact.drivers import macro_reference as MR  # noqa: E402
from ngcontact.drivers import run_macro  # noqa: E402
from ngcontact.errors import ConvergenceError  # noqa: E402
from ngcontact.output.report import Clock  # noqa: E402
from ngcontact.scene import loader  # noqa: E402
from ngcontact.fem.materials import isotropic, tresca, von_mises  # noqa: E402
from ngcontact.geometry import bodies as gm  # noqa: E402
from ngcontact.laws import homogenized as il  # noqa: E402
from ngcontact.macro import away_maxima as AM  # noqa: E402
from ngcontact.macro import discretization_error as DE  # noqa: E402
from ngcontact.macro import macro_problem as M  # noqa: E402
from ngcontact.macro import singular_maxima as SM  # noqa: E402
from ngcontact.output.writer import write_csv  # noqa: E402
from ngcontact.verification.lame import lame_press_fit_pressure  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
A, B, C = 0.5, 1.0, 2.0
E_IN, NU_IN, E_OUT, NU_OUT = 200.0, 0.3, 70.0, 0.25
K_N, DELTA, MAXH = 300.0, 1e-3, 0.3
KEYS = ("oracle", "order", "quantity", "value", "exact", "reference_uncertainty", "estimate", "true_error",
        "effectivity", "ratio")
#: the femur's oracle (:mod:`ngcontact.drivers.macro_reference`)
FEMUR = "femur (order 4, mesh sizes / 4, dense)"
REFINE_KEYS = ("tolerance", "scene_order", "orders", "mesh_levels", "elements", "ndof", "met", "largest_estimate",
               "largest_true_error", "smallest_effectivity", "seconds")
#: the tolerances the refinement is run to on Lame's press fit (the last two beyond order 4 on its mesh)
TOLERANCES = (0.1, 0.03, 0.01, 0.001, 0.0001)


class _Output:
    points_per_element = 5


class _Scene:
    """What :func:`ngcontact.drivers.macro_accuracy.order_samples` reads of a scene."""

    output = _Output


def ring_stress(r: float, r1: float, r2: float, p_in: float, p_out: float, nu: float) -> np.ndarray:
    """Lame's stress tensor (plane strain) in a ring ``r1 < r < r2`` under pressures on its faces."""
    a = (p_in * r1 ** 2 - p_out * r2 ** 2) / (r2 ** 2 - r1 ** 2)
    b = (p_in - p_out) * r1 ** 2 * r2 ** 2 / (r2 ** 2 - r1 ** 2)
    srr, stt = a - b / r ** 2, a + b / r ** 2
    return np.diag([srr, stt, nu * (srr + stt)])


def lame_exact() -> dict[str, float]:
    p = lame_press_fit_pressure(A, B, C, E_IN, NU_IN, E_OUT, NU_OUT, DELTA, K_N)
    inner, outer = ring_stress(A, A, B, 0.0, p, NU_IN), ring_stress(B, B, C, p, 0.0, NU_OUT)
    return {"peak_pressure": p, "resultant": p * B, "von_mises_inner": float(von_mises(inner)),
            "tresca_inner": float(tresca(inner)), "von_mises_outer": float(von_mises(outer)),
            "tresca_outer": float(tresca(outer))}


def row(oracle: str, order: int, e: DE.Estimate, exact: float, uncertainty: float = 0.0) -> dict:
    """One quantity's estimate against ``exact`` (``uncertainty``: the reference's own, 0 for a closed form)."""
    true = abs(e.value - exact)
    eff = e.error / true if e.error is not None and true > 0 else None
    return {"oracle": oracle, "order": order, "quantity": e.name, "value": e.value, "exact": exact,
            "reference_uncertainty": uncertainty, "estimate": e.error, "true_error": true, "effectivity": eff,
            "ratio": e.ratio if math.isfinite(e.ratio) else None}


def lame_rows() -> list[dict]:
    exact = lame_exact()
    out = []
    for order in (1, 2, 3, 4):
        g = gm.coaxial_plane_strain(A, B, C, maxh=MAXH, order=order)
        sup = (M.Support(label="sym_x", components=("x",)), M.Support(label="sym_y", components=("y",)))
        prob = M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="inner", counter="outer",
                              materials={"inner": isotropic(E_IN, NU_IN), "outer": isotropic(E_OUT, NU_OUT)},
                              law=il.InterfaceLaw(normal=il.LinearLaw(kn=K_N)), gap=-DELTA, supports=sup,
                              order=order)
        sol = M.solve(prob)

        def solve(p, start):
            return M.solve(p, start=start)
        samples = MA.order_samples(_Scene, sol, solve)
        for e in SM.check(MA.estimates(samples, sol), sol, samples[order], solve):
            key = "resultant" if e.name.startswith("resultant_") else e.name
            out.append(row("Lame press fit", order, e, exact[key]))
    return out


def femur_rows() -> list[dict]:
    """The femur's estimates as its run makes them (``ngcontact.drivers.macro_accuracy.accuracy``: the order
    ladder, the singular maxima, the maxima away from the singular points judged by local refinements) against
    the converged reference of :mod:`ngcontact.drivers.macro_reference` (order 4 on the mesh sizes divided by
    4, the suprema sampled densely, outside the same balls), with its own uncertainty from the same rule on the
    mesh sizes halved."""
    from ngcontact.drivers.run_macro import build_geometry, problem_of, solve_scene
    from ngcontact.drivers.run_strength import recovery_of
    sc = loader.load(os.path.join(ROOT, "geometries", "femur_stem.toml"))
    problem, _ = problem_of(sc, build_geometry(sc))
    sol = solve_scene(sc, problem)
    recovery = recovery_of(sc, problem.law)
    safety = MA.safety_factor_of(sc, recovery)

    def solve(p, start):
        return solve_scene(sc, p, start)
    exclusion = MA.exclusion_for(sc, sol)
    assert exclusion is not None         # the femur's interface ends closed at the bone's top
    samples = MA.order_samples(sc, sol, solve, safety, exclusion=exclusion)
    found = SM.check(MA.estimates(samples, sol), sol, samples[problem.order], solve)
    found = AM.settle(MA.away_judged(found, sol, solve, exclusion, samples[problem.order], safety), exclusion)
    component = next(e.name for e in found if e.name.startswith("resultant_")).removeprefix("resultant_")
    ref = MR.reference(sc, exclusion, recovery, component)
    companion = MR.reference(sc, exclusion, recovery, component, divide=MR.DIVIDE // 2)
    own = MR.uncertainty(ref, companion)
    return [row(FEMUR, problem.order, e, ref[e.name].value, own[e.name]) for e in found]


def lame_scene(order: int, tolerance: float):
    """Lame's press fit of :func:`lame_rows` as a macro scene stating ``discretization.tolerance``."""
    data = {"kind": "macro", "materials": {"inner": {"E": E_IN, "nu": NU_IN}, "outer": {"E": E_OUT, "nu": NU_OUT}},
            "bodies": {"rough": "inner", "counter": "outer"},
            "geometry": {"shape": "coaxial", "setting": "plane_strain", "dimensions": {"a": A, "b": B, "c": C}},
            "interface": {"law": "linear", "kn": K_N, "gap": -DELTA},
            "supports": [{"boundary": "sym_x", "components": ["x"]}, {"boundary": "sym_y", "components": ["y"]}],
            "discretization": {"order": order, "maxh": MAXH, "tolerance": tolerance}}
    return loader.from_dict(data, base_dir=ROOT)


def refinement_rows(order: int = 1, runs: dict | None = None) -> list[dict]:
    """The refinement from ``order`` to each of :data:`TOLERANCES`: where it stopped and how far it is
    (``runs``, if given, gets each tolerance's levels)."""
    exact = lame_exact()
    out = []
    for tol in TOLERANCES:
        t0 = time.perf_counter()
        try:
            acc = run_macro.run(lame_scene(order, tol), Clock()).results["accuracy"]
            levels, quantities = acc["refinement"]["levels"], acc["quantities"]
            named = [exact["resultant" if q["name"].startswith("resultant_") else q["name"]] for q in quantities]
            true = max(abs(q["value"] - e) / abs(e) for q, e in zip(quantities, named))
            effectivity = min(q["error"] / abs(q["value"] - e) for q, e in zip(quantities, named)
                              if abs(q["value"] - e) > 1e-8 * abs(e))
        except ConvergenceError as exc:
            levels, true, effectivity = exc.history["refinement"], None, None
        last = levels[-1]
        if runs is not None:
            runs[tol] = levels
        out.append({"tolerance": tol, "scene_order": order,
                    "orders": " ".join(str(lv["order"]) for lv in levels if lv["h_level"] == 0),
                    "mesh_levels": last["h_level"], "elements": last["elements"], "ndof": last["ndof"],
                    "met": last["met"], "smallest_effectivity": effectivity,
                    "largest_estimate": max(v for v in last["relative_errors"].values() if v is not None),
                    "largest_true_error": true, "seconds": time.perf_counter() - t0})
    return out


def level_errors(level: dict) -> tuple[float, float]:
    """The largest estimated and the largest true relative error of one refinement level on Lame's press fit
    (the resultant left out: it balances the load to round-off at every level)."""
    exact = lame_exact()
    names = [n for n in level["values"] if not n.startswith("resultant_")]
    estimate = max(level["relative_errors"][n] for n in names)
    true = max(abs(level["values"][n] - exact[n]) / abs(exact[n]) for n in names)
    return estimate, true


def refinement_plot(levels: list[dict], tolerance: float, path: str) -> None:
    """Per level of one refinement: the largest estimated and true relative error against the unknowns."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    ndof = [lv["ndof"] for lv in levels]
    est, true = zip(*(level_errors(lv) for lv in levels))
    p_levels = [k for k, lv in enumerate(levels) if lv["h_level"] == 0]
    ax.loglog(ndof, est, "o-", label="largest estimate")
    ax.loglog(ndof, true, "s--", label="largest true error (closed form)")
    for k, lv in enumerate(levels):
        ax.annotate(f"p{lv['order']}" if k in p_levels else f"h{lv['h_level']}", (ndof[k], est[k]), fontsize=7,
                    textcoords="offset points", xytext=(3, 4))
    ax.axhline(tolerance, color="0.5", lw=0.8, label=f"tolerance {tolerance:g}")
    ax.set_xlabel("unknowns of the level")
    ax.set_ylabel("relative error (largest over the headline quantities)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot(data: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    names = sorted({"resultant" if d["quantity"].startswith("resultant_") else d["quantity"] for d in data})
    for oracle, marker in (("Lame press fit", "o"), (FEMUR, "s")):
        for k, name in enumerate(names):
            pts = [(d["order"] + 0.04 * k, d["effectivity"]) for d in data if d["oracle"] == oracle
                   and d["quantity"].startswith(name) and d["effectivity"] is not None]
            if pts:
                ax.semilogy(*zip(*pts), marker, label=f"{oracle[:5]}: {name}", color=plt.cm.tab20(k))
    ax.axhspan(1.0, 10.0, color="0.9", label="aim: 1 to 10")
    ax.set_xlabel("order of the reported solution")
    ax.set_ylabel("effectivity (estimate / true error)")
    ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "macro_effectivity"), help="output directory")
    ap.add_argument("--quick", action="store_true", help="Lame only (no refined femur)")
    ap.add_argument("--refinement-only", action="store_true", help="only the refinement towards the tolerances "
                    "(and only its section published)")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    if not args.refinement_only:
        effectivity(args)
    runs: dict = {}
    refined = refinement_rows(runs=runs)
    refine_csv = os.path.join(args.out, "macro_refinement.csv")
    write_csv(refine_csv, list(REFINE_KEYS), [[d[k] for k in REFINE_KEYS] for d in refined])
    refine_png = os.path.join(args.out, "macro_refinement.png")
    refinement_plot(runs[TOLERANCES[-1]], TOLERANCES[-1], refine_png)
    if args.publish:
        benchmark_doc.publish("macro_refinement", "The macro refinement towards discretization.tolerance",
                              refine_csv, png=refine_png,
                              note="Lame's press fit above (maxh 0.3) as a scene of order 1 stating "
                              "discretization.tolerance: the order is raised on its mesh, curved at the order, up to "
                              "order 4, then the mesh is refined where the stress error indicator is large "
                              "(recovered-stress difference and the interface's normal-stress jump, Doerfler "
                              "marking, with the elements that hold a quantity still beyond the tolerance; Netgen's "
                              "local refinement; ngcontact/drivers/macro_refinement.py, "
                              "ngcontact/macro/error_indicator.py), each mesh level estimated by the order ladder "
                              "on its mesh and the sequence of mesh levels (the larger), until every headline "
                              "quantity's estimate meets it. orders: the order levels solved; mesh_levels: the "
                              "mesh refinements after them; met false: out of reach, the run ends with exit 3 (no "
                              "true error given). largest_true_error: the largest relative error against the closed "
                              "form over the headline quantities; smallest_effectivity: the smallest estimate / "
                              "true error over them (the resultant excluded where its true error is round-off). "
                              "The figure: every level of the run to the smallest tolerance (p: an order on the "
                              "scene's mesh, h: a mesh level), the largest estimated and true relative error over "
                              "the headline quantities but the resultant. Wall times on 2 cores shared with other "
                              "jobs (under load).")
    return 0


def effectivity(args) -> None:
    """The effectivity table and figure (the first section), published with ``--publish``."""
    data = lame_rows() + ([] if args.quick else femur_rows())
    csv_path = os.path.join(args.out, "macro_effectivity.csv")
    write_csv(csv_path, list(KEYS), [[d[k] for k in KEYS] for d in data])
    png = os.path.join(args.out, "macro_effectivity.png")
    plot(data, png)
    if args.publish:
        benchmark_doc.publish("macro_effectivity", "The macro error estimate against closed forms and a refined "
                              "femur", csv_path, png=png,
                              note="Estimate: from the orders one below and above on the same mesh "
                              "(ngcontact/macro/discretization_error.py); Lame's press fit with the interface "
                              "compliance in series on one coarse mesh (maxh 0.3) curved at the order, at orders "
                              "1 to 4 (order 1: straight-sided, its neighbours solved on it curved at order 2); the "
                              "femur scene at its order 3. Stress maxima as a default run estimates them: the "
                              "order ladder judged by ngcontact/macro/singular_maxima.py; the femur's interface "
                              "ends closed at the bone top, (11, 180) mm, where both bodies' stress grows without "
                              "bound (its global maxima and the global safety factor have no converged value and "
                              "no estimate: their 'exact' is the reference's mesh-dependent value). Rows *_away: "
                              "outside balls of radius 2.75 mm around the singular points "
                              "(ngcontact/macro/away_maxima.py), estimated by the ladder and two local "
                              "refinements at the points (ngcontact/macro/away_sequence.py). The femur's "
                              "reference (ngcontact/drivers/macro_reference.py): order 4 on the scene's mesh "
                              "sizes divided by 4, the elements where a ball's circle crosses the interface or "
                              "leaves the bodies refined 5 times before the solve, the maxima away taken as "
                              "suprema over the same set (a lattice of 24 intervals per element edge reaching the "
                              "faces, 65536 points per circle) and the safety factor at 21 points per interface "
                              "element. The bone's stress and the safety factor are extreme where the circle "
                              "around the bone top crosses the interface, (11, 177.25) mm, with a steep gradient "
                              "(the safety factor falls by ~0.07 per mm towards the edge): references sampled at "
                              "the run's 5 points per interface element (order 4 on the mesh sizes halved, or "
                              "divided by 4) miss 0.014 and 0.005 of the safety factor there, so they disagreed "
                              "with each other, while the field had converged (sampled at the same points, orders 4 "
                              "and 5 on the sizes halved and divided by 4 agree to 1e-4 in the safety factor and "
                              "30 Pa in the bone's stress). "
                              "reference_uncertainty: the reference's difference to the same rule on the mesh "
                              "sizes halved plus its sampling step on the circle (0 for a closed form). An empty "
                              "estimate is a quantity reported without one (not converging or singular). "
                              "Issue 35 asks for effectivities between 1 and 10.")


if __name__ == "__main__":
    sys.exit(main())
