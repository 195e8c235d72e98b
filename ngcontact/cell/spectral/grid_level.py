"""One level of the spectral refinement: the cell on a grid, its loads solved, and the record the estimate reads.

:mod:`~ngcontact.cell.spectral.refinement` and :mod:`~ngcontact.cell.spectral.coarser_grids` solve a sequence of
grids, each with :data:`GROWTH` times the points per direction of the one before.  A level starts its loads from
the coarser level's pressures, prolonged onto its grid (:func:`prolong`: the coarse points are every other fine
point, the points between take the mean of their neighbours): a start only, which saves the constrained CG the
first steps where the contact set shrinks from full contact; the answer is the level's own.  Its record holds per
load the headline quantities (:func:`~ngcontact.cell.cell_solution.headline`), which edges the quartic located
(:func:`~ngcontact.cell.spectral.grid_measures.edges_fitted`), the shares of the edges that no difference
bounds (:func:`~ngcontact.cell.spectral.contact_edges.unresolved_share`), and the coefficients of the whole
surface, the scale of eq. 34's coefficients on the real contact set; in 2D, on the levels whose estimate a stop
or the report reads, also the twin half a step over (:func:`solve_twin`,
:func:`~ngcontact.cell.spectral.grid_phase.twin_headline`; ``None`` on the others).
"""
from __future__ import annotations

import time
from typing import Any, Callable

import numpy as np

from ngcontact.cell.cell_solution import headline
from ngcontact.cell.spectral.contact_edges import unresolved_share
from ngcontact.cell.spectral.grid_measures import coefficients, edges_fitted
from ngcontact.cell.spectral.grid_phase import twin_headline

#: points per direction of a level over those of the previous level
GROWTH = 2


def prolong(p: np.ndarray) -> np.ndarray:
    """A periodic grid field on twice the points per direction: the coarse values at the even points, their
    (bi)linear interpolation between (non-negative where ``p`` is)."""
    out = p
    for axis in range(p.ndim):
        fine = np.repeat(out, 2, axis=axis)
        odd = [slice(None)] * p.ndim
        odd[axis] = slice(1, None, 2)
        fine[tuple(odd)] = 0.5 * (out + np.roll(out, -1, axis=axis))
        out = fine
    return out


def solve_level(make_cell: Callable[[int], Any], loads: list, n: int,
                coarser: list | None = None) -> tuple[Any, list, dict[str, Any]]:
    """The cell on ``n`` points per direction, its solutions of ``loads`` (from ``coarser``'s pressures,
    interpolated, where the coarser level's solutions are given) and the history entry of the level, its twin not
    yet solved (:func:`solve_twin`)."""
    t0 = time.perf_counter()
    cell = make_cell(n)
    starts = None
    if coarser is not None and all(c.fields["pressure"].shape[0] * GROWTH == n for c in coarser):
        starts = [prolong(c.fields["pressure"]) for c in coarser]
    sols = cell.sweep(loads, starts=starts)
    entry: dict[str, Any] = {
        "grid": n, "points": cell.points, "seconds": time.perf_counter() - t0,
        "iterations": [s.iterations for s in sols],
        "contact_fraction": [s.results["contact_fraction"] for s in sols],
        "mean_closure": [s.results["mean_closure"] for s in sols],
        "headline": [headline(s.results) for s in sols],
        "edges_fitted": [edges_fitted(cell, s.fields["pressure"], s.fields["gap"]) for s in sols],
        "islands": [unresolved_share(cell, s.fields["pressure"], s.fields["gap"]) for s in sols],
        "phase": None,
        "whole_surface": coefficients(cell, np.ones(cell.shape, bool)).as_dict()}
    return cell, sols, entry


def solve_twin(make_cell: Callable[[int], Any], loads: list, cell, sols: list, entry: dict[str, Any]) -> None:
    """Solve the twin half a step over of the level of ``cell`` and ``sols`` (2D;
    :func:`~ngcontact.cell.spectral.grid_phase.twin_headline`) into its history ``entry``, whose time then
    counts the twin's too.  Its loads start from the level's pressures at the midpoints between its points,
    which are the twin's (the odd points of :func:`prolong`)."""
    t0 = time.perf_counter()
    entry["phase"] = twin_headline(make_cell, cell, loads, [prolong(s.fields["pressure"])[1::2] for s in sols])
    entry["seconds"] += time.perf_counter() - t0
