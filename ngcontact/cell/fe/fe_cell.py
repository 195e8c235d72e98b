"""The FE cell behind the cell protocol (:class:`~ngcontact.cell.cell_solver.CellSolver`).

:class:`FECell` holds a :class:`~ngcontact.cell.fe.cell_problem.CellProblem` on the scene's mesh and, for
a flat 2D cell, the recipe of meshes graded towards given contact edges; it answers loads, sweeps,
refinement to a tolerance (each load on its own graded mesh, checked by one order more:
:mod:`ngcontact.cell.fe.edge_grading`) and the pressure response of the two-scale table.

The response at a mean pressure ``p``: ``k_n0`` is eq. 34 on the real contact set, ``k_n`` times the
contact fraction (located by the roots of the penetration in 2D) on a flat frictionless cell, else the
quadrature integral of the indicator; the closure is the projected mean normal jump on ``S_C``,

    c = int_{S_C} J_n |n.n0| ds / int_{S_C} |n.n0| ds,

which, unlike eq. 34's integral at quadrature points, does not jump when a quadrature point enters
contact.
"""
from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import ngsolve as ng

from ngcontact.cell.cell_load import CellLoad, cell_load
from ngcontact.cell.cell_solution import CellSolution
from ngcontact.cell.cell_solver import Refinement, Response, response_of
from ngcontact.cell.coefficients import coefficients
from ngcontact.cell.fe.cell_model import CellModel
from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.cell.fe.edge_grading import GradedSolve, solve_to_tolerance
from ngcontact.cell.fe.load_start import Predictor
from ngcontact.cell.fe.measures import contact_fraction, contact_integral, mean_jump, real_contact_coefficients
from ngcontact.errors import ModelError
from ngcontact.fem.quadrature import smooth_order

log = logging.getLogger(__name__)


class FECell:
    """An FE cell problem answering the cell protocol (module docstring).

    Parameters
    ----------
    cell
        The meshed cell (:class:`ngcontact.geometry.cell2d.Cell` or its 3D analogue).
    model
        The cell's physics (:class:`~ngcontact.cell.fe.cell_model.CellModel`).
    make_problem
        ``() -> CellProblem`` on ``cell``: built on the first solve (the whole-surface coefficients need
        the mesh only).
    threshold
        The Tresca threshold ``G`` of the whole-surface coefficients (eqs. 42-43), or ``None``.
    graded
        ``(vertices, order) -> CellProblem`` on the flat cell whose interface has those vertices, or
        ``None`` where the cell cannot be graded (a curved or 3D ``S_C``).
    h0
        The interface element size of the ungraded mesh (the grading's level 0).
    predictor
        The start of first loads whose contact edges seed the graded meshes, or ``None``.
    """

    def __init__(self, cell, model: CellModel, make_problem: Callable[[], CellProblem], *,
                 threshold: float | None = None, graded: Callable[[list[float], int], CellProblem] | None = None,
                 h0: float | None = None, predictor: Predictor | None = None):
        self.cell, self.model, self._make_problem = cell, model, make_problem
        self.dim = cell.dim
        self.period = float(cell.period[0])
        self.threshold = threshold
        self.graded, self.h0, self.predictor = graded, h0, predictor
        self._problem: CellProblem | None = None

    @classmethod
    def of(cls, problem: CellProblem, **options) -> FECell:
        """The cell protocol around a cell problem built already (``options``: those of the constructor)."""
        return cls(problem.cell, problem.model, lambda: problem, **options)

    @property
    def problem(self) -> CellProblem:
        """The cell problem of the last solve (the scene's mesh, or the last load's graded one)."""
        if self._problem is None:
            self._problem = self._make_problem()
        return self._problem

    # ------------------------------------------------------------ description
    def unknowns(self) -> int:
        return int(self.problem.ndof)

    def size(self) -> dict[str, Any]:
        return {"method": "fe", "ndof": self.unknowns()}

    def method_record(self) -> dict[str, Any] | None:
        return None

    def whole_surface(self) -> dict[str, Any]:
        return coefficients(self.cell, kn=self.model.k_n, gap=self.model.gap, G=self.threshold).as_dict()

    # ----------------------------------------------------------------- solves
    def solve(self, load: CellLoad, *, first: bool = True, measure: bool = True) -> CellSolution:
        return self.problem.solve(load, first=first, measure=measure)

    def sweep(self, loads: list[CellLoad]) -> list[CellSolution]:
        return self.problem.sweep(loads)

    def refines_by_default(self) -> bool:
        """No: a sweep without a stated tolerance keeps its fixed mesh (the FE cell's estimates are built
        for graded flat 2D cells only)."""
        return False

    def refine_to(self, tolerance: float, loads: list[CellLoad], required: bool = True) -> Refinement:
        """Each load on its own mesh, graded towards its contact edges until ``tolerance`` is met
        (:func:`~ngcontact.cell.fe.edge_grading.solve_to_tolerance`; out of reach it raises, ``required`` or
        not); the last load's problem becomes this cell's."""
        if self.graded is None or self.h0 is None:
            raise ModelError("a tolerance on the FE cell is built for flat 2D cells (graded towards the contact "
                             "edges); this cell cannot be graded")
        period = self.period
        order = self.model.order
        out: list[GradedSolve] = []
        for k, load in enumerate(loads):
            seed = self.predictor.edges(load) if self.predictor is not None else None
            out.append(solve_to_tolerance(self.graded, load, tolerance, self.h0, period, order, seed=seed))
            log.info("load %d: contact fraction %.10g after %d grading steps", k,
                     out[-1].solution.results["contact_fraction"], len(out[-1].history) - 1)
        self._problem = out[-1].problem
        return Refinement(solutions=[g.solution for g in out], estimates=[g.estimate for g in out],
                          per_load=[{"mesh_history": g.history,
                                     # the Newton steps of every level the load was solved on
                                     "newton_iterations": sum(h["newton_iterations"] for h in g.history)}
                                    for g in out],
                          histories=[g.newton for g in out],
                          how="each load on meshes graded towards its contact edges, then one order more: the larger "
                              "of the last grading change and the order's change")

    def response(self, pressure: float, length_unit: float = 1.0) -> Response:
        """The response at ``pressure`` (module docstring), from a first load's start."""
        problem = self.problem
        problem.solve(cell_load(problem.dim, pressure=float(pressure)), first=True, measure=False)
        fraction = float(contact_fraction(problem))
        if not problem.tangential_free:  # flat and frictionless: n = n0 on all of S_C
            kn0 = problem.model.k_n * fraction
        else:
            kn0 = float(real_contact_coefficients(problem)["k_n"])
        n0 = problem.n[problem.dim - 1]
        projected = float(contact_integral(problem, ng.IfPos(n0, n0, -n0), order=smooth_order(problem.model.order)))
        closure = float(mean_jump(problem)[problem.dim - 1]) * problem.area / projected * length_unit
        return response_of(fraction, kn0, closure, float(pressure))

    # ------------------------------------------------------------------ report
    def load_entry(self, solution: CellSolution) -> dict[str, Any]:
        """The report's entry of one load: its results and iteration counts."""
        return dict(solution.results, newton_iterations=solution.iterations,
                    coulomb_iterations=solution.coulomb_iterations)

    def solver_record(self, solutions: list[CellSolution], refinement: Refinement | None = None) -> dict[str, Any]:
        per_load = refinement.histories if refinement is not None else [s.newton for s in solutions]
        iterations = (sum(e["newton_iterations"] for e in refinement.per_load) if refinement is not None
                      else sum(s.iterations for s in solutions))
        return {"iterations": iterations, "converged": True, "per_load": per_load,
                "linear": self.problem.linear.summary()}

    def displacements(self) -> tuple[Any, dict[str, Any]] | None:
        """The mesh and the two bodies' displacement fields of the last state (for VTK)."""
        comps = self.problem.gfu.components
        return self.problem.mesh, {"u_rough": comps[0], "u_counter": comps[1]}

    def state(self):
        return self.problem.gfu.vec.FV().NumPy().copy()

    def set_state(self, state) -> None:
        vec = self.problem.gfu.vec.FV().NumPy()
        if state is None or len(state) != len(vec):
            raise RuntimeError(f"a worker's cell has {0 if state is None else len(state)} dofs, this one "
                               f"{len(vec)}: the mesh was not rebuilt identically")
        vec[:] = state
