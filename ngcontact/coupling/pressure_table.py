"""The cell's response over the pressure, tabulated: the table of the two-scale loop and its macro law.

The cell at a mean pressure ``p`` (compression positive) answers with its
real contact fraction, the coefficients of eq. 34 on its real contact set
and its mean closure ``c(p)``, whichever method solves it
(:meth:`ngcontact.cell.cell_solver.CellSolver.response`); the two-scale loop
(:mod:`ngcontact.coupling.two_scale`, paper Sec. 3.5) reads them from a
table over ``p`` and hands the macro problem the law ``p = P(c)``
(:func:`response_law`).

The table (:class:`CellTable`) is adaptive: every interval is checked at
its midpoint against a cell solve and halved while

    max(|f_mid - F(p_mid)| / max f, |c_mid - C(p_mid)| / max |c|, |p_mid - P(c_mid)| / max p) > table_tol

(``f`` the contact fraction, ``c`` the closure; ``F`` and ``C`` their
monotone cubic interpolants in ``p`` over the nodes before the check, what
:meth:`CellTable.__call__` returns, and ``P`` the macro law
:func:`response_law` of those nodes, the same interpolant in ``c``).  The
checked midpoints become nodes too, so the largest accepted discrepancy is
a conservative estimate of the interpolation error.  The interpolants are
the shape-preserving C1 cubics of Fritsch and Carlson
(:class:`~ngcontact.laws.homogenized.TabulatedLaw`): on the femur's
stem-grooves cell they meet the tolerance with about half the cell solves
a polyline needs, and the law they give has a continuous tangent.
The cell solves of one level of refinement (the start nodes, then the
midpoints of all intervals still to check) are independent; they go
through the table's ``map_tasks`` callable (``map_tasks(response,
pressures) -> responses``, serial by default), into which a process pool
can be plugged.  The number of cell solves does not
depend on the number of macro interface points.
"""
from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ngcontact.cell.cell_solver import RESPONSE_KEYS, Response
from ngcontact.errors import ConvergenceError, ModelError
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.laws import monotone_cubic

log = logging.getLogger(__name__)

#: the keys of a response (:data:`ngcontact.cell.cell_solver.Response`)
KEYS = RESPONSE_KEYS
#: the quantities whose interpolation error the table controls
CHECKED = ("contact_fraction", "closure")
#: a lower table end below the table is extended to this fraction of the requested one
EXTEND_BELOW = 0.5
#: relative amount by which a requested range may exceed the table without extending it (round-off of
#: the macro pressures between runs)
SLACK = 1e-6


def serial_map(task: Callable[[float], Response], items: Sequence[float]) -> list[Response]:
    """The default ``map_tasks``: the cell solves one after the other."""
    return [task(x) for x in items]


@dataclass
class CellTable:
    """Adaptive piecewise-linear table of a cell response in the pressure.

    Parameters
    ----------
    response
        Function ``p -> {"contact_fraction", "k_n0", "g_n0", "closure"}`` (a cell solve).
    tol
        Interpolation tolerance (module docstring).
    max_solves
        Largest number of cell solves of this table before giving up.
    map_tasks
        ``map_tasks(response, pressures) -> [response(p) for p in pressures]``:
        runs the independent cell solves of one refinement level.
    values
        Responses known already (e.g. read from a cache): not solved again.
    held
        Responses solved but not nodes of the table (the midpoints of the last estimate of the table's share
        of a macro run's error, :mod:`ngcontact.coupling.table_share`): a pressure asked for that is held
        becomes a node without a cell solve.
    """

    response: Callable[[float], Response]
    tol: float
    max_solves: int = 400
    map_tasks: Callable[[Callable[[float], Response], Sequence[float]], list[Response]] = serial_map
    values: dict[float, Response] = field(default_factory=dict)
    error_estimate: float = 0.0
    solves: int = 0   # cell problems solved by this table (not those it was given)
    held: dict[float, Response] = field(default_factory=dict)

    @property
    def pressures(self) -> np.ndarray:
        return np.array(sorted(self.values))

    def _solve(self, pressures) -> None:
        todo = sorted({float(p) for p in pressures} - set(self.values))
        for p in [p for p in todo if p in self.held]:
            self.values[p] = self.held.pop(p)
        todo = [p for p in todo if p not in self.values]
        if not todo:
            return
        if self.solves + len(todo) > self.max_solves:
            raise ConvergenceError(f"cell table: more than {self.max_solves} cell solves for "
                                   f"tolerance {self.tol:g} (two_scale.max_cell_solves: {self.solves} made, "
                                   f"{len(todo)} more asked)", {"pressures": sorted(self.values)})
        for p, value in zip(todo, self.map_tasks(self.response, todo)):
            if not all(np.isfinite(value[k]) for k in KEYS):
                raise ConvergenceError(f"cell table: non-finite cell response at p = {p:.6g}", dict(value))
            self.values[p] = {k: float(value[k]) for k in KEYS}
        self.solves += len(todo)

    def hold(self, pressures) -> dict[float, Response]:
        """The responses at ``pressures`` (solved where neither a node nor held), kept in :attr:`held` where they
        are not nodes; the table's law is unchanged."""
        nodes = dict(self.values)
        self._solve(pressures)
        self.held.update({p: v for p, v in self.values.items() if p not in nodes})
        self.values = nodes
        return {float(p): (nodes.get(float(p)) or self.held[float(p)]) for p in pressures}

    def used_midpoints(self, pressures, margin: int = 1) -> list[float]:
        """The midpoints of the table's intervals from the one holding the least of ``pressures`` to the one
        holding the largest (the pressures a macro solution uses: its law's error reaches it there only),
        and ``margin`` more on either side, whose nodes' slopes the cubic's in the range depend on."""
        P = self.pressures
        p = np.asarray(pressures, float)
        p = p[(p >= P[0]) & (p <= P[-1])]
        if not len(p):
            return []
        k = np.clip(np.searchsorted(P, [p.min(), p.max()], side="right") - 1, 0, len(P) - 2)
        lo, hi = max(int(k[0]) - margin, 0), min(int(k[1]) + margin, len(P) - 2)
        return [float(0.5 * (P[i] + P[i + 1])) for i in range(lo, hi + 1)]

    def _scale(self, key: str) -> float:
        return max([abs(v[key]) for v in self.values.values()] + [1e-300])

    def discrepancy(self, responses: dict[float, Response], scales: CellTable | None = None) -> dict[float, float]:
        """The largest relative discrepancy of each of ``responses`` (pressure -> response) against this table's
        interpolants and law (module docstring), relative to the largest values of ``scales`` (default this
        table)."""
        law, scales = response_law(self), scales or self
        p_scale = float(max(scales.pressures[-1], max(responses)))
        out = {}
        for m, vm in responses.items():
            at = self(m)
            out[m] = max([abs(vm[k] - float(at[k])) / scales._scale(k) for k in CHECKED]
                         + [abs(m - float(ie.pressure(law, [vm["closure"], 0.0]))) / p_scale])
        return out

    def _refine(self, intervals: list[tuple[float, float]]) -> None:
        """Check the intervals level by level (one batch of independent cell solves per level)."""
        while intervals:
            mids = [0.5 * (a + b) for a, b in intervals]
            before = CellTable(self.response, self.tol, values=dict(self.values))  # the nodes before this level
            self._solve(mids)
            errors = before.discrepancy({m: self.values[m] for m in mids}, self)
            nxt = []
            for (lo, hi), m in zip(intervals, mids):
                err = errors[m]
                if err > self.tol and hi - lo > 1e-6 * hi:
                    nxt += [(lo, m), (m, hi)]
                else:
                    self.error_estimate = max(self.error_estimate, err)
            intervals = nxt

    def cover(self, lo: float, hi: float, start_nodes: int = 5) -> bool:
        """Make the table span ``[lo, hi]`` (``0 < lo < hi``) within the tolerance; True if it grew."""
        if not 0 < lo < hi:
            raise ModelError(f"table range [{lo!r}, {hi!r}]: need 0 < lo < hi")
        if not self.values:
            nodes = list(np.geomspace(EXTEND_BELOW * lo, hi, start_nodes))
        else:
            p = self.pressures
            below, above = lo < p[0] * (1 - SLACK), hi > p[-1] * (1 + SLACK)
            if not (below or above):
                return False
            nodes = list(p)
            if below:
                nodes = list(np.geomspace(EXTEND_BELOW * lo, p[0], start_nodes)[:-1]) + nodes
            if above:
                nodes = nodes + list(np.geomspace(p[-1], hi, start_nodes)[1:])
        nodes = [float(q) for q in nodes]
        old = set(self.values)
        self._solve(nodes)
        self._refine([(a, b) for a, b in zip(nodes[:-1], nodes[1:]) if not (a in old and b in old)])
        log.info("cell table: %d nodes over [%.3e, %.3e] (%d cell solves), error estimate %.2e",
                 len(self.values), self.pressures[0], self.pressures[-1], self.solves, self.error_estimate)
        return True

    def __call__(self, p: float | np.ndarray) -> dict[str, np.ndarray | np.float64]:
        """Interpolated response at pressures ``p`` (held constant outside the table): the monotone cubic
        of each quantity in ``p`` (module docstring)."""
        P = self.pressures
        out: dict[str, np.ndarray | np.float64] = {}
        for key in KEYS:
            v = [self.values[q][key] for q in P]
            out[key] = monotone_cubic.evaluate(P, v, monotone_cubic.slopes(P, v), p)
        return out

    def as_dict(self) -> dict[str, list[float] | int | float]:
        P = self.pressures
        return {"pressure": P.tolist(), "cell_solves": self.solves, "nodes": len(P), "tolerance": self.tol,
                "error_estimate": self.error_estimate, "held": len(self.held),
                **{key: [self.values[q][key] for q in P] for key in KEYS}}


def response_law(table: CellTable) -> il.TabulatedLaw:
    """The cell's response ``p = P(c)`` as a tabulated normal law (module docstring).

    Raises
    ------
    ModelError
        The tabulated closure does not increase with the pressure (the cell
        response is not monotone, e.g. a cell solve that did not converge).
    """
    P = table.pressures
    c = np.array([table.values[q]["closure"] for q in P])
    # nodes closer than round-off to their neighbour carry no information and spoil the slopes
    keep = np.concatenate([[True], np.abs(np.diff(c)) > 1e-9 * np.max(np.abs(c))])
    P, c = P[keep], c[keep]
    if len(P) < 2:
        raise ModelError("cell table: need at least two distinct pressures for a law")
    if np.any(np.diff(c) <= 0):
        k = int(np.argmin(np.diff(c)))
        raise ModelError(f"cell table: the closure does not increase with the pressure between p = {P[k]:.6g} "
                         f"and {P[k + 1]:.6g} ({c[k]:.6g} -> {c[k + 1]:.6g}); the cell response is not monotone")
    c0 = c[0] - P[0] * (c[1] - c[0]) / (P[1] - P[0])   # first secant down to p = 0
    return il.TabulatedLaw(closure=(float(c0), *map(float, c)), pressure=(0.0, *map(float, P)),
                           interpolation="monotone_cubic")
