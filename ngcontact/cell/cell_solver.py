"""The cell protocol: one question, the response of one periodic cell, answered by any method.

Everything above :mod:`ngcontact.cell` (the drivers, the two-scale tables, the batch members) sees a cell
only through :class:`CellSolver`.  Two methods implement it:

* :class:`ngcontact.cell.fe.fe_cell.FECell`: finite elements on the meshed bodies (any profile; paper
  eqs. 49-51, penalized as eq. 65 or with exact non-penetration), refined towards the contact edges;
* :class:`ngcontact.cell.spectral.spectral_solver.SpectralCellSolver`: the small-slope cell on the grid
  of its gap, with FFTs, refined by grid doubling.

A third method is one sub-package implementing this protocol, plus its entry in the builder's choice
(:func:`ngcontact.drivers.build.cell_solver`) and the scene's choice list
(``discretization.method``).

The response of a cell to a mean pressure ``p`` (compression positive), which the two-scale loop
tabulates (paper Sec. 3.5; :mod:`ngcontact.coupling.pressure_table`), is the :data:`Response`: the real
contact fraction, ``k_n0`` of eq. 34 on the real contact set, the mean closure ``c`` and the gap term
``g_n0 = k_n0 c - p`` that makes the Winkler law pass through the cell's state.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.cell_solution import CellSolution

#: ``{"contact_fraction", "k_n0", "g_n0", "closure"}`` of the cell at one pressure
Response = dict[str, float]
#: the keys of a :data:`Response`
RESPONSE_KEYS = ("contact_fraction", "k_n0", "g_n0", "closure")


def response_of(fraction: float, kn0: float, closure: float, pressure: float) -> Response:
    """The :data:`Response` of a cell state: its contact fraction, ``k_n0`` and mean closure at ``pressure``
    (``g_n0 = k_n0 c - p``)."""
    return {"contact_fraction": float(fraction), "k_n0": float(kn0), "g_n0": float(kn0 * closure - pressure),
            "closure": float(closure)}


@dataclass
class Refinement:
    """A load sweep solved to a requested accuracy.

    Attributes
    ----------
    solutions
        The finest level's solution of each load.
    estimates
        Per load, the estimated error of each estimated quantity in its measure
        (:func:`~ngcontact.cell.cell_solution.measure`: ``contact_fraction`` absolute, ``mean_closure``
        relative, ...).
    per_load
        Per load, what the report adds to the load's entry besides the estimate (an FE cell's
        ``mesh_history`` and its Newton steps summed over the levels), possibly empty.
    method
        What the report adds to ``results.method`` (a spectral cell's finest grid and its levels),
        possibly empty.
    """

    solutions: list[CellSolution]
    estimates: list[dict[str, float]]
    per_load: list[dict[str, Any]] = field(default_factory=list)
    method: dict[str, Any] = field(default_factory=dict)
    #: the histories of every level's solve per load (the report's ``solver.per_load``), where kept
    histories: list[Any] = field(default_factory=list)
    #: how the estimates were made, in words for the report
    how: str = ""
    #: whether the refinement reached its tolerance within the method's size bound (an unrequired
    #: tolerance out of reach leaves the finest level as the answer, marked as not meeting it)
    met: bool = True
    #: the estimated quantities the refinement does not hold to the tolerance (reported with their estimate,
    #: not counted in the verdict)
    uncontrolled: tuple[str, ...] = ()
    #: per load, what each estimate's absolute error was divided by in its measure
    #: (:func:`~ngcontact.cell.cell_solution.scale`), where the method says
    scales: list[dict[str, float]] = field(default_factory=list)
    #: per load, the estimates the method states may exceed their error by more than ten times, with the
    #: reason (:func:`~ngcontact.cell.spectral.estimate_forms.loose_flags`), where the method says
    loose: list[dict[str, str]] = field(default_factory=list)
    #: the solutions are the scene's own discretization's, their error estimated without refining
    #: (:meth:`CellSolver.default_accuracy` of an FE cell)
    scene_discretization: bool = False
    #: where a refinement towards the default tolerance ended on its budget before meeting it: the budget and
    #: what meeting the tolerance would take, in words (the run's warning and ``accuracy.shortfall``), else ""
    shortfall: str = ""
    #: what the run's warning advises where there is a shortfall
    remedy: str = "raise discretization.budget_dofs or state discretization.tolerance"


class CellSolver(Protocol):
    """A discretized cell that answers loads (module docstring)."""

    #: the cell's dimension (2 or 3)
    dim: int
    #: the cell's period (the first tangential direction's)
    period: float

    def unknowns(self) -> int:
        """The number of unknowns of the discretization (FE dofs, grid points)."""

    def size(self) -> dict[str, Any]:
        """The discretization for a report: ``{"method": ..., "ndof" or "grid_points": ...}``."""

    def method_record(self) -> dict[str, Any] | None:
        """What the report states under ``results.method`` (``None``: nothing)."""

    def whole_surface(self) -> dict[str, Any]:
        """The coefficients of the whole contact surface (paper eqs. 34, 42-43; no contact solve)."""

    def whole_surface_error(self) -> tuple[dict[str, float] | None, str]:
        """The estimated absolute error of each scalar coefficient of :meth:`whole_surface`
        (:func:`ngcontact.cell.whole_surface.flat` names them) and how it was estimated, or ``None`` and the
        reason it is not."""

    def solve(self, load: CellLoad, *, first: bool = True, measure: bool = True) -> CellSolution:
        """Solve one load; ``first``: from a first load's start (else continued from the last state)."""

    def sweep(self, loads: list[CellLoad]) -> list[CellSolution]:
        """Solve the loads in order (each from the previous where the method continues)."""

    def refines_by_default(self) -> bool:
        """Whether a sweep whose scene states no tolerance is refined to the default one
        (:data:`ngcontact.cell.admissibility.DEFAULT_TOLERANCE`) by :meth:`refine_to`."""

    def default_accuracy(self, tolerance: float, loads: list[CellLoad]) -> Refinement | None:
        """The sweep of a scene that states no tolerance, held to the default ``tolerance``: refined to it
        (:meth:`refine_to` with ``required = False``) where the method :meth:`refines_by_default`, else
        solved on the scene's discretization with its error estimated (``scene_discretization``), or ``None``
        (the fixed discretization, not estimated)."""

    def scene_estimate(self, loads: list[CellLoad]) -> Refinement | None:
        """The sweep on the scene's own discretization with its error estimated and not refined
        (``scene_discretization``; an ensemble's members, whose numbers stay the scene's): the FE cell by one
        order more on the same mesh, the spectral cell from coarser grids; not estimated (the reason in
        ``how``, not met) where the method cannot, ``None`` without the recipe of another discretization."""

    def holds_loads_alone(self) -> bool:
        """Whether :meth:`default_accuracy` holds one load solved alone from the unloaded cell (a scene's
        independent loads, each a member of a batch: :mod:`ngcontact.drivers.cell_members`) to the default
        tolerance as it holds a sweep, returning its refinement: where the method's estimate and refinement
        are each load's own (the FE cell; the spectral cell with the recipe of its finer grids).  Where not,
        independent loads are solved on the scene's discretization, not estimated."""

    def refine_to(self, tolerance: float, loads: list[CellLoad], required: bool = True) -> Refinement:
        """Solve the loads on refined discretizations until the estimated error meets ``tolerance``.

        ``required``: the scene stated the tolerance (else it is the default one, and the method may bound
        its discretization more tightly).

        Raises
        ------
        ConvergenceError
            A ``required`` tolerance is out of the method's reach (its largest discretization); the
            message says how far it got.  An unrequired one returns the finest level with ``met = False``.
        """

    def penalty(self) -> float | None:
        """The penalty ``k_n`` where the contact is enforced by the paper's Winkler layer (eq. 65), else
        ``None`` (exact non-penetration)."""

    def share_solver(self) -> CellSolver:
        """The discretization of the same model on which the penalty's share is measured
        (:mod:`ngcontact.cell.penalty_share`): the method's own, or a finer twin of the same model where it
        has one that resolves the contact edges at a fraction of the cost."""

    def varied(self, *, enforcement: str | None = None, k_n: float | None = None) -> CellSolver | None:
        """The same cell on the same discretization with another enforcement or penalty (the penalty's share
        of the answer, :mod:`ngcontact.cell.penalty_share`); ``None`` where the method cannot have it."""

    def share_resolution(self) -> tuple[CellSolver, float] | None:
        """Where this discretization locates contact edges on points farther than the penalty's length
        ``E*/k_n``: a twin of the same model on a discretization that resolves the length of a softer penalty,
        and that penalty (the share of the contact fraction is extrapolated from it,
        :mod:`ngcontact.cell.penalty_share`); else ``None``."""

    def response(self, pressure: float, length_unit: float = 1.0) -> Response:
        """The :data:`Response` at a mean pressure, solved from a first load's start; lengths scaled by
        ``length_unit``."""

    def load_entry(self, solution: CellSolution) -> dict[str, Any]:
        """The report's entry of one load: its results and the method's iteration counts."""

    def solver_record(self, solutions: list[CellSolution], refinement: Refinement | None = None) -> dict[str, Any]:
        """The report's ``solver`` entry of a sweep: iterations, convergence, per-load records."""

    def displacements(self) -> tuple[Any, dict[str, Any]] | None:
        """The mesh and the bodies' displacement fields of the last state, where the method has them."""

    def state(self) -> Any:
        """The state after the last solve, as plain data (``None`` where the method keeps none)."""

    def set_state(self, state: Any) -> None:
        """Put a state of :meth:`state` (from a cell built identically, e.g. in a worker) in place."""


def joined(parts: list[Refinement]) -> Refinement:
    """The refinement of a sweep whose loads were held to a tolerance one by one: ``parts`` are the loads'
    own refinements in the loads' order (:meth:`CellSolver.holds_loads_alone`).

    The lists run over the loads (a part without estimates, scales or per-load records adds empty ones for
    its loads, so that they stay aligned); the sweep meets the tolerance where every part does, and its
    solutions are the scene's discretization's only where every part's are; ``how`` is the parts' one
    statement, or each distinct one with the loads it holds for; the shortfall is that of the unmet part
    with the largest estimate, the one that sets what meeting the tolerance would take.  ``method`` is the
    last part's (its discretization is the one the driver's cell holds), with every part's under
    ``per_load`` where they differ (a spectral load's own grid and levels).
    """
    def rows(pick) -> list:
        if not any(pick(p) for p in parts):
            return []
        return [row for p in parts for row in (pick(p) or [{} for _ in p.solutions])]

    hows: dict[str, list[int]] = {}
    k = 0
    for p in parts:
        hows.setdefault(p.how, []).extend(range(k, k + len(p.solutions)))
        k += len(p.solutions)
    how = next(iter(hows)) if len(hows) == 1 else "; ".join(
        f"load{'s' if len(ks) > 1 else ''} {', '.join(map(str, ks))}: {h}" for h, ks in hows.items())
    unmet = [p for p in parts if p.shortfall]
    worst = max(unmet, key=lambda p: max((max(e.values()) for e in p.estimates if e), default=0.0), default=None)
    return Refinement(solutions=[s for p in parts for s in p.solutions], estimates=rows(lambda p: p.estimates),
                      per_load=rows(lambda p: p.per_load), method=joined_method(parts),
                      histories=[h for p in parts for h in (p.histories or [s.newton for s in p.solutions])],
                      how=how, met=all(p.met for p in parts),
                      uncontrolled=tuple(dict.fromkeys(u for p in parts for u in p.uncontrolled)),
                      scales=rows(lambda p: p.scales), loose=rows(lambda p: p.loose),
                      scene_discretization=all(p.scene_discretization for p in parts),
                      shortfall=worst.shortfall if worst is not None else "",
                      **({"remedy": worst.remedy} if worst is not None else {}))


def joined_method(parts: list[Refinement]) -> dict[str, Any]:
    """The ``method`` record of :func:`joined`: the last part's, and every part's under ``per_load`` where
    they differ."""
    if not parts:
        return {}
    last = dict(parts[-1].method)
    if any(p.method != parts[-1].method for p in parts):
        last["per_load"] = [p.method for p in parts]
    return last
