"""The two-scale coupling loop of paper Sec. 3.5, with a tabulated cell response.

The cell at a mean pressure ``p`` (compression positive) has a real contact
set ``S_C(p)``, the coefficients of eq. 34 on it,

    k_n0(p) = (1/|T|) int_{S_C(p)} k_n (n.n0)^2 ds,      g_n0(p) = k_n0(p) c(p) - p,

and a mean closure ``c(p)``: the projected mean normal jump on ``S_C``
(:func:`cell_response`).  The law of step ii of Sec. 3.5 at an interface
point ``x`` whose previous macro pressure is ``p_k(x)`` is the Winkler law
``p = k_n0(p_k) (a_n - g0) - g_n0(p_k)``; at its fixed point ``p_{k+1} =
p_k = p`` it reads ``a_n - g0 = c(p)``.  The loop is therefore the chord
iteration of the macro problem whose law is the cell's own response
``p = P(a_n - g0)``, ``P`` the inverse of the monotone ``c(p)``, with the
chord slope ``k_n0`` instead of the tangent ``dP/dc``: it converges only
linearly (on the femur the change fell by about 0.4 per update, 6 updates),
and a law frozen at ``p_k`` is not the derivative of any energy of the
state, so its energy, residual and tangent describe a different problem
at every update.

Here the macro law is ``P`` itself, the :class:`~ngcontact.laws.homogenized.TabulatedLaw`
of the table's pairs ``(c_i, p_i)`` (:func:`response_law`):

    W(a) = int_{c_0}^{a_n - g0} P(s) ds,    tau_n = P(a_n - g0),    dtau_n/da_n = P'(a_n - g0),

whose energy, traction and tangent are consistent (tests/laws).  The pair
``(c_0, 0)`` below the smallest tabulated pressure extends the first secant
of the table to ``p = 0``.  Newton solves the nonlinearity of ``P`` inside
the macro solve; the loop only grows the table:

0. the macro problem is solved with the law it was given (the assumed
   contact set ``S_C(0)``), and, when the table already holds responses
   (read from the cache), then with :func:`response_law` of that table,
   warm-started from that solution;
1. the table is made to cover ``[table_min p_max, headroom p_max]`` of the
   current macro pressures (extensions go down to half the requested lower
   end, so that a slightly lower peak does not extend it again);
2. if the table grew, the macro problem is solved again with
   :func:`response_law`, warm-started from the solution with the law it
   was given (on the femur with Coulomb friction by the coupled Newton: 4
   Newton steps against 22 cold; always from that state, so that the answer
   does not depend on the path by which the table grew); its
   change ``max_x |sigma_n^(k)(x) - sigma_n^(k-1)(x)|`` is recorded and the
   loop stops below ``tol``; if it did not grow, the law is the one just
   solved with, whose solution is unchanged: the loop stops (change 0,
   no solve);
3. otherwise repeat from 1, or stop with a
   :class:`~ngcontact.errors.ConvergenceError` after ``max_iter`` updates.

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
(:class:`~ngcontact.laws.homogenized.TabulatedLaw`): measured on the
femur's stem-grooves cell (``table_tol`` 0.01, pressures 13 kPa to 32.5
MPa) they meet the tolerance with 11 cell solves where the polyline that
was used before needed 23, and the law they give has a continuous tangent.
The cell solves of one level of refinement (the start nodes, then the
midpoints of all intervals still to check) are independent; they go
through the table's ``map_tasks`` callable (``map_tasks(response,
pressures) -> responses``, serial by default), into which a process pool
can be plugged.  The number of cell solves does not
depend on the number of macro interface points.

Interface samples: the change is measured at the points of
:func:`ngcontact.macro.macro_measures.interface_samples`, along the
interface curve in 2D and axisymmetry (``points_per_element`` per boundary
element) and on the interface surface in 3D (vertices, edge midpoints and
centroid of every boundary triangle).  The pressure table needs only the
normal pressure ``p = -tau_n`` there, the normal component of the traction
in the local frame ``(n0, t1, t2)`` (eqs. 69-71), so it runs unchanged in
3D: the table's law ``P`` acts along ``n0`` in every setting.

A frictionless cell with a flat mean plane feels no shear: its table is
over the pressure only and the macro law keeps the friction it was given.
A cell with micro friction also has a :class:`~ngcontact.coupling.shear_table.ShearTable`
(``shear``; one tangent, so 2D and axisymmetric macro scenes only): its
rows, the shear against the tangential jump at a set of pressures, are
made to cover the same pressures and the macro interface's tangential
jumps (``headroom`` times the largest ``|a_t|``) at every update, and the
macro law's tangential part is the table's
:class:`~ngcontact.laws.homogenized.CellShear` instead of the given
friction.  The loop then stops only where neither table grew (a change of
the pressure below ``tol`` alone does not show that the last jumps are
covered).
"""
from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_problem import CellProblem
from ngcontact.coupling.shear_table import ShearTable
from ngcontact.cell.measures import (
    contact_fraction,
    contact_integral,
    mean_jump,
    real_contact_coefficients,
)
from ngcontact.errors import ConvergenceError, ModelError
from ngcontact.fem.quadrature import smooth_order
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.laws import monotone_cubic
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import macro_problem as M

log = logging.getLogger(__name__)

#: ``{"contact_fraction", "k_n0", "g_n0", "closure"}`` of the cell at one pressure
Response = dict[str, float]
#: one entry of the coupling history: iteration and cell-solve counts, pressures, Newton iterations
HistoryEntry = dict[str, int | float | bool | str | None]
KEYS = ("contact_fraction", "k_n0", "g_n0", "closure")
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


def cell_response(problem: CellProblem, pressure: float, length_unit: float = 1.0) -> Response:
    """Contact fraction, ``k_n0``, ``g_n0`` and mean closure of the cell at a mean pressure.

    ``problem`` is a :class:`ngcontact.cell.cell_problem.CellProblem`, solved from the
    rigid predictor.  ``k_n0`` is eq. 34 on the real contact set: ``k_n``
    times the contact fraction (located by the roots of the penetration in
    2D) on a flat cell, else the quadrature integral of the indicator.  The
    closure is the projected mean normal jump on ``S_C``,

        c = int_{S_C} J_n |n.n0| ds / int_{S_C} |n.n0| ds,

    which, unlike eq. 34's integral at quadrature points, does not jump when
    a quadrature point enters contact; ``g_n0 = k_n0 c - p`` makes the
    Winkler law pass through the cell's state.  Lengths are scaled by
    ``length_unit`` (metres per cell length unit); ``k_n0`` is a length
    ratio times ``k_n``.
    """
    problem.solve(cell_load(problem.dim, pressure=float(pressure)), first=True, measure=False)
    fraction = float(contact_fraction(problem))
    if not problem.tangential_free:  # flat and frictionless: n = n0 on all of S_C
        kn0 = problem.model.k_n * fraction
    else:
        kn0 = float(real_contact_coefficients(problem)["k_n"])
    n0 = problem.n[problem.dim - 1]
    projected = float(contact_integral(problem, ng.IfPos(n0, n0, -n0), order=smooth_order(problem.model.order)))
    closure = float(mean_jump(problem)[problem.dim - 1]) * problem.area / projected * length_unit
    return {"contact_fraction": fraction, "k_n0": kn0, "g_n0": kn0 * closure - float(pressure),
            "closure": closure}


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
    """

    response: Callable[[float], Response]
    tol: float
    max_solves: int = 400
    map_tasks: Callable[[Callable[[float], Response], Sequence[float]], list[Response]] = serial_map
    values: dict[float, Response] = field(default_factory=dict)
    error_estimate: float = 0.0
    solves: int = 0   # cell problems solved by this table (not those it was given)

    @property
    def pressures(self) -> np.ndarray:
        return np.array(sorted(self.values))

    def _solve(self, pressures) -> None:
        todo = sorted({float(p) for p in pressures} - set(self.values))
        if not todo:
            return
        if self.solves + len(todo) > self.max_solves:
            raise ConvergenceError(f"cell table: more than {self.max_solves} cell solves for "
                                   f"tolerance {self.tol:g}", {"pressures": sorted(self.values)})
        for p, value in zip(todo, self.map_tasks(self.response, todo)):
            if not all(np.isfinite(value[k]) for k in KEYS):
                raise ConvergenceError(f"cell table: non-finite cell response at p = {p:.6g}", dict(value))
            self.values[p] = {k: float(value[k]) for k in KEYS}
        self.solves += len(todo)

    def _scale(self, key: str) -> float:
        return max([abs(v[key]) for v in self.values.values()] + [1e-300])

    def _refine(self, intervals: list[tuple[float, float]]) -> None:
        """Check the intervals level by level (one batch of independent cell solves per level)."""
        while intervals:
            mids = [0.5 * (a + b) for a, b in intervals]
            before = CellTable(self.response, self.tol, values=dict(self.values))  # the nodes before this level
            law = response_law(before)
            self._solve(mids)
            p_scale = float(self.pressures[-1])
            nxt = []
            for (lo, hi), m in zip(intervals, mids):
                vm, at = self.values[m], before(m)
                err = max([abs(vm[k] - float(at[k])) / self._scale(k) for k in CHECKED]
                          + [abs(m - float(ie.pressure(law, [vm["closure"], 0.0]))) / p_scale])
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
                "error_estimate": self.error_estimate, **{key: [self.values[q][key] for q in P] for key in KEYS}}


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


@dataclass
class CouplingResult:
    """Outcome of :func:`couple`."""

    solution: M.MacroSolution
    table: CellTable
    history: list[HistoryEntry]
    converged: bool
    macro_solves: int
    shear: ShearTable | None = None


def tangential_law(problem: M.MacroProblem, shear: ShearTable | None) -> il.Tangential | None:
    """The macro law's tangential part: the cell's tabulated shear when there is one, else the given friction."""
    return shear.law() if shear is not None and shear.rows else problem.law.friction


def _cover_shear(shear: ShearTable | None, sol: M.MacroSolution, lo: float, hi: float, headroom: float,
                 points_per_element: int) -> bool:
    """Extend the shear table to the pressures ``[lo, hi]`` and the macro interface's tangential jumps."""
    if shear is None:
        return False
    jt = float(np.max(np.abs(MM.interface_profile(sol, points_per_element)["jump_t"])))
    s_hi = headroom * jt if jt > 0 else (shear.covered_jump or 1e-12)
    return shear.cover(lo, hi, s_hi)


#: ``solve(problem, start)``: a macro solve, warm-started from the vector ``start`` when it is not None
MacroSolve = Callable[[M.MacroProblem, "ng.BaseVector | None"], M.MacroSolution]


def _default_solve(problem: M.MacroProblem, start=None) -> M.MacroSolution:
    return M.solve(problem, start=start)


def _solve_warm_or_cold(solve: MacroSolve, problem: M.MacroProblem, start):
    """``solve`` from ``start``; where a warm start fails, once more cold.

    With the cell's tabulated shear, the first solve with the cell's law
    from the start law's solution (a bundle law with ``mu0``, whose pressure
    and slip differ widely) failed the coupled Newton's line search at its
    first step on the sawtooth block, while the cold start converged in 10
    steps.  Returns the solution and the start actually used.
    """
    if start is None:
        return solve(problem, None), None
    try:
        return solve(problem, start), start
    except ConvergenceError as err:
        log.info("two-scale loop: the warm-started macro solve failed (%s); solving cold", err)
        return solve(problem, None), None


def couple(problem: M.MacroProblem, table: CellTable, *, tol: float, max_iter: int = 20,
           table_min: float = 1e-3, headroom: float = 1.25, points_per_element: int = 5,
           solve: MacroSolve = _default_solve, warm: bool = True, shear: ShearTable | None = None
           ) -> CouplingResult:
    """Run the coupling loop (module docstring).

    Parameters
    ----------
    problem
        Macro problem with the start law (the assumed contact set).
    table
        :class:`CellTable` of the cell (filled as needed).
    tol
        Stop when the largest change of the macro normal stress at the
        interface sampling points falls below ``tol``.
    max_iter
        Largest number of law updates.
    table_min
        Lower end of the table as a fraction of the largest macro pressure.
    headroom
        Upper end of the table as a multiple of the largest macro pressure.
    points_per_element
        Sampling of the interface profile (2D and axisymmetric; a 3D
        surface is sampled at fixed points per triangle).
    solve
        Macro solver ``(problem, start) -> MacroSolution``.
    warm
        Start every macro solve with the cell's law from the solution with the scene's law.
    shear
        :class:`~ngcontact.coupling.shear_table.ShearTable` of a cell with
        micro friction (filled as needed; module docstring), or ``None``.

    Raises
    ------
    ConvergenceError
        No convergence within ``max_iter`` updates (carries the history).
    """
    given = len(table.values) >= 2 and (shear is None or bool(shear.rows))   # read from a cache: the start law
    macro_solves, newton, start = 0, 0, None
    scene_law_solution = None
    if warm or not given:
        sol = solve(problem, None)
        macro_solves, newton, start = 1, sol.history["newton_iterations"], sol.gfu.vec
        scene_law_solution = start
    if given:
        # the cached table's law, warm from the scene's law (the femur: 18 + 4 Newton steps, 22 cold;
        # the scene's law is the more robust start: cold, the table's law once needed a continuation);
        # without warm starts the scene's law is not solved at all
        problem = M.replace_law(problem, il.InterfaceLaw(normal=response_law(table),
                                                         friction=tangential_law(problem, shear)))
        sol, start = _solve_warm_or_cold(solve, problem, start)
        macro_solves, newton = macro_solves + 1, newton + sol.history["newton_iterations"]
    p_old = MM.interface_samples(sol, points_per_element)["pressure"]
    history: list[HistoryEntry] = [{"iteration": 0, "max_pressure": float(p_old.max()), "max_change": None,
                                     "cell_solves": 0, "newton_iterations": newton, "law_changed": True,
                                     "warm_start": given and start is not None,
                                     "start_law": ("cell table (after the scene's law)" if warm else "cell table")
                                     if given else "scene"}]
    change = float("inf")
    for k in range(1, max_iter + 1):
        p_hi = float(p_old.max())
        if not p_hi > 0:
            raise ConvergenceError("two-scale loop: the macro interface carries no pressure", {"history": history})
        grew = table.cover(table_min * p_hi, headroom * p_hi)
        grew = _cover_shear(shear, sol, table_min * p_hi, headroom * p_hi, headroom, points_per_element) or grew
        if not grew and (k > 1 or given):
            history.append({"iteration": k, "max_pressure": p_hi, "max_change": 0.0,
                            "cell_solves": table.solves + (shear.solves if shear is not None else 0),
                            "newton_iterations": 0, "law_changed": False, "warm_start": False})
            log.info("two-scale iteration %d: the table covers the pressures; the law is unchanged", k)
            return CouplingResult(solution=sol, table=table, history=history, converged=True,
                                  macro_solves=macro_solves, shear=shear)
        law = il.InterfaceLaw(normal=response_law(table), friction=tangential_law(problem, shear))
        # warm from the scene's start law's solution: with Coulomb friction by the coupled Newton the
        # femur's cell-law solve takes 4 steps from it against 22 cold (31, with a failed attempt and a
        # continuation in the Huber width, before its line search on the frozen Tresca energy); the
        # Coulomb fixed point had taken 26 warm against 17 cold, its first pass frozen far from either
        # solution.  Always from that one state, not from the last update's: the cell law's C1 cubic
        # is solved to Newton's tolerance, not exactly like a polyline, so the answer would depend on
        # the path by which the table grew (a cached table reproduces its first run only so)
        start = scene_law_solution if warm else None
        sol, start = _solve_warm_or_cold(solve, M.replace_law(problem, law), start)
        macro_solves += 1
        p_new = MM.interface_samples(sol, points_per_element)["pressure"]
        change = float(np.max(np.abs(p_new - p_old)))
        history.append({"iteration": k, "max_pressure": float(p_new.max()), "max_change": change,
                        "cell_solves": table.solves + (shear.solves if shear is not None else 0),
                        "newton_iterations": sol.history["newton_iterations"],
                        "law_changed": True, "warm_start": start is not None})
        log.info("two-scale iteration %d: max |delta sigma_n| = %.3e (tol %.1e), %d cell solves",
                 k, change, tol, table.solves)
        if change < tol and shear is None:
            return CouplingResult(solution=sol, table=table, history=history, converged=True,
                                  macro_solves=macro_solves)
        p_old = p_new
    raise ConvergenceError(f"two-scale loop: max |delta sigma_n| = {change:.3e} >= tol {tol:g} after "
                           f"{max_iter} updates", {"history": history})
