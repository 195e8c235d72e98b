"""The spectral cell on finer and finer grids until a tolerance is met, with an error estimate that bounds.

The grid is the spectral cell's only discretization parameter (:mod:`ngcontact.cell.spectral.layered_cell`):
the collocated pressure and gap, and with them the contact set of eq. 57 and the coefficients of eq. 34 on
it, converge as the grid step ``h`` shrinks.  How they converge decides the estimate:

* the contact fraction has its edges located between points (:mod:`ngcontact.cell.spectral.grid_measures`; in
  3D along the rows and columns by the line): an error of order ``h`` whose constant jumps with the edges'
  position between points, in 2D faster once the edge fit holds;
* the mean closure is a mean of the collocated jump: smoother, but its error changes sign as the grid crosses the edges.

So the sequence ``q_0, q_1, ...`` of a quantity on levels ``k`` has errors ``e_k = q_k - q`` that fall like ``rho^k``
on the whole, but level to level by an erratic factor, and that may cross zero.  The estimate of the reported
(finest) level ``k`` looks at the last ``WINDOW`` differences ``d_j = q_j - q_(j-1)`` (``j = k, k-1, k-2``) of each
headline quantity and each load on its own (:func:`ngcontact.cell.cell_solution.headline`: the contact fraction, the
mean closure, the normal effective stiffness and the coefficients of eq. 34 on the real contact set), in the measure
the verdict controls (:func:`ngcontact.cell.cell_solution.measure`: the contact fraction absolute, a coefficient
relative to the largest of its group, every other quantity relative), and takes one of two forms, which the report
names (:func:`sweep_estimates`):

1. **Richardson with the observed rate**, where the sequence is seen to be geometric: the two successive ratios
   ``|d_(k-1)| / |d_(k-2)|`` and ``|d_k| / |d_(k-1)|`` agree within the factor :data:`AGREE` and both contract at
   least by :data:`RATE_CAP`. The rate is the larger of the two, but never faster than the quantity's own order in
   the grid step (:data:`ORDER_RATE`: first order, ``1/2`` per level, for the contact fraction, whose edges are
   located between points, and for the mean closure too: a mean of the collocated jump, which an edge
   misplaced by a fraction of a step barely moves (the gap opens like ``(x - a)^(3/2)`` beyond an edge ``a``), but
   whose error is carried by the collocated pressure at the edges, singular like the inverse square root of the
   distance to an edge, with a first-order constant that changes sign as the edges cross the grid: two fast ratios
   just after such a sign change do not show the first-order stretch that follows, as on Westergaard's sinusoid at a
   fifth of its closing pressure); the estimate is the tail of the geometric series beyond level ``k``,
   ``|d_k| rho / (1 - rho)``, times :data:`SPREAD`, the scatter of one level's error about the geometric model (the
   erratic factor above: an edge's position between two points) that two ratios cannot resolve, and where the last
   ratio is :data:`DISAGREE` times the one before or more (a slowing sequence) at least the guarded bound on the last
   two differences (:mod:`.estimate_forms`). Where that exceeds the guarded bound below (which holds without the
   geometric model), the guarded bound is the estimate: Richardson only ever sharpens it.
2. **The guarded bound** wherever the two ratios disagree, one difference vanished, or the sequence does not contract
   ("where two successive differences disagree in rate, the estimate says so and takes the larger"): the rate is the
   larger of the ratios held to ``[RATE_FLOOR, RATE_CAP]`` (never faster than first order, and a sequence not
   contracting by ``RATE_CAP`` is taken as contracting by it), and the size of the next differences is the envelope
   ``D = max_i |d_(k-i)| ENVELOPE^i`` with ``ENVELOPE = 1/2``: the last difference, or an earlier one shrunk at first
   order, whichever is larger, so that a last difference that vanished by coincidence (a symmetric cell gives the
   same fraction on two grids; an edge's offset whose constant jumps between grids) is bounded by the ones before
   it; the tail ``D rho / (1 - rho)``, on the levels since after a ratio twice as fast (:mod:`.estimate_forms`).

In 2D the contact fraction and the coefficients of eq. 34 rest on edges located between points by one of two locators
(:func:`~ngcontact.cell.spectral.grid_measures.edge_offset`): the quartic fitted to the open gap where its window
holds enough points and the fit explains the gap, else the line through the first two open points, whose root is off
by a fraction of a step (first order, with a constant that jumps with the edges' position between points).  A 2D
window holding such levels takes the guarded bound for these quantities: two ratios of such differences agree by
chance (an error that stalls over two grids, as on a profile with kinks, alternates as if geometric).  In 3D (exact
contact) the line's offsets along the rows and columns hold a floor (``contact_edges``, form ``line``), above which
the differences are read as any other quantity's, Richardson's rate the observed one (not held to first order).  On a
smooth gap the quartic takes over at a grid fixed by its window (every edge of a load: :func:`~ngcontact.cell.spectral.
grid_measures.edges_fitted`, recorded per level), and the error drops there by one to two orders of magnitude.  A
difference between a level of the line and one of the quartic is the line's error, not a term of the quartic's
sequence: the window then bounds the error by the line's, which exceeds it by that drop.
So for these quantities of a load whose edges were fitted on the last ``r`` levels (:func:`fitted_run`), after the line:

* with ``r >= LOCATOR_LEVELS`` (two differences at least, so that one that vanished is seen beside the
  other) the estimate is also taken on those ``r`` levels alone, by the same rule (Richardson needs three
  differences, so two give the guarded bound), and the smaller of the two is reported: each is a bound on
  its own argument, the whole window's by the line's larger error, the fitted levels' by their own contraction;
* with ``0 < r < MIN_LEVELS`` the fitted levels are too few to see their rate: with ``r < LOCATOR_LEVELS``
  the window compares the two locators, a bound by the line's error; with ``r = LOCATOR_LEVELS`` the two
  fitted differences give the guarded bound, whose envelope ``|d_(k-1)| ENVELOPE`` is still of the size
  of the switch's drop.  Just after the switch the error may change sign, so that ``|d_k|`` is far below ``|d_(k-1)|``
  and neither says how fast the tail falls.  To a scene's own tolerance a stop waits for ``MIN_LEVELS`` fitted levels
  (:func:`locator_changing`) unless that level is beyond the largest grid (the whole window's estimate then stands):
  three differences whose two ratios decide between Richardson (they agree and contract) and the guarded bound (they
  do not: "the estimate says so and takes the larger").  Richardson's rate is held to first order there too, ``E =
  SPREAD |d_k| rho / (1 - rho)``, ``rho = max(|d_k| / |d_(k-1)|, |d_(k-1)| / |d_(k-2)|, 1/2)``: a contraction much
  faster than ``1/2`` right after the switch is the error crossing zero, and the next level falls at first order again
  (on Westergaard's sinusoid at a twentieth of its closing pressure the fitted errors fall by about 16 per doubling
  twice, then by 2: the observed rate would estimate a tenth of the error, the first-order one twice it).  The wait
  costs at most one 2D level more: the sweep, whose levels sum to about twice its finest, about doubles. On the level
  after a deferred stop (one whose estimates met the tolerance, the 2D stiffness's aside: a level refined on for the
  stiffness alone defers too) each estimate is the smaller of its own and the deferred one carried over, ``E_k =
  min(E_k^own, E_(k-1) + |d_k|)`` (:data:`CARRIED`): by ``|e_k| <= |e_(k-1)| + |q_k - q_(k-1)|`` a bound wherever
  ``E_(k-1)`` is one, it keeps a quantity whose window now holds a vanished difference (the mean closure at a fifth of
  Westergaard's closing pressure) at what the deferred level stated. Refined to the default tolerance (``sharpen =
  False`` in :func:`sweep_to_tolerance`) the first grid whose estimate meets it stops, its estimate a bound but not a
  sharp one. A load whose edges are never all fitted (a piecewise linear profile's kinks defeat the quartic) is
  estimated on the whole window.

The coefficients of eq. 34 on the real contact set are integrals over it (:mod:`ngcontact.cell.spectral.grid_measures`:
``k_n`` times the contact fraction, ``k_n`` times the gap integrated over the set), with the set's 2D edges
located between points as the contact fraction's: they converge as the fraction does and are estimated at its
order, and where the fraction's sequence of a load is not seen to be geometric (its estimate is the guarded bound)
neither are theirs, whose errors are the same edges' misplacements: a coefficient's own two ratios may agree by
chance where the edges' errors change sign, and its Richardson tail then misses an error that grows between grids.

The normal effective stiffness (:func:`~ngcontact.cell.spectral.grid_measures.effective_stiffness`) is in 3D that of
the collocated contact set, whose pressure, singular like the inverse square root of the distance to an edge,
converges at first order with a constant that the edges' position between points makes erratic: estimated at first
order, doubled (:data:`ERRATIC`).  In 2D (exact contact) it is that of the set with its edges located between points:
its error is the located edges', and it is estimated as the fraction is.  In 2D it is held to the tolerance like the
others, within a stated cap (:func:`stiffness_capped`): once every other quantity meets the tolerance, refinement
goes on for the stiffness alone for at most :data:`STIFFNESS_LEVELS` more levels within the largest grid, and only
while its estimate, were it to fall by :data:`STIFFNESS_RATE` per level (second order: faster than the first order of
edges located to a fraction of a step, so that a stiffness whose guarded estimate collapses once its differences
contract, as on the random profiles of ``docs/benchmarks.md`` (``random_profile_accuracy``), is not given up early),
could meet it within them.  Beyond the cap (a tolerance of 1e-4 where a narrow contact island, whose stiffness is
sensitive to its width, has an edge located to a fraction of a step only) the refinement stops, ``met = False``, the
stiffness counted in the verdict as not met (one warning line) and the cap named in the remarks; a scene's stated
tolerance so missed ends its run (:meth:`~ngcontact.cell.spectral.spectral_solver.SpectralCellSolver.refine_to`).  In
3D, whose cost bound (points squared) allows a few doublings only, it is reported with its estimate and not held
(:func:`uncontrolled`: listed in the verdict as not counted).

Three checks end a level's estimate. An island of fewer than :data:`.contact_edges.ISLAND_POINTS` points (3D:
across) has no resolved edges: its error may stall while the differences vanish, so its share of the quantities on
the edges is a floor under their estimates (:func:`.contact_edges.island_floor`, form ``island``; a 2D edge of a map
with kinks, a step within a step of one, else a quarter: ``kink``; a penalty's 2D edge located beyond its length
``E*/k_n``: ``penalty zone``; a 2D edge of a map without kinks, its quartic's spread from its half window's or the
line's share of a step: ``smooth``, :mod:`.smooth_edges`); a window across the level where the last island was
resolved is also taken on the resolved levels alone, the smaller reported. In 2D each estimate is at least the change
on the level's twin sampled half a step over (``phase``, :mod:`.grid_phase`): the error's part that jumps with the
edges' place between points.  The twin is solved only where its floor can matter: on a level whose estimates before
it let every quantity but the stiffness meet the tolerance (a stop, a deferral or the stiffness's cap reads them) and
on the largest grid (reported where nothing met the tolerance).  The floor only raises an estimate, so on any other
level it would leave the tolerance missed and change no decision; those levels' estimates in the history are
without it. An estimate (not Richardson's nor a floor) above :data:`.LOOSE` times the error its last
difference leaves at the last contraction, or (any form) at the one before where the last is twice as slow or more,
may exceed the error by as much: flagged with its reason, per quantity in the report
(:func:`~ngcontact.cell.spectral.estimate_forms.loose_flags`).

Levels double the points per direction (:data:`GROWTH`): the differences cost twice the finest level (2D: three times
with the reported level's twin, a solve more per level that waited), 4/3 in 3D. The effectivity (estimate over true
error of the reported level) is measured by ``scripts/spectral_effectivity.py`` against each cell's own value on a
much finer grid (``docs/benchmarks.md``).  No estimate can be sharp where the error of level ``k`` is small by chance:
where it crosses zero, or where it falls by much more than the differences before it show (a pre-asymptotic stretch
left for a faster regime), the differences still carry the size of the earlier errors, and the estimate exceeds the
error by their ratio.

A stop needs ``MIN_LEVELS`` levels (three differences: the window) and, to a scene's own tolerance, no load's edge
locator changing (above). The levels are known before the first solve (``grid`` times ``GROWTH^k`` up to
``max_points``, :func:`levels`; the scene layer bounds ``max_points`` by the cost of a solve,
:func:`ngcontact.scene.spectral_grid.spectral_cost`): the largest is stated first, and each level prints one progress
line as it ends. A tolerance out of reach ends in a :class:`~ngcontact.errors.ConvergenceError` where it was required
(the scene stated it), else the finest level is the answer, marked as not meeting it. Each level starts its loads
from the coarser level's pressures (:mod:`.grid_level`): a start only; the answer is the level's own."""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ngcontact.cell.cell_solution import COEFFICIENT, RELATIVE, headline, measure, scale, worst_estimate
from ngcontact.cell.spectral.contact_edges import (FITTED_STEP, ISLAND_POINTS, LINE_STEP, LOCATED_STEP, QUADRATURE,
                                                   fitted_run, island_floor, locator_kind, on_edges, resolved_run,
                                                   stall_floored, locator_changing as edges_changing)
from ngcontact.cell.spectral.estimate_forms import (AGREE, CARRIED, DISAGREE, FIRST_ORDER, GUARDED, LOOSE, RATE_CAP,
                                                    RATE_FLOOR, SAFETY, SPREAD, WINDOW, loose_flags, loose_remarks,
                                                    tail_estimate)
from ngcontact.cell.spectral.grid_level import GROWTH, solve_level, solve_twin
from ngcontact.cell.spectral.grid_phase import phase_floor
from ngcontact.cell.spectral.penalty_zone import INSIDE, PENALTY_LOG, zone_ahead
from ngcontact.cell.spectral.smooth_edges import SPREAD_STEPS
from ngcontact.errors import ConvergenceError

#: the run's progress lines (printed as its stage lines, :func:`ngcontact.runner.solve`)
progress = logging.getLogger("ngcontact.progress")

#: the fewest levels a stop needs: one more than the differences the estimate looks at
MIN_LEVELS = WINDOW + 1
#: the fastest contraction per level Richardson may assume: each quantity's own order in the grid step, first
#: for each (module docstring; any other quantity: :data:`FIRST_ORDER`)
ORDER_RATE = {"contact_fraction": 0.5, "mean_closure": 0.5}
#: the quantity held to the tolerance within a cap in 2D, reported and not held in 3D (module docstring)
STIFFNESS = "normal_stiffness"
#: the most levels the 2D stiffness alone may take beyond the grid where every other quantity met the tolerance,
#: and the contraction per level it is projected at (second order: optimistic; module docstring)
STIFFNESS_LEVELS = 3
STIFFNESS_RATE = 0.25
#: a quantity's estimate times this: the stiffness's first-order constant jumps with the edges' position between
#: points, so that its error may exceed the differences beside it (module docstring)
ERRATIC = {"normal_stiffness": {2: 1.0, 3: 2.0}}
#: the fewest levels whose 2D edges are all located by the quartic that estimate the quantities resting on the
#: edges on their own (two differences: one that vanished is seen beside the other; module docstring)
LOCATOR_LEVELS = 3
#: how the estimate is made, for the report
HOW = ("grids of twice the points per direction each; per quantity and load, Richardson with the observed rate "
       f"of the last {WINDOW} differences where their two ratios agree within a factor {AGREE:g} (rate at least "
       f"{FIRST_ORDER}, the tail times {SPREAD:g}; after a last ratio {DISAGREE:g} times the one before or more, at "
       "least the guarded tail of the last two differences) if that is the smaller, else the guarded geometric tail: "
       f"rate the larger ratio held to [{RATE_FLOOR}, {RATE_CAP}], an earlier difference bounding a vanished "
       f"last one (after a last ratio {DISAGREE:g} times below the one before, the last three levels: the difference "
       f"before shrunk by {SAFETY:g} times that ratio, at most 1/2, the rate alike); the contact fraction, "
       "coefficients and 2D stiffness (of the located set) guarded on levels of edges not all fitted by the quartic "
       f"(3D exact: Richardson at the observed rate, at least {LINE_STEP:g} step per edge crossed by a row or column)"
       f", and also on those fitted (at least {LOCATOR_LEVELS}; a stop waits for {MIN_LEVELS}), the smaller; after "
       "a deferred stop, the deferred grid's estimate plus the last difference where smaller; the effective "
       f"stiffness's estimate times {ERRATIC[STIFFNESS][2]:g} in 2D, held to the tolerance up to {STIFFNESS_LEVELS} "
       f"levels beyond the grid where the others met it while its estimate falling by {STIFFNESS_RATE:g} per level "
       f"would meet it (else not met), times {ERRATIC[STIFFNESS][3]:g} in 3D, reported, not held; at least "
       f"the share of contact islands of fewer than {ISLAND_POINTS} points (3D: across), and after such islands "
       f"also on the resolved levels (at least {LOCATOR_LEVELS}), the smaller; a step per 2D edge within a step of a "
       f"kink of the map's piecewise-linear surface, {LOCATED_STEP:g} of one per other edge of such a map "
       f"({FITTED_STEP:g} by the quartic; a load's edges {QUADRATURE:g} times their root-sum-square where below their "
       f"sum), {PENALTY_LOG:g} E*/k_n ln(period k_n / E*) per edge of a penalty located on points beyond E*/k_n, on a "
       f"2D map without kinks {SPREAD_STEPS:g} times each quartic edge's spread from the quartic on its window's first "
       f"half ({LOCATED_STEP:g} step per edge the line located); in 2D every quantity at least its change on the same "
       "grid sampled half a step over (twice the half-difference: the part of the error that changes sign with the "
       f"edges' place between points); above {LOOSE:g} times the error its last difference leaves at the last rate, "
       "or the one before where the last is twice as slow or more: flagged (quantities[].loose)")


@dataclass
class RefinedSweep:
    """The finest level's cell and solutions, the estimate per load, the history of levels, whether the
    tolerance is met, the estimate's remarks (its forms, guards that acted) and its form per load."""

    cell: Any
    solutions: list
    estimates: list[dict[str, float]]
    history: list[dict[str, Any]] = field(default_factory=list)
    met: bool = True
    remarks: list[str] = field(default_factory=list)
    #: per load, the form of each quantity's estimate (:data:`RICHARDSON` or :data:`GUARDED`)
    forms: list[dict[str, str]] = field(default_factory=list)
    #: per load, the estimates that may exceed the error by more than :data:`LOOSE` times, with the reason
    flags: list[dict[str, str]] = field(default_factory=list)
    #: the quantities the sweep does not hold to the tolerance (:func:`uncontrolled`)
    uncontrolled: tuple[str, ...] = ()
    #: where refinement stopped at the 2D stiffness's cap (:func:`stiffness_capped`): on which grid and why, else ""
    capped: str = ""

    @property
    def estimate(self) -> float:
        """The largest estimate of a quantity held to the tolerance."""
        return controlled_estimate(self.estimates, self.uncontrolled)

    @property
    def scales(self) -> list[dict[str, float]]:
        """Per load, what each quantity's absolute error is divided by in its measure on the finest level."""
        return [{name: scale(name, head, self.history[-1]["whole_surface"]) for name in head}
                for head in self.history[-1]["headline"]]


def uncontrolled(dim: int) -> tuple[str, ...]:
    """The estimated quantities a refinement of a ``dim``-dimensional cell does not hold to the tolerance (module
    docstring): none in 2D, the normal effective stiffness in 3D."""
    return () if dim == 2 else (STIFFNESS,)


def controlled_estimate(estimates: list[dict[str, float]], skip: tuple[str, ...] = ()) -> float:
    """The largest of the ``estimates`` (per load) of the quantities held to the tolerance (not in ``skip``)."""
    return max((e for per_load in estimates for name, e in per_load.items() if name not in skip), default=0.0)


def stiffness_capped(estimates: list[dict[str, float]], tolerance: float, grid: int, left: int) -> str:
    """Where every quantity but the stiffness meets ``tolerance`` on ``grid`` points per direction and the
    stiffness does not, with ``left`` levels the stiffness may still take (module docstring): a remark saying why
    refinement stops where its largest estimate ``E``, falling by :data:`STIFFNESS_RATE` per level, would still
    miss the tolerance after them; ``""`` where refinement may go on, or the stiffness meets it."""
    stiffness = max((per[STIFFNESS] for per in estimates if STIFFNESS in per), default=0.0)
    if stiffness <= tolerance or controlled_estimate(estimates, (STIFFNESS,)) > tolerance:
        return ""
    if left > 0 and stiffness * STIFFNESS_RATE ** left <= tolerance:
        return ""
    return (f"the normal stiffness's estimate {stiffness:.3g} misses the tolerance {tolerance:g} on grid {grid} "
            f"while every other quantity meets it, and {max(left, 0)} more level(s) within the cap (at most "
            f"{STIFFNESS_LEVELS} beyond the grid where the others met it, within the largest grid) would not "
            f"meet it even at {STIFFNESS_RATE:g} per level; at first order it would take about "
            f"{int(np.ceil(grid * stiffness / tolerance))} points per direction: not met")


def next_grid(grid: int, dim: int) -> int:
    """Points per direction of the next level: ``GROWTH`` times as many."""
    return grid * GROWTH


def sweep_estimates(history: list[dict[str, Any]], geometric_ok: bool = True
                    ) -> tuple[list[dict[str, float]], list[str], list[dict[str, str]]]:
    """Per load the estimate of each headline quantity on the last level of ``history`` (in its measure,
    :func:`~ngcontact.cell.cell_solution.measure`), the remarks (which estimates are Richardson's, the guards
    that acted) and per load the form of each estimate.  A quantity missing on some level (a stiffness in full
    contact) is not estimated, nor one that is zero on every level (a coefficient that the flat interface
    makes zero: ``k_t``, ``k_nt``, ``g_t``, ``G_n``; ``G_t`` without friction); not ``geometric_ok``: guarded only."""
    estimates, forms, guarded = [], [], []
    dim = 2 if history[-1].get("points") == history[-1].get("grid") else 3      # 3D: points = grid^2
    for k, last in enumerate(history[-1]["headline"]):
        out: dict[str, float] = {}
        ahead = zone_ahead(history[-1], k)      # a penalty's zone not yet resolved (contact_edges)
        form: dict[str, str] = {}
        for name in last:
            values = [h["headline"][k].get(name) for h in history]
            if None in values or not any(values):
                continue
            size = scale(name, last, history[-1]["whole_surface"])
            located = on_edges(name) or (name == STIFFNESS and dim == 2)       # 2D: the located set's stiffness
            # not geometric: a coefficient where the fraction is not, a penalty's line within E*/k_n or zone ahead
            geometric = geometric_ok and not (name.startswith(COEFFICIENT) and form.get("contact_fraction") == GUARDED
                                              or located and locator_kind(history[-1], k) == INSIDE or ahead)
            lined = located and bool(history[-1].get("islands", [{}] * (k + 1))[k].get("line", {}).get("share"))
            args = (measure(name) == RELATIVE, 0.0 if lined else ORDER_RATE.get(name, FIRST_ORDER), size)
            fitted = fitted_run(history, k) if located and not lined else len(history)
            run = min(fitted, resolved_run(history, k))        # levels of the quartic and of resolved islands
            out[name], form[name], note = tail_estimate(values, *args, geometric and fitted == len(history),
                                                         geometric_ok)
            since = run == fitted > WINDOW and stall_floored(history[-1], k)     # the quartic's levels, stall floored
            if LOCATOR_LEVELS <= run < len(history):
                sharp = tail_estimate(values[-run:], *args, geometric, geometric_ok, since)
                if sharp[0] < out[name]:
                    out[name], form[name], note = sharp[0], sharp[1], "; ".join(filter(None, (sharp[2], (
                        "the edge fit's own levels" if run == fitted else "the levels of resolved islands"))))
            out[name] *= ERRATIC.get(name, {}).get(dim, 1.0)
            if form[name] == GUARDED:
                guarded.append(f"load {k} {name}" + (f": {note}" if note else ""))
        estimates.append(out)
        forms.append(form)
    total = sum(len(f) for f in forms)
    remarks = [f"Richardson on {total - len(guarded)} of {total} estimates"]
    if guarded:
        remarks.append("guarded on " + ", ".join(guarded))
    return estimates, remarks, forms


def carried(previous: list[dict[str, float]], history: list[dict[str, Any]], estimates: list[dict[str, float]],
            forms: list[dict[str, str]]) -> int:
    """Lower ``estimates`` (per load, of the last level of ``history``; their ``forms`` with them) in place to
    the estimates ``previous`` of the level before plus the difference between the two levels where that is
    smaller: ``|e_k| <= |e_(k-1)| + |q_k - q_(k-1)|`` (module docstring).  Returns how many it lowered."""
    last, before = history[-1], history[-2]
    lowered = 0
    for k, per_load in enumerate(estimates):
        now, then = last["headline"][k], before["headline"][k]
        for name, own in ((n, e) for n, e in per_load.items() if n in previous[k]):
            bound = (previous[k][name] * scale(name, then, before["whole_surface"]) + abs(now[name] - then[name])
                     ) / scale(name, now, last["whole_surface"])
            if bound < own:
                per_load[name], forms[k][name] = bound, CARRIED
                lowered += 1
    return lowered


def locator_changing(history: list[dict[str, Any]]) -> bool:
    """Whether some load's edges came to be located by the quartic fewer than :data:`MIN_LEVELS` levels ago
    (:func:`~ngcontact.cell.spectral.contact_edges.locator_changing`; module docstring)."""
    return edges_changing(history, MIN_LEVELS)


def levels(grid: int, dim: int, max_points: int) -> list[int]:
    """The grids refinement may use: ``grid`` and each next one while its points are at most ``max_points``."""
    if grid ** (dim - 1) > max_points:
        raise ValueError(f"the first grid of {grid} points per direction exceeds the {max_points} points of the "
                         "largest")
    out = [grid]
    while next_grid(out[-1], dim) ** (dim - 1) <= max_points:
        out.append(next_grid(out[-1], dim))
    return out


def sweep_to_tolerance(make_cell: Callable[[int], Any], loads: list, tolerance: float, grid: int, dim: int,
                       max_points: int, required: bool = True, sharpen: bool = True) -> RefinedSweep:
    """Solve ``loads`` on grids from ``grid`` up until the estimate meets ``tolerance`` (module docstring).

    ``make_cell(n)`` builds the spectral cell of ``n`` points per direction.  The grids it may reach
    (:func:`levels`) are known and stated before the first solve; each level logs one progress line.
    Out of reach: a :class:`~ngcontact.errors.ConvergenceError` with the history where ``required``, else
    the finest level with ``met = False``.  ``sharpen``: a stop waits while an edge locator changes
    (:func:`locator_changing`), else the first grid whose estimate meets the tolerance is the answer.
    """
    grids = levels(grid, dim, max_points)
    skip = uncontrolled(dim)
    progress.info("spectral refinement may reach grid %d (%d points) in %d levels from grid %d", grids[-1],
                  grids[-1] ** (dim - 1), len(grids), grid)
    history: list[dict[str, Any]] = []
    sols: list = []
    flags: list[dict[str, str]] = []
    deferred = None                 # the estimates of a level that met the tolerance but waited on the edge fit
    first_met = None                # the level on which every quantity but the stiffness first met it
    for n in grids:
        cell, sols, entry = solve_level(make_cell, loads, n, sols or None)
        history.append(entry)
        estimates, remarks, forms = sweep_estimates(history) if len(history) > 1 else (None, [], [])
        if estimates is not None and deferred is not None:
            if lowered := carried(deferred, history, estimates, forms):
                remarks.append(f"{lowered} estimates carried from the deferred grid {history[-2]['grid']}: its "
                               "estimate plus the last difference")
        if estimates is not None:
            remarks += island_floor(history, estimates, forms)
            if n == grids[-1] or len(history) >= MIN_LEVELS and controlled_estimate(estimates, skip + (STIFFNESS,)
                                                                                    ) <= tolerance:
                solve_twin(make_cell, loads, cell, sols, entry)     # a level a stop or the report reads: lazy twin
            remarks += phase_floor(history, estimates, forms)
            flags = loose_flags(history, estimates, forms)
            entry["estimate"] = controlled_estimate(estimates, skip)
        progress.info("spectral grid %d: %.2f s%s", n, entry["seconds"],
                      f", estimate {entry['estimate']:.3g}" if estimates is not None else "")
        settled = not sharpen or n == grids[-1] or not locator_changing(history)
        ready = estimates is not None and len(history) >= MIN_LEVELS
        met = ready and entry["estimate"] <= tolerance
        done = RefinedSweep(cell=cell, solutions=sols, estimates=estimates or [], history=history,
                            remarks=remarks + loose_remarks(flags), forms=forms, flags=flags, uncontrolled=skip)
        if met and settled:
            return done
        rest = ready and controlled_estimate(estimates or [], skip + (STIFFNESS,)) <= tolerance
        others = rest and settled
        first_met = len(history) if others and first_met is None else first_met
        left = min(len(grids) - len(history), STIFFNESS_LEVELS - len(history) + (first_met or 0))
        capped = stiffness_capped(estimates or [], tolerance, n, left) if others and not skip else ""
        if capped:
            done.met, done.remarks = False, done.remarks + [capped]
            done.capped = (f"on grid {n}, where refinement stopped at its cap for the stiffness alone (at most "
                           f"{STIFFNESS_LEVELS} levels beyond the grid where every other quantity met it)")
            progress.info("spectral refinement stops on grid %d: the normal stiffness is capped", n)
            return done
        deferred = estimates if rest else None      # every quantity but the stiffness met it: carried on
    reached = worst_estimate(estimates, skip) if estimates is not None else "no estimate (one level)"
    message = (f"discretization.tolerance = {tolerance:g} not met: the estimate is {reached} on {entry['points']} "
               f"grid points, and the next grid of {next_grid(grids[-1], dim)} per direction would exceed "
               f"{max_points} points")
    if required:
        raise ConvergenceError(message + "; loosen the tolerance", {"levels": history})
    if estimates is None:
        estimates = [{name: float("inf") for name in headline(s.results)} for s in sols]
    return RefinedSweep(cell=cell, solutions=sols, estimates=estimates, history=history, met=False,
                        remarks=remarks + loose_remarks(flags) + [message], forms=forms, flags=flags,
                        uncontrolled=skip)
