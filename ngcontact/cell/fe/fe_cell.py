"""The FE cell behind the cell protocol (:class:`~ngcontact.cell.cell_solver.CellSolver`).

:class:`FECell` holds a :class:`~ngcontact.cell.fe.cell_problem.CellProblem` on the scene's mesh and, for
a flat 2D cell, the recipe of meshes graded towards given contact edges; it answers loads, sweeps,
refinement to a tolerance (each load on its own graded mesh, checked by higher orders:
:mod:`ngcontact.cell.fe.edge_grading`; a cell that cannot be graded by a sequence of finer discretizations
from its :class:`~ngcontact.cell.fe.second_discretization.Refiner` and the observed rate:
:mod:`ngcontact.cell.fe.second_discretization`) and the pressure response of the two-scale table.

A scene that states no tolerance is held to the default one (:meth:`FECell.default_accuracy`,
:mod:`ngcontact.cell.fe.default_refinement`): its own answer, its error estimated by one order more on the
same mesh (:mod:`ngcontact.cell.fe.saturation`), reported where that meets the tolerance, else refined as a
stated tolerance refines it (:meth:`FECell.default_refinement`) within the scene's budget of unknowns
(``discretization.budget_dofs``, default :data:`DEFAULT_DOFS`); with ``discretization.estimate =
"estimate"`` it is estimated and not refined.  A load solved alone (independent loads) is held so on its own
(:meth:`FECell.holds_loads_alone`): its estimate is one order more on the same mesh for that load, its
refinement meshes graded towards its own contact edges or that load on the refiner's finer discretizations.
Refinement to a tolerance not required (:meth:`FECell.refine_to` with ``required = False``) is bounded so
too and flagged when over (with the scene's level alone: not estimated).  A stated tolerance refines within
:data:`MAX_DOFS`.

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
from ngcontact.cell.fe.default_refinement import held_to_default
from ngcontact.cell.fe.edge_grading import GradedSolve, graded_refinement, solve_to_tolerance
from ngcontact.cell.fe.load_start import Predictor
from ngcontact.cell.fe import whole_surface_error
from ngcontact.cell.fe.saturation import estimate_on_scene
from ngcontact.cell.fe.second_discretization import InterfaceHalving, Refiner, Sequence, as_refinement, refine
from ngcontact.cell.fe.measures import contact_fraction, contact_integral, mean_jump, real_contact_coefficients
from ngcontact.errors import ModelError
from ngcontact.fem.quadrature import smooth_order

log = logging.getLogger(__name__)

#: the most dofs of a refined discretization at the default tolerance (per dimension)
DEFAULT_DOFS = {2: 120_000, 3: 40_000}
#: the most dofs of a refined discretization at a stated tolerance (per dimension)
MAX_DOFS = {2: 1_000_000, 3: 400_000}


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
        ``() ->`` the start of first loads whose contact edges seed the graded meshes (built when first
        asked), or ``None``.
    variant
        ``(**changes) -> FECell`` of the same scene with ``order``, ``interface_maxh``, ``enforcement`` or
        ``k_n`` changed, ``None`` where the scene's checks refuse the change; ``None``: no variants.
    interface_maxh
        The scene's interface element size (the second discretization halves it where the order cannot rise).
    twin
        ``() -> CellSolver``: the spectral cell of the same small-slope model on a grid that resolves the
        contact edges, where the cell has one (the penalty's share is taken from it), else ``None``.
    refiner
        ``(cell) -> Refiner``: the discretizations refining a cell that cannot be graded; ``None``: the
        interface element size halved level by level (:class:`InterfaceHalving`).
    budget
        The most unknowns of a discretization the refinement towards the default tolerance solves
        (``discretization.budget_dofs``); ``None``: :data:`DEFAULT_DOFS`.
    refine_default
        Whether a sweep without a stated tolerance is refined where its own answer misses the default one
        (``discretization.estimate = "auto"``), or only estimated (``"estimate"``).
    """

    def __init__(self, cell, model: CellModel, make_problem: Callable[[], CellProblem], *,
                 threshold: float | None = None, graded: Callable[[list[float], int], CellProblem] | None = None,
                 h0: float | None = None, predictor: Callable[[], Predictor | None] | None = None,
                 variant: Callable[..., FECell | None] | None = None, interface_maxh: float | None = None,
                 twin: Callable[[], Any] | None = None, refiner: Callable[[FECell], Refiner] | None = None,
                 budget: int | None = None, refine_default: bool = True):
        self.cell, self.model, self._make_problem = cell, model, make_problem
        self._refiner = refiner
        self.budget = int(budget) if budget is not None else DEFAULT_DOFS[cell.dim]
        self.refine_default = refine_default
        self.variant, self.interface_maxh, self.twin = variant, interface_maxh, twin
        self.dim = cell.dim
        self.period = float(cell.period[0])
        self.threshold = threshold
        self.graded, self.h0, self.predictor = graded, h0, predictor
        self._problem: CellProblem | None = None
        self._scene_ndof: int | None = None

    @classmethod
    def of(cls, problem: CellProblem, **options) -> FECell:
        """The cell protocol around a cell problem built already (``options``: those of the constructor)."""
        return cls(problem.cell, problem.model, lambda: problem, **options)

    @property
    def problem(self) -> CellProblem:
        """The cell problem of the last solve (the scene's mesh, or the last load's graded one)."""
        if self._problem is None:
            self._problem = self._make_problem()
            self._scene_ndof = self._scene_ndof or int(self._problem.ndof)
        return self._problem

    def restore(self, problem: CellProblem) -> None:
        """Make ``problem`` (one this cell solved before, e.g. the scene's) the one reported again."""
        self._problem = problem

    def scene_unknowns(self) -> int:
        """The dofs of the scene's own discretization (before any refinement replaced the problem)."""
        if self._scene_ndof is None:
            self._scene_ndof = int(self._make_problem().ndof) if self._problem is not None else self.unknowns()
        return self._scene_ndof

    # ------------------------------------------------------------ description
    def unknowns(self) -> int:
        return int(self.problem.ndof)

    def size(self) -> dict[str, Any]:
        return {"method": "fe", "ndof": self.unknowns()}

    def method_record(self) -> dict[str, Any] | None:
        return None

    def whole_surface(self) -> dict[str, Any]:
        return coefficients(self.cell, kn=self.model.k_n, gap=self.model.gap, G=self.threshold).as_dict()

    def whole_surface_error(self) -> tuple[dict[str, float] | None, str]:
        """One geometry order more on the same mesh (:mod:`ngcontact.cell.fe.whole_surface_error`)."""
        higher = self.variant(order=self.model.order + 1) if self.variant is not None else None
        if higher is None:
            return None, f"the scene's checks refuse geometry order {self.model.order + 1}, one more than its own"
        return whole_surface_error.estimates(self.whole_surface(), higher.whole_surface()), whole_surface_error.HOW

    # ----------------------------------------------------------------- solves
    def solve(self, load: CellLoad, *, first: bool = True, measure: bool = True) -> CellSolution:
        return self.problem.solve(load, first=first, measure=measure)

    def sweep(self, loads: list[CellLoad]) -> list[CellSolution]:
        return self.problem.sweep(loads)

    def penalty(self) -> float | None:
        return float(self.model.k_n) if self.model.enforcement == "penalty" else None

    def share_solver(self):
        """The spectral twin where the cell has one (the share is the model's, the same on any discretization
        that resolves it, and the twin's grid resolves the contact edges far below the mesh), else this cell."""
        return self.twin() if self.twin is not None else self

    def varied(self, *, enforcement: str | None = None, k_n: float | None = None) -> FECell | None:
        changes = {k: v for k, v in (("enforcement", enforcement), ("k_n", k_n)) if v is not None}
        return self.variant(**changes) if self.variant is not None else None

    def share_resolution(self) -> None:
        """None: the share comes from the spectral twin, which resolves it there (:meth:`share_solver`)."""

    def refiner(self) -> Refiner | None:
        """The discretizations that refine this cell where it cannot be graded
        (:mod:`~ngcontact.cell.fe.second_discretization`), ``None`` where the cell has no variants."""
        if self._refiner is not None:
            return self._refiner(self)
        if self.variant is None or self.interface_maxh is None:
            return None
        return InterfaceHalving(self, self.variant, self.interface_maxh)

    def default_refinement(self) -> str:
        """How :meth:`refine_to` refines (module docstring): ``"graded"`` (meshes graded towards the contact
        edges), ``"sequence"`` (the refiner's discretizations) or ``"none"`` (no recipe of another one)."""
        if self.graded is not None and self.h0 is not None:
            return "graded"
        return "none" if self.refiner() is None else "sequence"

    def refines_by_default(self) -> bool:
        """Whether a sweep without a stated tolerance whose own answer misses the default one is refined
        (within :attr:`budget`): where the scene asks it (``discretization.estimate = "auto"``) and the cell
        has a recipe of finer discretizations (:meth:`default_refinement`)."""
        return self.refine_default and self.default_refinement() != "none"

    def holds_loads_alone(self) -> bool:
        return True     # a load's estimate and refinement need no other load (module docstring)

    def default_accuracy(self, tolerance: float, loads: list[CellLoad]) -> Refinement | None:
        """The sweep held to the default ``tolerance``: the scene's own answer and its error from one order
        more on the same mesh (:mod:`ngcontact.cell.fe.saturation`), refined within :attr:`budget` where that
        misses ``tolerance`` and the cell :meth:`refines_by_default`
        (:mod:`ngcontact.cell.fe.default_refinement`)."""
        return held_to_default(self, tolerance, loads) if self.refines_by_default() else estimate_on_scene(self, loads)

    def scene_estimate(self, loads: list[CellLoad]) -> Refinement | None:
        return estimate_on_scene(self, loads)    # one order more on the scene's mesh (ngcontact.cell.fe.saturation)

    def refine_to(self, tolerance: float, loads: list[CellLoad], required: bool = True) -> Refinement:
        """Each load on its own mesh graded towards its contact edges until ``tolerance`` is met
        (:func:`~ngcontact.cell.fe.edge_grading.solve_to_tolerance`); a cell that cannot be graded: the sweep on
        the refiner's discretizations until the estimate meets it within :data:`MAX_DOFS`
        (:mod:`~ngcontact.cell.fe.second_discretization`); the last problem becomes this cell's. ``required =
        False`` (the default tolerance): within :attr:`budget`, out of reach the best answer with its estimate
        (:func:`warn_unmet`); a cell whose first refinement is beyond that bound is solved once, not estimated.

        Raises
        ------
        ConvergenceError
            ``required`` and out of reach for a counted quantity (the graded levels hold every one:
            :func:`~ngcontact.cell.fe.grading_estimate.out_of_reach`; issue 35: exit 3, never ``met = false``).
        """
        bound = MAX_DOFS[self.dim] if required else self.budget
        if self.graded is None or self.h0 is None:
            refined = as_refinement(self.compared(tolerance, loads, bound, required))
        else:
            refined = self.graded_solves(tolerance, loads, required, None if required else bound)[0]
        warn_unmet(refined, tolerance)       # only where not required: a required tolerance out of reach has raised
        return refined

    def graded_solves(self, tolerance: float, loads: list[CellLoad], required: bool,
                      max_dofs: int | None = None) -> tuple[Refinement, list[GradedSolve]]:
        """Each load on meshes graded towards its contact edges (:meth:`refine_to`; ``max_dofs``: no mesh
        beyond it after the first), and the graded solves."""
        assert self.graded is not None and self.h0 is not None       # refine_to's choice
        out: list[GradedSolve] = []
        for k, load in enumerate(loads):
            twin = self.predictor() if self.predictor is not None else None
            seed = twin.edges(load) if twin is not None else None
            out.append(solve_to_tolerance(self.graded, load, tolerance, self.h0, self.period, self.model.order,
                                          seed=seed, required=required, max_dofs=max_dofs))
            log.info("load %d: contact fraction %.10g after %d grading steps", k,
                     out[-1].solution.results["contact_fraction"], len(out[-1].history) - 1)
        self._problem = out[-1].problem
        return graded_refinement(out), out

    def compared(self, tolerance: float, loads: list[CellLoad], max_dofs: int, required: bool,
                 first: list[CellSolution] | None = None) -> Sequence:
        """The sweep on the refiner's discretizations, the last's problem becoming this cell's
        (:meth:`refine_to`; ``first``: the scene's sweep, solved already)."""
        refiner = self.refiner()
        if refiner is None:
            raise ModelError("this FE cell was built without the recipe of a finer discretization")
        done = refine(refiner, loads, tolerance, max_dofs, required, first)
        if done.cell is not self:
            self._problem = done.cell.problem
        return done

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


def warn_unmet(refined: Refinement, tolerance: float) -> None:
    """One warning line where a counted quantity's estimate misses the default ``tolerance`` (issue 35: the run
    goes on, ``accuracy.met = false``; a stated tolerance has raised before)."""
    worst = counted_worst(refined)
    if worst > tolerance:
        log.warning("accuracy not met: the FE cell's estimated error %.3g exceeds the default tolerance %g (%s); "
                    "refine interface_maxh or the order, or set discretization.tolerance", worst, tolerance,
                    refined.how)


def counted_worst(refined: Refinement) -> float:
    """The largest estimate of a quantity the verdict counts (not one of ``refined.uncontrolled``): what a stated
    tolerance raises on and the default one warns on."""
    return max((v for e in refined.estimates for n, v in e.items() if n not in refined.uncontrolled), default=0.0)
