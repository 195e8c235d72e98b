"""How honest is the spectral cell's refinement estimate? Its effectivity on five oracles.

The spectral cell's refinement (``discretization.tolerance``, ``ngcontact.cell.spectral.refinement``) stops
on the first grid whose estimate meets the tolerance and reports that grid's answer.  Here each oracle is
refined to several tolerances exactly as a run does, and the estimate of each load's headline quantities
on the reported grid (the contact fraction absolute, the mean closure and the normal effective stiffness
relative, the coefficients ``k_n`` and ``g_n`` of eq. 34 on the real contact set relative to their
whole-surface values: ``ngcontact.cell.cell_solution.measure``) is held against its true error in the same
measure: the difference from the same cell's value on a much finer grid (the cells have layers of finite depth, so a
half-space formula is not their converged value).  The ratio is the effectivity (issue 35 asks for it
between 1 and 10 on every oracle); the form of each estimate (Richardson, the guarded bound, or carried from
a grid where a stop waited, the share of unresolved contact islands, or a step at each 2D edge within a step
of a kink of the profile's piecewise-linear interpolant, a quarter step at every other edge of such a map (a
tenth where the quartic located it; a load's edges twice their root-sum-square where below their sum), and
the 2D stiffness of the located set as many steps of its change with each edge a step out, or on a map without
kinks the quartic's spread from its half window's, a quarter step where the line located the edge, or in 2D the change
on the same grid sampled half a step over), the true error of the grid twice as fine, whether the reported one is
small by chance, and the estimator's own flag where it states that its estimate may exceed the error by more than ten
times (``ngcontact.cell.spectral.estimate_forms``) are listed beside it.
Oracles, each with exact contact:

* ``westergaard``: Westergaard's sinusoid ``2h sin^2(pi x)``, layers of depth 1, first grid 64, grids up to
  8192, reference on 65536 points;
* ``westergaard_low``: the same sinusoid at two lighter loads (p = 0.0004, 0.0015), the same grids, where the
  errors fall much faster than the differences before them show once the edges' quartic locates the edges;
* ``random_2d``: a self-affine profile of 64 samples (Hurst 0.8, rms slope 0.1) as its piecewise linear
  interpolant, first grid 64, grids up to 8192, reference on 65536 points;
* ``random_2d_seed11``: the same construction with seed 11, whose lightest load has a contact island narrower
  than four points up to 2048 points (its error stalls over two grids);
* ``bisinusoid_3d``: ``h (2 - cos 2 pi x - cos 2 pi y)``, first grid 32, grids up to 256, reference on
  2048 x 2048 points (the contact fraction's errors on 256 points are a few 1e-5, of the size of a 1024 grid's
  own change from 512 points and of its own error against 4096 points: a 1024 reference cannot judge them).

A row is judged (column ``judged``, and only judged rows count in the summary) where its true error exceeds
``reference_change``, the reference's own change from the grid of half its points: below it the effectivity
measures the reference, not the estimate (as ``scripts/penalty_effectivity.py`` judges its rows).

    python scripts/spectral_effectivity.py [OUT] [--publish]
    python scripts/spectral_effectivity.py OUT --held-out 1,2,3
    python scripts/spectral_effectivity.py OUT --held-out 1,2,3 --smooth

Writes ``OUT/spectral_effectivity.csv`` and ``.png`` (default ``results/spectral_effectivity``).  With
``--held-out SEEDS`` the oracles are instead random profiles of those seeds, built as ``random_2d`` (loads
0.001, 0.003, 0.01; tolerances 1e-2 and 1e-3): surfaces the estimator was not argued on, which check that
its rules hold beyond the five oracles (not published); with ``--smooth`` too, smooth profiles of three harmonics
(:func:`smooth_profile_gap`, loads 0.0004, 0.0015, 0.004, tolerances 1e-2 to 1e-4), whose edges the quartic locates
on every fine grid.
"""
from __future__ import annotations

import argparse
import os
import sys
from dataclasses import dataclass
from functools import partial
from typing import Callable

import numpy as np
from scipy.optimize import minimize_scalar

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.cell.cell_load import cell_load  # noqa: E402
from ngcontact.cell.cell_solution import headline  # noqa: E402
from ngcontact.cell.spectral.contact_edges import LINE_STEP  # noqa: E402
from ngcontact.cell.spectral.grid_measures import coefficients, contact_weights  # noqa: E402
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell  # noqa: E402
from ngcontact.cell.spectral.refinement import sweep_to_tolerance  # noqa: E402
from ngcontact.cell.spectral.smooth_edges import SPREAD_STEPS  # noqa: E402
from ngcontact.errors import ConvergenceError  # noqa: E402
from ngcontact.geometry.random_surface import self_affine  # noqa: E402
from ngcontact.output.writer import write_csv  # noqa: E402

NU, H, DEPTH = 0.3, 0.01, 1.0
TOLERANCES = (1e-2, 1e-3, 1e-4)
KEYS = ("oracle", "tolerance", "met", "load", "pressure", "grid", "quantity", "value", "form", "estimate", "true_error",
        "next_error", "reference_change", "locator_bias", "by_chance", "effectivity", "flag", "judged")


@dataclass
class Oracle:
    """A spectral cell by its gap on ``n`` points, its loads, first grid, largest grid and reference grid."""

    name: str
    dim: int
    gap: Callable[[int], np.ndarray]
    pressures: tuple[float, ...]
    first: int
    largest: int
    reference: int
    k_n: float = 1e3              # the Winkler layer's stiffness (eq. 65) where ``enforcement`` is "penalty"
    enforcement: str = "exact"


def westergaard_gap(n: int) -> np.ndarray:
    return 2 * H * np.sin(np.pi * np.arange(n) / n) ** 2


def random_profile_gap(n: int, samples: int = 64, seed: int = 5) -> np.ndarray:
    """A self-affine profile of ``samples`` points as its periodic piecewise linear interpolant on ``n`` points."""
    heights = self_affine(dim=2, grid=samples, hurst=0.8, rms_slope=0.1, seed=seed)
    closed = np.append(heights, heights[0])
    return np.interp(np.arange(n) / n, np.arange(samples + 1) / samples, closed.max() - closed)


def smooth_profile_gap(n: int, seed: int = 0) -> np.ndarray:
    """A smooth periodic profile of three harmonics ``z(x) = sum a_k cos(2 pi k x + phi_k)``, ``k = 1, 2, 3``,
    amplitudes ``U(0.2, 1) / k`` and phases ``U(0, 2 pi)`` drawn from ``seed``, as the gap below its highest
    point scaled to a height of ``2 H``: ``2 H (max z - z) / (max z - min z)``, on ``n`` points.

    The extremes are those of the continuous profile (:func:`profile_extremes`), so that every grid samples one
    surface: the extremes of the ``n`` samples miss them by ``O(n^-2)`` and would shift the gap level and scale
    from grid to grid by about 1e-7 at 8192 points, as much as the mean closure's own error there."""
    harmonics = smooth_harmonics(seed)
    top, bottom = profile_extremes(harmonics)
    return 2 * H * (top - harmonic_sum(np.arange(n) / n, harmonics)) / (top - bottom)


def smooth_harmonics(seed: int) -> list[tuple[int, float, float]]:
    """The wave numbers, amplitudes and phases of :func:`smooth_profile_gap`'s profile of ``seed``."""
    rng = np.random.default_rng(seed)
    return [(k, rng.uniform(0.2, 1.0) / k, rng.uniform(0.0, 2 * np.pi)) for k in (1, 2, 3)]


def harmonic_sum(s, harmonics):
    """``sum a_k cos(2 pi k s + phi_k)`` at ``s``."""
    return sum(a * np.cos(2 * np.pi * k * s + phase) for k, a, phase in harmonics)


def profile_extremes(harmonics, samples: int = 4096) -> tuple[float, float]:
    """The largest and smallest values of :func:`harmonic_sum` over a period: the extreme samples of ``samples``
    points, each polished by a bounded scalar minimisation within a step of it."""
    s = np.arange(samples) / samples
    z = harmonic_sum(s, harmonics)
    out = []
    for sign, at in ((1.0, s[np.argmax(z)]), (-1.0, s[np.argmin(z)])):
        found = minimize_scalar(lambda t: -sign * harmonic_sum(t, harmonics), method="bounded",
                                bounds=(at - 1.0 / samples, at + 1.0 / samples), options={"xatol": 1e-13})
        out.append(float(harmonic_sum(found.x, harmonics)))
    return out[0], out[1]


def bisinusoid_gap(n: int) -> np.ndarray:
    s = np.arange(n) / n
    return H * (2 - np.cos(2 * np.pi * s[None, :]) - np.cos(2 * np.pi * s[:, None]))


def random_profile_11_gap(n: int) -> np.ndarray:
    """The random profile of another seed (11): its lightest load's smaller contact island stays narrower than
    a few points up to 2048 points, and its error stalls over two grids."""
    return random_profile_gap(n, seed=11)


ORACLES = (Oracle("westergaard", 2, westergaard_gap, (0.000863, 0.00345, 0.00863), 64, 2 ** 13, 2 ** 16),
           Oracle("westergaard_low", 2, westergaard_gap, (0.0004, 0.0015), 64, 2 ** 13, 2 ** 16),
           Oracle("random_2d", 2, random_profile_gap, (0.001, 0.003, 0.01), 64, 2 ** 13, 2 ** 16),
           Oracle("random_2d_seed11", 2, random_profile_11_gap, (0.001, 0.003, 0.01), 64, 2 ** 13, 2 ** 16),
           Oracle("bisinusoid_3d", 3, bisinusoid_gap, (0.001, 0.004, 0.01), 32, 256, 2048))


class Solved:
    """A spectral cell whose sweep is solved once (the levels are shared by the tolerances)."""

    cache: dict = {}

    def __init__(self, oracle: Oracle, n: int):
        self.oracle, self.n = oracle, n
        self.cell = SpectralCell(dim=oracle.dim, period=1.0, grid=n, rough=Layer(1.0, NU, DEPTH),
                                 counter=Layer(1.0, NU, DEPTH), gap=oracle.gap(n), k_n=oracle.k_n,
                                 enforcement=oracle.enforcement,
                                 tol=1e-12, max_iter=100000)
        self.points = self.cell.points

    def __getattr__(self, name):
        return getattr(self.cell, name)       # the cell's grid, gap, k_n, ... (its whole-surface coefficients)

    def sweep(self, loads, starts=None):
        key = (self.oracle.name, self.n)
        if key not in self.cache:
            self.cache[key] = self.cell.sweep(loads)
        return self.cache[key]


def locator_bias(oracle: Oracle, grid: int, reference: list) -> list[dict[str, float]]:
    """Per load, in 2D, the quantities on the edges (the contact fraction, ``k_n`` and ``g_n`` of eq. 34 on the
    real contact set) of the reference's own pressure and gap sampled on ``grid`` points, their edges located
    there as on a solved grid, less the reference's values (absolute): the error of the edge localisation alone,
    without the grid's collocation error.  Empty in 3D (points counted)."""
    if oracle.dim != 2:
        return [{} for _ in reference]
    cell, step, out = Solved(oracle, grid).cell, oracle.reference // grid, []
    for ref in reference:
        p, gap = ref.fields["pressure"][::step], ref.fields["gap"][::step]
        sampled = coefficients(cell, p > 0, weights=contact_weights(cell, p, gap)).as_dict()
        exact = headline(ref.results)
        out.append({"contact_fraction": sampled["contact_fraction"] - exact["contact_fraction"],
                    "coefficient_k_n": sampled["k_n"] - exact["coefficient_k_n"],
                    "coefficient_g_n": sampled["g_n"] - exact["coefficient_g_n"]})
    return out


def oracle_rows(oracle: Oracle, tolerances=TOLERANCES) -> list[dict]:
    """Per tolerance, load and quantity: the reported value, the estimate's form and size, the true error, that
    of the grid twice as fine, whether the true error is small by chance (of another sign than the coarser grid's,
    or below the finer grid's) and the effectivity."""
    loads = [cell_load(oracle.dim, pressure=p) for p in oracle.pressures]
    reference = Solved(oracle, oracle.reference).sweep(loads)
    half = Solved(oracle, oracle.reference // 2).sweep(loads)
    out = []
    for tol in tolerances:
        try:
            refined = sweep_to_tolerance(lambda n: Solved(oracle, n), loads, tol, oracle.first, oracle.dim,
                                         oracle.largest ** (oracle.dim - 1))
        except ConvergenceError:
            continue                      # beyond the study's largest grid: nothing reported
        grid = refined.history[-1]["grid"]
        finer = Solved(oracle, 2 * grid).sweep(loads)
        bias = locator_bias(oracle, grid, reference)
        for k, (sol, ref, est, form, flags) in enumerate(zip(refined.solutions, reference, refined.estimates,
                                                             refined.forms, refined.flags)):
            head, exact_head, finer_head = headline(sol.results), headline(ref.results), headline(finer[k].results)
            for name in est:
                value, exact = head[name], exact_head[name]
                scale = refined.scales[k][name]
                error = abs(value - exact) / scale
                coarser = refined.history[-2]["headline"][k][name] - exact
                next_error = abs(finer_head[name] - exact) / scale
                out.append({"oracle": oracle.name, "tolerance": tol, "met": refined.met, "load": k,
                            "pressure": oracle.pressures[k],
                            "grid": grid, "quantity": name, "value": value, "form": form[name],
                            "estimate": est[name], "true_error": error,
                            "next_error": next_error,
                            "reference_change": abs(headline(half[k].results)[name] - exact) / scale,
                            "locator_bias": abs(bias[k][name]) / scale if name in bias[k] else "",
                            "by_chance": bool(coarser * (value - exact) < 0 or error < next_error),
                            "effectivity": est[name] / error if error > 0 else float("inf"),
                            "flag": flags.get(name, "")})
            for row in out[-len(est):]:
                row["judged"] = judged(row)
    return out


def judged(row: dict) -> bool:
    """Whether the row's true error exceeds the reference's own change (else its effectivity is the reference's)."""
    return row["true_error"] > row["reference_change"]


def held_out(seeds: list[int], smooth: bool = False) -> tuple[Oracle, ...]:
    """The random profiles of ``seeds`` as oracles, built as ``random_2d``, or ``smooth`` ones
    (:func:`smooth_profile_gap`; module docstring)."""
    if smooth:
        return tuple(Oracle(f"smooth_seed{s}", 2, partial(smooth_profile_gap, seed=s), (0.0004, 0.0015, 0.004), 64,
                            2 ** 13, 2 ** 16) for s in seeds)
    return tuple(Oracle(f"random_2d_seed{s}", 2, partial(random_profile_gap, seed=s), (0.001, 0.003, 0.01), 64,
                        2 ** 13, 2 ** 16) for s in seeds)


def seed_list(text: str) -> list[int]:
    """``--held-out``'s comma-separated seeds, refused unless each is a non-negative integer."""
    try:
        seeds = [int(s) for s in text.split(",")]
    except ValueError:
        seeds = [-1]
    if min(seeds) < 0:
        raise argparse.ArgumentTypeError(f"--held-out = {text!r}: comma-separated non-negative integer seeds "
                                         "are allowed, e.g. 1,2,3")
    return seeds


def plot(data: list[dict], path: str, oracles: tuple[Oracle, ...] = ORACLES) -> None:
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4))
    quantities = list(dict.fromkeys(d["quantity"] for d in data))
    for colour, oracle in zip((f"C{i}" for i in range(len(oracles))), (o.name for o in oracles)):
        for marker, quantity in zip("os^vDx", quantities):
            pts = [(d["true_error"], d["effectivity"]) for d in data if d["judged"] and d["oracle"] == oracle
                   and d["quantity"] == quantity and np.isfinite(d["effectivity"])]
            if pts:
                ax.loglog(*zip(*pts), marker, color=colour, label=f"{oracle}, {quantity}")
    ax.axhspan(1.0, 10.0, color="0.9", label="aim: 1 to 10")
    ax.set_xlabel("true error of the reported grid")
    ax.set_ylabel("effectivity (estimate / true error)")
    ax.legend(fontsize=5, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def listed(rows: list[dict]) -> str:
    """Rows as ``oracle tolerance load quantity effectivity``, comma-separated ("none" without rows)."""
    return ", ".join(f"{d['oracle']} {d['tolerance']:g} load {d['load']} {d['quantity']} {d['effectivity']:.3g}"
                     for d in rows) or "none"


def below_bias(row: dict) -> bool:
    """Whether the row's true error is below its edge localisation's own error (2D quantities on the edges)."""
    return row["locator_bias"] != "" and row["true_error"] < row["locator_bias"]


def summarize(rows: list[dict]) -> tuple[str, int]:
    """The table's summary in words (of the judged rows, :func:`judged`), and how many rows above 10 are small by
    chance."""
    data = [d for d in rows if d["judged"]]
    effs = np.array([d["effectivity"] for d in data])
    outside = int(((effs < 1) | (effs > 10)).sum())
    summary = (f"{len(rows)} estimates, {len(data)} judged (true error above `reference_change`): effectivity from "
               f"{effs.min():.3g} to {effs.max():.3g}, {outside} outside [1, 10] ({int((effs < 1).sum())} below 1, "
               f"{int((effs > 10).sum())} above 10); not judged: {listed([d for d in rows if not d['judged']])}")
    per_quantity = "; ".join(
        f"{q} {min(e):.3g} to {max(e):.3g}" for q in dict.fromkeys(d["quantity"] for d in data)
        for e in [[d["effectivity"] for d in data if d["quantity"] == q]])
    above = [d for d in data if d["effectivity"] > 10]
    unflagged = [d for d in above if not d["flag"]]
    flagged = sum(1 for d in data if d["flag"])
    summary += (f"; per quantity: {per_quantity}; {flagged} flagged by the estimator (column `flag`), of them "
                f"{sum(1 for d in above if d['flag'])} above 10 and {flagged - sum(1 for d in above if d['flag'])} at "
                f"most 10 (the estimate within ten times the error after all); above 10 and not flagged: "
                f"{listed(unflagged)}; of those, not by chance: {listed([d for d in unflagged if not d['by_chance']])}"
                f"; judged rows whose true error is below the edge localisation's own error (`locator_bias`): "
                f"{sum(1 for d in data if below_bias(d))}, of them above 10: "
                f"{listed([d for d in above if below_bias(d)])}")
    return summary, sum(1 for d in above if d["by_chance"])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "spectral_effectivity"), help="output directory")
    ap.add_argument("--held-out", type=seed_list, metavar="SEEDS",
                    help="random profiles of these seeds (e.g. 1,2,3) instead of the five oracles, not published")
    ap.add_argument("--smooth", action="store_true", help="with --held-out: smooth profiles of three harmonics")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    if args.held_out and args.publish:
        ap.error(f"--held-out = {','.join(map(str, args.held_out))} with --publish: the published section holds the "
                 "five oracles only; drop one of the two")
    if args.smooth and not args.held_out:
        ap.error("--smooth without --held-out: the smooth profiles are held-out oracles; give their seeds")
    oracles = held_out(args.held_out, args.smooth) if args.held_out else ORACLES
    tolerances = TOLERANCES[:2] if args.held_out and not args.smooth else TOLERANCES
    data = [row for oracle in oracles for row in oracle_rows(oracle, tolerances)]
    os.makedirs(args.out, exist_ok=True)
    csv_path = os.path.join(args.out, "spectral_effectivity.csv")
    write_csv(csv_path, list(KEYS), [[d[k] for k in KEYS] for d in data])
    plot(data, os.path.join(args.out, "spectral_effectivity.png"), oracles)
    summary, chance = summarize(data)
    print(summary)
    if args.publish:
        benchmark_doc.publish("spectral_effectivity", "The spectral refinement's estimate against the converged value",
                              csv_path, note="Five oracles (Westergaard's sinusoid at three loads and at two lighter "
                              "ones, p = 0.0004 and 0.0015; random 64-sample profiles of seeds 5 and 11 in 2D; a "
                              "bisinusoid in 3D), exact contact, layers of depth 1, each refined to the "
                              "tolerances 1e-2, 1e-3, 1e-4 as a run does (grids doubling; every headline quantity "
                              "of each load: the contact fraction absolute, the mean closure and the normal "
                              "effective stiffness relative, the coefficients k_n and g_n of eq. 34 on the real "
                              "contact set relative to their whole-surface values; in 2D the refinement holds the "
                              "stiffness too, up to three grids beyond the one where the others meet the tolerance "
                              "and within the study's largest grid, else stops there, `met` false; in 3D the "
                              "stiffness is reported with its estimate, not held; "
                              "per quantity and load "
                              "Richardson with the observed rate where the last two ratios of differences agree and "
                              "it is the smaller (where the last contraction is at least twice as slow as the one "
                              "before, at least the guarded envelope of the last two differences, the one before "
                              "the last halved), else the guarded geometric tail (where the last contraction is "
                              "at least twice as fast as the one before, its envelope on the last three levels: the "
                              "difference before the last shrunk by twice the contraction before it, at most a "
                              "half, the first one dropped): column `form`; the contact "
                              "fraction and coefficients guarded on levels whose edges are not all located by the "
                              "quartic (2D; in 3D see `line`), and in 2D also estimated on the levels whose "
                              "edges the quartic located, a stop to the tolerance waiting for four of them (on "
                              "those levels a sequence whose last contraction is at least twice as slow as the one "
                              "before and below 0.7 takes the guarded envelope of its last two differences where "
                              "smaller, the quartic's stall bounded by `smooth`); on the "
                              "grid after such a wait the waited grid's estimate plus the last difference where "
                              "smaller: `carried`; at least the share of contact islands of fewer than four "
                              "points (3D: across), their points and a step beyond: `island`; a window across the "
                              "level where a load's last such island came to be resolved also estimated on the "
                              "resolved levels alone, at least three, the smaller; in 2D at least a grid step per "
                              "contact edge within a step of a kink of a profile's piecewise-linear interpolant, "
                              "where the edge may stay pinned over grids, and on such a map a quarter step per "
                              "other edge (a tenth where the quartic located it), and the normal stiffness (2D: of "
                              "the located set) as many steps of its change with each edge a step out, whose erratic "
                              "fraction of a step the differences may not show, a load's edges twice the "
                              "root-sum-square of their shares where below their sum: `kink`; in 3D at least "
                              f"{LINE_STEP:g} of a step per crossing of an edge by a row or column, summed, above "
                              "which the quantities on the edges take Richardson at the observed rate: `line`; in "
                              f"2D on a map without kinks at least {SPREAD_STEPS:g} times each edge's root spread "
                              "from the quartic on the first half of its window, where the window's length, set by "
                              "its patch, does not shrink with the step and its error stalls, and a quarter step "
                              "per edge the line located: `smooth`; in 2D every quantity at least its change on "
                              "the same grid sampled half a step over, twice the half-difference that bounds the "
                              "part of the error which changes sign with the edges' place between points, where "
                              "the differences between grids may stall: `phase`); a tolerance not "
                              "met within the study's largest grid reports nothing. The true error of the reported "
                              "grid is against the same cell on a much finer grid; `next_error` is that of the grid "
                              "twice as fine, `reference_change` the reference's own change from the grid of half "
                              "its points (3D reference: 2048 x 2048), `judged` whether the true error exceeds "
                              "it (a row not judged is not counted: its effectivity measures the reference), "
                              "`locator_bias` (2D, quantities on the edges) the error of the reported "
                              "grid's edge localisation alone: the reference's own pressure and gap sampled on the "
                              "grid, their edges located there, against the reference. `flag`: the estimator's own "
                              "statement that its estimate may exceed the error by more than ten times (a "
                              "guarded, carried or kink estimate above ten times the error its last difference "
                              "leaves at the last contraction, not an island's share, whose stalled error the last "
                              "difference does not measure, or an estimate of any form above ten times the error "
                              "it leaves at the contraction before where the last two disagree, the last twice as "
                              "slow or more), with its reason, as the report lists it (results.accuracy.quantities"
                              "[].loose). Issue 35 asks for effectivities between 1 and 10. "
                              f"{summary}. Of the rows above 10, {chance} have a reported error small by chance "
                              "(`by_chance`: of another sign than the coarser grid's, or below the finer grid's); "
                              "in the others the error fell from the coarser grid by much more than the "
                              "differences before it show: where their last two contractions disagree the flag "
                              "says so; where they agree, no estimate from the differences up to the reported "
                              "grid can see it (nor a chance error). A row whose true error lies below its "
                              "`locator_bias` has the edge localisation's error cancelled by the collocation's: its "
                              "effectivity measures that cancellation.",
                              png=os.path.join(args.out, "spectral_effectivity.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
