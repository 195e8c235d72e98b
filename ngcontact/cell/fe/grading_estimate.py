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
alone, with the tail of a ratio 1/2 (:data:`GRADING_TAIL`), for every headline quantity.

The other headline quantities.  The normal effective stiffness and the coefficients of eq. 34 on the real
contact set are estimated over the same orders, in their measure (:func:`~ngcontact.cell.cell_solution.measure`),
by the same observed-rate tail (:func:`order_estimate`), and the refinement holds every one of them to the
tolerance, as it holds the fraction and the closure: where one misses it, the knob that reduces its larger part
is turned (:func:`edges_miss`: a grading step where its edges' part below misses, else one order more), and a
stated tolerance still missed when the steps and orders are spent ends the run with the figures
(:func:`out_of_reach`, exit 3).  Three parts the orders do not show are added as floors:

* **the set's share** (:func:`set_share`). In 2D a coefficient integrates ``k_n`` (``k_n``) or ``k_n g0``
  (``g_n``) over the very pieces whose measure is the contact fraction
  (:func:`~ngcontact.cell.fe.measures.real_contact_coefficients`), so its error from the contact set is that
  of the set: ``k_n`` moves by ``k_n`` times the fraction's error (on a flat cell ``k_n`` *is* ``k_n`` times
  the fraction), ``g_n`` by ``k_n g_e`` times it, ``g_e`` the largest initial gap at the ends of the elements
  holding the edges (the gap where the edges may lie).  With the fraction's estimate ``E_f`` (absolute) the
  shares are ``k_n E_f`` and ``k_n g_e E_f``: the fraction's own error, weighted as eq. 34 weighs the set's
  ends.  At a light load ``g_n`` is small (it grows like the cube of the patch's width) while ``g_e`` is not,
  so on Westergaard's sinusoid its relative share is ``g_e / (h (f - sin(pi f) / pi))`` times the fraction's
  error, 21 at ``p/p* = 0.05``: the quantity that keeps a light load's grading going.  Exact contact's
  stiffness is that of the contact set held closed, the set of its closed nodes interpolated to the edges
  (:func:`~ngcontact.cell.fe.stiffness.edge_interpolation`): it moves with the set's measure as ``k_n`` does,
  and takes the share of ``k_n`` relative to ``k_n`` as its floor, or the edges' record where larger.  A
  penalty's stiffness takes none (:func:`penalty_stiffness`): ``[s]_+`` vanishes at its edges, so its tangent
  is the exact derivative of the discrete response to the load (``S = dp/dU``,
  :func:`~ngcontact.cell.fe.stiffness.edge_correction`).  The far-face jump is the derivative in the load of
  the minimum energy, ``U = -dPi*/dp``, so ``1/S_h - 1/S = -d^2 (Pi*_h - Pi*) / dp^2``, the load's second
  derivative of the energy's error, which is quadratic in the solution's error: the stiffness's error is a
  product of the solution's error and of its changes with the load, which its own sequences over the orders
  and the grading show, not first order in the edges' position as the fraction's is (a penalty's edge moves
  by the penetration's error over the penetration's slope there, ``p' / k_n``, small in its thin zone).
  Its two parts then add: the orders' tail bounds the answer's distance from the final mesh's limit, the
  grading's tail of its own change that limit's distance from the model's (the triangle inequality; the
  other quantities' set share, taken at the fraction's whole estimate, holds both parts already);
* **its grading's tail** (:func:`quantity_grading_tail`): the quantity's own change over the last grading
  step, at the grading's rate;
* **an alternating last order** (:func:`alternating`): where the last two changes over the orders alternate
  in sign the sequence swings about its limit (an edge inside its element: the last order may be worse than
  the one before), and the last change bounds the error, as an alternating series' last term does.

The orders' tail itself, of every quantity, is that of an alternating series where the last two changes
alternate (:func:`orders_tail`): the remainder of a series whose terms alternate and contract by ``rho`` is
at most its first term, ``rho |d_k|``, not the monotone ``rho / (1 - rho) |d_k|``, which on Hertz's patch with
exact contact (``tests/cell/test_hertz_effectivity.py``) bounded a swinging fraction ten times over.

Against Westergaard's closed forms (``2a``, ``k_n 2a``, ``k_n h (2a - sin(2 pi a) / pi)``) and the spectral
cell's stiffness of the same layers on 2^16 to 2^18 points (Richardson's limit), exact contact, at ``p/p* =
0.5`` and tolerance ``1e-2``, the estimates bound the errors (``tests/cell/test_graded_headline_estimates.py``);
on the shipped ``westergaard_graded.toml`` at ``1e-4`` (penalty ``k_n = 1e6``) against the same model graded
three levels and two orders finer (``scripts/graded_effectivity.py``), those of the fraction, ``k_n`` and ``g_n``
lie between 1 and 10 at ``p/p* = 0.05`` and ``0.5``, the stiffness's at 0.5
(``tests/cell/test_graded_finer_reference.py``).  Its penalty stiffness, by the sum of its tails, bounds its
error at both loads, within 10 times at 0.5; at 0.05 its error lies far below the set's share the estimate took
before, and below its own grading's tail too (the section ``graded_effectivity`` of ``docs/benchmarks.md``).
Sharper rules tried on that section's recorded levels (the larger of the stiffness's two tails instead of their
sum, its grading's tail scaled by the orders' contraction, exact contact's set share alone, the orders' tail
without its safety factor) each take some estimate there below its error
(``tests/cell/test_graded_recorded_levels.py``).
"""
from __future__ import annotations

from typing import Any

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_solution import COEFFICIENT, measure, scale
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
    """The error of the last of ``orders`` (entries of successive orders on one mesh), per headline quantity in
    its measure (:func:`~ngcontact.cell.cell_solution.measure`), by the observed rate of :data:`ORDER_RATE`; the
    contact fraction's at least the grading's tail (:func:`grading_tail`), every other quantity's at least its
    own (:func:`quantity_grading_tail`); and its remark (module docstring).  A quantity missing on some order,
    or zero on all (a coefficient the flat frictionless cell makes zero), is not estimated."""
    out, notes = {}, []
    last = orders[-1].get("headline") or {"contact_fraction": orders[-1]["contact_fraction"],
                                           "mean_closure": orders[-1]["mean_closure"]}
    if len(orders) < 2:        # stopped before an order was raised: the last grading step's changes
        entry = orders[-1]
        change = entry["fraction_change"] if grading_change is None else grading_change
        unknown = float("inf")
        out = {"contact_fraction": unknown if change is None else GRADING_TAIL * change,
               "mean_closure": unknown if entry["closure_change"] is None else entry["closure_change"]}
        for name in (n for n in last if n not in out and any([last[n]])):
            moved = (entry.get("changes") or {}).get(name)
            out[name] = unknown if moved is None else GRADING_TAIL * moved / scale(name, last)
        return out, "stopped before an order was raised: the last grading step's changes"
    for name in last:
        values = [e.get("headline", {}).get(name, e.get(name)) for e in orders]
        if None in values or not any(values):
            continue
        out[name], note = orders_tail(values, scale(name, last))
        if note:
            notes.append(f"{name}: {note}")
    grading, note = grading_tail(orders, grading_change)
    if grading > out["contact_fraction"]:
        out["contact_fraction"] = grading
        notes.append(f"contact_fraction: {note}")
    for name in (n for n in out if n not in ("contact_fraction", "mean_closure")):
        values = [e["headline"][name] for e in orders]
        swing = alternating(values) / scale(name, last)
        if swing > out[name]:
            out[name] = swing
            notes.append(f"{name}: the last order's change (its changes alternate in sign)")
        if penalty_stiffness(orders, name) and (tail := quantity_grading_tail(orders, name, scale(name, last))):
            out[name] += tail                       # the two parts of its error add (module docstring)
            notes.append(f"{name}: plus the grading's tail of its own change (a penalty's stiffness)")
        own = edges_part(orders, name, out["contact_fraction"])
        if own[0] > out[name]:
            out[name] = own[0]
            notes.append(f"{name}: {own[1]}")
    return out, "; ".join(notes)


def orders_tail(values: list[float], size: float) -> tuple[float, str]:
    """The orders' tail of :data:`ORDER_RATE` over ``values`` (successive orders), in the measure of ``size``;
    where the last two changes alternate in sign, the remainder of an alternating series contracting at the
    same ratio ``rho``: at most the first change omitted, ``rho |d_k|`` instead of the monotone ``rho / (1 -
    rho) |d_k|``, so the tail times ``1 - rho`` (module docstring; with the same safety factor 3 it still
    bounds a monotone remainder while ``rho <= 2/3``)."""
    tail, note = ORDER_RATE.tail(values, False, size)
    swing = alternating(values)
    if swing > 0.0 and tail > 0.0:
        x = tail * size / (ORDER_RATE.safety * swing)      # rho / (1 - rho) of the tail
        tail /= 1.0 + x
        note = "; ".join(n for n in (note, "alternating: the first change omitted bounds the rest") if n)
    return tail, note


def edges_miss(orders: list[dict[str, Any]], grading_change: float | None, estimate: dict[str, float],
               tolerance: float) -> bool:
    """Whether a quantity misses ``tolerance`` by its edges' part, which no order on this mesh reduces: the
    contact fraction's grading tail (:func:`grading_tail`), another quantity's :func:`edges_part` at the
    fraction's ``estimate``.  The graded refinement then grades further (and checks the new mesh by its own
    orders) instead of raising the order, which reduces the orders' part only (module docstring)."""
    if grading_tail(orders, grading_change)[0] > tolerance:
        return True
    return any(edges_part(orders, name, estimate["contact_fraction"])[0] > tolerance for name in estimate
               if name not in ("contact_fraction", "mean_closure"))


def out_of_reach(tolerance: float, estimate: dict[str, float], entry: dict[str, Any], steps: int, raises: int,
                 grading_change: float | None) -> str:
    """The figures of a stated ``tolerance`` the graded refinement could not meet: the largest ``estimate`` of
    the last level (``entry``) solved after ``steps`` grading steps and ``raises`` order raises, its mesh, and
    the contact fraction's changes between the last two grading levels (``grading_change``) and with the last
    order (module docstring)."""
    e, name = max((v, n) for n, v in estimate.items())

    def change(c: float | None) -> str:
        return "-" if c is None else format(c, ".3g")
    return (f"discretization.tolerance = {tolerance:g} not reached after {steps} grading steps and {raises} order "
            f"raises (smallest element {entry['smallest_element']:.3g}, order {entry['order']}, {entry['ndof']} "
            f"dofs): the largest estimate is {e:.3g} ({name}, {measure(name)}); the contact fraction's "
            f"{estimate['contact_fraction']:.3g}, the mean closure's {estimate['mean_closure']:.3g}; the contact "
            f"fraction changes by {change(grading_change)} between the last two grading levels and by "
            f"{change(entry['fraction_change'])} with the last order; loosen the tolerance or raise the order")


def alternating(values: list[float]) -> float:
    """Where the last two changes of ``values`` (successive orders) alternate in sign, the size of the last: the
    sequence then swings about its limit, which lies between the last two values while the swings shrink (the
    bound of an alternating series), so that ``|q_k - q| <= |q_k - q_(k-1)|``; else 0 (module docstring)."""
    if len(values) < 3:
        return 0.0
    d = [b - a for a, b in zip(values[-3:-1], values[-2:])]
    return abs(d[1]) if d[0] * d[1] < 0 else 0.0


def edges_part(orders: list[dict[str, Any]], name: str, fraction_error: float) -> tuple[float, str]:
    """The part of a headline quantity's error (other than the contact fraction and the mean closure) that
    the orders on one mesh do not reduce, in its measure, and what it is: the larger of its grading's tail
    (:func:`quantity_grading_tail`) and, for a coefficient on the real contact set, the set's share
    (:func:`set_share`) at the contact fraction's estimate ``fraction_error``; for the normal effective
    stiffness of exact contact, that of the contact set held closed, the set's share of ``k_n`` relative to
    ``k_n`` or the edges' record; a penalty's stiffness, its grading's tail alone (:func:`penalty_stiffness`,
    module docstring)."""
    last = orders[-1]["headline"]
    size = scale(name, last)
    tail, share = quantity_grading_tail(orders, name, size), set_share(orders[-1], name, fraction_error) / size
    if penalty_stiffness(orders, name):
        return tail, "the grading's tail of its own change (a penalty's stiffness: no set's share)"
    if name == "normal_stiffness" and last.get(COEFFICIENT + "k_n"):
        share = set_share(orders[-1], COEFFICIENT + "k_n", fraction_error) / abs(last[COEFFICIENT + "k_n"])
    edges = orders[-1].get("stiffness_edges")
    if name == "normal_stiffness" and edges:
        share = max(share, (edges["slope"] * fraction_error + edges["spread"]) / size)
    if share >= tail:
        return share, "the contact set's share (the contact fraction's estimate, weighted as eq. 34 weighs it)"
    return tail, "the grading's tail of its own change"


def penalty_stiffness(orders: list[dict[str, Any]], name: str) -> bool:
    """Whether ``name`` is the normal effective stiffness of a penalty cell, the derivative of its discrete
    response, which takes no set's share and adds its grading's tail to its orders' (module docstring)."""
    return name == "normal_stiffness" and bool(orders[-1].get("penalty"))


def stiffness_edges(results: dict[str, Any]) -> dict[str, float] | None:
    """The record of exact contact's stiffness at its edges (2D, :func:`~ngcontact.cell.fe.stiffness.edge_record`:
    its change with the contact fraction and what one interpolation for several edges leaves), or ``None``."""
    K = results.get("effective_stiffness")
    return (K.get("edges") or None) if isinstance(K, dict) else None


def set_share(entry: dict[str, Any], name: str, fraction_error: float) -> float:
    """The absolute error a coefficient of eq. 34 takes from its real contact set, that of the contact fraction
    (module docstring): ``k_n E_f`` for ``k_n``, ``k_n g_e E_f`` for ``g_n``, ``E_f = fraction_error`` the
    fraction's (absolute) estimate and ``g_e`` the largest initial gap at the ends of the elements holding the
    contact edges; 0 for any other quantity, or without the record."""
    cells, k_n = entry.get("edge_cells"), entry.get("k_n")
    if not cells or not k_n or name not in (COEFFICIENT + "k_n", COEFFICIENT + "g_n"):
        return 0.0
    weight = 1.0 if name == COEFFICIENT + "k_n" else max(abs(g) for _, g in cells)
    return k_n * weight * fraction_error


def quantity_grading_tail(orders: list[dict[str, Any]], name: str, size: float) -> float:
    """The error a headline quantity other than the contact fraction and the mean closure has left from the
    edges' resolution (module docstring): the grading's tail ``rho / (1 - rho)`` of its change over the last
    grading step at the order graded, divided by ``size`` (its measure's scale), ``rho`` as
    :func:`grading_tail`'s; 0 where that change is not recorded."""
    moved = (orders[0].get("changes") or {}).get(name)
    if not moved:
        return 0.0
    rate = grading_rate(orders)
    return rate / (1.0 - rate) * moved / size


def grading_rate(orders: list[dict[str, Any]]) -> float:
    """The contraction per grading step of the edges' error: :data:`GRADING_RATE`, or the grading steps' agreed
    observed ratio where larger, at most :data:`GRADING_CAP` (module docstring)."""
    observed = orders[0].get("grading_ratio")
    return min(max(GRADING_RATE, observed if observed is not None else 0.0), GRADING_CAP)


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
    rate = grading_rate(orders)
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


def edge_cells(problem, edges) -> list[list[float]]:
    """Per contact edge the largest interface element touching it and the largest initial gap at those elements'
    ends, ``[size, gap]``: where the edge may lie and the gap there
    (:func:`set_share`); a cell without an initial gap (a flat patch) has gap 0 there."""
    rule = ng.IntegrationRule([(0.0,), (1.0,)], [0.0, 0.0])
    mips = problem.mesh.MapToAllElements(rule, problem.mesh.Boundaries("contact"))
    x = np.asarray(ng.x(mips)).reshape(-1, 2)
    g = np.zeros(x.shape) if problem.gap is None else np.asarray(problem.gap(mips), dtype=float).reshape(-1, 2)
    lo, hi = x.min(axis=1), x.max(axis=1)
    out = []
    for e in edges:
        near = (lo <= e + 1e-12) & (hi >= e - 1e-12)
        if not near.any():
            near = np.abs(0.5 * (lo + hi) - e) == np.min(np.abs(0.5 * (lo + hi) - e))
        out.append([float(np.max(hi[near] - lo[near])), float(np.max(g[near]))])
    return out
