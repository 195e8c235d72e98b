"""The cell table's share of a two-scale run's error, and the table refined towards ``discretization.tolerance``.

The macro law of a two-scale run is the table's ``p = P_T(c)`` (:mod:`ngcontact.coupling.pressure_table`;
the loop of paper Sec. 3.5 converges to the macro problem with that law).  Its interpolation error reaches a
headline quantity ``Q`` of the macro solution (peak pressure, interface resultant, stress maxima:
:func:`ngcontact.macro.discretization_error.headlines`) only through the table's intervals in which the
pressures of the macro interface lie, and, through the cubic's slopes at their ends, their neighbours.
Those intervals (from the one holding the least pressure to the one holding the largest, and one more on
either side) are halved twice,

    T' = T + midpoints of those intervals of T,     T'' = T' + midpoints of those intervals of T',

the macro problem is solved with the laws of ``T'`` and ``T''`` (warm from the solution with ``T``) and

    d1 = |Q(T') - Q(T)|,   d2 = |Q(T'') - Q(T')|,   e_Q = max(2 d1, d1 + 2 d2),   share = max_Q e_Q / |Q|

is the estimate of the table's error of each quantity of the solution with ``T``.  Why: with ``e = Q(T) - Q*``
and ``e' = Q(T') - Q* = rho e``, ``|e| = d1 / |1 - rho|``, at most ``2 d1`` when ``|rho| <= 1/2``: the error
of the monotone cubic at least halves where its intervals are halved (first order at a kink of the cell's
response, such as the onset of full contact, of third order where it is smooth); and ``|e| <= d1 + |e'|``
with ``|e'| <= 2 d2`` by the same argument one halving further.  Either bound alone fails where its
difference is small by accident: a discrete cell (the spectral cell's contact set changes by whole grid
points) answers piecewise smoothly, and on the press fit at twice its interference one halving changed the
peak pressure by a small part of its error, which the second halving showed (the quantities where the second
bound is the larger are listed per round as ``second_halving_larger``).  The larger of the two is taken.
Its effectivity is tested against a table halved four times more (tests/coupling/test_table_share.py) and
measured by ``scripts/two_scale_table_share.py`` (docs/benchmarks.md).

Refinement: while the share exceeds :data:`FRACTION` of the tolerance, the midpoints of ``T'`` where the table's own
error (the discrepancy of the held response against ``T``'s interpolants and law,
:meth:`~ngcontact.coupling.pressure_table.CellTable.discrepancy`) is at least :data:`MARK` of its largest become
nodes, the macro problem is solved with the new law, and the estimate is made again (the other midpoints stay held:
the next estimate halves those intervals without a cell solve), at most :data:`MAX_ROUNDS` times.  A round whose
first halving alone puts the share above the limit (``2 d1``, the smaller bound, the parts added) refines without
the second halving, which could only raise it; its share is that lower bound (``halvings`` 1).  Beyond
:data:`MAX_ROUNDS` rounds, or past the table's bound on its cell solves, the tolerance is out of reach and the run
ends with its figures (a :class:`~ngcontact.errors.ConvergenceError`, exit 3).  The rest of the tolerance is left to
the macro discretization and the loop's residual, each judged on its own.

The midpoints of the last estimate are solved but are not nodes of the answer's law: the table keeps them
(:attr:`~ngcontact.coupling.pressure_table.CellTable.held`) and the cache stores them, so that a second run
of the scene reproduces the first and estimates its share without a cell solve.

A cell with micro friction has a second table, the shear table of :mod:`ngcontact.coupling.shear_table` (rows
``s -> tau`` at pressures, the macro law's tangential part). Its share is estimated the same way, each table on its
own (the other held at its nodes), and the shear table in each of its two directions on its own: in the pressure,
the rows' pressure intervals holding the interface's pressures, and one more on either side, get a row at their
middle (at the far-face jumps of a neighbour carried along the ray); in the jump, every row in that range its jump
intervals halved (:func:`shear_loads`); twice, as above. The law's error is the sum of the two directions' exactly,
``T - tau = (I_p tau - tau) + I_p (T_i - tau_i)`` (``I_p``: the rows interpolated in ``p`` along the rays): halving
the rows changes the first, halving the rows' intervals the second, and one direction at a time costs twice and four
times the visited nodes, not four and sixteen times. In the jump only the intervals up to the one holding the
largest ``|s| / p`` of the interface's points that use the row, carried to it along the ray, and one more: the law
at a point of pressure ``p`` in ``[p_i, p_i+1]`` reads the rows ``i`` and ``i + 1`` only, at ``s p_i / p`` and
``s p_i+1 / p``, so a row's jumps in use are those of the points in the pressure intervals beside it (and, for the
points between the samples where the law is integrated, in theirs). The interface's largest ``|s| / p`` instead is
unbounded at the contact's edge (``p -> 0``) and took every interval of every row in range. A new row likewise ends
one interval beyond the furthest its points reach (beyond its last node the law holds its shear; no point of the
interface is there); made a node it is made whole (:func:`whole_rows`): the rows reach as far as before, and the
table's cover and a second run of the scene solve no cell for it. The parts add, ``e_Q = e_Q(pressure table) +
e_Q(shear table, pressure) + e_Q(shear table, jump)``; each part is reported (``parts``). While the sum exceeds the
limit, the largest part alone is refined and the next round estimates it alone; the others keep their last estimates
(``carried``): refining one table or direction leaves the others' terms of the law's error as they were (new rows take
their jumps along the rays, their polyline errors their neighbours'). A direction's first midpoints all become nodes
(:data:`SHEAR_MARK` = 0): marked by the table's own error, which lies where the macro feels it least, its share stalled.

Where the scene has a strength check, its safety factor (eq. 78 by the linear recovery) is a headline quantity
of the share too: its correctors are the strength cell's and depend on the law only through whether it has a
tangential part, which no table refinement changes, so each estimate's solve gives its safety factor at the cost
of one linear recovery.  So are the maxima away from the bodies' singular points (the caller's ``measure``:
:meth:`ngcontact.drivers.run_two_scale.Relevel.table_share`).
"""
from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ngcontact.coupling.pressure_table import CellTable, response_law
from ngcontact.coupling.shear_table import ShearLoad, ShearTable
from ngcontact.errors import ConvergenceError
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.macro.discretization_error import Sample
from ngcontact.macro.macro_measures import interface_profile, interface_samples

log = logging.getLogger(__name__)
progress = logging.getLogger("ngcontact.progress")

#: the table is refined until its share is below this fraction of ``discretization.tolerance``
FRACTION = 0.5
#: the most halvings of the intervals the interface's pressures lie in
MAX_ROUNDS = 8
#: the estimate's factor on the difference (module docstring: the error at least halves with the intervals)
FACTOR = 2.0
#: a refinement round makes nodes of the pressure table's first midpoints only where its own error there is at
#: least this fraction of its largest (0: all of them; module docstring)
MARK = 0.5
#: the same for the shear table: all of them (module docstring)
SHEAR_MARK = 0.0
#: what the report's ``how`` says
HOW = ("the table's intervals holding the macro interface's pressures (and one more on either side; with a shear "
       "table also its rows' pressure and jump intervals the interface uses, one direction at a time) halved "
       "twice (one cell solve at each midpoint) and the macro problem solved again with each law: the larger of "
       "twice the first change of each headline quantity and the first change plus twice the second (the "
       "monotone cubic's error at least halves with its intervals; ngcontact.coupling.table_share)")


class _Part:
    """A table of the macro law as a part of the share: ``table`` and its cell solves."""

    def __init__(self, table):
        self.table = table

    @property
    def solves(self) -> int:
        return self.table.solves


class PressurePart(_Part):
    """The pressure table as a part of the share: its intervals holding the interface's pressures halved."""

    name = "pressure_table"
    table: CellTable

    def nodes(self, level: CellTable | None = None) -> int:
        return len((level or self.table).values)

    def finer(self, sol: M.MacroSolution, points_per_element: int, of: CellTable | None = None) -> CellTable:
        """``of`` (default the table) halved where ``sol``'s interface uses it, held by the table."""
        p = interface_samples(sol, points_per_element)["pressure"]
        return _finer(self.table, dict((of or self.table).values), p[p > 0])

    @staticmethod
    def law(level: CellTable, law: il.InterfaceLaw) -> il.InterfaceLaw:
        return replace(law, normal=response_law(level))

    def adopt(self, level: CellTable) -> int:
        """The midpoints of ``level`` made nodes; with :data:`MARK` > 0 only those where the table's own error
        (:meth:`CellTable.discrepancy`) is at least that fraction of its largest.  Returns how many."""
        new = {m: level.values[m] for m in set(level.values) - set(self.table.values)}
        errors = self.table.discrepancy(new) if new else {}
        top = max(errors.values(), default=0.0)
        for m in [m for m, e in errors.items() if e >= MARK * top]:
            self.table.values[m] = self.table.held.pop(m)
        return sum(e >= MARK * top for e in errors.values())


class ShearPart(_Part):
    """The shear table halved in one ``direction`` (``"pressure"``: new rows; ``"jump"``: the rows' intervals) as a
    part of the share (module docstring)."""

    table: ShearTable

    def __init__(self, table: ShearTable, direction: str):
        super().__init__(table)
        self.direction = direction
        self.name = f"shear_table_in_{direction}"

    def nodes(self, level: ShearTable | None = None) -> int:
        return sum(len(r) for r in (level or self.table).rows.values())

    def finer(self, sol: M.MacroSolution, points_per_element: int, of: ShearTable | None = None) -> ShearTable:
        """``of`` (default the table) halved in :attr:`direction` where ``sol``'s interface uses it, held by the
        table."""
        prof = interface_profile(sol, points_per_element)
        return shear_finer(of or self.table, prof["pressure"], prof["jump_t"], keeper=self.table,
                           direction=self.direction)

    @staticmethod
    def law(level: ShearTable, law: il.InterfaceLaw) -> il.InterfaceLaw:
        return replace(law, friction=level.law())

    def adopt(self, level: ShearTable) -> int:
        """The loads of ``level`` made nodes; with :data:`SHEAR_MARK` > 0 only where the table's own error
        (:func:`shear_own_errors`) is at least that fraction of its largest.  Returns how many."""
        groups = shear_own_errors(self.table, level)
        top = max((e for e, _ in groups), default=0.0)
        loads = [x for e, g in groups if e >= SHEAR_MARK * top for x in g]
        loads = sorted(set(loads) | set(whole_rows(self.table, {q for q, _ in loads} - set(self.table.rows))))
        self.table._solve(loads, match=True)
        return len(loads)


def _rays(P: np.ndarray, p: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Per pressure interval ``i`` of ``P`` (``lo <= i <= hi``) the largest ``|s| / p`` of the samples in it or in
    its neighbours (a margin for the points between the samples, where the macro law is integrated)."""
    k = np.clip(np.searchsorted(P, p, side="right") - 1, 0, len(P) - 2)
    own = np.zeros(len(P) - 1)
    np.maximum.at(own, k, s / p)
    wide = np.maximum(own, np.maximum(np.concatenate([[0.0], own[:-1]]), np.concatenate([own[1:], [0.0]])))
    return wide


def shear_loads(table: ShearTable, pressures: np.ndarray, jumps: np.ndarray, margin: int = 1,
                whole: bool = False, direction: str = "both") -> list[ShearLoad]:
    """The cell loads that halve ``table`` where a macro interface with ``pressures`` and tangential ``jumps`` [m]
    uses it (module docstring): a row at the middle of every pressure interval (the law's zero row at ``p = 0``
    included) from the one holding the least pressure to the one holding the largest and ``margin`` more on
    either side, at the far-face jumps of its neighbour of more nodes carried along the ray ``s / p``; on every
    row in that range, new rows too, the middle of every jump interval up to the one holding the largest
    ``|s| / p`` of the interface's points that use the row (those in the pressure intervals beside it, and in
    theirs: :func:`_rays`) carried to it, and ``margin`` more (a flat interval of a monotone row, exact, is not
    halved).  A new row ends there (its last node at the end of its last halved interval; beyond it the law holds
    its shear, where no point of the interface is).  ``whole``: every interval of those rows and whole new rows
    (the oracle's finer tables); ``direction``: ``"pressure"`` the new rows alone (at their first nodes),
    ``"jump"`` the halved intervals of the rows there are alone, ``"both"`` all."""
    if direction not in ("pressure", "jump", "both"):
        raise ValueError(f"direction {direction!r}: 'pressure', 'jump' or 'both'")
    keep = np.asarray(pressures, float) > 0
    p, s = np.asarray(pressures, float)[keep], np.abs(np.asarray(jumps, float)[keep])
    if not len(p) or not table.rows:
        return []
    P = np.concatenate([[0.0], table.pressures])
    k = np.clip(np.searchsorted(P, [p.min(), p.max()], side="right") - 1, 0, len(P) - 2)
    lo, hi = max(int(k[0]) - margin, 0), min(int(k[1]) + margin, len(P) - 2)
    R = np.full(len(P) - 1, np.inf) if whole else _rays(P, p, s)
    # per row: (the row whose nodes it has, its far-face jumps, the largest ray of the points that use it)
    rows = {float(P[i]): (float(P[i]), table.row(float(P[i]))[0], max(R[i - 1], R[i] if i < len(R) else 0.0))
            for i in range(max(lo, 1), hi + 2)}
    for i in range(lo, hi + 1):
        m = 0.5 * (P[i] + P[i + 1])
        near = max((q for q in (P[i], P[i + 1]) if q > 0), key=lambda q: len(table.rows[q]))
        rows[float(m)] = (float(near), table.row(near)[0] * m / near, R[i])
    loads = []
    for q, (near, d_q, ray) in rows.items():
        d_n, s_n, _ = table.row(near)
        j = min(int(np.searchsorted(s_n, ray * near, side="right")) + margin, len(d_q) - 1)
        new = q not in table.rows
        if new and direction != "jump":
            loads += [(q, float(d)) for d in d_q[1:j + 1]]
        if direction == "both" or (direction == "jump" and not new):
            loads += [(q, float(0.5 * (a + b))) for a, b, a0, b0 in zip(d_q[:j], d_q[1:j + 1], d_n[:j],
                                                                           d_n[1:j + 1])
                      if not table._flat(near, float(a0), float(b0))]
    return loads


def shear_finer(table: ShearTable, pressures: np.ndarray, jumps: np.ndarray, keeper: ShearTable | None = None,
                whole: bool = False, direction: str = "both") -> ShearTable:
    """A copy of ``table`` halved where ``pressures`` and ``jumps`` use it (:func:`shear_loads`), its new
    responses held by ``keeper`` (default ``table``)."""
    got = (keeper or table).hold(shear_loads(table, pressures, jumps, whole=whole, direction=direction))
    rows = {p: dict(r) for p, r in table.rows.items()}
    for (p, d), v in got.items():
        rows.setdefault(p, {0.0: (0.0, 0.0)})[d] = v
    return ShearTable(table.response, table.tol, table.length_unit, map_tasks=table.map_tasks, rows=rows)


def whole_rows(table: ShearTable, new: set[float]) -> list[ShearLoad]:
    """The loads that make rows of ``table`` at the new pressures ``new`` whole: all far-face jumps of the row
    beside each of more nodes, carried along the ray (as :func:`shear_loads` made its first ones).  A row made
    so reaches as far as its neighbours, and the table's cover (:meth:`ShearTable.cover`) finds it as it finds
    them (a second run of the scene solves no cell for it)."""
    P = table.pressures
    loads = []
    for q in sorted(new):
        i = int(np.searchsorted(P, q))
        near = max((float(x) for x in P[max(i - 1, 0):i + 1]), key=lambda x: len(table.rows[x]))
        loads += [(q, float(d)) for d in table.row(near)[0][1:] * q / near]
    return loads


def shear_own_errors(table: ShearTable, level: ShearTable) -> list[tuple[float, list[ShearLoad]]]:
    """``table``'s own error where ``level`` (a :func:`shear_finer` copy) adds nodes, with the loads that would
    mend it: a new row's largest discrepancy against the rows around it carried along the rays (as the law
    interpolates; the zero row at ``p = 0``), a new node of a row its discrepancy against the row's polyline;
    both relative to the table's largest shear (as the tolerance's checks)."""
    scale = max(table._row_scale(p) for p in table.rows)
    P = np.concatenate([[0.0], table.pressures])
    out = []
    for q in sorted(set(level.rows) - set(table.rows)):
        i = min(int(np.searchsorted(P, q)), len(P) - 1)
        lo, hi = P[i - 1], P[i]
        _, s, t = level.row(q)
        f = (q - lo) / (hi - lo)
        guess = f * table.along_ray(hi, q, s) + ((1 - f) * table.along_ray(lo, q, s) if lo > 0 else 0.0)
        out.append((float(np.max(np.abs(t - guess))) / scale, [(q, d) for d in level.rows[q] if d != 0.0]))
    for p in set(table.rows) & set(level.rows):
        _, s, t = table.row(p)
        for d in sorted(set(level.rows[p]) - set(table.rows[p])):
            sm, tm = level.rows[p][d]
            out.append((abs(tm - float(np.interp(sm, s, t))) / scale, [(p, d)]))
    return out


@dataclass
class TableShare:
    """The tables' share of each headline quantity's error at the answer (relative), per table (``parts``), with
    the values and the rounds of refinement that led to it."""

    solution: M.MacroSolution
    values: dict[str, float]
    errors: dict[str, float]
    shares: dict[str, float]
    tolerance: float
    rounds: list[dict[str, Any]] = field(default_factory=list)
    parts: dict[str, dict[str, float]] = field(default_factory=dict)
    not_counted: dict[str, str] = field(default_factory=dict)

    @property
    def share(self) -> float:
        return max(self.shares.values(), default=0.0)

    @property
    def limit(self) -> float:
        return FRACTION * self.tolerance

    def quantity(self) -> dict[str, Any]:
        """The share as a quantity of the accuracy verdict (``cell_table_share``)."""
        parts = {name: {"share": max(q.values(), default=0.0), "per_quantity": dict(q),
                        "largest_in": _largest(q)} for name, q in self.parts.items()}
        return {"name": "cell_table_share", "value": self.share, "error": self.share, "relative_error": self.share,
                "controlled": "relative", "limit": self.limit, "met": self.share <= self.limit, "counted": True,
                "largest_in": _largest(self.shares), "per_quantity": dict(self.shares), "parts": parts,
                "not_counted": dict(self.not_counted), "rounds": self.rounds,
                "how": HOW + f"; the tables' parts added; refined until below {FRACTION:g} of the tolerance"}


def _largest(shares: dict[str, float]) -> str | None:
    return max(shares, key=lambda k: shares[k]) if shares else None


def _changes(a: dict[str, Sample], b: dict[str, Sample]) -> dict[str, float]:
    return {k: abs(b[k].value - a[k].value) for k in a if k in b}


def _finer(table: CellTable, base: dict, pressures) -> CellTable:
    """``base``'s nodes with its intervals around ``pressures`` halved (:meth:`CellTable.used_midpoints`), their
    responses held by ``table``."""
    base_table = CellTable(table.response, table.tol, values=base)
    return CellTable(table.response, table.tol, values={**base, **table.hold(base_table.used_midpoints(pressures))})


def estimate(sol: M.MacroSolution, parts: CellTable | Sequence[PressurePart | ShearPart],
             solve: Callable[..., M.MacroSolution], measure: Callable[[M.MacroSolution], dict[str, Sample]],
             tolerance: float, points_per_element: int = 5, refine: bool = True,
             not_counted: dict[str, str] | None = None) -> TableShare:
    """The tables' share of ``sol``'s headline quantities (``measure``), ``sol`` solved with their law
    (``parts``: :class:`PressurePart` and, with a shear table, :class:`ShearPart`; a bare table is the pressure
    table's part); with ``refine``, the tables refined until the share is below :data:`FRACTION` of
    ``tolerance`` (module docstring; the answer is then the returned ``solution``).
    ``solve(problem, start)``: the scene's macro solve; ``not_counted``: quantities left out, and why.

    Raises
    ------
    ConvergenceError
        The share stays above its limit after :data:`MAX_ROUNDS` rounds or a table's bound on cell solves.
    """
    tables: list[Any] = [PressurePart(parts)] if isinstance(parts, CellTable) else list(parts)
    rounds: list[dict[str, Any]] = []
    own = measure(sol)
    limit = FRACTION * tolerance
    active: list[Any] = list(tables)         # the parts estimated this round; the others' last estimates
    carried: dict[str, dict[str, float]] = {}
    records: dict[str, dict[str, Any]] = {}
    while True:
        solves = _solves(tables)
        levels: dict[str, list[Any]] = {part.name: [] for part in active}
        found: dict[str, list[tuple[M.MacroSolution, dict[str, Sample]]]] = {part.name: [] for part in active}
        for step in range(2):
            for part in active:
                try:
                    level = part.finer(sol, points_per_element, *levels[part.name][-1:])
                except ConvergenceError as err:
                    raise ConvergenceError(_out_of_reach(tolerance, rounds, str(err)),
                                           {"table_share": rounds}) from None
                got = solve(M.replace_law(sol.problem, part.law(level, sol.problem.law)), sol.gfu.vec)
                levels[part.name].append(level)
                found[part.name].append((got, measure(got)))
            if step == 0 and refine and _first_bound(own, found, carried) > limit:
                break                               # refined in any case: the second halving would not decide it
        by_part: dict[str, dict[str, float]] = {}
        record: dict[str, dict[str, Any]] = {}
        second_larger: set[str] = set()
        for part in active:
            once = found[part.name][0][1]
            d1 = _changes(own, once)
            d2 = _changes(once, found[part.name][1][1]) if len(found[part.name]) > 1 else {}
            by_part[part.name] = {k: max(FACTOR * d1[k], d1[k] + FACTOR * d2.get(k, 0.0)) for k in d1}
            second_larger |= {k for k in d1 if d1[k] + FACTOR * d2.get(k, 0.0) > FACTOR * d1[k]
                              and own[k].magnitude > 0 and by_part[part.name][k] / own[k].magnitude > 1e-12}
            sizes = [part.nodes()] + [part.nodes(lv) for lv in levels[part.name]]
            record[part.name] = {"nodes": sizes[0], "midpoints": [b - a for a, b in zip(sizes, sizes[1:])]}
        for part in (p for p in tables if p.name in carried):   # not refined since (module docstring)
            by_part[part.name] = {k: v * own[k].magnitude for k, v in carried[part.name].items() if k in own}
            record[part.name] = {**records[part.name], "nodes": part.nodes(), "midpoints": [], "carried": True}
        by_part = {part.name: by_part[part.name] for part in tables}
        record = {part.name: record[part.name] for part in tables}
        errors = {k: sum(e.get(k, 0.0) for e in by_part.values()) for k in own if k in by_part[active[0].name]}
        shares = {k: e / own[k].magnitude for k, e in errors.items() if own[k].magnitude > 0}
        part_shares = {name: {k: e[k] / own[k].magnitude for k in shares if k in e} for name, e in by_part.items()}
        share = TableShare(sol, {k: s.value for k, s in own.items()}, errors, shares, tolerance, rounds, part_shares,
                           dict(not_counted or {}))
        for name, q in part_shares.items():
            record[name]["share"] = max(q.values(), default=0.0)
        rounds.append({"nodes": {n: r["nodes"] for n, r in record.items()}, "parts": record,
                       "cell_solves": _solves(tables) - solves, "share": share.share,
                       "largest_in": _largest(shares), "second_halving_larger": sorted(second_larger),
                       "halvings": len(found[active[0].name])})
        progress.info("cell tables: %s; their share of the macro quantities %s%.3g (limit %.3g)",
                      ", ".join(f"{n} {r['nodes']} nodes" for n, r in record.items()),
                      "at least " if rounds[-1]["halvings"] < 2 else "", share.share, share.limit)
        if not refine or share.share <= share.limit:
            return share
        if len(rounds) >= MAX_ROUNDS:
            raise ConvergenceError(_out_of_reach(tolerance, rounds, f"{MAX_ROUNDS} halvings are the bound"),
                                   {"table_share": rounds})
        part = max(tables, key=lambda p: record[p.name]["share"])   # the largest part alone (module docstring)
        try:
            level = levels[part.name][0] if part in active else part.finer(sol, points_per_element)
        except ConvergenceError as err:
            raise ConvergenceError(_out_of_reach(tolerance, rounds, str(err)), {"table_share": rounds}) from None
        rounds[-1]["halved"] = {part.name: part.adopt(level)}
        if part in active and rounds[-1]["halved"][part.name] == record[part.name]["midpoints"][0]:
            sol, own = found[part.name][0]     # all of T' adopted: solved already
        else:
            start = found[part.name][0][0].gfu.vec if part in active else sol.gfu.vec
            sol = solve(M.replace_law(sol.problem, part.law(part.table, sol.problem.law)), start)
            own = measure(sol)
        active, carried, records = [part], {n: q for n, q in part_shares.items() if n != part.name}, record


def _solves(tables: Sequence[Any]) -> int:
    """The cell solves of the parts' tables (two parts may halve one table)."""
    return sum(t.solves for t in {id(part.table): part.table for part in tables}.values())


def _first_bound(own: dict[str, Sample], found: dict[str, list[tuple[M.MacroSolution, dict[str, Sample]]]],
                 carried: dict[str, dict[str, float]]) -> float:
    """The share by the first halving alone (twice its change; the parts, ``carried`` too, added): a lower bound."""
    first = [_changes(own, f[0][1]) for f in found.values()] + [{k: v * own[k].magnitude / FACTOR for k, v in
                                                                  c.items() if k in own} for c in carried.values()]
    err = {k: sum(FACTOR * d.get(k, 0.0) for d in first) for k in own}
    return max((e / own[k].magnitude for k, e in err.items() if own[k].magnitude > 0), default=0.0)


def _out_of_reach(tolerance: float, rounds: list[dict[str, Any]], why: str) -> str:
    last = rounds[-1] if rounds else None
    figures = ("no estimate was made" if last is None else
               f"with nodes {last['nodes']} its share is {last['share']:.3g} (in {last['largest_in']}), "
               "shares by round " + ", ".join(f"{r['share']:.3g}" for r in rounds))
    return (f"discretization.tolerance = {tolerance:g} not met by the cell table: {figures}, above "
            f"{FRACTION:g} of the tolerance; {why}; loosen the tolerance or check the cell's response "
            "(a response that does not converge with its table)")

