"""Issue 35's first aim: a random 64 x 64 map on the spectral cell, posed with a tolerance of 1 % and nothing else.

The cell of the issue's first table: a random self-affine height map of 64 x 64 samples
(:func:`ngcontact.geometry.random_surface.self_affine`, the spectrum of the shipped
``geometries/cells/self_affine_spectral.toml`` drawn on 64 points per direction: Hurst 0.8, rms slope 0.1,
roll-off 1/4, cut-off 1/32 of the period, seed 3), the map's bilinear interpolant as the surface, two layers of
depth 1 (``E = 1``, ``nu = 0.3``), the spectral cell with exact contact, three loads (contact fractions
near 0.09, 0.17 and 0.40).  Its ``[discretization]`` says ``method = "spectral"`` (the cell of the table)
and ``tolerance = 0.01`` and nothing else: the grid is the refinement's (``discretization.tolerance``,
``ngcontact.cell.spectral.refinement``), which doubles from the map's own 64 points until its estimate
meets the tolerance.  The scene is written as TOML and run as a user runs it (``ngcontact run``, a child
process, its wall time measured around it).

Per load: the reported contact fraction and its estimate (absolute, as the package judges the contact
fraction, and relative to the value), the converged reference (the same scene on the grid ``REFERENCE``,
the largest a spectral cell accepts, with the grid half as fine beside it: their difference bounds the
reference's own error when each doubling at least halves it, and Richardson's extrapolation of the reported,
half and full reference grids at their observed rate is listed beside it), the true error (absolute and
relative), the effectivity (estimate / true absolute error) and the run's wall time.  The issue asks each
contact fraction within 2 % of the converged value, each effectivity in [1, 10], in no more time than
Tamaas' Polonsky-Keer-Rey solver on 512 x 512 points for the same three loads: that row is measured where
``import tamaas`` works (the ``bench`` extra; one half-space of the pair's ``E* = E / (2 (1 - nu^2))``
against the rigid bilinear surface on 512 x 512 points) and says why it is skipped where it does not.
Tamaas stops at its own relative residual, not at an error of the contact fraction: its row is timed at
``TAMAAS_TOL`` and its contact fractions are compared with a solve at ``TAMAAS_TIGHT`` (the row's note gives
their largest difference), so that the time compared is that of an answer converged far below the 1 % posed
to ours.

    python scripts/random_map_accuracy.py [OUT] [--quick] [--publish]

Writes ``OUT/random_map_accuracy.csv`` and ``.png`` (default ``results/random_map_accuracy``); ``--quick``
poses a 16 x 16 map (cut-off 1/8) from grid 8 with a tolerance of 5 % against 256 and 512 points (seconds; a smoke run).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from typing import Any

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.output.writer import write_csv  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
E, NU = 1.0, 0.3
E_STAR = E / (2 * (1 - NU ** 2))
PRESSURES = (0.002, 0.004, 0.01)
SAMPLES, SEED = 64, 3
TOLERANCE = 0.01
#: the reference grid (the largest spectral grid a 3D cell accepts) and the grid half as fine beside it
REFERENCE = 2048
#: Tamaas' tolerance bounds its own residual (the relative orthogonality of pressure and gap), not the contact
#: fraction: the row is timed at TAMAAS_TOL and the contact fractions are checked against TAMAAS_TIGHT
TAMAAS_GRID, TAMAAS_TOL, TAMAAS_TIGHT = 512, 1e-4, 1e-10
KEYS = ("solver", "load", "pressure", "grid", "contact_fraction", "estimate", "estimate_relative", "reference",
        "reference_half", "reference_richardson", "true_error", "true_error_relative", "error_to_richardson",
        "effectivity", "within_2_percent", "effectivity_in_1_10", "seconds", "solve_seconds", "note")

SCENE = """kind = "cell"
title = "Random 64 x 64 map, spectral cell, exact contact, tolerance 1 %"

[materials.solid]
E = {E}
nu = {NU}

[bodies]
rough = "solid"
counter = "solid"

[geometry]
profile = "self_affine"
arrangement = "summit"
period = 1.0
h_rough = 1.0
h_counter = 1.0
spectrum = {{ hurst = 0.8, rms_slope = 0.1, rolloff = 0.25, cutoff = {cutoff}, grid = {samples}, seed = {seed} }}

[contact]
k_n = 1.0e3
enforcement = "exact"

[load]
pressure = [{pressures}]

[discretization]
method = "spectral"
{discretization}
"""


def cutoff(samples: int) -> float:
    """The spectrum's short-wavelength cut-off: 1/32 of the period, at least two of the map's grid steps."""
    return max(1 / 32, 2 / samples)


def map_gap(grid: int, samples: int = SAMPLES) -> np.ndarray:
    """The scene's initial gap on ``grid x grid`` points: ``max H - H`` of the map's bilinear interpolant, as
    :func:`ngcontact.drivers.cell_gap.gap_samples` samples it (a rigid surface of height ``-gap`` for Tamaas)."""
    from ngcontact.geometry import cell3d
    from ngcontact.geometry.random_surface import as_height_map, self_affine
    heights = as_height_map(self_affine(dim=3, grid=samples, period=1.0, hurst=0.8, rms_slope=0.1, rolloff=0.25,
                                        cutoff=cutoff(samples), seed=SEED))
    return cell3d.bilinear_samples(heights.max() - heights, 1.0, grid)


def scene_text(discretization: str, samples: int = SAMPLES) -> str:
    return SCENE.format(E=E, NU=NU, samples=samples, cutoff=cutoff(samples), seed=SEED,
                        pressures=", ".join(map(str, PRESSURES)), discretization=discretization)


def run(text: str, out: str, name: str) -> tuple[dict, float]:
    """``ngcontact run`` of the scene ``text`` in a child process: its report's results and wall time."""
    path = os.path.join(out, name + ".toml")
    with open(path, "w") as fh:
        fh.write(text)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, (ROOT, os.environ.get("PYTHONPATH")))))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "ngcontact", "run", path, "--out", os.path.join(out, name), "--quiet"],
                   check=True, env=env)
    seconds = time.perf_counter() - t0
    with open(os.path.join(out, name, "report.json")) as fh:
        return json.load(fh)["results"], seconds


def fractions(results: dict) -> list[float]:
    return [load["contact_fraction"] for load in results["loads"]]


def richardson(coarse: float, half: float, fine: float) -> float:
    """The three grids' limit at their observed rate ``r = d2 / d1``: ``fine + d2 r / (1 - r)``; the finest
    value where the differences do not fall monotonically (``0 < r < 1`` fails)."""
    d1, d2 = half - coarse, fine - half
    r = d2 / d1 if d1 else 0.0
    return fine + d2 * r / (1 - r) if 0 < r < 1 else fine


def ngcontact_rows(out: str, quick: bool) -> list[dict]:
    samples, tol, reference = (16, 0.05, 512) if quick else (SAMPLES, TOLERANCE, REFERENCE)
    first = "grid = 8\n" if quick else ""
    posed, seconds = run(scene_text(f"{first}tolerance = {tol}", samples), out, "posed")
    grid = posed["method"]["grid"]
    solve = sum(level["seconds"] for level in posed["method"]["refinement"])
    fine, _ = run(scene_text(f'grid = {reference}\nestimate = "off"', samples), out, f"grid_{reference}")
    half, _ = run(scene_text(f'grid = {reference // 2}\nestimate = "off"', samples), out, f"grid_{reference // 2}")
    rows = []
    for k, (value, ref, ref_half, load) in enumerate(zip(fractions(posed), fractions(fine), fractions(half),
                                                         posed["loads"])):
        estimate = load["error_estimate"]["contact_fraction"]
        error = abs(value - ref)
        effectivity = estimate / error if error > 0 else float("inf")
        limit = richardson(value, ref_half, ref) if grid == reference // 4 else ref
        rows.append({"solver": "ngcontact spectral, tolerance " + str(tol), "load": k, "pressure": PRESSURES[k],
                     "grid": grid, "contact_fraction": value, "estimate": estimate,
                     "estimate_relative": estimate / value, "reference": ref, "reference_half": ref_half,
                     "reference_richardson": limit, "true_error": error, "true_error_relative": error / ref,
                     "error_to_richardson": abs(value - limit) / abs(limit), "effectivity": effectivity,
                     "within_2_percent": bool(error <= 0.02 * ref), "effectivity_in_1_10": bool(1 <= effectivity <= 10),
                     "seconds": seconds, "solve_seconds": solve,
                     "note": f"grids {[lv['grid'] for lv in posed['method']['refinement']]}; "
                             f"accuracy.met = {posed['accuracy']['met']}"})
    return rows


def tamaas_row(out: str, quick: bool) -> dict:
    """Tamaas' Polonsky-Keer-Rey on the bilinear surface on 512 x 512 points, the three loads; or why not."""
    row: dict[str, Any] = {key: "" for key in KEYS}
    row.update(solver="tamaas PolonskyKeerRey", grid=TAMAAS_GRID)
    try:
        import tamaas as tm
    except ImportError:
        row["note"] = "skipped: tamaas is not importable here (pip extra bench)"
        return row
    surface = -map_gap(TAMAAS_GRID, 16 if quick else SAMPLES)
    tm.set_log_level(tm.LogLevel.error)

    def solve(tol: float) -> list[float]:
        found = []
        for p in PRESSURES:
            model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [1.0, 1.0], [TAMAAS_GRID, TAMAAS_GRID])
            model.E, model.nu = E_STAR, 0.0  # Tamaas' E* = E / (1 - nu^2) = the pair's E / (2 (1 - nu^2))
            solver = tm.PolonskyKeerRey(model, np.ascontiguousarray(surface), tol)
            solver.max_iter = 100000
            solver.solve(p)  # the mean pressure p
            found.append(float(np.mean(np.asarray(model.traction) > 0)))
        return found

    t0 = time.perf_counter()
    found = solve(TAMAAS_TOL)
    seconds = time.perf_counter() - t0
    tight = solve(TAMAAS_TIGHT)
    drift = max(abs(a - b) / b for a, b in zip(found, tight))
    row.update(seconds=seconds,
               note=f"tolerance {TAMAAS_TOL:g}; half-space contact fractions "
                    + ", ".join(f"{f:.4g}" for f in found)
                    + f" (time only: a half-space, not the layers); they differ from tolerance {TAMAAS_TIGHT:g}'s "
                      f"by at most {100 * drift:.2g} %")
    return row


def plot(rows: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    ours = [r for r in rows if r["solver"].startswith("ngcontact")]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(8, 3.6))
    loads = [r["load"] for r in ours]
    ax.semilogy(loads, [r["true_error_relative"] for r in ours], "o-", label="true error (relative)")
    ax.semilogy(loads, [r["error_to_richardson"] for r in ours], "o:", label="error against Richardson's limit")
    ax.semilogy(loads, [r["estimate_relative"] for r in ours], "s--", label="estimate (relative)")
    ax.axhline(0.02, color="0.5", lw=0.8, label="aim: 2 %")
    ax.set_xticks(loads, [f"p = {r['pressure']}" for r in ours])
    ax.set_ylabel("relative error of the contact fraction")
    ax.legend(fontsize=6, loc="lower left")
    timed = [r for r in rows if r["seconds"] != ""]
    bx.bar([r["solver"].split(",")[0] for r in timed], [r["seconds"] for r in timed])
    bx.set_ylabel("wall time of the three loads [s]")
    bx.set_title("; ".join(f"Tamaas: {r['note']}" for r in rows if r["solver"].startswith("tamaas")
                           and r["seconds"] == "") or "", fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def verdict(rows: list[dict]) -> str:
    ours = [r for r in rows if r["solver"].startswith("ngcontact")]
    peer = [r for r in rows if r["solver"].startswith("tamaas")][0]
    errors = ", ".join(f"{100 * r['true_error_relative']:.2g} %" for r in ours)
    to_limit = ", ".join(f"{100 * r['error_to_richardson']:.3g} %" for r in ours)
    limit_effs = ", ".join(f"{r['estimate'] / (r['error_to_richardson'] * r['reference_richardson']):.3g}"
                           for r in ours)
    effs = ", ".join(f"{r['effectivity']:.3g}" for r in ours)
    within = all(r["within_2_percent"] for r in ours)
    missed = sum(r["error_to_richardson"] > 0.02 for r in ours)
    honest = all(r["effectivity_in_1_10"] for r in ours)
    took = f"{ours[0]['seconds']:.3g} s"
    time_part = (f"Time against Tamaas: {took} against Tamaas' {peer['seconds']:.3g} s" if peer["seconds"] != ""
                 else f"Time against Tamaas: unmeasured here ({peer['note']}); this run took {took}")
    return (f"Within 2 %: {'met' if within else 'not met'} against the reference (true errors {errors}, reported "
            f"grid {ours[0]['grid']}); against Richardson's limit {to_limit}: "
            f"{'met' if not missed else f'{missed} of {len(ours)} loads beyond 2 %'}. Effectivity in [1, 10]: "
            f"{'met' if honest else 'not met'} ({effs}; against Richardson's limit {limit_effs}). {time_part}.")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "random_map_accuracy"), help="output directory")
    ap.add_argument("--quick", action="store_true", help="a 16 x 16 map, tolerance 5 %%, reference 512 (seconds)")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    rows = ngcontact_rows(args.out, args.quick) + [tamaas_row(args.out, args.quick)]
    csv_path = os.path.join(args.out, "random_map_accuracy.csv")
    write_csv(csv_path, list(KEYS), [[r[k] for k in KEYS] for r in rows])
    png = os.path.join(args.out, "random_map_accuracy.png")
    plot(rows, png)
    summary = verdict(rows)
    print(summary)
    if args.publish:
        benchmark_doc.publish("random_map_accuracy", "A random 64 x 64 map posed with a tolerance of 1 % (issue 35)",
                              csv_path, note=NOTE + " " + summary, png=png)
    return 0


NOTE = ("The random 64 x 64 map of issue 35's first table (self-affine, Hurst 0.8, rms slope 0.1, seed 3; its "
        "bilinear interpolant), layers of depth 1, the spectral cell with exact contact, three mean pressures, "
        "posed with `method = \"spectral\"` and `discretization.tolerance = 0.01` only and run as `ngcontact run` "
        "(`seconds`: the child process's wall time, start-up included; `solve_seconds`: its refinement's levels). "
        "`estimate`: the reported absolute estimate of the contact fraction (the measure the package holds to the "
        "tolerance), `estimate_relative` the same over the value. `reference`: the same scene on 2048 x 2048 "
        "points (the largest spectral grid), `reference_half` on 1024 x 1024 (their difference bounds the "
        "reference's error when each doubling at least halves it), `reference_richardson` the limit of the "
        "reported, 1024 and 2048 grids at their observed rate (the true error is against `reference`; "
        "`error_to_richardson` is the relative error against this limit, a second view of the reference's own "
        "error). `effectivity` = estimate / true absolute error. Aims: every contact fraction within 2 % "
        "of the converged value, effectivity in [1, 10], no more time than Tamaas' Polonsky-Keer-Rey on 512 x 512 "
        "points for the same three loads. Timings on a 2-core machine shared with other jobs.")


if __name__ == "__main__":
    sys.exit(main())
