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

Refinement: while the share exceeds :data:`FRACTION` of the tolerance, ``T`` becomes ``T'`` (its solution is
the one just solved, now the answer) and the estimate is made again on the new intervals, at most
:data:`MAX_ROUNDS` times; beyond that, or past the table's bound on its cell solves, the tolerance is out of
reach and the run ends with its figures (a :class:`~ngcontact.errors.ConvergenceError`, exit 3).  The rest of
the tolerance is left to the macro discretization and the loop's residual, each judged on its own.

The midpoints of the last estimate are solved but are not nodes of the answer's law: the table keeps them
(:attr:`~ngcontact.coupling.pressure_table.CellTable.held`) and the cache stores them, so that a second run
of the scene reproduces the first and estimates its share without a cell solve.
"""
from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ngcontact.coupling.pressure_table import CellTable, response_law
from ngcontact.errors import ConvergenceError
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.macro.discretization_error import Sample
from ngcontact.macro.macro_measures import interface_samples

log = logging.getLogger(__name__)
progress = logging.getLogger("ngcontact.progress")

#: the table is refined until its share is below this fraction of ``discretization.tolerance``
FRACTION = 0.5
#: the most halvings of the intervals the interface's pressures lie in
MAX_ROUNDS = 8
#: the estimate's factor on the difference (module docstring: the error at least halves with the intervals)
FACTOR = 2.0
#: what the report's ``how`` says
HOW = ("the table's intervals holding the macro interface's pressures (and one more on either side) halved "
       "twice (one cell solve at each midpoint) and the macro problem solved again with each law: the larger of "
       "twice the first change of each headline quantity and the first change plus twice the second (the "
       "monotone cubic's error at least halves with its intervals; ngcontact.coupling.table_share)")


@dataclass
class TableShare:
    """The table's share of each headline quantity's error at the answer (relative, :data:`FACTOR` times the
    change), with the values and the rounds of refinement that led to it."""

    solution: M.MacroSolution
    values: dict[str, float]
    errors: dict[str, float]
    shares: dict[str, float]
    tolerance: float
    rounds: list[dict[str, Any]] = field(default_factory=list)

    @property
    def share(self) -> float:
        return max(self.shares.values(), default=0.0)

    @property
    def limit(self) -> float:
        return FRACTION * self.tolerance

    def quantity(self) -> dict[str, Any]:
        """The share as a quantity of the accuracy verdict (``cell_table_share``)."""
        worst = max(self.shares, key=lambda k: self.shares[k]) if self.shares else None
        return {"name": "cell_table_share", "value": self.share, "error": self.share, "relative_error": self.share,
                "controlled": "relative", "limit": self.limit, "met": self.share <= self.limit, "counted": True,
                "largest_in": worst, "per_quantity": dict(self.shares), "rounds": self.rounds,
                "how": HOW + f"; refined until below {FRACTION:g} of the tolerance"}


def _changes(a: dict[str, Sample], b: dict[str, Sample]) -> dict[str, float]:
    return {k: abs(b[k].value - a[k].value) for k in a if k in b}


def _finer(table: CellTable, base: dict, pressures) -> CellTable:
    """``base``'s nodes with its intervals around ``pressures`` halved (:meth:`CellTable.used_midpoints`), their
    responses held by ``table``."""
    base_table = CellTable(table.response, table.tol, values=base)
    return CellTable(table.response, table.tol, values={**base, **table.hold(base_table.used_midpoints(pressures))})


def estimate(sol: M.MacroSolution, table: CellTable, solve: Callable[..., M.MacroSolution],
             measure: Callable[[M.MacroSolution], dict[str, Sample]], tolerance: float,
             points_per_element: int = 5, refine: bool = True) -> TableShare:
    """The table's share of ``sol``'s headline quantities (``measure``), ``sol`` solved with the law of
    ``table``; with ``refine``, the table refined until the share is below :data:`FRACTION` of
    ``tolerance`` (module docstring; the answer is then the returned ``solution``).
    ``solve(problem, start)``: the scene's macro solve.

    Raises
    ------
    ConvergenceError
        The share stays above its limit after :data:`MAX_ROUNDS` rounds or the table's bound on cell solves.
    """
    rounds: list[dict[str, Any]] = []
    own = measure(sol)
    while True:
        p = interface_samples(sol, points_per_element)["pressure"]
        p = p[p > 0]
        solves, held = table.solves, len(table.held)
        solutions = []
        try:
            levels = [_finer(table, dict(table.values), p)]
            levels.append(_finer(table, dict(levels[0].values), p))
        except ConvergenceError as err:
            raise ConvergenceError(_out_of_reach(tolerance, rounds, str(err)), {"table_share": rounds}) from None
        for level in levels:
            law = il.InterfaceLaw(normal=response_law(level), friction=sol.problem.law.friction)
            solutions.append(solve(M.replace_law(sol.problem, law), sol.gfu.vec))
        once, twice = (measure(s) for s in solutions)
        d1, d2 = _changes(own, once), _changes(once, twice)
        errors = {k: max(FACTOR * d1[k], d1[k] + FACTOR * d2.get(k, 0.0)) for k in d1}
        shares = {k: e / own[k].magnitude for k, e in errors.items() if own[k].magnitude > 0}
        share = TableShare(sol, {k: s.value for k, s in own.items()}, errors, shares, tolerance, rounds)
        sizes = [len(table.values)] + [len(lv.values) for lv in levels]
        rounds.append({"nodes": sizes[0], "midpoints": [b - a for a, b in zip(sizes, sizes[1:])],
                       "cell_solves": table.solves - solves, "held_before": held, "share": share.share,
                       "largest_in": max(shares, key=lambda k: shares[k]) if shares else None,
                       "second_halving_larger": sorted(k for k in d1 if d1[k] + FACTOR * d2.get(k, 0.0)
                                                       > FACTOR * d1[k] and own[k].magnitude > 0
                                                       and errors[k] / own[k].magnitude > 1e-12)})
        progress.info("cell table: %d nodes; its share of the macro quantities %.3g (limit %.3g)",
                      len(table.values), share.share, share.limit)
        if not refine or share.share <= share.limit:
            return share
        if len(rounds) >= MAX_ROUNDS:
            raise ConvergenceError(_out_of_reach(tolerance, rounds, f"{MAX_ROUNDS} halvings are the bound"),
                                   {"table_share": rounds})
        for m in set(levels[0].values) - set(table.values):
            table.values[m] = table.held.pop(m)
        sol, own = solutions[0], once


def _out_of_reach(tolerance: float, rounds: list[dict[str, Any]], why: str) -> str:
    last = rounds[-1] if rounds else None
    figures = ("no estimate was made" if last is None else
               f"with {last['nodes']} nodes its share is {last['share']:.3g} (in {last['largest_in']}), "
               "shares by round " + ", ".join(f"{r['share']:.3g}" for r in rounds))
    return (f"discretization.tolerance = {tolerance:g} not met by the cell table: {figures}, above "
            f"{FRACTION:g} of the tolerance; {why}; loosen the tolerance or check the cell's response "
            "(a response that does not converge with its table)")

