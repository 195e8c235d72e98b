"""The grid's phase against the surface: a second sample of one 2D level's error, half a step over.

A grid of ``n`` points per period samples the gap at ``x_j = j h``, ``h = P / n``.  Its collocated answer ``q_n``
(:mod:`~ngcontact.cell.spectral.layered_cell`) depends on the step and on where the points fall on the surface:
on the offset ``phi`` (in steps, ``[0, 1)``) of each contact edge from the last point before it.  Its error splits
as

    ``e_n(phi) = s_n + o_n(phi)``,  ``o_n`` of zero mean over ``phi``,

a part ``s_n`` the same at every offset and a part ``o_n`` that jumps as refinement moves the edges between points
(the erratic factor of :mod:`~ngcontact.cell.spectral.refinement`).  The differences between grids see both, and
``o`` alone can stall them: two levels whose ``e_n`` happen to be equal leave a difference far below either error,
which no rule on differences can tell from convergence (on a smooth profile of three harmonics the mean closure's
error held 2e-7 over 4096 and 8192 points with a difference of 3e-8 between them; ``docs/benchmarks.md``, the
spectral effectivity's held-out profiles).

**The twin.**  The same cell posed on the gap sampled half a step over (:func:`posed_on`), at ``x_j + h / 2``:
every second point of the grid twice as fine, so the same surface (a formula, a table's or a map's interpolant;
``make_cell(2 n)``'s gap).  Its answer ``q'_n = q + s_n + o_n(phi + 1/2)`` shares ``s_n``, and the first harmonic
of ``o_n`` in ``phi`` changes sign half a step over, ``o(phi + 1/2) = -o(phi)``, so that ``|o_n(phi)| = |q_n -
q'_n| / 2`` for that harmonic.  The floor of a 2D level's estimate is :data:`PHASE_SAFETY` times that,

    ``E_n >= PHASE_SAFETY |q_n - q'_n| / 2 = |q_n - q'_n|``,

the harmonics beyond the first within the safety factor 2.  It bounds ``o`` at the reported level itself,
whichever way the differences stalled; ``s_n``, which the twin does not see, the differences bound.  Each estimate
is raised to its floor where smaller (form :data:`PHASE`), in the quantity's measure
(:func:`~ngcontact.cell.cell_solution.scale`).  One more solve of the level's size, from the level's own pressures
interpolated to the twin's points, on the levels whose estimate a stop or the report reads
(:mod:`~ngcontact.cell.spectral.refinement`: the floor only raises an estimate, so elsewhere it changes no
decision).  2D only: a 3D twin would double the cost of the dearest solves, and the 3D line's floor bounds the
crossings of its edges (:mod:`~ngcontact.cell.spectral.contact_edges`).
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ngcontact.cell.cell_solution import headline, scale
from ngcontact.cell.spectral.layered_cell import SpectralCell

#: the estimate's form where the grid's phase bounds it (module docstring)
PHASE = "phase"
#: the floor's factor on the half-difference between the grid and its twin half a step over (module docstring)
PHASE_SAFETY = 2.0


def twin_headline(make_cell: Callable[[int], Any], cell, loads: list, starts: list | None
                  ) -> list[dict[str, float]] | None:
    """Per load, the headline quantities of ``cell`` posed on the gap sampled half a step over (module docstring:
    every second point of ``make_cell(2 n)``'s gap), solved from the pressures ``starts`` on the twin's points
    (``None``: from zero); ``None`` in 3D."""
    if cell.dim != 2:
        return None
    twin = posed_on(cell, make_cell(2 * cell.grid).g0[1::2])
    return [headline(s.results) for s in twin.sweep(loads, starts=starts)]


def posed_on(cell: SpectralCell, gap: np.ndarray) -> SpectralCell:
    """The same cell (layers, grid, interface law, solver) posed on another initial ``gap`` of its grid."""
    twin = SpectralCell(dim=cell.dim, period=cell.period, grid=cell.grid, rough=cell.rough, counter=cell.counter,
                        gap=gap, k_n=cell.k_n, enforcement=cell.enforcement, tol=cell.tol, max_iter=cell.max_iter,
                        friction=cell.friction)
    twin.preconditioned, twin.friction_method = cell.preconditioned, cell.friction_method
    return twin


def phase_floor(history: list[dict[str, Any]], estimates: list[dict[str, float]], forms: list[dict[str, str]]
                ) -> list[str]:
    """Raise in place each estimate of the last level of ``history`` (per load; its form with it) to
    ``PHASE_SAFETY`` times half its change on the twin half a step over, where that is larger (module
    docstring).  Returns a remark per load raised; none where the level has no twin (3D)."""
    last = history[-1]
    remarks = []
    for k, (per_load, twin) in enumerate(zip(estimates, last.get("phase") or [])):
        now, raised = last["headline"][k], []
        for name in per_load:
            if twin.get(name) is None or now.get(name) is None:
                continue
            floor = PHASE_SAFETY * abs(now[name] - twin[name]) / 2 / scale(name, now, last["whole_surface"])
            if floor > per_load[name]:
                per_load[name], forms[k][name] = floor, PHASE
                raised.append(name)
        if raised:
            remarks.append(f"load {k}: {', '.join(raised)} bounded by {PHASE_SAFETY:g} times half the change on "
                           f"grid {last['grid']} sampled half a step over")
    return remarks
