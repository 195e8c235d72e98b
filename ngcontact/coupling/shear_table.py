"""The cell's tangential response tabulated over pressure and shear, for a cell with micro friction.

A cell with micro friction (Tresca or Coulomb, paper eqs. 9, 16) under a
mean pressure ``p`` and a prescribed tangential far-face jump ``Delta``
transmits a mean shear ``tau`` (the reaction on the counter's far face,
sign: the shear the rough body transmits to the counter) and has a mean
tangential interface jump

    s = int_{S_C} J.t0 |n.n0| ds / int_{S_C} |n.n0| ds,

the tangential companion of the closure of :meth:`ngcontact.cell.fe.fe_cell.FECell.response`
(the far-face jump minus the share of the cell's bulk, which the macro
bodies carry themselves).  For growing ``Delta`` the shear rises while
parts of ``S_C`` stick and levels off when the whole surface slides: on a
sawtooth with micro Coulomb ``mu`` and faces at ``theta`` the plateau is
the wedge's ``tau / p = (tan theta + mu) / (1 - mu tan theta)``, which the
homogenized ``mu0`` of eqs. 42-43 (equal to ``mu`` on any 2D profile) does
not see.  :class:`ShearTable` tabulates rows ``s -> tau`` at pressures
``p_i`` and hands them to the macro problem as the law
:class:`ngcontact.laws.homogenized.CellShear`.

Error control, as the pressure table's (:class:`ngcontact.coupling.pressure_table.CellTable`):

* in the jump, per row: every interval of ``Delta`` is checked at its
  midpoint and halved while ``|tau_mid - T_row(s_mid)| / max_row |tau| >
  tol``; the checked midpoints become nodes; an interval whose ends carry
  the same shear on a row whose shear never decreases is flat and not
  checked (the sliding plateau);
* in the pressure: every interval of pressures is checked by a row at its
  midpoint, halved while ``max_j |tau_mid,j - T(p_mid, s_mid,j)| /
  max |tau| > tol`` (``T`` the law's interpolation of the two outer rows,
  along the rays ``s / p = const``, at the middle row's jumps); the checked
  rows become rows.

The largest accepted discrepancies are the reported error estimates.  The
rows cover the jumps ``[0, s_hi]`` asked for (the macro interface's, with
headroom): a row is extended by doubling ``Delta`` until its last jump
reaches ``s_hi`` or its shear levels off (the last doubling changed it by
at most ``tol``; beyond the row the law holds the shear: the cell slides).
A range asked for that exceeds the rows by at most ``tol`` (relative: in
pressure at either end, and in the jump) is covered already: the loop asks
with headroom, so the interface's own pressures and jumps lie well inside
the rows, while the request moves a little with the macro solution each
time the law changes.  Extended by any excess, the loop's last growth on
the FE friction block (``scripts/two_scale_table_share.py``) moved its
largest pressure by a relative 1e-6 and the loop added four rows within
1e-6 of the last one: the same row solved four more times.
The cell solves of one level (all rows' new nodes together) are independent
and go through ``map_tasks``, like the pressure table's.

On a symmetric sawtooth with micro Coulomb friction the macro block's
sliding ratio ``tau / p`` from this table is the resolved one to many digits
and the rigid wedge's ``(tan a + mu) / (1 - mu tan a)``, where the
hand-set ``mu`` and the bundle with the ``mu0`` of eqs. 42-43 fall well
short (``scripts/sawtooth_shear.py``: docs/benchmarks.md, section
sawtooth_shear).  The rows are interpolated along ``s / p``, not at fixed
``s``: the shear's kink moves with the pressure, so fixed ``s`` needs many
more rows and cell solves for the same tolerance.

Scope: the rows are odd in ``s`` through ``(0, 0)``, which holds for cells
symmetric under ``t0 -> -t0``; a cell that transmits a shear at zero
tangential jump (an asymmetric sawtooth) is refused (:class:`~ngcontact.errors.ModelError`).
2D cells only (one tangent).
"""
from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.cell.fe.measures import contact_integral, mean_jump, mean_traction
from ngcontact.errors import ConvergenceError, ModelError
from ngcontact.fem.quadrature import smooth_order
from ngcontact.laws import homogenized as il

log = logging.getLogger(__name__)

#: ``{"shear", "jump"}`` of the cell at one ``(pressure, far-face jump)``
ShearResponse = dict[str, float]
#: a cell solve of the table: ``(pressure, far-face tangential jump in cell units)``
ShearLoad = tuple[float, float]
#: a lower pressure end below the table is extended to this fraction of the requested one
EXTEND_BELOW = 0.5
#: largest number of doublings of a row's far-face jump
MAX_DOUBLINGS = 24
#: two far-face jumps of one row closer than this (relative) are one load: a row's jumps carried along the rays
#: by two paths (``d q / a`` and ``(d m / a) q / m``) differ in their last bits, and were solved twice
SAME_LOAD = 1e-12


def serial_map(task: Callable[[ShearLoad], ShearResponse], items: Sequence[ShearLoad]) -> list[ShearResponse]:
    """The default ``map_tasks``: the cell solves one after the other."""
    return [task(x) for x in items]


def cell_shear_response(problem: CellProblem, pressure: float, jump: float, length_unit: float = 1.0
                        ) -> ShearResponse:
    """Mean shear and mean tangential interface jump (module docstring) of a 2D cell.

    ``jump`` is the prescribed tangential far-face jump ``Delta`` (rough minus
    counter, cell length units); the returned ``jump`` is ``s`` in metres
    (times ``length_unit``), ``shear`` the mean shear [stress] the rough body
    transmits to the counter along ``t0``.  Solved from a first load's start.
    """
    if problem.dim != 2:
        raise ModelError("the shear table needs a 2D cell (one tangent)")
    load = cell_load(2, pressure=float(pressure), tangential_jump=(float(jump),))
    problem.solve(load, first=True, measure=False)
    n0 = problem.n[1]
    projected = float(contact_integral(problem, ng.IfPos(n0, n0, -n0), order=smooth_order(problem.model.order)))
    s = float(mean_jump(problem)[0]) * problem.area / projected * length_unit
    return {"shear": -float(mean_traction(problem, load)[0]), "jump": s}


@dataclass
class ShearTable:
    """Adaptive table of the cell's shear over pressure and tangential jump (module docstring).

    Parameters
    ----------
    response
        ``(p, Delta) -> {"shear", "jump"}`` (a cell solve, ``Delta`` in cell units).
    tol
        Interpolation tolerance (relative to the largest shear of a row, or of the table).
    length_unit
        Metres per cell length unit (``s`` is in metres, ``Delta`` in cell units).
    max_solves
        Largest number of cell solves of this table (a scene's ``two_scale.max_cell_solves``).
    map_tasks
        Runs the independent cell solves of one level.
    rows
        ``{p: {Delta: (s, tau)}}`` known already (e.g. from a cache).
    """

    response: Callable[[ShearLoad], ShearResponse]
    tol: float
    length_unit: float = 1.0
    max_solves: int = 800
    map_tasks: Callable[[Callable[[ShearLoad], ShearResponse], Sequence[ShearLoad]], list[ShearResponse]] = serial_map
    rows: dict[float, dict[float, tuple[float, float]]] = field(default_factory=dict)
    jump_error: float = 0.0
    pressure_error: float = 0.0
    solves: int = 0
    covered_jump: float = 0.0   # the largest s a cover() asked for
    checked: list[tuple[float, float, float]] = field(default_factory=list)   # (lo, middle, hi) rows checked
    #: solved for the share's estimate (:mod:`ngcontact.coupling.table_share`), not nodes: taken without a solve
    held: dict[ShearLoad, tuple[float, float]] = field(default_factory=dict)

    def _known(self) -> set[ShearLoad]:
        return {(p, d) for p, r in self.rows.items() for d in r} | set(self.held)

    def _fetch(self, todo: list[ShearLoad]) -> dict[ShearLoad, tuple[float, float]]:
        """Cell solves of ``todo`` (none known), counted against :attr:`max_solves`."""
        if not todo:
            return {}
        if self.solves + len(todo) > self.max_solves:
            raise ConvergenceError(f"shear table: more than {self.max_solves} cell solves for tolerance {self.tol:g} "
                                   f"(two_scale.max_cell_solves: {self.solves} made, {len(todo)} more asked)",
                                   {"pressures": sorted(self.rows)})
        out = {}
        for (p, d), value in zip(todo, self.map_tasks(self.response, todo)):
            s, t = float(value["jump"]), float(value["shear"])
            if not (np.isfinite(s) and np.isfinite(t)):
                raise ConvergenceError(f"shear table: non-finite cell response at p = {p:.6g}, jump {d:.6g}",
                                       dict(value))
            out[(p, d)] = (s, t)
        self.solves += len(todo)
        return out

    def _matched(self, loads: Sequence[ShearLoad]) -> set[ShearLoad]:
        """``loads``, each replaced by a known one of its row within :data:`SAME_LOAD` where there is one."""
        rows: dict[float, list[float]] = {}
        for p, d in self._known():
            rows.setdefault(p, []).append(d)
        out = set()
        for p, d in loads:
            p, d = float(p), float(d)
            ds = np.asarray(rows.get(p, []), dtype=float)
            if ds.size:
                near = float(ds[np.argmin(np.abs(ds - d))])
                d = near if abs(near - d) <= SAME_LOAD * abs(d) else d
            out.add((p, d))
        return out

    def _solve(self, loads: Sequence[ShearLoad], match: bool = False) -> None:
        """Make ``loads`` nodes (held ones without a cell solve); with ``match`` a load known to round-off
        (:data:`SAME_LOAD`) is the known one."""
        wanted = self._matched(loads) if match else {(float(p), float(d)) for p, d in loads}
        for load in sorted(wanted & set(self.held)):
            self.rows.setdefault(load[0], {0.0: (0.0, 0.0)})[load[1]] = self.held.pop(load)
        for (p, d), v in self._fetch(sorted(wanted - self._known())).items():
            self.rows.setdefault(p, {0.0: (0.0, 0.0)})[d] = v

    def hold(self, loads: Sequence[ShearLoad]) -> dict[ShearLoad, tuple[float, float]]:
        """The responses at ``loads`` (solved where neither a node nor held), kept in :attr:`held` where they
        are not nodes (a load known to round-off, :data:`SAME_LOAD`, is the known one); the table's law is
        unchanged."""
        wanted = self._matched(loads)
        self.held.update(self._fetch(sorted(wanted - self._known())))
        return {(p, d): self.rows[p][d] if p in self.rows and d in self.rows[p] else self.held[(p, d)]
                for p, d in wanted}

    def row(self, p: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(Delta, s, tau)`` of the row at ``p``, sorted by ``Delta``."""
        r = self.rows[p]
        d = np.array(sorted(r))
        return d, np.array([r[x][0] for x in d]), np.array([r[x][1] for x in d])

    @property
    def pressures(self) -> np.ndarray:
        return np.array(sorted(self.rows))

    def _row_scale(self, p: float) -> float:
        return max(float(np.max(np.abs(self.row(p)[2]))), 1e-300)

    def _plateaued(self, p: float) -> bool:
        """The row's shear changed by at most ``tol`` over the last doubling of the far-face jump."""
        r = self.rows[p]
        last = max(r)
        return last > 0 and 0.5 * last in r and abs(r[last][1] - r[0.5 * last][1]) <= self.tol * self._row_scale(p)

    def _build(self, pressures: Sequence[float], s_hi: float) -> None:
        """Start, extend and refine the rows at ``pressures`` (all rows' solves of a level together)."""
        pressures = [float(p) for p in pressures]
        d_hi = s_hi / self.length_unit
        old = {p: set(self.rows.get(p, ())) for p in pressures}
        self._solve([(p, f * d_hi) for p in pressures for f in (0.25, 0.5, 1.0) if p not in self.rows])
        for _ in range(MAX_DOUBLINGS):
            short = [p for p in pressures if self.row(p)[1][-1] < s_hi and not self._plateaued(p)]
            if not short:
                break
            self._solve([(p, 2.0 * self.row(p)[0][-1]) for p in short])
        else:
            raise ConvergenceError(f"shear table: rows reach neither the jump {s_hi:.3e} nor a plateau after "
                                   f"{MAX_DOUBLINGS} doublings", {"pressures": pressures})
        intervals = [(p, a, b) for p in pressures for a, b in zip(self.row(p)[0][:-1], self.row(p)[0][1:])
                     if not (a in old[p] and b in old[p])]
        while intervals:
            mids = [(p, 0.5 * (a + b)) for p, a, b in intervals]
            self._solve([pm for pm, (p, a, b) in zip(mids, intervals) if not self._flat(p, a, b)])
            nxt = []
            for (p, a, b), (_, m) in zip(intervals, mids):
                if m not in self.rows[p]:     # a flat interval of a monotone row: not solved (see _flat)
                    continue
                r = self.rows[p]
                (sa, ta), (sb, tb), (sm, tm) = r[a], r[b], r[m]
                guess = ta + (tb - ta) * (sm - sa) / (sb - sa) if sb != sa else tb
                err = abs(tm - guess) / self._row_scale(p)
                if err > self.tol and b - a > 1e-6 * b:
                    nxt += [(p, a, m), (p, m, b)]
                else:
                    self.jump_error = max(self.jump_error, err)
            intervals = nxt

    def _flat(self, p: float, a: float, b: float) -> bool:
        """Both ends of ``[a, b]`` carry the same shear (to ``1e-3 tol``) and the row is monotone.

        A shear that does not decrease with the far-face jump is constant
        between two equal values, and the polyline is exact there: the
        sliding plateau is not checked point by point.
        """
        _, _, t = self.row(p)
        r = self.rows[p]
        return bool(np.all(np.diff(t) >= -1e-9 * self._row_scale(p))) and \
            abs(r[b][1] - r[a][1]) <= 1e-3 * self.tol * self._row_scale(p)

    def _check_odd(self, p: float) -> None:
        """Refuse a cell that transmits a shear at zero tangential jump (the rows are odd through 0)."""
        t0 = float(self.response((p, 0.0))["shear"])
        self.solves += 1
        if abs(t0) > self.tol * self._row_scale(p):
            raise ModelError(f"shear table: the cell transmits a shear {t0:.6g} at zero tangential jump under "
                             f"p = {p:.6g} (an asymmetric profile); the tabulated cell shear assumes a cell "
                             "symmetric under t0 -> -t0")

    # ------------------------------------------------------------ cover
    def along_ray(self, row: float, p: float, s: np.ndarray) -> np.ndarray:
        """The row at ``row`` carried to the pressure ``p`` along ``s / p = const`` (as the law interpolates)."""
        r = p / row
        return r * np.interp(np.asarray(s) / r, self.row(row)[1], self.row(row)[2])

    def _triple_error(self, lo: float, m: float, hi: float) -> float:
        """Largest discrepancy of the row at ``m`` against the rows at ``lo`` and ``hi`` interpolated."""
        _, s, t = self.row(m)
        f = (m - lo) / (hi - lo)
        guess = (1 - f) * self.along_ray(lo, m, s) + f * self.along_ray(hi, m, s)
        return float(np.max(np.abs(t - guess))) / max(self._row_scale(p) for p in self.rows)

    def _refine_pressures(self, intervals: list[tuple[float, float]], s_hi: float) -> None:
        """Check ``intervals`` by their middle rows (one level of rows at a time), halving the failed ones."""
        while intervals:
            mids = [0.5 * (a + b) for a, b in intervals]
            self._build(mids, s_hi)
            nxt = []
            for (lo, hi), m in zip(intervals, mids):
                err = self._triple_error(lo, m, hi)
                self.checked.append((lo, m, hi))
                if err > self.tol and hi - lo > 1e-6 * hi:
                    nxt += [(lo, m), (m, hi)]
                else:
                    self.pressure_error = max(self.pressure_error, err)
            intervals = nxt

    def cover(self, lo: float, hi: float, s_hi: float, start_nodes: int = 3) -> bool:
        """Make the table span the pressures ``[lo, hi]`` and the jumps ``[0, s_hi]``; True if it grew."""
        if not (0 < lo < hi and s_hi > 0):
            raise ModelError(f"shear table range p in [{lo!r}, {hi!r}], s up to {s_hi!r}: need 0 < lo < hi, s > 0")
        before = self.solves
        if not self.rows:
            nodes = [float(q) for q in np.geomspace(EXTEND_BELOW * lo, hi, start_nodes)]
            self._build(nodes, s_hi)
            self._check_odd(nodes[-1])
            new = nodes
        else:
            P = list(self.pressures)
            new = []
            if lo < P[0] * (1 - self.tol):       # within tol of the rows: covered (module docstring)
                new += [float(q) for q in np.geomspace(EXTEND_BELOW * lo, P[0], start_nodes)[:-1]]
            if hi > P[-1] * (1 + self.tol):
                new += [float(q) for q in np.geomspace(P[-1], hi, start_nodes)[1:]]
            if s_hi <= self.covered_jump * (1 + self.tol):
                s_hi = min(s_hi, self.covered_jump)
            self._build(sorted(set(P) | set(new)), max(s_hi, self.covered_jump))
        longer = s_hi > self.covered_jump and bool(self.checked)
        self.covered_jump = max(self.covered_jump, s_hi)
        P = list(self.pressures)
        todo = [(a, b) for a, b in zip(P[:-1], P[1:]) if a in new or b in new]
        if longer:
            # the rows grew in s: the pressure intervals checked before are checked again on the longer rows
            self.pressure_error = 0.0
            for lo, m, hi in self.checked:
                if self._triple_error(lo, m, hi) > self.tol and hi - lo > 1e-6 * hi:
                    todo += [(lo, m), (m, hi)]
                else:
                    self.pressure_error = max(self.pressure_error, self._triple_error(lo, m, hi))
        self._refine_pressures(sorted(set(todo)), self.covered_jump)
        if self.solves > before:
            log.info("shear table: %d rows over p in [%.3e, %.3e], s up to %.3e (%d cell solves), error "
                     "estimates %.2e (jump), %.2e (pressure)", len(self.rows), P[0], P[-1], self.covered_jump,
                     self.solves, self.jump_error, self.pressure_error)
        return self.solves > before

    # ------------------------------------------------------------ law and report
    def law(self) -> il.CellShear:
        """The :class:`~ngcontact.laws.homogenized.CellShear` of the rows (a zero row at ``p = 0``)."""
        P = self.pressures
        jumps: list[tuple[float, ...]] = [(0.0, 1.0)]
        shears: list[tuple[float, ...]] = [(0.0, 0.0)]
        for p in P:
            _, s, t = self.row(p)
            keep = np.concatenate([[True], np.diff(s) > 1e-12 * max(float(s[-1]), 1e-300)])
            if np.any(np.diff(s[keep]) <= 0):
                raise ModelError(f"shear table: the tangential jump does not grow with the far-face jump at "
                                 f"p = {p:.6g}; the cell response is not monotone")
            jumps.append(tuple(float(x) for x in s[keep]))
            shears.append(tuple(float(x) for x in t[keep]))
        return il.CellShear(pressure=(0.0, *map(float, P)), jumps=tuple(jumps), shears=tuple(shears))

    def as_dict(self) -> dict:
        P = self.pressures
        return {"pressure": P.tolist(), "rows": len(P), "nodes": int(sum(len(self.rows[p]) for p in P)),
                "cell_solves": self.solves, "tolerance": self.tol, "jump_error_estimate": self.jump_error,
                "pressure_error_estimate": self.pressure_error, "covered_jump": self.covered_jump,
                "far_face_jump": [self.row(p)[0].tolist() for p in P],
                "jump": [self.row(p)[1].tolist() for p in P], "shear": [self.row(p)[2].tolist() for p in P]}
