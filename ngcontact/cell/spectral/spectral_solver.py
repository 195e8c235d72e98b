"""The spectral cell behind the cell protocol (:class:`~ngcontact.cell.cell_solver.CellSolver`).

:class:`SpectralCellSolver` holds a :class:`~ngcontact.cell.spectral.layered_cell.SpectralCell` and the
recipe of the same cell on another grid: it answers loads (each from zero pressure: the small-slope
problem has one solution whatever the path, for friction too since a load is solved in tractions at
once), sweeps, refinement to a tolerance by grid growth
(:mod:`ngcontact.cell.spectral.refinement`) and the pressure response of the two-scale table.

Its response at a mean pressure ``p``: both layers are flat and ``n = n0`` on all of ``S_C``, so
``k_n0 = k_n`` times the contact fraction (eq. 34 on the real contact set; the fraction with its 2D
edges located between grid points, :func:`ngcontact.cell.spectral.grid_measures.contact_fraction`), and
the closure is the mean normal jump ``c = mean(J_n)`` over the period.  Frictionless cells only: the
spectral cell carries no shear without friction (the two-scale loop's shear table solves the FE cell).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ngcontact.cell.cell_load import CellLoad, cell_load
from ngcontact.cell.cell_solution import CellSolution, worst_estimate
from ngcontact.cell.cell_solver import Refinement, Response, response_of
from ngcontact.cell.spectral import grid_measures
from ngcontact.cell.spectral.coarser_grids import HOW as COARSER_HOW, estimate_from_coarser, why_not
from ngcontact.cell.spectral.penalty_zone import penalty_length
from ngcontact.cell.spectral.layered_cell import SpectralCell, SpectralSolution
from ngcontact.cell.spectral.refinement import HOW, sweep_to_tolerance, uncontrolled
from ngcontact.cell.whole_surface import flat
from ngcontact.errors import ConvergenceError

#: the grid fields a solution hands on (the closure is in its surface distribution)
FIELDS = ("pressure", "gap", "shear", "slip")
#: a 2D penalty's share of the contact fraction is measured where its length E*/k_n spans this many grid steps, on
#: at least this many points (:meth:`SpectralCellSolver.share_resolution`)
SHARE_STEPS, SHARE_GRID = 32, 32768


class SpectralCellSolver:
    """A spectral cell answering the cell protocol (module docstring).

    Parameters
    ----------
    cell
        The spectral cell on the scene's grid.
    make_cell
        ``n -> SpectralCell`` of the same cell on ``n`` points per direction (refinement).
    max_points
        The most grid points refinement to a stated tolerance may use.
    default_max_points
        The most grid points refinement to the default tolerance may use (default: ``max_points``).
    refine_default
        Whether a sweep without a stated tolerance is refined to the default one (``discretization.estimate =
        "auto"``), or answered on its own grid with its error estimated from coarser grids (``"estimate"``: a
        level of an accuracy study, whose grid is its knob's setting).
    variant
        ``(**changes) -> SpectralCellSolver`` of the same scene and grid with ``enforcement`` or ``k_n``
        changed (the penalty's share), ``None`` where refused.
    """

    def __init__(self, cell: SpectralCell, make_cell: Callable[[int], SpectralCell] | None = None,
                 max_points: int | None = None, default_max_points: int | None = None,
                 variant: Callable[..., SpectralCellSolver | None] | None = None, refine_default: bool = True):
        self.cell = cell
        self.refine_default = refine_default
        self.dim = cell.dim
        self.period = cell.period
        self.make_cell, self.max_points, self.default_max_points = make_cell, max_points, default_max_points
        self.variant = variant

    # ------------------------------------------------------------ description
    def unknowns(self) -> int:
        return int(self.cell.points)

    def size(self) -> dict[str, Any]:
        return {"method": "spectral", "grid_points": self.unknowns()}

    def method_record(self) -> dict[str, Any] | None:
        c = self.cell
        return {"name": "spectral", "grid": c.grid, "points": c.points, "enforcement": c.enforcement,
                "solver": "constrained_cg" if c.friction is None else "accelerated_proximal_gradient",
                "tolerance": c.tol}

    def whole_surface(self) -> dict[str, Any]:
        return grid_measures.coefficients(self.cell, np.ones(self.cell.shape, bool)).as_dict()

    def whole_surface_error(self) -> tuple[dict[str, float] | None, str]:
        """Exact (zero): the small-slope cell's contact surface is the flat interface, whose normal is ``n0``
        everywhere, so the normal components ``beta`` of eq. 34 are constants on any grid, and a term carrying
        the gap is its mean over the grid's points, the exact mean of the gap as the cell defines it (on its
        own grid)."""
        return ({name: 0.0 for name in flat(self.whole_surface())},
                "exact: the flat interface of the small-slope cell, the gap's mean over its own grid")

    # ----------------------------------------------------------------- solves
    def solution(self, sol: SpectralSolution) -> CellSolution:
        """The protocol's solution of one of the spectral cell's own."""
        surface: dict[str, np.ndarray] = {}
        if self.cell.dim == 2:
            c = self.cell
            surface = {"x": c.period * np.arange(c.grid) / c.grid, "pressure": sol.fields["pressure"],
                       "gap": sol.fields["gap"], "closure": sol.fields["closure"]}
        history = {"method": "constrained_cg", "iterations": sol.iterations, "residuals": sol.residuals}
        return CellSolution(load=sol.load, results=sol.results, surface=surface,
                            fields={k: sol.fields[k] for k in FIELDS if k in sol.fields}, newton=[history])

    def solve(self, load: CellLoad, *, first: bool = True, measure: bool = True) -> CellSolution:
        return self.solution(self.cell.solve(load))

    def sweep(self, loads: list[CellLoad]) -> list[CellSolution]:
        return [self.solution(s) for s in self.cell.sweep(loads)]

    def refines_by_default(self) -> bool:
        """Whether a sweep without a stated tolerance is refined to the default one: where the recipe of
        finer grids is known and the scene asks it (:attr:`refine_default`)."""
        return self.refine_default and self.make_cell is not None and self.max_points is not None

    def holds_loads_alone(self) -> bool:
        """Yes where the recipe of other grids is known: the grid-doubling estimate and refinement of a sweep
        (:func:`~ngcontact.cell.spectral.refinement.sweep_to_tolerance`, and the coarser grids' estimate) are
        per load already, each load solved from zero pressure, so a load refined alone takes the same
        estimate, only its own grids (those of the worst load of a sweep it would share)."""
        return self.make_cell is not None and self.max_points is not None

    def default_accuracy(self, tolerance: float, loads: list[CellLoad]) -> Refinement | None:
        """Refined to the default ``tolerance`` within the default size bound where the cell
        :meth:`refines_by_default` (:meth:`refine_to`); else, where the recipe of other grids is known, the
        scene's own grid with its error estimated from coarser grids (:meth:`scene_estimate`; a miss is
        reported, not refined); else ``None``."""
        if self.refines_by_default():
            return self.refine_to(tolerance, loads, required=False)
        return self.scene_estimate(loads) if self.holds_loads_alone() else None

    def scene_estimate(self, loads: list[CellLoad]) -> Refinement | None:
        """The sweep on the scene's grid, its error estimated from three coarser grids
        (:mod:`ngcontact.cell.spectral.coarser_grids`); not estimated (the reason in ``how``, not met) where the
        grid does not halve so; ``None`` without the recipe of other grids."""
        if self.make_cell is None:
            return None
        first, make = self.cell, self.make_cell
        done = estimate_from_coarser(lambda n: first if n == first.grid else make(n), loads, first.grid)
        if done is None:
            return Refinement(solutions=self.sweep(loads), estimates=[], how=why_not(first.grid), met=False,
                              scene_discretization=True)
        method = {"estimate_grids": [h["grid"] for h in done.history],
                  "estimate_seconds": sum(h["seconds"] for h in done.history[:-1])}
        how = COARSER_HOW + f"; {HOW}" + (f" ({'; '.join(done.remarks)})" if done.remarks else "")
        return Refinement(solutions=[self.solution(s) for s in done.solutions], estimates=list(done.estimates),
                          method=method, how=how, uncontrolled=uncontrolled(first.dim), scales=done.scales,
                          loose=done.flags,
                          scene_discretization=True)

    def refine_to(self, tolerance: float, loads: list[CellLoad], required: bool = True) -> Refinement:
        """Grids from the scene's up until the estimate meets ``tolerance``
        (:func:`~ngcontact.cell.spectral.refinement.sweep_to_tolerance`); the finest grid's cell becomes this
        solver's.  A ``required`` tolerance (the scene's) may use grids up to ``max_points`` and raises out of
        reach, and waits for the 2D edge fit's own levels before a stop (``sharpen``); the default one up to
        ``default_max_points``, its first grid that meets it the answer, and out of reach the finest level
        with ``met = False``.  A required tolerance the 2D stiffness misses at its cap
        (:func:`~ngcontact.cell.spectral.refinement.stiffness_capped`) is out of reach too: it raises, with the
        figures (issue 35: a stated tolerance out of reach ends the run, exit 3, never ``met = false``)."""
        if self.make_cell is None or self.max_points is None:
            raise ValueError("this spectral cell was built without the recipe of finer grids")
        first, make = self.cell, self.make_cell
        bound = self.max_points if required or self.default_max_points is None else self.default_max_points
        bound = max(min(bound, self.max_points), first.points)
        refined = sweep_to_tolerance(lambda n: first if n == first.grid else make(n), loads, tolerance,
                                     first.grid, first.dim, bound, required=required, sharpen=required)
        if required and refined.capped:
            raise ConvergenceError(
                f"discretization.tolerance = {tolerance:g} not met: the estimate is "
                f"{worst_estimate(refined.estimates)} {refined.capped}: "
                + next(r for r in refined.remarks if r.startswith("the normal stiffness's estimate"))
                + "; state a looser discretization.tolerance (every counted quantity's estimate is held to it)",
                {"levels": refined.history})
        self.cell = refined.cell
        method = {"grid": self.cell.grid, "points": self.cell.points, "refinement": refined.history}
        solutions = [self.solution(s) for s in refined.solutions]
        if len(refined.history) < 2:
            return Refinement(solutions=solutions, estimates=[], method=method, met=False,
                              how=f"not estimated: the grid of {first.points} points is the largest of the size "
                                  f"bound ({bound} points), so there is no finer grid to compare with")
        how = HOW + (f" ({'; '.join(refined.remarks)})" if refined.remarks else "")
        return Refinement(solutions=solutions, estimates=list(refined.estimates), method=method,
                          met=refined.met, how=how, uncontrolled=refined.uncontrolled,
                          scales=refined.scales, loose=refined.flags, shortfall=refined.capped,
                          remedy="the stiffness converges as its contact edges are located (at first order where "
                                 "to a fraction of a step): state a looser discretization.tolerance to meet it, "
                                 "or read it with its estimate")

    def penalty(self) -> float | None:
        return float(self.cell.k_n) if self.cell.enforcement == "penalty" else None

    def share_solver(self) -> SpectralCellSolver:
        return self

    def varied(self, *, enforcement: str | None = None, k_n: float | None = None) -> SpectralCellSolver | None:
        """The same cell on the grid of the last solve with another enforcement or penalty."""
        changes = {k: v for k, v in (("enforcement", enforcement), ("k_n", k_n)) if v is not None}
        return self.variant(grid=self.cell.grid, **changes) if self.variant is not None else None

    def share_resolution(self) -> tuple[SpectralCellSolver, float] | None:
        """A 2D penalty whose length ``lambda = E*/k_n`` spans fewer than :data:`SHARE_STEPS` steps of the grid:
        the cell on :data:`SHARE_GRID` points at least and the softer penalty ``k_1`` whose length spans that
        many of its steps (at most ``k_n``); ``None`` otherwise (module docstring of
        :mod:`ngcontact.cell.penalty_share`)."""
        lam = penalty_length(self.cell)
        if lam <= 0.0 or lam >= SHARE_STEPS * self.cell.period / self.cell.grid or self.variant is None:
            return None
        grid = max(self.cell.grid, SHARE_GRID)
        twin = self.variant(grid=grid)
        k1 = min(self.cell.k_n, self.cell.k_n * lam * grid / (SHARE_STEPS * self.cell.period))
        return (twin, k1) if twin is not None else None

    def response(self, pressure: float, length_unit: float = 1.0) -> Response:
        """The response at ``pressure`` (module docstring), from zero pressure."""
        sol = self.cell.solve(cell_load(self.cell.dim, pressure=float(pressure)))
        fraction = float(sol.results["contact_fraction"])
        closure = float(sol.results["mean_closure"]) * length_unit
        return response_of(fraction, self.cell.k_n * fraction, closure, float(pressure))

    # ------------------------------------------------------------------ report
    def load_entry(self, solution: CellSolution) -> dict[str, Any]:
        """The report's entry of one load: its results and constrained CG steps."""
        return dict(solution.results, iterations=solution.iterations)

    def solver_record(self, solutions: list[CellSolution], refinement: Refinement | None = None) -> dict[str, Any]:
        return {"iterations": sum(s.iterations for s in solutions), "converged": True,
                "per_load": [s.newton[0] for s in solutions]}

    def displacements(self) -> tuple[Any, dict[str, Any]] | None:
        return None            # the layers' interiors are not sampled

    def state(self):
        return None

    def set_state(self, state) -> None:
        return None
