"""The error of a spectral cell's answer on its own grid, from the same loads on coarser grids.

Refinement to a tolerance (:mod:`ngcontact.cell.spectral.refinement`) estimates the error of the finest of a
sequence of grids, each with twice the points per direction of the one before, from the differences
``d_j = q_j - q_(j-1)`` of its last :data:`~ngcontact.cell.spectral.estimate_forms.WINDOW` levels
(:func:`~ngcontact.cell.spectral.refinement.sweep_estimates`: Richardson with the observed rate where the
sequence is seen to be geometric, else the guarded geometric tail; the island floor and the loose flags).
That estimate needs the sequence that ends at the reported grid, not grids beyond it.  So a cell answered on
the scene's own grid ``n`` (an ensemble's member, :mod:`ngcontact.drivers.run_ensemble`, which keeps the
scene's discretization so that the members' spread is the surface class's and its numbers the scene's) is
estimated as the finest of the :data:`~ngcontact.cell.spectral.refinement.MIN_LEVELS` grids ``n / 8, n / 4,
n / 2, n``, the fewest a stop of the refinement needs, by the same estimate in its guarded form only: the same
quantities and measures, the geometric tail of the envelope ``D = max_i |d_(k-i)| / 2^i`` at the larger
observed ratio held to ``[1/2, 0.7]``, so that the first, largest difference bounds the later ones at first
order.  Not Richardson: grids coarser than a height map's samples (an ensemble's random surfaces) sample
fewer of its heights, so roughness appears level by level and two fast ratios of the coarse differences may
be a coincidence of a sequence not yet in its asymptotic regime.  On a member of a self-affine class (64
samples, cut-off a quarter of them) the mean closure's coarse differences fell by 14 and by 5.5, Richardson
claimed a fifth of the error of grid 64 (which grew again beyond it, to the 1,024-point answer), the
guarded bound twice it (``tests/drivers/test_ensemble.py``).

Each coarser grid samples the same surface: a gap given by a formula at its points, a height map's or random
surface's samples through the bilinear interpolant that also defines the surface on finer grids
(:func:`ngcontact.drivers.cell_gap.gap_samples`).  A coarse grid that misses the surface's short wavelengths
(a random surface's cut-off within a few of its points) shows large differences, and the estimate is large:
the scene's grid is then not shown to be converged, which is what the estimate is for.  The scene's grid is
solved last and from zero pressure, as without the estimate, so its numbers are those of the plain sweep; a
coarser grid starts from the one before it, interpolated (:func:`~ngcontact.cell.spectral.grid_level.prolong`).

Cost: the three coarser grids hold ``1/4 + 1/16 + 1/64 = 0.33`` of the scene grid's points in 3D and
``1/2 + 1/4 + 1/8 = 0.88`` in 2D, each solved in fewer constrained CG steps (their count grows like the
square root of the points per direction, :func:`ngcontact.scene.spectral_grid.spectral_cost`), so the
estimate costs at most a third (3D) of the scene's own solve more; in 2D seven eighths, and the scene grid's
twin half a step over (:mod:`~ngcontact.cell.spectral.grid_phase`), one solve of its size from its own pressures.
A grid that does not halve three times to at least :data:`COARSEST` points per direction is not estimated (the reason is
reported).
"""
from __future__ import annotations

from typing import Any, Callable

from ngcontact.cell.spectral.contact_edges import island_floor
from ngcontact.cell.spectral.estimate_forms import loose_flags, loose_remarks
from ngcontact.cell.spectral.grid_level import GROWTH, solve_level, solve_twin
from ngcontact.cell.spectral.grid_phase import phase_floor
from ngcontact.cell.spectral.refinement import MIN_LEVELS, RefinedSweep, sweep_estimates

#: the fewest points per direction of the coarsest grid
COARSEST = 4
#: how the estimate is made, for the report
HOW = (f"the scene's grid and {MIN_LEVELS - 1} coarser ones, each with half the points per direction of the next "
       "(at most a third of the scene's solve more in 3D, in 2D seven eighths and its twin half a step over), "
       "estimated as the finest of that sequence as refinement estimates its finest grid")


def coarser_levels(grid: int) -> list[int] | None:
    """The grids ``grid / 8, grid / 4, grid / 2, grid`` (coarsest first), or ``None`` where ``grid`` does not
    halve so to at least :data:`COARSEST` points per direction."""
    step = GROWTH ** (MIN_LEVELS - 1)
    if grid % step or grid // step < COARSEST:
        return None
    return [grid // GROWTH ** k for k in range(MIN_LEVELS - 1, -1, -1)]


def why_not(grid: int) -> str:
    """Why a grid is not estimated from coarser ones (:func:`coarser_levels` is ``None``)."""
    return (f"not estimated: the grid of {grid} points per direction does not halve {MIN_LEVELS - 1} times to at "
            f"least {COARSEST} points; a grid that is a multiple of {COARSEST * GROWTH ** (MIN_LEVELS - 1)} is "
            "estimated from coarser ones")


def estimate_from_coarser(make_cell: Callable[[int], Any], loads: list, grid: int) -> RefinedSweep | None:
    """``loads`` on ``grid`` (``make_cell(grid)``'s solutions, from zero pressure) with the estimate of their
    error from the coarser grids of :func:`coarser_levels` (module docstring); ``None`` where there are none."""
    grids = coarser_levels(grid)
    if grids is None:
        return None
    history: list[dict[str, Any]] = []
    sols: list = []
    for n in grids:
        cell, sols, entry = solve_level(make_cell, loads, n, None if n == grid else (sols or None))
        history.append(entry)
    solve_twin(make_cell, loads, cell, sols, entry)         # the scene's grid only: the one reported
    estimates, remarks, forms = sweep_estimates(history, geometric_ok=False)
    remarks += island_floor(history, estimates, forms) + phase_floor(history, estimates, forms)
    flags = loose_flags(history, estimates, forms)
    return RefinedSweep(cell=cell, solutions=sols, estimates=estimates, history=history,
                        remarks=remarks + loose_remarks(flags), forms=forms, flags=flags)
