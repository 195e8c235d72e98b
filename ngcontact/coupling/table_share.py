"""The cell table's share of a two-scale run's error, and the table refined towards ``discretization.tolerance``.

The macro law of a two-scale run is the table's ``p = P_T(c)`` (:mod:`ngcontact.coupling.pressure_table`;
the loop of paper Sec. 3.5 converges to the macro problem with that law).  Its interpolation error reaches a
headline quantity ``Q`` of the macro solution (peak pressure, interface resultant, stress maxima:
:func:`ngcontact.macro.discretization_error.headlines`) only through the table's intervals in which the
pressures of the macro interface lie.  Those intervals are halved,

    T' = T + { (p_i + p_{i+1}) / 2 : some interface pressure lies in [p_i, p_{i+1}] },

the macro problem is solved once more with the law of ``T'`` (warm from the solution with ``T``) and

    d_Q = |Q(T') - Q(T)|,    e_Q = 2 d_Q,    share = max_Q e_Q / |Q|

is the estimate of the table's error of each quantity of the solution with ``T``.  Why twice the
difference: with ``e = Q(T) - Q*`` and ``e' = Q(T') - Q* = rho e``, ``|e| = d_Q / |1 - rho|``, which is at
most ``2 d_Q`` when ``|rho| <= 1/2``: the error of the monotone cubic at least halves where its intervals
are halved (first order at a kink of the cell's response, such as the onset of full contact, of third order
where it is smooth).  The estimate's effectivity ``2 |1 - rho|`` then lies in ``[1, 3]``.

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
HOW = ("the table's intervals holding the macro interface's pressures halved (one cell solve at each "
       "midpoint) and the macro problem solved again with that law: twice the change of each headline "
       "quantity (the monotone cubic's error at least halves with its intervals; "
       "ngcontact.coupling.table_share)")


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


def _shares(a: dict[str, Sample], b: dict[str, Sample]) -> tuple[dict[str, float], dict[str, float]]:
    errors = {k: FACTOR * abs(b[k].value - a[k].value) for k in a if k in b}
    return errors, {k: e / a[k].magnitude for k, e in errors.items() if a[k].magnitude > 0}


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
        mids = table.used_midpoints(p[p > 0])
        solves = table.solves
        try:
            finer = CellTable(table.response, table.tol, values={**table.values, **table.hold(mids)})
        except ConvergenceError as err:
            raise ConvergenceError(_out_of_reach(tolerance, rounds, str(err)), {"table_share": rounds}) from None
        law = il.InterfaceLaw(normal=response_law(finer), friction=sol.problem.law.friction)
        other = solve(M.replace_law(sol.problem, law), sol.gfu.vec)
        again = measure(other)
        errors, shares = _shares(own, again)
        share = TableShare(sol, {k: s.value for k, s in own.items()}, errors, shares, tolerance, rounds)
        rounds.append({"nodes": len(table.values), "midpoints": len(mids), "cell_solves": table.solves - solves,
                       "share": share.share, "largest_in": max(shares, key=lambda k: shares[k]) if shares else None})
        progress.info("cell table: %d nodes, %d intervals used; its share of the macro quantities %.3g (limit %.3g)",
                      len(table.values), len(mids), share.share, share.limit)
        if not refine or share.share <= share.limit:
            return share
        if len(rounds) >= MAX_ROUNDS:
            raise ConvergenceError(_out_of_reach(tolerance, rounds, f"{MAX_ROUNDS} halvings are the bound"),
                                   {"table_share": rounds})
        for m in mids:
            table.values[m] = table.held.pop(m)
        sol, own = other, again


def _out_of_reach(tolerance: float, rounds: list[dict[str, Any]], why: str) -> str:
    last = rounds[-1] if rounds else None
    figures = ("no estimate was made" if last is None else
               f"with {last['nodes']} nodes its share is {last['share']:.3g} (in {last['largest_in']}), "
               "shares by round " + ", ".join(f"{r['share']:.3g}" for r in rounds))
    return (f"discretization.tolerance = {tolerance:g} not met by the cell table: {figures}, above "
            f"{FRACTION:g} of the tolerance; {why}; loosen the tolerance or check the cell's response "
            "(a response that does not converge with its table)")

