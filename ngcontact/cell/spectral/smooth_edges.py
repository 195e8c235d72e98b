"""The error of the 2D contact edges of a map without kinks: the quartic's spread, the line's share of a step.

A 2D edge of exact contact is placed at the root of the least-squares quartic of ``r = gap^(2/3)`` on a window
``[lo, hi)`` of open points beyond it, or where that window is too short or the fit misses, at the root of the line
through the first two open points (:mod:`~ngcontact.cell.spectral.grid_measures`).  On a map with kinks each edge
holds a share of a step fixed by calibration (:mod:`~ngcontact.cell.spectral.contact_edges`, form ``kink``); this
module bounds the edges of a map without kinks (a smooth profile), whose differences between grids may vanish
while the edges' errors stall, in two ways.

**The quartic's spread.**  The fit's own error at the root goes as ``rho^-5``, ``rho`` the largest Bernstein
ellipse about the window in which ``r`` is analytic, a function of ``hi`` against the distance ``R`` to ``r``'s
nearest singularity (the patch's other end).  Where the window is set by that distance (a share of the open run or
of the patch), its length in the period does not change as the grid is refined, so neither does the fit's error:
the located edge holds an offset of fixed length until the window reaches its cap of points and then shrinks with
the step.  Over such levels the edge's error stalls while the differences vanish, as an unresolved island's does.
The same quartic on the window's first half, ``[lo, (lo + hi) / 2)``, reads ``r`` inside a larger ellipse, its
own error a small part of the full window's, so the two roots differ by about the full window's error:

    ``delta_e = |t(lo, hi) - t(lo, (lo + hi) / 2)|``  steps,

one order more in the window's reach, as one grid doubling is in the step.  The half window's own error, of the
collocation's noise at fewer points, may cancel part of the spread: each such edge holds :data:`SPREAD_STEPS`
``delta_e`` steps (on smooth profiles of three harmonics the edges' error reached 1.3 times twice the spread,
``scripts/spectral_effectivity.py --held-out ... --smooth``); a quartic edge whose half window holds no fit,
:data:`~ngcontact.cell.spectral.grid_measures.FITTED_STEP`.

**The line's share.**  An edge the line located is off by a fraction of a step that jumps between grids (first
order, :mod:`~ngcontact.cell.spectral.contact_edges`, calibrated on random profiles), and on a smooth profile as
much: it holds :data:`~ngcontact.cell.spectral.grid_measures.LOCATED_STEP` of a step, as on a map with kinks.

The shares ``s_e`` (steps) of a load's edges are summed (their errors need not share a sign): of the contact
fraction ``sum_e s_e / n``, of eq. 34's ``k_n`` on the real contact set ``k_n`` times that, of ``g_n`` ``k_n sum_e
s_e g0(e) / n``, and of the 2D stiffness of the located set ``sum_e s_e |dK_e|``, ``dK_e`` its change with that
edge a step out (:func:`~ngcontact.cell.spectral.grid_measures.edge_stiffness`).
:func:`~ngcontact.cell.spectral.contact_edges.island_floor` floors the estimates of those quantities by them (form
:data:`SMOOTH`); the spectral effectivity of ``docs/benchmarks.md`` tests it.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ngcontact.cell.cell_solution import COEFFICIENT
from ngcontact.cell.spectral.grid_measures import (EDGE_MIN_POINTS, FITTED_STEP, LOCATED_STEP, edge_offset,
                                                   edge_stiffness, edge_window, kinks, quartic_root)

#: the estimate's form where the edges of a map without kinks bound it (module docstring)
SMOOTH = "smooth"
#: steps of each quantity on the edges a quartic-located edge holds per step of its spread (module docstring)
SPREAD_STEPS = 4.0
#: fewest points of the half window (a quartic's five coefficients and a misfit)
HALF_POINTS = EDGE_MIN_POINTS // 2


def fit_spread(root: np.ndarray, on: np.ndarray, i: int, step: int) -> tuple[bool, float | None]:
    """Whether the quartic located the edge beyond the last contact point ``i``, and its spread ``|t(lo, hi) -
    t(lo, (lo + hi) / 2)|`` in steps (module docstring), ``None`` where its half window holds no fitting quartic."""
    located, fitted = edge_offset(root, on, i, step)
    lo, hi = edge_window(root, on, i, step)
    half = (lo + hi) // 2
    if not fitted or half - lo < HALF_POINTS:
        return fitted, None
    inner = quartic_root(root, i, step, lo, half, located)
    return True, None if inner is None else abs(located - inner)


def edge_share(fitted: bool, spread: float | None) -> float:
    """An edge's share in steps (module docstring): :data:`SPREAD_STEPS` times the quartic's spread, else
    ``FITTED_STEP`` where the quartic located it, ``LOCATED_STEP`` where the line did."""
    if spread is not None:
        return SPREAD_STEPS * spread
    return FITTED_STEP if fitted else LOCATED_STEP


def smooth_share(cell, p: np.ndarray, gap: np.ndarray) -> dict[str, Any]:
    """The share of each quantity on the edges held by the 2D edges of exact contact of a pressure ``p`` on the
    deformed ``gap``, on a map without kinks (module docstring): ``{"fitted": edges the quartic located, "lined":
    edges the line did, "steps": their summed share in steps, "share": {headline name: absolute share}}``; none in
    3D, with a penalty, on a map with kinks or without edges."""
    on, n = p > 0, p.size
    if (cell.dim != 2 or getattr(cell, "enforcement", "exact") != "exact" or on.all() or not on.any()
            or kinks(cell.g0).any()):
        return {"fitted": 0, "lined": 0, "steps": 0.0, "share": {}}
    root = np.maximum(gap, 0.0) ** (2.0 / 3.0)
    located = {(int(i), step): fit_spread(root, on, int(i), step)
               for step in (1, -1) for i in np.flatnonzero(on & ~np.roll(on, -step))}
    steps = {key: edge_share(*found) for key, found in located.items()}
    total = sum(steps.values())
    heights = sum(s * float(cell.g0[i]) for (i, _), s in steps.items())
    stiffness = edge_stiffness(cell, on, gap)["edges"]
    fitted = sum(1 for found, _ in located.values() if found)
    return {"fitted": fitted, "lined": len(steps) - fitted, "steps": total,
            "share": {"contact_fraction": total / n, COEFFICIENT + "k_n": cell.k_n * total / n,
                      COEFFICIENT + "g_n": cell.k_n * heights / n,
                      "normal_stiffness": sum(s * abs(stiffness[key][1]) for key, s in steps.items()
                                              if key in stiffness)}}


def smooth_remark(edges: dict[str, Any], grid: int, raised: list[str]) -> str:
    """The report's remark on a load whose estimates of ``raised`` the share ``edges`` (:func:`smooth_share`) floors
    on ``grid`` points."""
    return (f"{edges['fitted']} edge(s) located by the quartic on grid {grid}, {edges['lined']} by the line, "
            f"{edges['steps']:.3g} step(s) in all: {', '.join(raised)} bounded by each quartic's spread from its half "
            "window's, a share of a step each else")
