"""The error of an FE cell that cannot be graded, from a sequence of finer discretizations and its rate.

Grading towards the contact edges (:mod:`ngcontact.cell.fe.edge_grading`) needs the flat 2D interface whose
edges are points on a line and loads solved afresh.  A 3D cell (edges are curves), a curved ``S_C`` (square
hills, a conforming profile) or a frictional load path (solved in order) is refined instead by solving the
same sweep on a sequence of discretizations given by a :class:`Refiner`, and the error of the last is
estimated from the sequence (:mod:`ngcontact.cell.fe.observed_rate`).

The refiner of such a cell is :class:`InterfaceHalving` (a flat 3D cell with exact contact:
:class:`~ngcontact.cell.fe.contact_edge_refinement.ContactEdgeRefinement`): the interface element size halved
from level to level at the scene's order (``h, h/2, h/4, ...``, the bulk mesh as before; along the contact
edge only). The contact fraction converges at least like ``h``: a contact edge cuts its elements anywhere, and
the fraction counts the cut elements' share to first order (in 3D the fraction is the quadrature integral of
the contact indicator, whose error at the edge curves is of that order whatever the polynomial order); the
closure converges faster.  So the
observed ratio of successive differences is held to at least ``1/2`` (:data:`HALVING_RATE`).  One order
more on the same mesh is not a sequence that converges at a rate one may observe here: on the shipped 3D
bisinusoid its contact fraction moved 0.029 from order 2 to 3 and 0.010 from 3 to 4 while the error of
order 4 against the converged spectral twin was still 0.021 (the indicator's edge error does not fall with
the order), so the tail of the differences would claim a quarter of the error.

The loop (:func:`refine`): the scene's discretization is level 0; each next level is solved if its unknowns
(known once its mesh is built, before the solve) are within the size bound; the estimate of the last level
needs three levels (two observed differences), or two where the third is beyond the bound; it stops when the
estimate meets the tolerance, or, where no tolerance was stated, when the observed rate of the estimate puts
the tolerance beyond the size bound (:func:`_beyond_reach`) by each of the last two pairs of estimated levels:
one pair of a sequence not yet asymptotic can show a rate far below the one that follows.  An
:class:`Extrapolating` refiner names the levels its geometric tails take (:meth:`~Extrapolating.sequence`:
those of one sequence in its size) and when its extrapolation exists
(:meth:`~Extrapolating.ready`); before that its estimate within the tolerance does not stop the loop, since
the tail of levels not yet asymptotic in that size claims less than their error.  Out of reach: a
:class:`~ngcontact.errors.ConvergenceError` with the figures
where the tolerance was stated, else the last level with ``met = False``.  Per load: the contact fraction
absolutely, the mean closure and the normal effective stiffness relatively, as everywhere
(:data:`ngcontact.cell.admissibility.ESTIMATED`), and the coefficients of eq. 34 on the real contact set
relative to their group (:func:`ngcontact.cell.cell_solution.measure`), all held to the tolerance.
A refiner is any :class:`Refiner`, each with its
own :class:`~ngcontact.cell.fe.observed_rate.Convergence`.  A :class:`Floored` refiner also gives a bound of
each quantity's absolute error that includes what its sequence cannot see (the contact edge's ladder: its
spectral twin, :mod:`ngcontact.cell.fe.contact_edge_refinement`, "The twin's bound"); the estimate is that
bound where the refiner names the quantity as measured by it, else the larger of the two; the quantities it
names as uncontrolled are reported with their estimate and neither stop the loop nor count in the verdict.
A :class:`Steered` refiner has more than one knob: before each level the loop tells it which quantities'
estimates miss the tolerance, and it chooses the knob of the next level from them (the contact edge's ladder:
the edge size, or its grading where only the stiffness misses), or names why no level of its can meet them.
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Protocol, runtime_checkable

from ngcontact.cell.cell_solution import COEFFICIENT, CellSolution, headline, scale, worst_estimate
from ngcontact.cell.cell_solver import Refinement
from ngcontact.cell.fe.observed_rate import Convergence, dofs_to_meet, exponent, sequence_estimates
from ngcontact.errors import ConvergenceError, ModelError, SceneError

log = logging.getLogger(__name__)
#: the run's progress lines
progress = logging.getLogger("ngcontact.progress")

#: how the answers of an interface mesh halved level by level converge (module docstring)
HALVING_RATE = Convergence(floor=0.5, assumed=0.5, cap=0.7, safety=1.5)
#: the quantities estimated: whether the measure is relative
MEASURES = {"contact_fraction": False, "mean_closure": True, "normal_stiffness": True}
#: the most levels (the scene's and its refinements)
MAX_LEVELS = 6


class Refiner(Protocol):
    """The discretizations of one FE cell, coarsest (the scene's) first, and how their answers converge."""

    #: how the estimate treats the sequence
    rule: Convergence

    def level(self, k: int) -> Any:
        """The cell of level ``k`` (an object with ``sweep(loads)`` and ``unknowns()``), ``None`` where the
        scene refuses it."""

    def describe(self, k: int) -> str:
        """Level ``k`` in words ("interface_maxh 0.03")."""


@runtime_checkable
class Extrapolating(Protocol):
    """A refiner whose levels form a sequence in one size to which a quantity extrapolates
    (:class:`~ngcontact.cell.fe.contact_edge_refinement.ContactEdgeRefinement`: the contact fraction in the
    element size at the contact edge): the value reported is the extrapolation, its estimate the
    extrapolation's, in place of the last level's value and geometric tail."""

    def extrapolated(self, heads: list[list[dict[str, float]]]) -> dict[str, list[Any]]:
        """Per quantity name, per load the extrapolation (``value``, ``estimate``, ``how``) of the levels'
        headline quantities ``heads[level][load]``, or ``None`` where the levels do not yet give one."""

    def sequence(self, heads: list[list[dict[str, float]]]) -> list[list[dict[str, float]]]:
        """The levels whose differences the geometric tails take: those of one sequence in the size."""

    def ready(self, levels: int) -> bool:
        """Whether ``levels`` solved levels give the extrapolation: before, the sequence is not taken as
        converged, whatever the geometric tail says (the levels it is made of are not yet asymptotic)."""


@runtime_checkable
class Floored(Protocol):
    """A refiner with a bound of the error that includes what its sequence does not see (module docstring)."""

    #: the quantities whose estimate is that bound alone, in place of the sequence's
    measured: tuple[str, ...]
    #: the quantities reported with their estimate but not held to the tolerance
    uncontrolled: tuple[str, ...]

    def twin_floors(self, reported: list[dict[str, float]], k: int) -> list[dict[str, tuple[float, str]]]:
        """Per load, per quantity, the floor of the absolute error of level ``k``'s ``reported`` value and its
        form in words."""


@runtime_checkable
class Steered(Protocol):
    """A refiner whose next level depends on which estimates miss the tolerance (module docstring)."""

    def steer(self, k: int, missing: set[str]) -> str | None:
        """Choose the knob of level ``k`` from the quantities whose estimates miss the tolerance on the levels
        solved so far (none before the first estimate); a reason in words where none of its levels can meet
        them (the loop stops there), else ``None``."""


@dataclass
class InterfaceHalving:
    """Level ``k``: the scene's cell with ``interface_maxh / 2^k`` at the scene's order (module docstring)."""

    scene_cell: Any
    variant: Callable[..., Any]
    interface_maxh: float
    rule: Convergence = HALVING_RATE

    def level(self, k: int) -> Any:
        return self.scene_cell if k == 0 else self.variant(interface_maxh=self.interface_maxh / 2 ** k)

    def describe(self, k: int) -> str:
        return f"interface_maxh {self.interface_maxh / 2 ** k:g}"


@dataclass
class Sequence:
    """The last level's cell and solutions, the estimate per load, the levels solved, whether the tolerance
    is met, and how the estimate was made in words."""

    cell: Any
    solutions: list[CellSolution]
    estimates: list[dict[str, float]]
    levels: list[dict[str, Any]] = field(default_factory=list)
    met: bool = True
    how: str = ""
    #: per load, what each estimate's absolute error is divided by (:func:`~ngcontact.cell.cell_solution.scale`)
    scales: list[dict[str, float]] = field(default_factory=list)
    #: the unknowns of the first level beyond the size bound (not solved), where that stopped the loop
    beyond: int | None = None
    #: why the loop stopped short of the tolerance, in words ("" where it met it)
    stop: str = ""
    #: the estimated quantities not held to the tolerance (:class:`Floored`)
    uncontrolled: tuple[str, ...] = ()


def _level(cell, loads, k: int, refiner: Refiner, known: list[CellSolution] | None = None
           ) -> tuple[list[CellSolution], dict[str, Any]]:
    """Solve level ``k`` (``known``: its sweep, solved already) and its record."""
    t0 = time.perf_counter()
    sols = cell.sweep(loads) if known is None else known
    entry = {"discretization": refiner.describe(k), "ndof": int(cell.unknowns()),
             "seconds": time.perf_counter() - t0,
             "contact_fraction": [s.results["contact_fraction"] for s in sols],
             "mean_closure": [s.results["mean_closure"] for s in sols]}
    progress.info("FE refinement, %s: %d dofs, %.2f s", entry["discretization"], entry["ndof"], entry["seconds"])
    return sols, entry


def refine(refiner: Refiner, loads: list, tolerance: float, max_dofs: int, required: bool,
           first: list[CellSolution] | None = None) -> Sequence:
    """The sweep on the refiner's levels until the estimate meets ``tolerance`` (module docstring); ``first``:
    the scene's sweep (level 0), where solved already."""
    heads: list[list[dict[str, float]]] = []
    levels: list[dict[str, Any]] = []
    cell = sols = None
    estimates: list[dict[str, float]] = []
    scales: list[dict[str, float]] = []
    remarks: list[str] = []
    stop = f"the most levels ({MAX_LEVELS})"
    beyond = None
    free = refiner.uncontrolled if isinstance(refiner, Floored) else ()
    for k in range(MAX_LEVELS):
        if isinstance(refiner, Steered):
            why = refiner.steer(k, {n for e in estimates for n, v in e.items() if v > tolerance and n not in free})
            if why is not None:
                stop = why
                break
        try:
            nxt = refiner.level(k)
        except (SceneError, ModelError) as exc:     # a level the mesher cannot build: out of reach, as refused
            if required or k == 0:
                raise
            stop = f"{refiner.describe(k)} cannot be built ({exc})"
            break
        if nxt is None:
            stop = f"the scene refuses {refiner.describe(k)}"
            break
        if k > 0 and nxt.unknowns() > max_dofs:
            beyond = int(nxt.unknowns())
            stop = f"{refiner.describe(k)} would have {beyond} dofs, beyond {max_dofs}"
            break
        cell = nxt
        sols, entry = _level(cell, loads, k, refiner, first if k == 0 else None)
        levels.append(entry)
        heads.append([headline(s.results) for s in sols])
        if len(heads) > 1:
            # the coefficients' scale: the whole surface's (paper eq. 34 with w = 1), where a load reports them
            whole = cell.whole_surface() if any(n.startswith(COEFFICIENT) for h in heads[-1] for n in h) else None
            sequence = refiner.sequence(heads) if isinstance(refiner, Extrapolating) else heads
            estimates, remarks = sequence_estimates(sequence, refiner.rule, MEASURES, whole)
            if isinstance(refiner, Extrapolating):
                remarks += _extrapolate(refiner.extrapolated(heads), sols, estimates)
            if isinstance(refiner, Floored):
                remarks += _floor(refiner.twin_floors([headline(s.results) for s in sols], len(heads) - 1),
                                  sols, estimates, whole, refiner.measured)
            scales = [{n: scale(n, head, whole) for n in e} for e, head in zip(estimates, heads[-1])]
            entry["estimate"] = max((v for e in estimates for n, v in e.items() if n not in free), default=0.0)
            if len(heads) >= 3 and _settled(refiner, len(heads)) and entry["estimate"] <= tolerance:
                return Sequence(cell, sols, estimates, levels, True, _how(refiner, levels, remarks), scales,
                                uncontrolled=free)
            hopeless = None if required or len(heads) < 3 else _beyond_reach(levels, tolerance, max_dofs)
            if hopeless is not None:
                stop = hopeless
                break
    assert cell is not None and sols is not None      # level 0 is the scene's own cell
    worst = levels[-1].get("estimate")
    if len(heads) == 2 and _settled(refiner, 2) and worst is not None and worst <= tolerance:   # third beyond
        return Sequence(cell, sols, estimates, levels, True, _how(refiner, levels, remarks + [f"stopped: {stop}"]),
                        scales, uncontrolled=free)
    reached = "no estimate (one level)" if worst is None else worst_estimate(estimates, free)
    message = (f"discretization.tolerance = {tolerance:g} not met: the estimate is {reached} on "
               f"{levels[-1]['discretization']} ({levels[-1]['ndof']} dofs), and {stop}")
    if required:
        raise ConvergenceError(message + "; loosen the tolerance, or refine interface_maxh or the order by hand",
                               {"levels": levels})
    if not estimates:
        estimates = [{} for _ in sols]
    return Sequence(cell, sols, estimates, levels, False, _how(refiner, levels, remarks + [message]), scales,
                    beyond, stop, free)


def _settled(refiner: Refiner, levels: int) -> bool:
    """Whether an estimate within the tolerance on ``levels`` levels ends the loop: always, but for an
    :class:`Extrapolating` refiner not :meth:`~Extrapolating.ready` yet."""
    return not isinstance(refiner, Extrapolating) or refiner.ready(levels)


def _extrapolate(found: dict[str, list[Any]], sols: list[CellSolution], estimates: list[dict[str, float]]
                 ) -> list[str]:
    """Report each extrapolated quantity (:class:`Extrapolating`) as its extrapolation: the value in the
    load's results (the last level's own value beside it as ``<name>_last_level``), its estimate in place of
    the geometric tail; the remarks saying so."""
    remarks = []
    for name, per_load in found.items():
        for k, ext in enumerate(per_load):
            if ext is None or name not in estimates[k]:
                continue
            sols[k].results.setdefault(f"{name}_last_level", sols[k].results[name])
            sols[k].results[name] = ext.value
            estimates[k][name] = ext.estimate
            remarks.append(f"load {k} {name}: extrapolated, {ext.how}")
    return remarks


def _floor(floors: list[dict[str, tuple[float, str]]], sols: list[CellSolution], estimates: list[dict[str, float]],
           whole: dict[str, Any] | None, measured: tuple[str, ...] = ()) -> list[str]:
    """Set each estimated quantity's estimate to its :class:`Floored` bound (in the quantity's measure): in
    place of the sequence's for the ``measured`` quantities, else where the bound is larger; the remarks naming
    the bound's form."""
    remarks = []
    for k, per_load in enumerate(floors):
        head = headline(sols[k].results)
        for name, (bound, form) in per_load.items():
            if name not in estimates[k]:
                continue
            floor = bound / scale(name, head, whole)
            if name in measured:
                remarks.append(f"load {k} {name}: the {form} ({floor:.3g}) in place of the sequence's "
                               f"{estimates[k][name]:.3g}")
                estimates[k][name] = floor
            elif floor > estimates[k][name]:
                remarks.append(f"load {k} {name}: {estimates[k][name]:.3g} raised to the {form} ({floor:.3g})")
                estimates[k][name] = floor
    return remarks


def _beyond_reach(levels: list[dict[str, Any]], tolerance: float, max_dofs: int) -> str | None:
    """Why an unrequired tolerance is out of reach within ``max_dofs`` at the rates both the last two pairs of
    estimated levels show (:func:`~ngcontact.cell.fe.observed_rate.dofs_to_meet`), else ``None``."""
    est = [lv for lv in levels if "estimate" in lv]
    if len(est) < 3:
        return None
    needs = []
    for pair in (est[-3:-1], est[-2:]):
        a = exponent([lv["ndof"] for lv in pair], [lv["estimate"] for lv in pair], (0.0, 0.0))
        need = dofs_to_meet(pair[-1]["ndof"], pair[-1]["estimate"], tolerance, a)
        if need is None or need[0] <= max_dofs:
            return None
        needs.append(need[0])
    return (f"meeting {tolerance:g} would take about {needs[-1]:.2g} dofs at the observed rate (and "
            f"{needs[0]:.2g} at the rate of the pair of levels before), beyond {max_dofs}")


def _how(refiner: Refiner, levels: list[dict[str, Any]], remarks: list[str]) -> str:
    """The estimate in words: the levels, the rule, the remarks."""
    head = ("the sweep on " + ", ".join(lv["discretization"] for lv in levels) + "; the last reported, its error "
            + refiner.rule.describe())
    return "; ".join([head] + remarks)


def as_refinement(done: Sequence) -> Refinement:
    """The cell protocol's record of a refined sweep: per load every level's contact fraction and closure; a
    sweep on the scene's level alone (the next beyond the default size bound) is not estimated."""
    per_load = [{"discretizations": [{"discretization": lv["discretization"], "ndof": lv["ndof"],
                                      "contact_fraction": lv["contact_fraction"][k],
                                      "mean_closure": lv["mean_closure"][k]} for lv in done.levels],
                 "newton_iterations": s.iterations}          # the reported (last) discretization's
                for k, s in enumerate(done.solutions)]
    histories = [s.newton for s in done.solutions]
    if len(done.levels) == 1:
        how = f"not estimated: {done.how.split('; ')[-1]}; set discretization.tolerance to refine beyond the bound"
        log.warning("accuracy not known: %s", how)
        return Refinement(solutions=done.solutions, estimates=[{} for _ in done.solutions], per_load=per_load,
                          histories=histories, how=how)
    return Refinement(solutions=done.solutions, estimates=done.estimates, per_load=per_load, histories=histories,
                      how=done.how, met=done.met, scales=done.scales, uncontrolled=done.uncontrolled)
