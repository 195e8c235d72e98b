"""The contact set's edges and islands as the refinement's estimate sees them (spectral cell).

The headline quantities that rest on the contact edges (:func:`on_edges`: the contact fraction and the
coefficients of eq. 34 on the real contact set, :mod:`~ngcontact.cell.spectral.grid_measures`) are
estimated by :mod:`~ngcontact.cell.spectral.refinement` from their differences between grids, and two
things the differences cannot show are read off the levels here:

* which of the two edge locators placed a load's edges on each level (:func:`fitted_run`,
  :func:`locator_changing`; the refinement's module docstring says why a window across the change of
  locator bounds the quartic's error by the line's);
* **contact islands too narrow for the grid** (:func:`unresolved_share`).  An island of ``w`` collocation
  points is resolved when its edges are: each edge is located between the last contact point and the
  first open one, by the line through the first two open points to within a step, so an island of fewer
  than :data:`ISLAND_POINTS` points is narrower than the reach of its two edges' locators, and its
  collocated pressure (singular like the inverse square root of the distance to either edge, paper eq. 57
  on the set) has no interior.  Its located width then does not converge at the first order of the
  resolved edges: it may be close to nothing on two successive grids (an island below a step wide at
  both), so that the differences vanish while the error is the island's whole share; it stalls.  Such an
  island's share of each quantity is bounded by its points and one step beyond each edge: the share of
  eq. 34 on its points and its two open neighbours (``K0 = k_n |S| / |T|``, ``g_n = k_n mean(1_S g0)``,
  :func:`~ngcontact.cell.spectral.grid_measures.coefficients`), whatever the island's true width below
  that.  The refinement takes it as a floor on the difference-based estimate of each quantity on the
  edges (:func:`island_floor`): the floor falls like ``h`` while islands stay unresolved, and vanishes
  once every island spans :data:`ISLAND_POINTS` points.

In 3D the contact fraction's edges are located along the grid's rows and columns by the line
(:func:`~ngcontact.cell.spectral.grid_measures.row_weights`), each to a fraction of a step: an island's area is
off by an error of order ``h`` times its perimeter with an erratic constant, a small part of a resolved island's
area.  An island fewer than :data:`ISLAND_POINTS` points across in a
direction of the grid (no run of that many contact points along it: :func:`narrow_islands`; the islands are
4-connected across the period, :func:`periodic_labels`) is all boundary: its count may be off by its whole
size, and two grids may locate it alike while its true area differs, as a 2D island's located width may.
Its share is bounded the same way, by its points and one step beyond its boundary (the 4-neighbours of its
points), eq. 34 on them; the refinement takes it as the same floor.

**A window across an island's resolution.**  While a load has an unresolved island, every headline quantity
carries the island's stalled share (the mean closure and the stiffness too: the island's collocated pressure,
on fewer points than its edges' reach, has no interior); once every island spans :data:`ISLAND_POINTS`
points, that share falls at the rate of resolved edges.  A difference between the last level with such an
island and the first without is therefore that island's error, not a term of the resolved sequence, as a
difference across the change of 2D edge locator is the line's (:mod:`~ngcontact.cell.spectral.refinement`):
the guarded envelope, which shrinks an earlier difference at first order only (``|d_(k-i)| / 2^i``), then
bounds the resolved levels' error by the unresolved one's.  So each quantity of a load whose islands are all
resolved on the last ``r`` levels (:func:`resolved_run`) only, ``r`` at least the refinement's
``LOCATOR_LEVELS`` (two differences: one that vanished is seen beside the other), is also estimated on
those ``r`` levels alone by the same rule, and the smaller estimate is reported (each bounds the error on its
own argument; on the edges' quantities the levels must also be the quartic's where any are).  An island
still unresolved on the last level keeps its floor; a window of resolved levels is left as it is.

**An edge at a kink of the map.**  A height map's surface is the piecewise-linear interpolant of its samples
(:mod:`~ngcontact.drivers.cell_gap`): its gap ``g0`` has a slope that jumps at each sample, ``g0''`` a Dirac
there.  Beside such a kink the gap beyond an edge is not ``(x - a)^(3/2)``: the edge's position is set by the
pressure's balance against a gap whose curvature is concentrated at one point, and it converges only once the
grid resolves the kink's neighbourhood, not at the first order of a smooth edge.  An edge located within a grid
step of a kink (:func:`kinks`: points whose second difference of ``g0`` exceeds its ``KINK_RATIO`` times those
two points away, a Dirac among the smooth or zero curvature of the segments beside it) may thus stall
over several grids, pinned to the kink while the differences shrink (random profiles of 64 samples: an edge at a
sample on 1024 to 8192 points, off it by a fifth of the 4096 grid's step on 65,536; the contact fraction's error
stalls at a third of a step while its differences fall tenfold).  Where the edge's true position lies within one
step of the kink, moving the located edge by one step bounds its error: the contact fraction changes by ``h /
P``, ``K0 = k_n |S| / |T|`` by ``k_n h / P`` and ``g_n = k_n mean(1_S g0)`` by at most ``k_n h / P`` times the
largest ``g0`` within a step of the edge (the grid points bounding the piecewise-linear ``g0`` there;
:func:`kink_share`), combined with the load's other edges (below).
The refinement takes that share as a floor on the estimate of each quantity on the edges, as an island's
(:func:`island_floor`, form :data:`KINK`).  The floor rests on the edge lying within a step of the kink, which
no difference shows (its premise: an edge pinned to a kink lies at it to a fraction of a step on each grid that
does not resolve it); it falls like ``h``, and exceeds the error of an edge located to a fraction ``f`` of a step
by ``1 / f``, so that an estimate it sets above ``LOOSE`` times the error the last difference
leaves is flagged (:mod:`~ngcontact.cell.spectral.estimate_forms`).  A notch (an open run of fewer than
:data:`ISLAND_POINTS` points inside contact at a kink where the map's valley is sharper than the pressed surface
follows) has both edges within a step of its kink: its true width lies between nothing and the ``s`` steps
between its two contact points (a wider one would open a point more), so its error is at most ``max(w, s - w)``
steps, ``w`` its located width (one open point located a step wide, the notch far narrower: on the random
profile of seed 9 at p = 0.01 the located width halves with the step); one that no grid point sees yet is not
bounded here (on the profile of seed 6 at p = 0.003 such a notch carries half the 4096 grid's error in the
contact fraction).  A smooth gap (``g0''`` continuous) has no kinks.  In 3D no kink floor is taken: a map's kinks
lie on the lines of its samples, which a patch's edge crosses at points, so that only the rows crossing the edge
within a step of such a point are pinned, and the guarded bound of the differences holds the rest.

**Every other edge of a map with kinks.**  Away from the kinks the gap beyond an edge is smooth over the few steps
the line through the first two open points reads, but neither locator converges as on a smooth gap: the line is off
by a fraction of a step whose size and sign change from grid to grid, as the kinks nearest to the edge move between
points, and the quartic reads a window kept within half the way to the nearest kink
(:func:`~ngcontact.cell.spectral.grid_measures.edge_offset`; a window that reached across it was off by as much)
(calibration below).  So the edges' error is of the order of the step, with a constant erratic from grid to grid: the
differences may show its changes of sign, not its size (on seed 7 at p = 0.003 it grows from 0.014 to 0.21 of a step
on 2048 to 8192 points while they contract twofold: an estimate from them is half the error).  On a map with kinks
each edge not at a kink therefore holds :data:`LOCATED_STEP` of a step of each quantity on the edges where the line
located it, :data:`FITTED_STEP` where the quartic did (exact contact: its window reads the smooth gap), as the same
floor (form :data:`KINK`).  The 2D normal effective stiffness, of the set with its edges located between points
(exact contact, :mod:`~ngcontact.cell.spectral.grid_measures`), carries the same edges' error: each edge's share is
its steps above (a step at a kink, a notch's on each of its edges, :data:`FITTED_STEP` or :data:`LOCATED_STEP`
elsewhere) times the stiffness's change with that edge alone a step out
(:func:`~ngcontact.cell.spectral.grid_measures.edge_stiffness`; :func:`stiffness_share`), the same floor under its
estimate.  (With a penalty the stiffness is the collocated set's, whose error on the profiles of seeds 1 to 12 was
0.1 of its change with every edge a step out in the median, 0.53 at most: :data:`STIFFNESS_STEP` of each edge's
change, summed; its edges are bounded as the line's, the quartic reading beyond the penalty's length.)

**A load's edges together.**  Each edge's error is made by its own locator on its own stretch of gap: but for a share
of one sign (which the differences between grids show) a load's edges' errors are independent and do not add up to
the sum of their bounds.  The edges hold together :data:`QUADRATURE` times the root-sum-square of their shares
(:func:`quadrature`), or their sum where smaller: errors of zero mean within ``s_i`` spread by at most ``sqrt(sum
s_i^2)``, and the factor covers a share of one sign (a load's signed errors summed were 1.1 times their own
root-sum-square in the median, 3.1 at most, all twelve edges of a load inside by 0.006 to 0.17 of a
step).  Calibration on random profiles of 64 samples, seeds 13 to 40 (the benchmarks' are 1 to 12), three loads (p =
0.001, 0.003, 0.01), grids 1024 to 32,768 against 262,144 points, each edge matched to the reference's nearest on
its side (504 loads and grids, 4,912 edges): an edge's error by the line 0.05 of a step in the median, 0.18 in the
99th percentile, 0.29 at most (one of 2,920 beyond :data:`LOCATED_STEP`), by the quartic 0.008, 0.044, 0.057, at a
kink 0.17, 0.65, 1.02 (on 1024 points), a notch's width 0.43 of its bound in the median, 1.4 at most; over its
load's combined shares the contact fraction's error was 0.13 in the median, 0.34 in the 90th percentile, 0.76 at
most, ``g_n``'s 0.66 and the stiffness's 0.61 at most, every load within its floor by 1.3 times or more, loads with
a notch or island no grid point sees yet included (over the sum of the shares: 0.084, 0.24, 0.76).

**The 3D line's crossings.**  In 3D each row and each column crossing a contact edge holds its own located edge,
the root of the line through ``gap^(2/3)`` at its first two open points
(:func:`~ngcontact.cell.spectral.grid_measures.row_weights`), off by a fraction ``delta_i`` of a step that changes
with the crossing's position between points from row to row and from grid to grid.  Each such offset moves the
located set by ``delta_i h`` along a row of width ``h``, so that with ``N`` crossings per direction (the two
directions' weights are averaged) the contact fraction's error from them is ``sum_i delta_i h^2``.  Neighbouring
rows cross one edge at nearby positions between points, so their offsets share a sign over stretches of the edge
and add up rather than cancel: the bound is the sum, ``LINE_STEP N h^2`` for ``|delta_i| <= LINE_STEP``
(:func:`crossing_share`; ``K0 = k_n |S| / |T|`` by ``k_n`` times that, ``g_n = k_n mean(1_S g0)`` by ``k_n
LINE_STEP h^2`` times the sum of ``g0`` at the crossings' last contact points).  The offsets' size and sign jump
between grids, so the differences may vanish while this error stalls (the bisinusoid of ``docs/benchmarks.md``,
spectral effectivity, whose contact fraction at its lightest load errs by about the same on 256 and 512 points per
direction while the difference between them is a sixth of it): it is a floor under the estimate of each quantity
on the edges (:func:`island_floor`, form :data:`LINE`), which then need not hold the differences' tail to first
order (:mod:`~ngcontact.cell.spectral.refinement`).  :data:`LINE_STEP` is calibrated on that bisinusoid (the
mean ``|delta|`` its contact fraction's errors on 256 to 1024 points imply, against 4096 points, is at most 0.04
of a step) and checked on random maps of 64 x 64 samples (``scripts/random_map_accuracy.py``).

**A penalty's edges** (``contact.enforcement = "penalty"``) hold the floor of the penalty's zone, argued in
:mod:`~ngcontact.cell.spectral.penalty_zone`.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from scipy import ndimage

from ngcontact.cell.cell_solution import COEFFICIENT, scale
from ngcontact.cell.spectral.grid_measures import (FITTED_STEP, LOCATED_STEP, coefficients, edge_offset, edge_stiffness,
                                                   kinks)
from ngcontact.cell.spectral.penalty_zone import INSIDE, INSIDE_STEP, PENALTY_LOG, PENALTY_ZONE, penalty_zone_share
from ngcontact.cell.spectral.smooth_edges import SMOOTH, smooth_remark, smooth_share

#: the fewest collocation points of a resolved 2D contact island (module docstring)
ISLAND_POINTS = 4
#: the form of an estimate raised to the floor of the unresolved islands, as the report names it
ISLAND = "island"
#: the form of an estimate raised to the floor of the edges beside a kink of the map (module docstring)
KINK = "kink"
#: the factor on the root-sum-square of a load's edges' shares that bounds their error together (module docstring)
QUADRATURE = 2.0
#: with a penalty, the share of the stiffness's change with each edge a step out that bounds its error (same)
STIFFNESS_STEP = 0.5
#: the form of an estimate raised to the floor of the 3D line's crossings of the contact edges (module docstring)
LINE = "line"
#: the share of a step that bounds the mean offset of the 3D line's located crossings (module docstring)
LINE_STEP = 0.05


def on_edges(name: str) -> bool:
    """Whether a headline quantity rests on the contact edges located between points in 2D: the contact
    fraction and the coefficients of eq. 34 on the real contact set (:mod:`~ngcontact.cell.spectral.grid_measures`)."""
    return name == "contact_fraction" or name.startswith(COEFFICIENT)


def fitted_run(history: list[dict[str, Any]], k: int) -> int:
    """The levels at the end of ``history`` on which every edge of load ``k`` is located by the quartic
    (:func:`~ngcontact.cell.spectral.grid_measures.edges_fitted`), or, with a penalty, by the line on points
    within its length (:func:`penalty_zone_share`: ``inside``; module docstring); the last level's kind
    only, 0 where it is neither."""
    kinds = [locator_kind(entry, k) for entry in history]
    run = 0
    for kind in reversed(kinds):
        if kind is None or kind != kinds[-1]:
            break
        run += 1
    return run


def stall_floored(entry: dict[str, Any], k: int) -> bool:
    """Whether load ``k``'s 2D located edges on the level ``entry`` hold a floor against their stall: a share of a
    map with kinks' edges or of a smooth map's (:mod:`~ngcontact.cell.spectral.smooth_edges`)."""
    held = entry.get("islands", [{}] * (k + 1))[k]
    return bool(held.get("kinks", {}).get("share") or held.get("smooth", {}).get("share"))


def locator_kind(entry: dict[str, Any], k: int) -> str | None:
    """How a level located the edges of load ``k``: ``"quartic"``, ``"inside"`` (a penalty's edges, all by the
    line on points within its length) or ``None`` (the line elsewhere)."""
    if entry.get("edges_fitted", [False] * (k + 1))[k]:
        return "quartic"
    zone = entry.get("islands", [{}] * (k + 1))[k].get("penalty", {})
    return INSIDE if zone.get("inside") else None


def resolved_run(history: list[dict[str, Any]], k: int) -> int:
    """The levels at the end of ``history`` on which load ``k`` has no contact island of fewer than
    :data:`ISLAND_POINTS` points (3D: across; :func:`unresolved_share`, recorded per level; a level without that
    record counts as resolved)."""
    run = 0
    for entry in reversed(history):
        if entry.get("islands", [{}] * (k + 1))[k].get("islands", 0):
            break
        run += 1
    return run


def locator_changing(history: list[dict[str, Any]], min_levels: int) -> bool:
    """Whether some load's edges came to be located by the quartic fewer than ``min_levels`` levels ago:
    its fitted levels then show fewer than the two ratios of differences that decide between Richardson and
    the guarded bound (:mod:`~ngcontact.cell.spectral.refinement`); not a penalty's line within its length, whose
    levels take the guarded bound on either window (module docstring)."""
    loads = [k for k in range(len(history[-1]["headline"])) if locator_kind(history[-1], k) != INSIDE]
    return any(0 < run < min(min_levels, len(history)) for run in (fitted_run(history, k) for k in loads))


def islands(on: np.ndarray) -> list[tuple[int, int]]:
    """The runs of ``True`` of a periodic 1D mask as ``(first point, points)``; none where it is all
    ``True`` or all ``False``."""
    if on.all() or not on.any():
        return []
    first = np.flatnonzero(on & ~np.roll(on, 1))
    last = np.flatnonzero(on & ~np.roll(on, -1))
    last = np.roll(last, -1) if last[0] < first[0] else last      # the run that wraps ends after the others
    return [(int(a), int((b - a) % on.size) + 1) for a, b in zip(first, last)]


def periodic_labels(on: np.ndarray) -> tuple[np.ndarray, int]:
    """The islands of a periodic 2D mask (4-connected, across the period too) as a label ``1..n`` per point
    (0 where open) and their number ``n``; none where it is all ``True`` or all ``False``."""
    if on.all() or not on.any():
        return np.zeros(on.shape, int), 0
    labels, n = ndimage.label(on)
    parent = np.arange(n + 1)

    def root(i: int) -> int:
        while parent[i] != i:
            i = parent[i]
        return i
    for a, b in ((labels[0, :], labels[-1, :]), (labels[:, 0], labels[:, -1])):     # the opposite sides meet
        for i, j in zip(a[(a > 0) & (b > 0)], b[(a > 0) & (b > 0)]):
            ri, rj = root(int(i)), root(int(j))
            parent[max(ri, rj)] = min(ri, rj)
    _, compact = np.unique([root(i) for i in range(n + 1)], return_inverse=True)
    return compact[labels], int(compact.max())


def narrow_islands(on: np.ndarray) -> tuple[np.ndarray, int, int]:
    """The points of the islands of a periodic 2D mask fewer than :data:`ISLAND_POINTS` points across in
    either direction of the grid (no run of that many along it, module docstring), how many such islands,
    and the smallest island's points (0 without islands)."""
    labels, n = periodic_labels(on)
    if n == 0:
        return np.zeros(on.shape, bool), 0, 0
    wide = np.ones(n + 1, bool)
    for axis in (0, 1):
        run = on.copy()
        for step in range(1, ISLAND_POINTS):
            run &= np.roll(on, -step, axis=axis)
        wide &= np.bincount(labels[run], minlength=n + 1) > 0
    narrow = ~wide
    narrow[0] = False
    return narrow[labels], int(narrow.sum()), int(np.bincount(labels.ravel())[1:].min())


def kink_share(cell, p: np.ndarray, gap: np.ndarray) -> dict[str, Any]:
    """The share of each quantity on the edges held by the 2D contact edges of a pressure ``p`` (``gap`` the
    deformed gap the edges are located on) that lie within one grid step of a kink of the cell's gap ``g0``
    (:func:`kinks`): one step per such edge, ``g_n``'s at the largest ``g0`` within a step of the edge; a notch
    (an open run of fewer than :data:`ISLAND_POINTS` points both of whose edges are such) ``max(w, s - w)`` steps,
    its located width ``w`` against the ``s`` steps between its contact points (module docstring); :data:`LOCATED_STEP`
    (:data:`FITTED_STEP` by the quartic) per other edge of a map with kinks; :func:`quadrature`.  ``{"edges": at a kink,
    "notches": how many, "located": how many others, "share": {headline name: absolute share}}``; no share
    without kinks."""
    steps, kinked_edges, notches = edge_steps(cell, p, gap)
    if not steps:
        return {"edges": 0, "notches": 0, "share": {}}
    n = p.size
    total = quadrature([s for s, _, _ in steps.values()], [notch for _, _, notch in steps.values()])
    heights = quadrature([s * h for s, h, _ in steps.values()], [notch for _, _, notch in steps.values()])
    return {"edges": kinked_edges + 2 * notches, "notches": notches, "located": len(steps) - kinked_edges - 2 * notches,
            "share": {"contact_fraction": total / n, COEFFICIENT + "k_n": cell.k_n * total / n,
                      COEFFICIENT + "g_n": cell.k_n * heights / n}}


def quadrature(terms: list[float], notch: list[bool]) -> float:
    """The bound of a load's edges of shares ``terms`` (module docstring): :data:`QUADRATURE` times their root-sum-
    square where below their sum; a notch's share, listed on each of its two edges (``notch``), counts once."""
    weighted = [(t, 0.5 if at_notch else 1.0) for t, at_notch in zip(terms, notch)]
    return float(min(sum(w * t for t, w in weighted), QUADRATURE * np.sqrt(sum(w * t * t for t, w in weighted))))


def edge_steps(cell, p: np.ndarray, gap: np.ndarray) -> tuple[dict[tuple[int, int], tuple[float, float, bool]],
                                                              int, int]:
    """The steps of its error that bound each located 2D edge of a map with kinks (:func:`kink_share`), as
    ``{(last contact point, step): (steps, largest g0 within a step, of a notch)}`` (a notch's steps on each of its
    two edges), with how many edges lie at a kink outside notches and how many notches; none without kinks."""
    on, n = p > 0, p.size
    at = np.flatnonzero(kinks(cell.g0))
    if cell.dim != 2 or on.all() or not on.any() or at.size == 0:
        return {}, 0, 0
    root = np.maximum(gap, 0.0) ** (2.0 / 3.0)
    edges = {}                          # (last contact point, step): (offset, kinked, largest g0, by the quartic)
    for step in (1, -1):
        for i in (int(j) for j in np.flatnonzero(on & ~np.roll(on, -step))):
            t, fitted = edge_offset(root, on, i, step, at)
            x = i + step * t
            reach = np.arange(int(np.floor(x - 1.0)), int(np.ceil(x + 1.0)) + 1) % n   # the steps it may move across
            edges[i, step] = (t, bool(np.min(np.abs((at - x + n / 2) % n - n / 2)) <= 1.0), float(cell.g0[reach].max()),
                              fitted and getattr(cell, "enforcement", "exact") == "exact")
    steps: dict[tuple[int, int], tuple[float, float, bool]] = {}
    notches = 0
    for first, w in islands(~on):                        # a notch: both edges of a short open run at a kink
        right, left = ((first - 1) % n, 1), ((first + w) % n, -1)
        if w < ISLAND_POINTS and edges[right][1] and edges[left][1]:
            located = w + 1 - edges[right][0] - edges[left][0]
            notch = (max(located, w + 1 - located), max(edges[right][2], edges[left][2]), True)
            steps[right] = steps[left] = notch
            del edges[right], edges[left]
            notches += 1
    steps.update({key: (1.0 if kinked else FITTED_STEP if fitted else LOCATED_STEP, height, False)
                  for key, (_, kinked, height, fitted) in edges.items()})
    return steps, sum(1 for _, kinked, _, _ in edges.values() if kinked), notches


def stiffness_share(cell, p: np.ndarray, gap: np.ndarray) -> float:
    """The share of the 2D normal effective stiffness held by the located edges of a map with kinks: per edge its
    steps of :func:`edge_steps` times the stiffness's change with that edge a step out (:func:`~ngcontact.cell.
    spectral.grid_measures.edge_stiffness`), by :func:`quadrature`; with a penalty, whose stiffness is the collocated
    set's, :data:`STIFFNESS_STEP` of a step per edge, summed (module docstring); 0 without kinks."""
    steps = edge_steps(cell, p, gap)[0]
    if not steps:
        return 0.0
    shares = edge_stiffness(cell, p > 0, gap)["edges"]
    if cell.enforcement != "exact":
        return sum(STIFFNESS_STEP * abs(shares[key][1]) for key in steps if key in shares)
    return quadrature([s * abs(shares[key][1]) for key, (s, _, _) in steps.items() if key in shares],
                      [False] * len(steps))


def crossing_share(cell, p: np.ndarray) -> dict[str, Any]:
    """The share of each quantity on the edges held by the 3D line's located crossings of the contact edges of a
    pressure ``p`` along the grid's rows and columns (module docstring): ``{"crossings": per direction, "share":
    {headline name: absolute share}}``, ``LINE_STEP`` of a step per crossing, summed; no share in 2D."""
    on = p > 0
    if cell.dim != 3 or on.all() or not on.any():
        return {"crossings": 0, "share": {}}
    count, heights = 0.0, 0.0
    for axis in (0, 1):
        for step in (1, -1):
            last = on & ~np.roll(on, -step, axis)             # last contact point before an edge
            count += 0.5 * last.sum()
            heights += 0.5 * float(cell.g0[last].sum())
    share = LINE_STEP / p.size
    return {"crossings": int(round(count)), "share": {"contact_fraction": share * count,
                                                      COEFFICIENT + "k_n": cell.k_n * share * count,
                                                      COEFFICIENT + "g_n": cell.k_n * share * heights}}


def unresolved_share(cell, p: np.ndarray, gap: np.ndarray | None = None) -> dict[str, Any]:
    """The share of each quantity on the edges held by the islands of fewer than :data:`ISLAND_POINTS`
    points of a pressure ``p`` (in 3D: points across, :func:`narrow_islands`; module docstring):
    ``{"points": the smallest island's points (0 without islands), "islands": how many are unresolved,
    "share": {headline name: absolute share}, "kinks": the share of the edges beside a kink of the map}``
    (:func:`kink_share`, 2D with the deformed ``gap``); no share without such islands or edges."""
    mask = np.zeros(p.shape, bool)
    if cell.dim == 2:
        runs = islands(p > 0)
        small = [(a, w) for a, w in runs if w < ISLAND_POINTS]
        for a, w in small:
            mask[np.arange(a - 1, a + w + 1) % p.size] = True       # the island and an open point each side
        count, points = len(small), min((w for _, w in runs), default=0)
    else:
        narrow, count, points = narrow_islands(p > 0)
        mask = narrow.copy()
        for axis in (0, 1):                                         # the island and its open 4-neighbours
            mask |= np.roll(narrow, 1, axis=axis) | np.roll(narrow, -1, axis=axis)
    out: dict[str, Any] = {"points": points, "islands": count, "share": {},
                           "kinks": kink_share(cell, p, gap) if gap is not None else {"edges": 0, "notches": 0,
                                                                                      "share": {}}}
    out["penalty"] = penalty_zone_share(cell, p, gap) if gap is not None else {"edges": 0, "share": {}, "inside": False}
    if cell.dim == 3 and getattr(cell, "enforcement", "exact") == "exact":
        out["line"] = crossing_share(cell, p)
    elif gap is not None:
        out["smooth"] = smooth_share(cell, p, gap)
    if out["kinks"]["share"] and gap is not None:
        out["kinks"]["share"]["normal_stiffness"] = stiffness_share(cell, p, gap)
    if count:
        whole = coefficients(cell, mask).as_dict()
        out["share"] = {"contact_fraction": whole["contact_fraction"], COEFFICIENT + "k_n": whole["k_n"],
                        COEFFICIENT + "g_n": whole["g_n"]}
    return out


def island_floor(history: list[dict[str, Any]], estimates: list[dict[str, float]], forms: list[dict[str, str]]
                 ) -> list[str]:
    """Raise in place each estimate of a quantity on the edges (per load, of the last level of ``history``;
    its form with it) to the share of the load's unresolved islands in its measure where that is larger
    (module docstring).  Returns a remark per load raised."""
    last = history[-1]
    remarks = []
    for k, (per_load, unresolved) in enumerate(zip(estimates, last.get("islands", []))):
        for form, shares in ((ISLAND, unresolved["share"]), (KINK, unresolved.get("kinks", {}).get("share", {})),
                             (PENALTY_ZONE, unresolved.get("penalty", {}).get("share", {})),
                             (LINE, unresolved.get("line", {}).get("share", {})),
                             (SMOOTH, unresolved.get("smooth", {}).get("share", {}))):
            raised = []
            for name, share in shares.items():
                if name in per_load and (floor := share / scale(name, last["headline"][k], last["whole_surface"])
                                         ) > per_load[name]:
                    per_load[name], forms[k][name] = floor, form
                    raised.append(name)
            if raised and form == ISLAND:
                remarks.append(f"load {k}: {unresolved['islands']} contact island(s) of fewer than {ISLAND_POINTS} "
                               f"points (in 3D across; the smallest island {unresolved['points']} point(s)) on grid "
                               f"{last['grid']}: {', '.join(raised)} bounded by their share, one step beyond each "
                               "edge")
            elif raised and form == LINE:
                remarks.append(f"load {k}: {unresolved['line']['crossings']} crossings of the contact edges per "
                               f"direction on grid {last['grid']}: {', '.join(raised)} bounded by {LINE_STEP:g} of a "
                               "step per crossing")
            elif raised and form == SMOOTH:
                remarks.append(f"load {k}: " + smooth_remark(unresolved["smooth"], last["grid"], raised))
            elif raised and form == PENALTY_ZONE:
                zone = unresolved["penalty"]
                remarks.append(f"load {k}: {zone['edges']} contact edge(s) of the penalty located on grid "
                               f"{last['grid']} on points beyond its length E*/k_n: {', '.join(raised)} bounded by "
                               f"{zone['bound']:.3g} per edge ({PENALTY_LOG:g} E*/k_n ln(period k_n / E*)), "
                               f"{INSIDE_STEP:g} of a step per edge located within it")
            elif raised:
                kinked = unresolved["kinks"]
                remarks.append(f"load {k}: {kinked['edges']} contact edge(s) within a step of a kink of the map on "
                               f"grid {last['grid']} ({kinked['notches']} notch(es) of fewer than {ISLAND_POINTS} open "
                               f"points at one) and {kinked.get('located', 0)} other(s): {', '.join(raised)} bounded "
                               f"by a step at each edge at a kink, {LOCATED_STEP:g} ({FITTED_STEP:g} by the quartic) "
                               "of a step at each other, a notch by its width's bound, the stiffness by as many steps "
                               "of its change with each edge a step out, in quadrature")
    return remarks
