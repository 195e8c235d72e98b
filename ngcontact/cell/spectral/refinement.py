"""The spectral cell on finer and finer grids until a tolerance is met.

The grid is the spectral cell's only discretization parameter
(:mod:`ngcontact.cell.spectral.layered_cell`): the collocated pressure and gap, and
with them the contact set of eq. 57 and the coefficients of eq. 34 on it,
converge as the grid step shrinks.  The error of the contact fraction falls
like the grid step or faster (2D: the edges located between grid points,
:mod:`ngcontact.cell.spectral.grid_measures`; 3D: a count of grid points, one
layer of points at the contact edges), with a constant that depends on where
the edges fall between points, so it does not fall smoothly enough for
Richardson extrapolation.  Hence a comparison estimate on widely spaced
levels:

1. solve the whole load sweep on grid ``N_0`` (``discretization.grid``), then
   on grids with ``GROWTH`` times the points of the previous one (2D:
   ``4 N``; 3D: ``2 N`` per direction);
2. the estimate of level ``k`` is, over the loads, the larger of
   ``|f_k - f_(k-1)|`` (contact fraction, absolute) and
   ``|c_k - c_(k-1)| / |c_k|`` (mean closure, relative): the error of the
   coarser level, an upper bound of the finer one's once the sequence
   contracts by the factor ``GROWTH`` per level;
3. stop when it is at most the tolerance; the answer reported is the finest
   level's.  A level beyond ``max_points`` raises
   :class:`~ngcontact.errors.ConvergenceError` with the history.

The levels are known before the first solve (``grid`` times ``GROWTH^k``
up to ``max_points``, :func:`levels`; the scene layer bounds
``max_points`` by the cost of a solve,
:func:`ngcontact.scene.spectral_grid.spectral_cost`): the largest is stated
first, and each level prints one progress line as it ends.

Each level solves from scratch: nothing carries between grids but the
comparison, so a frictional load path is simply solved again per level.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from typing import Any, Callable

from ngcontact.errors import ConvergenceError

log = logging.getLogger(__name__)
#: the run's progress lines (printed as its stage lines, :func:`ngcontact.runner.solve`)
progress = logging.getLogger("ngcontact.progress")

#: points of a level over those of the previous level
GROWTH = 4


@dataclass
class RefinedSweep:
    """The finest level's cell and solutions, the estimate per load and the history of levels."""

    cell: Any
    solutions: list
    estimates: list[dict[str, float]]
    history: list[dict[str, Any]] = field(default_factory=list)

    @property
    def estimate(self) -> float:
        return max(max(e.values()) for e in self.estimates)


def next_grid(grid: int, dim: int) -> int:
    """Points per direction of the next level: ``GROWTH`` times the points in all."""
    return grid * GROWTH if dim == 2 else grid * round(GROWTH ** 0.5)


def level_change(coarse: list, fine: list) -> list[dict[str, float]]:
    """Per load, the change of the contact fraction (absolute) and of the mean closure (relative)."""
    out = []
    for a, b in zip(coarse, fine):
        fa, fb = a.results["contact_fraction"], b.results["contact_fraction"]
        ca, cb = a.results["mean_closure"], b.results["mean_closure"]
        out.append({"contact_fraction": abs(fb - fa),
                    "mean_closure": abs(cb - ca) / abs(cb) if cb != 0 else abs(cb - ca)})
    return out


def levels(grid: int, dim: int, max_points: int) -> list[int]:
    """The grids refinement may use: ``grid`` and each next one while its points are at most ``max_points``."""
    if grid ** (dim - 1) > max_points:
        raise ValueError(f"the first grid of {grid} points per direction exceeds the {max_points} points of the "
                         "largest")
    out = [grid]
    while next_grid(out[-1], dim) ** (dim - 1) <= max_points:
        out.append(next_grid(out[-1], dim))
    return out


def sweep_to_tolerance(make_cell: Callable[[int], Any], loads: list, tolerance: float, grid: int, dim: int,
                       max_points: int) -> RefinedSweep:
    """Solve ``loads`` on grids from ``grid`` up until the estimate meets ``tolerance`` (module docstring).

    ``make_cell(n)`` builds the spectral cell of ``n`` points per direction.  The grids it may reach
    (:func:`levels`) are known and stated before the first solve; each level logs one progress line.
    """
    grids = levels(grid, dim, max_points)
    progress.info("spectral refinement may reach grid %d (%d points) in %d levels from grid %d", grids[-1],
                  grids[-1] ** (dim - 1), len(grids), grid)
    history: list[dict[str, Any]] = []
    previous = None
    n = grid
    while True:
        t0 = time.perf_counter()
        cell = make_cell(n)
        sols = cell.sweep(loads)
        entry: dict[str, Any] = {
            "grid": n, "points": cell.points, "seconds": time.perf_counter() - t0,
            "iterations": [s.iterations for s in sols],
            "contact_fraction": [s.results["contact_fraction"] for s in sols],
            "mean_closure": [s.results["mean_closure"] for s in sols]}
        estimates = level_change(previous, sols) if previous is not None else None
        if estimates is not None:
            entry["estimate"] = max(max(e.values()) for e in estimates)
        history.append(entry)
        progress.info("spectral grid %d: %.2f s%s", n, entry["seconds"],
                      f", estimate {entry['estimate']:.3g}" if estimates is not None else "")
        if estimates is not None and entry["estimate"] <= tolerance:
            return RefinedSweep(cell=cell, solutions=sols, estimates=estimates, history=history)
        previous = sols
        n = next_grid(n, dim)
        if n ** (dim - 1) > max_points:
            reached = f"{entry['estimate']:.3g}" if estimates is not None else "no estimate (one level)"
            raise ConvergenceError(
                f"discretization.tolerance = {tolerance:g} not met: the estimate is {reached} on "
                f"{entry['points']} grid points, and the next grid of {n} per direction would exceed "
                f"{max_points} points; loosen the tolerance", {"levels": history})
