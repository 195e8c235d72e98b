"""The forms of the spectral refinement's estimate, and the estimates that may be loose by much.

:mod:`~ngcontact.cell.spectral.refinement` estimates the error of each headline quantity of a load on the
reported grid ``k`` in one of nine forms, which the report names: Richardson's tail with the observed rate
(:data:`RICHARDSON`), the guarded geometric tail (:data:`GUARDED`), the estimate of a deferred grid plus the
last difference (:data:`CARRIED`), the share of contact islands too narrow for the grid
(:data:`~ngcontact.cell.spectral.contact_edges.ISLAND`), a step at each 2D edge within a step of a kink of
a map's piecewise-linear surface (:data:`~ngcontact.cell.spectral.contact_edges.KINK`), a share of a penalty's
length at each 2D edge located beyond it (:data:`~ngcontact.cell.spectral.penalty_zone.PENALTY_ZONE`), a share
of a step at each 3D crossing of an edge by a row or column (:data:`~ngcontact.cell.spectral.contact_edges.LINE`),
a share of each 2D edge of a map without kinks, the quartic's spread from its half window's or the line's
share of a step (:data:`~ngcontact.cell.spectral.smooth_edges.SMOOTH`), or in 2D the change on the same grid
sampled half a step over (:data:`~ngcontact.cell.spectral.grid_phase.PHASE`).
Each is a bound on its own argument; none is sharp where the error of grid ``k`` is far below the differences
that bound it.

The last two differences ``d_(k-1)``, ``d_k`` (``d_k = q_k - q_(k-1)``) say how large that error is in the
model every form rests on: where the levels beyond ``k`` contract as the last one did, by ``rho = |d_k| /
|d_(k-1)|`` (held to at most first order in the grid step, ``rho <= 1/2``: a slower last step is taken at
first order), the error ``e_k = sum_(j > k) d_j`` is the tail left by the last difference, ``|d_k| rho / (1 -
rho)`` (:func:`tail_left`). An estimate above :data:`LOOSE` times that tail (in the quantity's measure,
:func:`~ngcontact.cell.cell_solution.measure`) therefore rests on something else than the last step: an
earlier, larger difference (the guarded envelope: a first-order stretch before a faster regime, such as the 2D
edges' quartic once it locates them, or an error that crossed zero), the deferred grid's estimate carried
over, or a step at an edge beside a kink of the map (a bound while the edge may be pinned to the kink; an edge
located within a tenth of a step of its true place has an error more than :data:`LOOSE` times below it, and
unlike an island's stalled share the last difference then shows it). The error may then lie below the estimate
by more than :data:`LOOSE` times, and the estimate is flagged with its reason (:func:`loose_flags`), listed in
the report (:func:`loose_remarks`). The flag never lowers an estimate: a fast last step is often followed by a
first-order one (on Westergaard's sinusoid at a twentieth of its closing pressure the quartic's errors fall by
about 16 per doubling twice, then by 2), and an earlier difference bounds the error where the last one
vanished by coincidence (a stall, a symmetric cell). Richardson's form states its rate and holds it to first
order on purpose (the same sinusoid) and is not flagged by that tail. Nor is an unresolved island's share
(:data:`~ngcontact.cell.spectral.contact_edges.ISLAND`), nor a penalty's zone, nor a smooth map's edges (their
located edges' errors stall alike), nor the grid's phase (the level's own change half a step over, which no
difference between levels measures): such an island's error stalls while the differences
vanish (:mod:`~ngcontact.cell.spectral.contact_edges`), so the last difference measures neither its size nor
how far it lies below the share. The share exceeds that error by more than :data:`LOOSE` times only where the
island's located width happens to be right to a tenth of its points and one step beyond each edge, which, like
an error small by chance, no difference shows; the report names the island and its share instead.

**A change of regime within the window.**  The guarded envelope ``D = max_i |d_(k-i)| / 2^i`` carries each
earlier difference to level ``k`` at first order.  Where the last contraction ``c = |d_k| / |d_(k-1)|`` is at
least :data:`DISAGREE` times faster than the one before, ``c' = |d_(k-1)| / |d_(k-2)|`` (:func:`regime_changed`),
the sequence has left the regime of ``d_(k-2)``: either a faster one set in at level ``k - 1`` (the 2D edges'
quartic, an island resolved, the end of a pre-asymptotic stretch), and ``d_(k-2)`` is a difference of the
earlier regime, which the first-order envelope carries to level ``k`` above the error by the ratio of the two
regimes' contractions; or the last difference vanished by coincidence, and the error of level ``k`` is about
that of level ``k - 1``.  In both the bound needs only the levels since the change, ``k - 2`` to ``k``
(:func:`guarded_bound`):

    ``E = D rho / (1 - rho)``,  ``D = max(|d_k|, |d_(k-1)| min(SAFETY c', ENVELOPE))``,  ``rho = max(c, c')``
    held to ``[RATE_FLOOR, RATE_CAP]``.

``|d_(k-1)| c'`` is the last difference the regime before predicts; where the last one vanished, the error
of level ``k - 1`` it leaves is the tail ``|d_(k-1)| c' / (1 - c')``, at most ``SAFETY |d_(k-1)| c'`` for ``c'
<= 1/2`` (:data:`SAFETY` = 2: the stated safety factor), and never more than the first-order envelope's own
term ``|d_(k-1)| / 2``.  The tail beyond ``k`` still falls at the slower of the two contractions, as every
guarded rate does ("where two successive differences disagree in rate, the estimate says so and takes the
larger", issue 35): a tail at the faster one stopped a penalty cell's refinement a grid early, where its
quartic-located edges carry an error no difference shows.  So the estimate never exceeds the whole window's
envelope: it drops ``d_(k-2)``, and shrinks ``d_(k-1)`` faster than first order where the regime before
contracted by less than ``ENVELOPE / SAFETY``.  Its premise, that a vanished last difference leaves at most
what the regime before predicts, is what the oracles test (``docs/benchmarks.md``, the spectral
effectivity).  A zero difference is
a coincidence of equal values (a symmetric cell), not a contraction: the whole window's envelope bounds it.
The estimate from the scene's own grid and coarser ones (:mod:`~ngcontact.cell.spectral.coarser_grids`),
where a fast contraction of coarse grids may be a coincidence of roughness appearing level by level, keeps
the whole window's envelope.

Where the last two contractions disagree, the last at least :data:`DISAGREE` times slower than the one
before (``|d_k| / |d_(k-1)| >= 2 |d_(k-1)| / |d_(k-2)|``: their observed orders in the grid step differ by
one or more), every form takes the slower ("where two successive differences disagree in rate, the estimate
says so and takes the larger", issue 35).  The last difference is then large for the contraction before it:
it carries the error of level ``k - 1`` more than that of level ``k``, which may have fallen at the faster
contraction, as the mean closure of a random profile does on the whole (at about a quarter per level) while
single levels scatter about that rate.  So an estimate of any form above :data:`LOOSE` times the tail its
last difference leaves at the faster contraction, ``|d_k| rho' / (1 - rho')`` with ``rho' = |d_(k-1)| /
|d_(k-2)|`` (:func:`faster_contraction`), is flagged too, with both contractions: it says so.  An estimate
within :data:`LOOSE` times both tails may still exceed an error that is small by chance (one that crosses
zero on the reported grid, or a level's error that falls several times faster than its differences while
their two contractions agree), which no difference shows (``docs/benchmarks.md``, the spectral
effectivity).

**A slowing sequence on the quartic's own levels.**  Beyond Richardson's band (the two contractions apart by
:data:`AGREE` or more) a slowing sequence keeps the whole window's guarded bound, ``d_(k-2)`` carried at first
order: ``d_(k-1)`` may have vanished by coincidence, the error stalling over levels ``k - 2`` to ``k``.  On the
levels whose 2D edges the quartic located (``since`` in :func:`tail_estimate`; the located quantities' estimate on
the quartic's own levels, :mod:`~ngcontact.cell.spectral.refinement`) such a stall of the edges is the quartic's
own, of a window whose length the patch sets, and the floor of the edges' spread from their half window's bounds it
(:mod:`~ngcontact.cell.spectral.smooth_edges`, exact contact; on a map with kinks its steps per edge,
:mod:`~ngcontact.cell.spectral.contact_edges`; a load without either, a penalty's on a smooth map, keeps the whole
window: :func:`~ngcontact.cell.spectral.contact_edges.stall_floored`).  So there the slowing sequence, the last
contraction :data:`DISAGREE` times slower than the one before or more and at most :data:`RATE_CAP`, takes the
guarded bound on the levels since the fast contraction, ``max(|d_k|, ENVELOPE |d_(k-1)|) rho / (1 - rho)``, where
smaller: on Westergaard's sinusoid at light loads the whole window carried the line's last difference onto the
quartic's levels, far above their error (``docs/benchmarks.md``, the spectral effectivity).

**A slowing sequence within Richardson's band.**  Two contractions within :data:`AGREE` of each other take
Richardson's tail, and the last may still be :data:`DISAGREE` times slower than the one before (``2 c' <= c
< 3 c'``, :func:`slowed`): the two constants overlap there, and the sequence is slowing.  Its fast contraction
``c'`` ended at level ``k - 1``, where the difference ``d_(k-1)`` was small for the trend before it (an edge's
position between points, the scatter :data:`SPREAD` stands for, or a pre-asymptotic stretch ending), and the
slower one that follows need not stop at ``c``: the error of level ``k`` may stay near that of level ``k - 1``,
which the last difference then understates (a random profile's mean closure whose differences contracted by
0.057, then 0.16, had on that last grid an error of twice its last difference, beyond Richardson's first-order
tail times :data:`SPREAD`, and the next difference grew).  The error of level ``k - 1`` is what ``d_(k-1)``
leaves at first order, and the estimate takes the larger ("where two successive differences disagree in rate,
the estimate says so and takes the larger", issue 35): Richardson's tail, or the guarded bound on the levels
since the fast contraction, ``k - 2`` to ``k`` (:func:`guarded_bound` of ``d_k`` and ``d_(k-1)``:
``max(|d_k|, ENVELOPE |d_(k-1)|) rho / (1 - rho)``), ``d_(k-1)`` carried to level ``k`` at first order.  That
exceeds Richardson's ``2 |d_k|`` (at first order) only where ``c < 1/4``, by ``1 / (4 c)`` at most ``1 / (8
c')``.  ``d_(k-2)`` is left out: it is the difference before the fast contraction, which the two agreeing
ratios already measured, and carried at first order (``|d_(k-2)| / 4``) it would exceed ``|d_(k-1)| / 2`` by
``1 / (2 c')``, the whole window's guarded bound, which the estimate takes where the two contractions differ
by :data:`AGREE` or more.  So a slowing estimate lies between Richardson's and the whole window's guarded
bound; where it exceeds Richardson's, it is above :data:`LOOSE` times the tail the last difference leaves at
the faster contraction, and (unless carried lower) the flag above says so, with both contractions.
"""
from __future__ import annotations

from typing import Any

from ngcontact.cell.cell_solution import scale
from ngcontact.cell.spectral.contact_edges import ISLAND, KINK, LINE, LINE_STEP
from ngcontact.cell.spectral.grid_phase import PHASE
from ngcontact.cell.spectral.penalty_zone import PENALTY_ZONE
from ngcontact.cell.spectral.smooth_edges import SMOOTH

#: the forms of the estimate, as the report names them (:data:`CARRIED`: after a deferred stop, module
#: docstring of :mod:`~ngcontact.cell.spectral.refinement`)
RICHARDSON, GUARDED, CARRIED = "Richardson", "guarded", "carried"
#: an estimate above this many times the last difference of its quantity is flagged (module docstring)
LOOSE = 10.0
#: two successive contractions of a quantity differing by this factor or more differ by at least one order in
#: the grid step (each level halves it): they disagree (module docstring)
DISAGREE = 2.0
#: the slowest contraction per level the error left by the last difference is taken at (first order)
FIRST_ORDER = 0.5
#: the estimate's tails from the last differences of a quantity over the levels (module docstring of
#: :mod:`~ngcontact.cell.spectral.refinement`): how many, and the constants of its two forms
#: the differences the estimate looks at, and the fewest levels a stop needs
WINDOW = 3
#: the slowest and the fastest contraction per level the guarded bound assumes (module docstring of
#: :mod:`~ngcontact.cell.spectral.refinement`)
RATE_FLOOR = 0.5
RATE_CAP = 0.7
#: an earlier difference shrinks by this per level in the guarded envelope (first order in the grid step)
ENVELOPE = 0.5
#: where the last contraction is :data:`DISAGREE` times faster than the one before, the difference before the last
#: shrinks by this many times the contraction before it, at most :data:`ENVELOPE` (module docstring)
SAFETY = 2.0
#: a last difference this many times below the envelope is said to have vanished (a remark only)
VANISHED = 4.0
#: two successive ratios within this factor of each other make the sequence geometric (Richardson)
AGREE = 3.0
#: Richardson's tail times this: the scatter of one level's error about the geometric model
SPREAD = 2.0
#: why, per form of the estimate (module docstring)
WHY_LOOSE = {GUARDED: "an earlier difference bounds it", CARRIED: "carried from the deferred grid",
             KINK: "the contact edges of a map with kinks, bounded by a step at a kink, a quarter elsewhere",
             LINE: f"the 3D line's crossings of the contact edges, bounded by {LINE_STEP:g} of a step each"}


def loose_flags(history: list[dict[str, Any]], estimates: list[dict[str, float]], forms: list[dict[str, str]]
                ) -> list[dict[str, str]]:
    """Per load, the estimates of the last level of ``history`` that may exceed their error by more than
    :data:`LOOSE` times, with the reason (:func:`loose_reason`, in the quantity's measure; module docstring)."""
    last = history[-1]
    flags = []
    for k, per_load in enumerate(estimates):
        now, out = last["headline"][k], {}
        for name, e in per_load.items():
            size = scale(name, now, last["whole_surface"])
            why = loose_reason([h["headline"][k][name] / size for h in history[-4:]], e, forms[k][name])
            if why:
                out[name] = why
        flags.append(out)
    return flags


def loose_reason(values: list[float], estimate: float, form: str) -> str:
    """Why ``estimate`` (of the last of ``values``, two to four levels of a quantity in its measure, made in
    ``form``) may exceed its error by more than :data:`LOOSE` times, "" where it may not (module docstring):
    above :data:`LOOSE` times the tail its last difference leaves at the last contraction (:func:`tail_left`;
    not Richardson's form nor an island's, a penalty zone's, a smooth map's edges' or the phase's floor), or
    above :data:`LOOSE` times the tail it leaves at the contraction before, where the last two disagree, the last
    slower by :data:`DISAGREE` or more (:func:`faster_contraction`; any form)."""
    left, rate = tail_left(values[-3:])
    if form not in (RICHARDSON, ISLAND, PENALTY_ZONE, SMOOTH, PHASE) and estimate > LOOSE * left:
        return (f"{times(estimate, left)} the tail the last difference leaves at its rate {rate:.2g}: "
                f"{WHY_LOOSE.get(form, WHY_LOOSE[GUARDED])}")
    faster = faster_contraction(values)
    if faster is not None and estimate > LOOSE * faster[0]:
        return (f"{times(estimate, faster[0])} the tail the last difference leaves at the rate before it, "
                f"{faster[1]:.2g}: the last two contractions disagree ({faster[1]:.2g}, then {faster[2]:.2g}), "
                "the estimate takes the slower")
    return ""


def times(estimate: float, left: float) -> str:
    """``estimate`` over ``left`` in words."""
    return f"{estimate / left:.3g} times" if left > 0 else "far above"


def faster_contraction(values: list[float]) -> tuple[float, float, float] | None:
    """Where the last of the two contractions of ``values`` (four levels) is at least :data:`DISAGREE` times
    slower than the one before, ``|d_k| / |d_(k-1)| >= DISAGREE |d_(k-1)| / |d_(k-2)|``: the tail the last
    difference leaves at the contraction before, ``|d_k| rho / (1 - rho)`` with that ``rho`` (held to at most
    :data:`FIRST_ORDER`), and the two contractions; else ``None``."""
    d = [abs(b - a) for a, b in zip(values[:-1], values[1:])]
    if len(d) < 3 or d[0] <= 0 or d[1] <= 0:
        return None
    before, last = d[1] / d[0], d[2] / d[1]
    if not slowed(last, before):
        return None
    rate = min(before, FIRST_ORDER)
    return d[2] * rate / (1.0 - rate), before, last


def tail_left(values: list[float]) -> tuple[float, float]:
    """The error of the last of ``values`` (two or three levels of a quantity in its measure) that the last
    difference ``d_k`` leaves where the next differences contract as the last one did, ``|d_k| rho / (1 -
    rho)``, with ``rho = |d_k| / |d_(k-1)|`` held to at most first order (:data:`FIRST_ORDER`: then
    ``|d_k|``, as with two levels only), and that rate."""
    d = [abs(b - a) for a, b in zip(values[:-1], values[1:])]
    rate = min(d[-1] / d[-2], FIRST_ORDER) if len(d) > 1 and d[-2] > 0 else FIRST_ORDER
    return d[-1] * rate / (1.0 - rate), rate


def loose_remarks(flags: list[dict[str, str]]) -> list[str]:
    """The report's remark listing the flags of :func:`loose_flags`, none without flags."""
    listed = [f"load {k} {name} ({why})" for k, per_load in enumerate(flags) for name, why in per_load.items()]
    return [f"may exceed the error by more than {LOOSE:g} times: " + ", ".join(listed)] if listed else []


def differences(values: list[float], relative: bool, scale: float | None = None) -> list[float]:
    """The sizes of the last ``WINDOW`` differences of ``values``, the newest first, in the estimate's measure:
    divided by ``scale`` where given, else by the last value where ``relative``."""
    if scale is None:
        scale = abs(values[-1]) if relative and values[-1] != 0 else 1.0
    return [abs(b - a) / scale for a, b in zip(values[:-1], values[1:])][::-1][:WINDOW]


def richardson(d: list[float], order_rate: float) -> tuple[float, float, str] | None:
    """Richardson's estimate from the differences ``d`` (newest first), its rate and a remark, where the window's
    two ratios agree (module docstring of :mod:`~ngcontact.cell.spectral.refinement`); where the last contraction is
    the slower by :data:`DISAGREE` or more (:func:`slowed`), at least the guarded bound on the last two differences
    (module docstring); ``None`` where they do not agree."""
    if len(d) < WINDOW or min(d[1:]) <= 0:
        return None
    ratios = [d[i] / d[i + 1] for i in range(WINDOW - 1)]
    if min(ratios) <= 0 or max(ratios) > RATE_CAP or max(ratios) > AGREE * min(ratios):
        return None
    rate = max(max(ratios), order_rate)
    tail = SPREAD * d[0] * rate / (1.0 - rate)
    if not slowed(*ratios):
        return tail, rate, ""
    since = guarded_bound(d[:WINDOW - 1])[0]         # the levels since the fast contraction: the last two differences
    if since <= tail:
        return tail, rate, ""
    return since, rate, (f"; the last contraction {ratios[0]:.2g} at least {DISAGREE:g} times slower than the one "
                         f"before, {ratios[1]:.2g}: the guarded bound on the levels since")


def slowed(last: float, before: float) -> bool:
    """Whether the contraction ``last`` is at least :data:`DISAGREE` times slower than the one ``before`` it (module
    docstring)."""
    return last >= DISAGREE * before


def guarded_bound(d: list[float], regime: bool = True) -> tuple[float, str]:
    """The guarded geometric tail ``E = D rho / (1 - rho)`` from the differences ``d`` (newest first; module
    docstring of :mod:`~ngcontact.cell.spectral.refinement`) and a remark where a guard acted ("" otherwise):
    ``rho`` the larger ratio held to ``[RATE_FLOOR, RATE_CAP]``, ``D = max_i |d_(k-i)| ENVELOPE^i``, or where the
    last contraction ``c = |d_k| / |d_(k-1)|`` is at least :data:`DISAGREE` times faster than the one before,
    ``c' = |d_(k-1)| / |d_(k-2)|`` (:func:`regime_changed`; ``regime``), ``D`` on the levels since,
    ``max(|d_k|, |d_(k-1)| min(SAFETY c', ENVELOPE))`` (module docstring)."""
    ratios = [d[i] / d[i + 1] for i in range(len(d) - 1) if d[i + 1] > 0]
    observed = max(ratios) if ratios else RATE_CAP
    rate = min(max(observed, RATE_FLOOR), RATE_CAP)
    if regime and regime_changed(d):
        shrink = min(SAFETY * d[1] / d[2], ENVELOPE)
        return max(d[0], d[1] * shrink) * rate / (1.0 - rate), (
            f"the last contraction {d[0] / d[1]:.2g} at least {DISAGREE:g} times faster than the one before, "
            f"{d[1] / d[2]:.2g}: the levels since, the difference before the last shrunk by {shrink:.2g}")
    terms = [d[i] * ENVELOPE ** i for i in range(len(d))]
    envelope = max(terms)
    remark = []
    if observed > RATE_CAP:
        remark.append(f"not contracting (ratio {observed:.2g}): rate {RATE_CAP}")
    if envelope > VANISHED * terms[0]:
        remark.append("the last difference nearly vanished: an earlier one bounds it")
    return envelope * rate / (1.0 - rate), "; ".join(remark)


def regime_changed(d: list[float]) -> bool:
    """Whether the last of the differences ``d`` (newest first, three at least) contracted at least
    :data:`DISAGREE` times faster than the one before, ``|d_k| / |d_(k-1)| <= |d_(k-1)| / |d_(k-2)| / DISAGREE``,
    each difference measured (a zero one is a coincidence of equal values; module docstring)."""
    return len(d) >= WINDOW and min(d[:WINDOW]) > 0 and DISAGREE * d[0] * d[2] <= d[1] * d[1]


def tail_estimate(values: list[float], relative: bool, order_rate: float = RATE_FLOOR,
                  scale: float | None = None, geometric: bool = True, regime: bool = True, since: bool = False
                  ) -> tuple[float, str, str]:
    """The estimated error of the last of ``values`` (a quantity on successive levels; module docstring), its
    form (:data:`RICHARDSON` where that is the smaller, else :data:`GUARDED`) and a remark on it.  Needs two
    values at least; ``order_rate`` is the quantity's :data:`ORDER_RATE`; ``scale``: the size the error is
    divided by (default: 1, or the last value where ``relative``); not ``geometric``: the guarded bound only; not
    ``regime``: its envelope over the whole window, a change of regime not looked for (:func:`guarded_bound`);
    ``since``: levels the 2D quartic located, whose slowing sequence beyond Richardson's band takes the guarded bound
    on the levels since its fast contraction where smaller (module docstring)."""
    d = differences(values, relative, scale)
    fitted = richardson(d, order_rate) if geometric else None
    estimate, remark = guarded_bound(d, regime)
    if since and len(d) == WINDOW and min(d) > 0 and slowed(d[0] / d[1], d[1] / d[2]) and d[0] <= RATE_CAP * d[1]:
        bound = guarded_bound(d[:WINDOW - 1])[0]        # the quartic's levels since its fast contraction
        if bound < estimate:
            estimate, remark = bound, (f"the quartic's levels since its contraction {d[1] / d[2]:.2g}, the last "
                                       f"{d[0] / d[1]:.2g} slower: its edges' stall bounded by their spread")
    if fitted is None or fitted[0] >= estimate:
        return estimate, GUARDED, remark
    return fitted[0], RICHARDSON, f"rate {fitted[1]:.2g}{fitted[2]}"
