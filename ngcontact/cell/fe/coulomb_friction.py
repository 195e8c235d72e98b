"""The cell problem under Coulomb friction with the penalty: coupled Newton, fixed point as the fallback.

Coulomb's threshold ``G = mu p`` (paper eqs. 16-17, penalized contact of
eq. 65) is solved on the cell by one of two iterations with the same
solution (a zero of the residual ``R(u)`` of
:mod:`ngcontact.solvers.coulomb_newton` is a fixed point ``u = argmin
Pi_T(.; mu p(u))`` and conversely):

* ``"newton"`` (default): Newton on ``R`` with the consistent,
  non-symmetric tangent (:func:`ngcontact.solvers.coulomb_newton.coupled_newton`,
  form :func:`ngcontact.cell.fe.cell_energy.coulomb_residual`), globalized by
  the exact line search on the Tresca energy with the threshold frozen at
  the iterate (:class:`~ngcontact.solvers.coulomb_newton.FrozenTresca`).
  Its tangent solves follow the cell's
  :class:`~ngcontact.solvers.linear_solver.LinearSolver`: LU directly,
  GMRES with BDDC iteratively.  Should the coupled Newton fail (an active
  set cycling, ``max_iter``, GMRES not converging), the state is reset to
  its start and the fixed point solves the load; the failed attempt's
  steps stay in the history and count.
* ``"fixed_point"``: the Tresca passes of
  :func:`ngcontact.solvers.coulomb.coulomb_fixed_point` with Anderson
  mixing, each pass's threshold ``mu p`` of the previous pass (stopping
  rule ``coulomb_rtol`` on the pressure change).

On ``geometries/cells/rectangular_coulomb.toml`` the coupled Newton takes
fewer Newton steps per load than the fixed point, each of whose passes
is a whole Newton solve (its steps per load: docs/benchmarks.md, section
coulomb_newton_globalization).
"""
from __future__ import annotations

import logging

from ngcontact.cell.fe import measures
from ngcontact.cell.fe.cell_energy import coulomb_residual
from ngcontact.errors import ConvergenceError
from ngcontact.solvers.coulomb import MIXING_DEPTH, coulomb_fixed_point
from ngcontact.solvers.coulomb_newton import FrozenTresca, coupled_newton

log = logging.getLogger(__name__)

#: Iterations of the Coulomb threshold
METHODS = ("newton", "fixed_point")


def solve_coulomb(problem, free, newton_once) -> tuple[list[dict], int]:
    """Solve the current load of ``problem`` under Coulomb friction from its current state.

    ``free``: the load's free dofs; ``newton_once(free, atol)``: the
    problem's Tresca Newton solve (for the fixed point).  Returns the
    Newton histories and the number of threshold updates (coupled steps or
    fixed-point passes).
    """
    coupled = problem.coulomb == "newton"
    histories: list[dict] = []
    if coupled:
        start = problem.gfu.vec.CreateVector()
        start.data = problem.gfu.vec
        try:
            h = _coupled(problem, free)
            return [h], h["iterations"]
        except ConvergenceError as err:
            log.info("coupled Coulomb Newton failed (%s); the fixed point solves the load", err)
            histories.append(err.history)
            problem.gfu.vec.data = start
    fixed = _fixed_point(problem, free, newton_once)
    return histories + fixed["newton"], fixed["coulomb_iterations"]


def _pressure(problem):
    return measures.sample_surface(problem, {"p": problem.pressure})["p"]


def _coupled(problem, free) -> dict:
    if problem.coulomb_residual is None:
        problem.coulomb_residual = coulomb_residual(problem)
    previous = problem.coulomb_previous

    def freeze() -> None:
        previous.vec.data = problem.gfu.vec

    return coupled_newton(problem.coulomb_residual, problem.gfu, freedofs=free, linear=problem.linear,
                          frozen=FrozenTresca(problem.form, freeze), pressure=lambda: _pressure(problem),
                          rtol=problem.rtol, atol=problem.atol, max_iter=problem.max_iter,
                          active_set=problem.active_set)


def _fixed_point(problem, free, newton_once) -> dict:
    first_residual: list[float] = []
    previous = problem.coulomb_previous

    def freeze() -> None:
        previous.vec.data = problem.gfu.vec

    def put(x) -> None:
        problem.gfu.vec.FV().NumPy()[:] = x

    def tresca_solve() -> dict:
        # later passes stop at rtol times the first pass's initial residual
        atol = max(problem.atol, problem.rtol * first_residual[0]) if first_residual else problem.atol
        h = newton_once(free, atol)
        if not first_residual:
            first_residual.append(h["residuals"][0])
        return h

    return coulomb_fixed_point(freeze, tresca_solve, lambda: _pressure(problem),
                               rtol=problem.model.coulomb_rtol, max_iter=problem.model.coulomb_max_iter,
                               state=(lambda: problem.gfu.vec.FV().NumPy().copy(), put), depth=MIXING_DEPTH)
