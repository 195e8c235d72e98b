"""The error of a graded FE cell's answer: the orders' tail and the grading's (:mod:`ngcontact.cell.fe.edge_grading`).

The answer of :func:`~ngcontact.cell.fe.edge_grading.solve_to_tolerance` is the highest of successive orders
on the finest mesh graded towards the contact edges.  Its error has two parts, each bounded by a tail:

* the smooth bulk's, from the orders on that mesh (:data:`ORDER_RATE`, the observed-rate tail of
  :mod:`ngcontact.cell.fe.observed_rate`);
* the edges', which the orders on one mesh do not see: an edge inside its element converges algebraically and
  not monotonically in the order (on Westergaard and Hertz the last order is often worse than the one before).

The grading's tail.  Near an edge the gap opens like ``s^(3/2)`` with the
distance ``s`` (Westergaard, Hertz); an element of size ``h`` containing
the edge has a gap error of order ``h^(3/2)``, which moves the root by
order ``h``: the edge position converges at first order in the size of the
element holding it.  A grading step adds ``LEVELS_PER_STEP`` levels of
ratio ``RATIO`` around the edges the previous level found, so the element
holding the edge shrinks by ``RATIO^LEVELS_PER_STEP`` (1/16) per step at
least while the previous edge lies within the finest element of the new
mesh, and the error of an edge contracts by ``rho = 1/16`` per step.  The
error of the contact fraction is at most the measure of the symmetric
difference ``|A - A*|`` of the final contact set ``A`` and the exact one
``A*`` over the period (for one interval per patch, the sum of its ends'
errors).  With ``A'`` the contact set of the level whose edges the mesh was
graded towards, ``|A - A*| <= rho |A' - A*|`` and the triangle inequality
of the symmetric difference give

    |A - A*| <= rho / (1 - rho) |A - A'|,

the grading's tail (:func:`grading_tail`; the move ``|A - A'|`` of
:func:`set_move`, at least the last grading step's change).  Measured as
sets, islands of a flickering contact set near an edge (a stiff penalty
on a coarse level) count by their lengths, not by their ends.  Where three
grading steps at one order show a slower contraction, their last two
ratios agreeing within a factor 2 (:data:`~ngcontact.cell.fe.observed_rate.DISAGREE`), the larger
observed ratio is taken instead: the theory's ``1/16`` is the fastest
contraction assumed, never a faster one observed (:data:`GRADING_RATE`);
a single ratio, or two that disagree, is pre-asymptotic (on Westergaard
with ``k_n = 1e6 E`` the steps' ratios 0.42 and 0.057) and
leaves the theory's.  The move is that of the final order's contact set,
not the graded order's: it holds the previous level's whole error, and
the final order's own error only adds
to it.  The first order is a rate, not a bound with a known constant: the
contraction ``1/16`` per step is its claim, held against Hertz's periodic
row and Westergaard, exact and penalty, at tolerances ``1e-2`` and ``1e-3``
(``tests/cell/test_hertz_effectivity.py``, ``tests/cell/test_edge_grading.py``: effectivity between 1 and 10).

Where the loop stopped before an order was raised (a size bound), the last grading step's change stands
alone, with the tail of a ratio 1/2 (:data:`GRADING_TAIL`).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ngcontact.cell.fe.observed_rate import Convergence

#: ratio of consecutive element sizes towards an edge
RATIO = 0.25
#: grading levels added per step
LEVELS_PER_STEP = 2
#: how the answers of successive orders on one graded mesh converge (:mod:`ngcontact.cell.fe.observed_rate`):
#: geometrically (the edges are isolated in elements ``h0 r^L``, the bulk is smooth), the contraction observed
#: from order to order, three times the tail because that contraction grows slowly with the order
ORDER_RATE = Convergence(floor=0.0, assumed=0.5, cap=0.7, safety=3.0)
#: the contact fraction's error after a grading step over its change where no order raise has checked the
#: level (a size bound stopped the loop): the geometric tail at a ratio 1/2 per step, first order as a halved
#: mesh (a penalty's edge layer of width ~E/k_n is resolved only once the elements are smaller: no faster is
#: assumed without the orders' check)
GRADING_TAIL = 1.0
#: the contraction per grading step of an edge's error (module docstring, the grading's tail): first order in
#: the size of the element holding the edge, which a step divides by ``RATIO ** LEVELS_PER_STEP``; an observed
#: slower contraction is taken instead, up to this cap (a step that does not contract is taken as this)
GRADING_RATE = RATIO ** LEVELS_PER_STEP
GRADING_CAP = 0.7


def order_estimate(orders: list[dict[str, Any]], grading_change: float | None = None
                   ) -> tuple[dict[str, float], str]:
    """The error of the last of ``orders`` (entries of successive orders on one mesh), per quantity, by the
    observed rate of :data:`ORDER_RATE`; the contact fraction's at least the grading's tail
    (:func:`grading_tail`); and its remark."""
    out, notes = {}, []
    if len(orders) < 2:        # stopped before an order was raised: the last grading step's changes
        last = orders[-1]
        change = last["fraction_change"] if grading_change is None else grading_change
        unknown = float("inf")
        return ({"contact_fraction": unknown if change is None else GRADING_TAIL * change,
                 "mean_closure": unknown if last["closure_change"] is None else last["closure_change"]},
                "stopped before an order was raised: the last grading step's changes")
    for name, relative in (("contact_fraction", False), ("mean_closure", True)):
        out[name], note = ORDER_RATE.tail([e[name] for e in orders], relative)
        if note:
            notes.append(f"{name}: {note}")
    grading, note = grading_tail(orders, grading_change)
    if grading > out["contact_fraction"]:
        out["contact_fraction"] = grading
        notes.append(f"contact_fraction: {note}")
    return out, "; ".join(notes)


def grading_tail(orders: list[dict[str, Any]], grading_change: float | None) -> tuple[float, str]:
    """The error of the last order's contact fraction left by the edges' resolution, and how it was found
    (module docstring, the grading's tail): ``rho / (1 - rho)`` times the final contact set's move from that
    of the level the mesh was graded towards (at least the last grading step's change), ``rho`` the larger of
    :data:`GRADING_RATE` and the grading steps' agreed observed ratio, at most :data:`GRADING_CAP`."""
    move = orders[-1].get("set_move")
    size = max(move or 0.0, grading_change or 0.0)
    if size == 0.0:
        return 0.0, ""
    observed = orders[0].get("grading_ratio")
    rate = min(max(GRADING_RATE, observed if observed is not None else 0.0), GRADING_CAP)
    how = (f"observed grading ratio {observed:.2g}" if observed is not None and observed > GRADING_RATE
           else f"grading ratio {GRADING_RATE:g}")
    return rate / (1.0 - rate) * size, (f"the grading's tail, its contact set moved by {size:.2g} since the "
                                        f"level graded towards, {how}")


def merged(intervals) -> np.ndarray:
    """``(n, 2)`` disjoint intervals, sorted, with those that touch joined."""
    out: list[list[float]] = []
    for lo, hi in sorted((min(a, b), max(a, b)) for a, b in intervals):
        if out and lo <= out[-1][1] + 1e-14:
            out[-1][1] = max(out[-1][1], hi)
        else:
            out.append([lo, hi])
    return np.asarray(out, dtype=float).reshape(-1, 2)


def set_move(contact, towards, period: float) -> float | None:
    """The measure of the symmetric difference of the contact sets ``contact`` and ``towards`` (disjoint
    intervals of one period, :func:`merged`), over the period (``None`` without ``towards``).  Where both are
    intervals whose ends pair up it is the sum of the ends' moves; islands (a flickering contact set near an
    edge) count by their lengths, not by their number of ends."""
    if towards is None:
        return None
    a, b = merged(contact), merged(towards)

    def length(x):
        return float(np.sum(x[:, 1] - x[:, 0]))

    common = np.minimum(a[:, None, 1], b[None, :, 1]) - np.maximum(a[:, None, 0], b[None, :, 0])
    return (length(a) + length(b) - 2.0 * float(np.sum(np.maximum(common, 0.0)))) / period
