"""The error of a 2D contact edge located by the quartic, read off the quartic on half its window.

A 2D edge of exact contact is placed at the root of the least-squares quartic of ``r = gap^(2/3)`` on a window
``[lo, hi)`` of open points beyond it (:mod:`~ngcontact.cell.spectral.grid_measures`, its docstring's reach).  The
fit's own error at the root goes as ``rho^-5``, ``rho`` the largest Bernstein ellipse about the window in which
``r`` is analytic, a function of ``hi`` against the distance ``R`` to ``r``'s nearest singularity (the patch's
other end, a kink).  Where the window is set by that distance (a share of the open run or of the patch), its
length in the period does not change as the grid is refined, so neither does the fit's error: the located edge
holds an offset of fixed length, however many points the window holds, until the window reaches its cap of points
and then shrinks with the step (the error then falls as ``rho^-5`` of a window half as long per level).  Over such
levels the edge's error stalls while the differences between levels vanish, as an unresolved island's does
(:mod:`~ngcontact.cell.spectral.contact_edges`): no difference shows it.

The same quartic on the window's first half, ``[lo, (lo + hi) / 2)``, reads ``r`` inside an ellipse larger by
about the factor ``rho`` grows with ``R / hi``; its error is a small part of the full window's (``rho^-5`` at twice
``R / hi``), so the two roots differ by about the full window's error:

    ``delta_e = |t(lo, hi) - t(lo, (lo + hi) / 2)|``  steps,

one order more in the window's reach, as one grid doubling is in the step.  Each edge the quartic located
therefore holds :data:`SPREAD_STEPS` ``delta_e`` steps of each quantity on the edges (the factor: the half window's
own error, of the collocation's noise at fewer points, may cancel part of the spread), summed over the load's
edges (their errors need not share a sign): of the contact fraction ``sum_e s_e / n``, of eq. 34's ``k_n`` on the
real contact set ``k_n`` times that, of ``g_n`` ``k_n sum_e s_e g0(e) / n``, and of the 2D stiffness of the located
set ``sum_e s_e |dK_e|``, ``dK_e`` its change with that edge a step out (:func:`~ngcontact.cell.spectral.
grid_measures.edge_stiffness`).  :func:`~ngcontact.cell.spectral.contact_edges.island_floor` floors the estimates
of those quantities by these shares (form :data:`FIT`).  The oracles that test it (``docs/benchmarks.md``, the
spectral effectivity) include smooth profiles of three harmonics, whose quartic-located edges stall at a few
thousandths of a step on grids whose window is set by the patch.  An edge the half window cannot fit (too few
points, a misfit) holds no share: the line or the full quartic's other bounds stand.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ngcontact.cell.cell_solution import COEFFICIENT
from ngcontact.cell.spectral.grid_measures import (EDGE_MIN_POINTS, edge_offset, edge_stiffness, edge_window, kinks,
                                                   quartic_root)

#: the estimate's form where the quartic's spread bounds it (module docstring)
FIT = "fit"
#: steps of each quantity on the edges an edge holds per step of its quartic's spread (module docstring)
SPREAD_STEPS = 2.0
#: fewest points of the half window (a quartic's five coefficients and a misfit)
HALF_POINTS = EDGE_MIN_POINTS // 2


def fit_spread(root: np.ndarray, on: np.ndarray, i: int, step: int, at: np.ndarray | None = None) -> float | None:
    """``|t(lo, hi) - t(lo, (lo + hi) / 2)|`` in steps for the edge beyond the last contact point ``i`` (module
    docstring), ``None`` where the quartic did not locate it or its half window holds no fitting quartic."""
    located, fitted = edge_offset(root, on, i, step, at)
    lo, hi = edge_window(root, on, i, step, at)
    half = (lo + hi) // 2
    if not fitted or half - lo < HALF_POINTS:
        return None
    inner = quartic_root(root, i, step, lo, half, located)
    return None if inner is None else abs(located - inner)


def fit_share(cell, p: np.ndarray, gap: np.ndarray) -> dict[str, Any]:
    """The share of each quantity on the edges held by the quartic-located 2D edges of exact contact of a pressure
    ``p`` on the deformed ``gap`` (module docstring): ``{"edges": how many hold a share, "steps": their summed
    spread in steps, "share": {headline name: absolute share}}``; none in 3D, with a penalty or without edges."""
    on, n = p > 0, p.size
    if cell.dim != 2 or getattr(cell, "enforcement", "exact") != "exact" or on.all() or not on.any():
        return {"edges": 0, "steps": 0.0, "share": {}}
    root = np.maximum(gap, 0.0) ** (2.0 / 3.0)
    at = np.flatnonzero(kinks(cell.g0))
    spreads = {(int(i), step): fit_spread(root, on, int(i), step, at)
               for step in (1, -1) for i in np.flatnonzero(on & ~np.roll(on, -step))}
    steps = {key: SPREAD_STEPS * s for key, s in spreads.items() if s is not None}
    if not steps:
        return {"edges": 0, "steps": 0.0, "share": {}}
    total = sum(steps.values())
    heights = sum(s * float(cell.g0[i]) for (i, _), s in steps.items())
    stiffness = edge_stiffness(cell, on, gap)["edges"]
    return {"edges": len(steps), "steps": total / SPREAD_STEPS,
            "share": {"contact_fraction": total / n, COEFFICIENT + "k_n": cell.k_n * total / n,
                      COEFFICIENT + "g_n": cell.k_n * heights / n,
                      "normal_stiffness": sum(s * abs(stiffness[key][1]) for key, s in steps.items()
                                              if key in stiffness)}}
