"""The penalty's zone at a 2D contact edge, as the spectral refinement's estimate sees it (eq. 65).

With the Winkler layer of eq. 65 (``contact.enforcement = "penalty"``) the gap beyond an edge opens like
``(x - a)^(3/2)`` only farther than the length ``lambda = E*/k_n`` from it (:func:`penalty_length`,
``1/E* = sum (1 - nu^2)/E`` over the two bodies): nearer, the layer carries the pressure, which falls to zero
smoothly, and the gap opens faster. The quartic's window (tens to hundreds of steps) and, on a step above ``lambda``,
the line's two points read the gap there, where it looks like that of a rigid edge placed off the penalty's own: the
located edge converges, as the grid is refined, to that outer edge, and its error stalls while the differences
between grids vanish (the quartic's window is a fixed share of the open run up to about 7,500 points per period),
then grows as the window shrinks into ``lambda``, before the line, on steps below ``lambda``, takes over and
converges at first order. On Westergaard's sinusoid (layers of depth 1) refined to 1e-3 at ``k_n = 1e4`` the contact
fraction of each load is off by 0.71 ``lambda`` per edge on 16,384 points (8e-5) while the estimate from the
differences was 1.6e-5 to 4.6e-6; at ``k_n = 1e3, 1e5, 1e6`` the outer edge is off by 0.49, 1.15 and 1.46 ``lambda``
(the penalty's own move of the edge, which it misses in part, grows like ``lambda ln(1 / lambda)``:
:mod:`ngcontact.cell.penalty_share`).

So each edge of a penalty located on points beyond ``lambda`` (by the quartic, or by the line on a step above
``lambda``; :func:`penalty_zone_share`) holds ``B = PENALTY_LOG lambda ln(P / lambda)`` (``P`` the period), with
``PENALTY_LOG = 1/4``: 1.9 to 3.6 ``lambda`` from ``k_n = 1e3`` to ``1e6``, two and a half to four times the error
above; the contact fraction ``B / P`` per edge, ``K0 = k_n |S| / |T|`` ``k_n B / P``, ``g_n`` ``k_n B / P`` times the
largest ``g0`` within ``B`` and a step of the edge, summed over such edges, the same floor as an island's (form
:data:`PENALTY_ZONE`; like an island's stalled share it is not flagged by its last difference, which does not show
it).

Within ``lambda`` the gap opens like ``(x - a)^2`` (the pressure falls to zero linearly), so ``gap^(2/3)`` goes like
``(x - a)^(4/3)`` and the line through its first two open points, a step apart, is off by up to a third of a step
(``1 - 1/(2^(4/3) - 1)`` where the first lies a step beyond the edge), and by more where the collocated set holds a
point too many or too few: first order, with a constant that jumps with the edge's position between points, which the
differences may hide (at ``k_n = 1e4`` refined to 1e-4 the contact fraction's guarded estimate on 524,288 points was
half its error, 0.38 of a step per edge). Each edge so located holds :data:`INSIDE_STEP` of a step, half, in the same
floor (about 1.3 times that error). A run of levels whose edges are all located so is a locator's own, as the
quartic's (:func:`~ngcontact.cell.spectral.contact_edges.fitted_run`): a window across the change from the quartic's
levels is also taken on them alone (guarded, never Richardson's; a stop does not wait for them,
:func:`~ngcontact.cell.spectral.contact_edges.locator_changing`: the whole window's bound stands).

Every quantity of a load, the mean closure and the stiffness too, changes once more as the step falls below
``lambda``: the collocated pressure then resolves the layer's zone at each edge, which coarser grids pass over. On
Westergaard's sinusoid the mean closure's differences contract over several grids, then turn and stay near one size
down to the grid whose step is ``lambda`` (``tests/cell/test_penalty_edges.py``): a sequence seen as geometric before
that change says nothing of it. So on a level whose step exceeds ``lambda`` (:func:`zone_ahead`) no quantity of the
load takes Richardson's tail, only the guarded bound, whose envelope keeps the earlier, larger differences.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ngcontact.cell.cell_solution import COEFFICIENT
from ngcontact.cell.spectral.grid_measures import edge_offset

#: the form of an estimate raised to the floor of a penalty's edges read beyond its length (module docstring)
PENALTY_ZONE = "penalty zone"
#: the kind of a level whose penalty's edges are all located by the line on points within its length
INSIDE = "inside"
#: the share of a step that bounds a penalty's edge located by the line within its length (module docstring)
INSIDE_STEP = 0.5
#: the bound on such an edge's error over ``lambda ln(P / lambda)``, ``lambda = E* / k_n`` (module docstring)
PENALTY_LOG = 0.25


def zone_ahead(entry: dict[str, Any], k: int) -> bool:
    """Whether a level's step exceeds the penalty's length ``lambda`` at load ``k`` with edges in contact: the
    change of regime where the grid comes to resolve the penalty's zone lies ahead (module docstring)."""
    return not entry.get("islands", [{}] * (k + 1))[k].get("penalty", {}).get("resolved", True)


def penalty_length(cell) -> float:
    """The length ``lambda = E* / k_n`` over which a 2D penalty's edge departs from a rigid one (module docstring):
    ``E*`` the plane-strain modulus of the two bodies in series, ``1 / E* = sum (1 - nu^2) / E``; 0 for exact
    contact and in 3D."""
    if cell.dim != 2 or cell.enforcement != "penalty":
        return 0.0
    return 1.0 / (cell.k_n * sum((1.0 - layer.nu ** 2) / layer.E for layer in (cell.rough, cell.counter)))


def penalty_zone_share(cell, p: np.ndarray, gap: np.ndarray) -> dict[str, Any]:
    """The share of each quantity on the edges held by the 2D edges of a penalty's pressure ``p`` (module
    docstring): an edge located on points farther than its length ``lambda`` (:func:`penalty_length`; by the
    quartic, or by the line on a step above ``lambda``) may be off by ``B = PENALTY_LOG lambda ln(P / lambda)``,
    one located by the line within it by :data:`INSIDE_STEP` of a step ``h``: the contact fraction by that over
    ``P``, ``K0`` ``k_n`` times as much, ``g_n`` that times the largest ``g0`` within it and a step of the edge.
    ``{"edges": how many beyond, "bound": B, "inside": whether none is, "resolved": whether the step is at most
    lambda (:func:`zone_ahead`), "share": {headline name: absolute share}}``; no share without a penalty's edges."""
    lam, on, n = penalty_length(cell), p > 0, p.size
    step = cell.period / n
    if lam <= 0.0 or on.all() or not on.any():
        return {"edges": 0, "bound": 0.0, "share": {}, "inside": False, "resolved": True}
    bound = PENALTY_LOG * lam * max(np.log(cell.period / lam), 1.0)
    root = np.maximum(gap, 0.0) ** (2.0 / 3.0)
    edges, total, heights = 0, 0.0, 0.0
    for side in (1, -1):
        for i in (int(j) for j in np.flatnonzero(on & ~np.roll(on, -side))):
            beyond = edge_offset(root, on, i, side)[1] or step > lam
            off = bound if beyond else INSIDE_STEP * step
            reach = int(np.ceil(off / step)) + 1
            edges, total = edges + beyond, total + off
            heights += off * float(cell.g0[np.arange(i - reach, i + reach + 1) % n].max())
    return {"edges": edges, "bound": bound, "inside": not edges, "resolved": step <= lam, "share": {
        "contact_fraction": total / cell.period, COEFFICIENT + "k_n": cell.k_n * total / cell.period,
        COEFFICIENT + "g_n": cell.k_n * heights / cell.period}}
