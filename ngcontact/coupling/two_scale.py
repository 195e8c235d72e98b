"""The two-scale coupling loop of paper Sec. 3.5, with a tabulated cell response.

Loop (steps i-vi of Sec. 3.5):

0. the macro problem is solved with the law it was given: the assumed
   contact set ``S_C(0)`` (e.g. the direction bundle of the whole contact
   surface, whose rigid-asperity contact set is the start);
1. at every interface point ``x`` the macro normal stress ``sigma_n(x) = p(x)``
   (compression positive) loads the cell problem, whose real contact set
   ``S_C(p)`` gives the coefficients of eq. 34 on that set,

       k_n0(p) = (1/|T|) int_{S_C(p)} k_n (n.n0)^2 ds,
       g_n0(p) = (1/|T|) int_{S_C(p)} k_n g (n.n0) ds;

   (``g_n0`` in the form of :func:`cell_response`);
2. the macro problem is solved again with the unilateral law whose
   coefficients vary along the interface (:class:`ngcontact.laws.homogenized.FieldLaw`,
   ``p = [k_n0(x) (a_n - g0) - g_n0(x)]_+`` with ``k_n0(x) = k_n0(p_k(x))``);
3. repeat from 1 until ``max_x |sigma_n^(k)(x) - sigma_n^(k-1)(x)| < tol``
   at the sampling points of the interface profile, or stop with a
   :class:`~ngcontact.errors.ConvergenceError` after ``max_iter`` updates.

Cost.  The cell response depends on the load numbers the cell can feel.  A
frictionless cell with a flat mean plane carries no shear, so its contact set
depends on ``p`` alone (its macro strain does not move the contact set of a
small-slope cell either): the response ``(contact fraction, k_n0, g_n0)`` is
tabulated once over the pressures needed, ``[table_min p_max, p_max]``, and
interpolated linearly in ``p``; below the table the coefficients are held
constant.  The table is adaptive: every interval is checked at its midpoint
against a direct cell solve and halved while

    max(|f_mid - f_interp| / max f, |g_mid - g_interp| / max |g_n0|) > table_tol

(``f`` the contact fraction, ``g`` = ``g_n0``, maxima over the table, that of
``|g_n0|`` at least the largest tabulated pressure); the checked midpoints become
nodes too, so the largest accepted discrepancy is a conservative estimate of
the interpolation error.  The number of cell solves is then independent of the
number of macro interface points.  The table grows when a later iteration
needs higher (or lower) pressures.
"""
from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_problem import CellProblem
from ngcontact.cell.measures import (
    contact_fraction,
    contact_integral,
    mean_jump,
    real_contact_coefficients,
)
from ngcontact.errors import ConvergenceError
from ngcontact.laws import homogenized as il
from ngcontact.fem.interpolants import piecewise_linear
from ngcontact.macro import macro_problem as M
from ngcontact.macro import macro_measures as MM
from ngcontact.errors import ModelError
from ngcontact.fem.quadrature import smooth_order

log = logging.getLogger(__name__)

#: ``{"contact_fraction", "k_n0", "g_n0"}`` of the cell at one pressure
Response = dict[str, float]
#: one entry of the coupling history: iteration and cell-solve counts, pressures, Newton iterations
HistoryEntry = dict[str, int | float | None]


def cell_response(problem: CellProblem, pressure: float, length_unit: float = 1.0) -> Response:
    """Contact fraction, ``k_n0`` and ``g_n0`` of the cell at a mean pressure.

    ``problem`` is a :class:`ngcontact.cell.cell_problem.CellProblem`, solved from the
    rigid predictor.  ``k_n0`` is eq. 34 on the real contact set: ``k_n``
    times the contact fraction (located by the roots of the penetration in
    2D) on a flat cell, else the quadrature integral of the indicator.
    ``g_n0`` makes the law pass through the cell's state,

        g_n0 = k_n0 Jbar_n - p,

    ``Jbar_n`` the projected mean normal jump on ``S_C``; for a jump uniform
    over the real contact set this is eq. 34's ``(1/|T|) int k_n g ds``;
    ``Jbar_n = int_{S_C} J_n |n.n0| ds / int_{S_C} |n.n0| ds``, but
    unlike that integral at quadrature points it does not jump when a
    quadrature point enters contact, so the table can interpolate it.
    Lengths are scaled by ``length_unit`` (metres per cell length unit);
    ``k_n0`` is a length ratio times ``k_n``.
    """
    problem.solve(cell_load(problem.dim, pressure=float(pressure)), first=True, measure=False)
    fraction = float(contact_fraction(problem))
    if not problem.tangential_free:  # flat and frictionless: n = n0 on all of S_C
        kn0 = problem.model.k_n * fraction
    else:
        kn0 = float(real_contact_coefficients(problem)["k_n"])
    n0 = problem.n[problem.dim - 1]
    projected = float(contact_integral(problem, ng.IfPos(n0, n0, -n0), order=smooth_order(problem.model.order)))
    jbar = float(mean_jump(problem)[problem.dim - 1]) * problem.area / projected * length_unit
    return {"contact_fraction": fraction, "k_n0": kn0, "g_n0": kn0 * jbar - float(pressure)}


@dataclass
class CellTable:
    """Adaptive piecewise-linear table of a cell response in the pressure.

    Parameters
    ----------
    response
        Function ``p -> {"contact_fraction", "k_n0", "g_n0"}`` (a cell solve).
    tol
        Interpolation tolerance (module docstring).
    max_solves
        Largest number of cell solves before giving up.
    """

    response: Callable[[float], Response]
    tol: float
    max_solves: int = 400
    values: dict[float, Response] = field(default_factory=dict)
    error_estimate: float = 0.0

    @property
    def solves(self) -> int:
        return len(self.values)

    @property
    def pressures(self) -> np.ndarray:
        return np.array(sorted(self.values))

    def _value(self, p: float) -> Response:
        if p not in self.values:
            if len(self.values) >= self.max_solves:
                raise ConvergenceError(f"cell table: more than {self.max_solves} cell solves for "
                                       f"tolerance {self.tol:g}", {"pressures": sorted(self.values)})
            self.values[p] = self.response(p)
        return self.values[p]

    def _scale(self, key: str) -> float:
        """Largest |value| in the table; for ``g_n0`` (a stress) at least the largest pressure."""
        floor = max(self.values) if key == "g_n0" else 1e-300
        return max([abs(v[key]) for v in self.values.values()] + [floor])

    def _refine(self, a: float, b: float) -> None:
        stack = [(a, b)]
        while stack:
            lo, hi = stack.pop()
            m = 0.5 * (lo + hi)
            va, vb, vm = self._value(lo), self._value(hi), self._value(m)
            err = max(abs(vm[key] - 0.5 * (va[key] + vb[key])) / self._scale(key)
                      for key in ("contact_fraction", "g_n0"))
            if err > self.tol and hi - lo > 1e-6 * hi:
                stack += [(lo, m), (m, hi)]
            else:
                self.error_estimate = max(self.error_estimate, err)

    def cover(self, lo: float, hi: float, start_nodes: int = 5) -> None:
        """Make the table span ``[lo, hi]`` (``0 < lo < hi``) within the tolerance."""
        if not 0 < lo < hi:
            raise ModelError(f"table range [{lo!r}, {hi!r}]: need 0 < lo < hi")
        if not self.values:
            nodes = np.geomspace(lo, hi, start_nodes)
        else:
            p = self.pressures
            grown = list(p)
            if lo < p[0]:
                grown = list(np.geomspace(lo, p[0], start_nodes)[:-1]) + grown
            if hi > p[-1]:
                grown = grown + list(np.geomspace(p[-1], hi, start_nodes)[1:])
            nodes = np.array(grown)
        old = set(self.values)
        for a, b in zip(nodes[:-1], nodes[1:]):
            if a in old and b in old:
                continue  # an interval already checked
            self._refine(float(a), float(b))
        log.info("cell table: %d solves over [%.3e, %.3e], error estimate %.2e", self.solves,
                 self.pressures[0], self.pressures[-1], self.error_estimate)

    def __call__(self, p: float | np.ndarray) -> dict[str, np.ndarray | np.float64]:
        """Interpolated response at pressures ``p`` (held constant outside the table)."""
        P = self.pressures
        out: dict[str, np.ndarray | np.float64] = {}
        for key in ("contact_fraction", "k_n0", "g_n0"):
            out[key] = np.interp(p, P, [self.values[q][key] for q in P])
        return out

    def as_dict(self) -> dict[str, list[float] | int | float]:
        P = self.pressures
        return {"pressure": P.tolist(), "cell_solves": self.solves, "tolerance": self.tol,
                "error_estimate": self.error_estimate,
                **{key: [self.values[q][key] for q in P] for key in ("contact_fraction", "k_n0", "g_n0")}}


def field_law(sol: M.MacroSolution, table: CellTable, pressure: ng.CoefficientFunction) -> il.FieldLaw:
    """The law of step 2: the table composed with the projected pressure field on ``S_0``."""
    p = sol.problem
    mesh = p.mesh
    on = mesh.Boundaries(p.interface)
    V = ng.H1(mesh, order=p.order, definedon=on)
    pgf = ng.GridFunction(V)
    pgf.Set(pressure, definedon=on)
    P = table.pressures
    kn = np.array([table.values[q]["k_n0"] for q in P])
    off = np.array([table.values[q]["g_n0"] for q in P]) / kn
    # interpolated into the same space, so the macro assembly evaluates two plain fields
    # instead of the table's sum of ramps at every quadrature point
    fields = []
    for values in (kn, off):
        gf = ng.GridFunction(V)
        gf.Set(piecewise_linear(pgf, list(zip(P, values))), definedon=on)
        fields.append(gf)
    return il.FieldLaw(kn=fields[0], offset=fields[1], stiffness=float(kn.max()))


def interface_pressure(sol: M.MacroSolution) -> ng.CoefficientFunction:
    """The macro normal stress ``p`` on ``S_0`` as a CoefficientFunction."""
    return MM.interface_tractions(sol)[0]


@dataclass
class CouplingResult:
    """Outcome of :func:`couple`."""

    solution: M.MacroSolution
    table: CellTable
    history: list[HistoryEntry]
    converged: bool
    macro_solves: int


def couple(problem: M.MacroProblem, table: CellTable, *, tol: float, max_iter: int = 20,
           table_min: float = 1e-3, headroom: float = 1.25, points_per_element: int = 5,
           solve: Callable[[M.MacroProblem], M.MacroSolution] = M.solve) -> CouplingResult:
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
        Largest number of coefficient updates.
    table_min
        Lower end of the table as a fraction of the largest macro pressure.
    headroom
        Upper end of the table as a multiple of the largest macro pressure.
    points_per_element
        Sampling of the interface profile.
    solve
        Macro solver ``problem -> MacroSolution``.

    Raises
    ------
    ConvergenceError
        No convergence within ``max_iter`` updates (carries the history).
    """
    sol = solve(problem)
    p_old = MM.interface_profile(sol, points_per_element)["pressure"]
    history: list[HistoryEntry] = [{"iteration": 0, "max_pressure": float(p_old.max()), "max_change": None,
                                     "cell_solves": 0, "newton_iterations": sol.history["newton_iterations"]}]
    friction = problem.law.friction
    for k in range(1, max_iter + 1):
        p_hi = float(p_old.max())
        if not p_hi > 0:
            raise ConvergenceError("two-scale loop: the macro interface carries no pressure", {"history": history})
        if not table.values or p_hi > table.pressures[-1] or table_min * p_hi < table.pressures[0]:
            # headroom above, so that a slowly growing peak does not extend the table every time
            table.cover(table_min * p_hi, headroom * p_hi)
        law = il.InterfaceLaw(normal=field_law(sol, table, interface_pressure(sol)), friction=friction)
        sol = solve(M.replace_law(problem, law))
        p_new = MM.interface_profile(sol, points_per_element)["pressure"]
        change = float(np.max(np.abs(p_new - p_old)))
        history.append({"iteration": k, "max_pressure": float(p_new.max()), "max_change": change,
                        "cell_solves": table.solves, "newton_iterations": sol.history["newton_iterations"]})
        log.info("two-scale iteration %d: max |delta sigma_n| = %.3e (tol %.1e), %d cell solves",
                 k, change, tol, table.solves)
        if change < tol:
            return CouplingResult(solution=sol, table=table, history=history, converged=True,
                                  macro_solves=k + 1)
        p_old = p_new
    raise ConvergenceError(f"two-scale loop: max |delta sigma_n| = {change:.3e} >= tol {tol:g} after "
                           f"{max_iter} updates", {"history": history})
