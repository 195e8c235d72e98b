"""The two-scale coupling loop of paper Sec. 3.5, with a tabulated cell response.

The cell at a mean pressure ``p`` (compression positive) has a real contact
set ``S_C(p)``, the coefficients of eq. 34 on it,

    k_n0(p) = (1/|T|) int_{S_C(p)} k_n (n.n0)^2 ds,      g_n0(p) = k_n0(p) c(p) - p,

and a mean closure ``c(p)``: the projected mean normal jump on ``S_C``
(:meth:`~ngcontact.cell.cell_solver.CellSolver.response`).  The law of step ii of Sec. 3.5 at an interface
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
of the table's pairs ``(c_i, p_i)``
(:func:`~ngcontact.coupling.pressure_table.response_law`):

    W(a) = int_{c_0}^{a_n - g0} P(s) ds,    tau_n = P(a_n - g0),    dtau_n/da_n = P'(a_n - g0),

whose energy, traction and tangent are consistent (tests/laws).  The pair
``(c_0, 0)`` below the smallest tabulated pressure extends the first secant
of the table to ``p = 0``.  Newton solves the nonlinearity of ``P`` inside
the macro solve; the loop only grows the table:

0. the macro problem is solved with the law it was given (the assumed
   contact set ``S_C(0)``), and, when the table already holds responses
   (read from the cache), then with :func:`response_law` of that table,
   warm-started from that solution.  That first solve is never the answer:
   it starts the cell law's solve and sets the table's first range, so
   Newton stops it at ``START_RTOL`` (1e-4 of the first residual) instead of
   the scene's ``rtol``.  That saves the scene law's last steps, taken where
   its contact and stick sets have long settled, and the cell law's solve
   takes as many steps from there as from the exact solution.  Both
   a first run and a cached one start that solve from the same state, so
   the cached run still reproduces the first to round-off;
1. the table is made to cover ``[table_min p_max, headroom p_max]`` of the
   current macro pressures (extensions go down to half the requested lower
   end, so that a slightly lower peak does not extend it again);
2. if the table grew, the macro problem is solved again with
   :func:`response_law`, warm-started from the solution with the law it
   was given (on the femur with Coulomb friction by the coupled Newton far
   fewer Newton steps than cold; always from that state, so that the answer
   does not depend on the path by which the table grew); its
   change ``max_x |sigma_n^(k)(x) - sigma_n^(k-1)(x)|`` is recorded and the
   loop stops below ``tol``; if it did not grow, the law is the one just
   solved with, whose solution is unchanged: the loop stops (change 0,
   no solve);
3. otherwise repeat from 1, or stop with a
   :class:`~ngcontact.errors.ConvergenceError` after ``max_iter`` updates.

The table, its cell solves, its interpolation (a monotone C1 cubic) and
its error control are :class:`~ngcontact.coupling.pressure_table.CellTable`.

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
from dataclasses import dataclass
from typing import Protocol

import ngsolve as ng
import numpy as np

from ngcontact.coupling.pressure_table import CellTable, response_law
from ngcontact.coupling.shear_table import ShearTable
from ngcontact.errors import ConvergenceError
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import macro_problem as M

log = logging.getLogger(__name__)

#: one entry of the coupling history: iteration and cell-solve counts, pressures, Newton iterations
HistoryEntry = dict[str, int | float | bool | str | None]


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


#: the scene law's solve, when it only starts the cell law's, stops at this Newton ``rtol``
#: (or the scene's, if looser): it saves the scene law's last Newton steps, and the cell law's
#: solve from there takes as many steps as from the scene law's exact solution (module docstring, step 0)
START_RTOL = 1e-4


class MacroSolve(Protocol):
    """``solve(problem, start, rtol=None)``: a macro solve, warm-started from the vector ``start``
    when it is not None, to the Newton tolerance ``rtol`` when it is given and looser than the
    scene's (else the scene's)."""

    def __call__(self, problem: M.MacroProblem, start: ng.BaseVector | None, rtol: float | None = None
                 ) -> M.MacroSolution: ...


def _default_solve(problem: M.MacroProblem, start=None, rtol: float | None = None) -> M.MacroSolution:
    return M.solve(problem, start=start, rtol=max(M.RTOL, rtol or 0.0))


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
           solve: MacroSolve = _default_solve, warm: bool = True, shear: ShearTable | None = None,
           start_rtol: float = START_RTOL) -> CouplingResult:
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
    start_rtol
        Newton tolerance of the scene law's solve, which only starts the
        cell law's (module docstring, step 0); the scene's own where it is
        looser.

    Raises
    ------
    ConvergenceError
        No convergence within ``max_iter`` updates (carries the history).
    """
    given = len(table.values) >= 2 and (shear is None or bool(shear.rows))   # read from a cache: the start law
    macro_solves, newton, start = 0, 0, None
    scene_law_solution = None
    if warm or not given:
        # only the start of the cell law's solve (or of the table's range): carried to START_RTOL
        sol = solve(problem, None, start_rtol)
        macro_solves, newton, start = 1, sol.history["newton_iterations"], sol.gfu.vec
        scene_law_solution = start
    if given:
        # the cached table's law, warm from the scene's law (on the femur fewer Newton steps in all than cold;
        # the scene's law is the more robust start: cold, the table's law can need a continuation);
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
                                     if given else "scene",
                                     "scene_law_rtol": start_rtol if scene_law_solution is not None else None}]
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
        # femur's cell-law solve takes far fewer steps from it than cold (the Coulomb fixed point would
        # gain nothing: its first pass is frozen far from either solution).
        # Always from that one state, not from the last update's: the cell law's C1 cubic
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
