"""Refinement of a resolved (``direct``) solution towards ``discretization.tolerance``: the order, then the mesh.

A resolved scene that states ``discretization.tolerance`` is not only judged against it
(:mod:`ngcontact.drivers.resolved_accuracy`): while the estimated error of a headline quantity (the contact
fraction of ``S_C^eps``, held to the tolerance as an absolute error; the contact force's magnitude, as a
relative one) exceeds it, the discretization is refined and the solution and its estimate are made again,
until every quantity meets the tolerance or a bound is reached (:data:`MAX_REFINED_ORDER`, :data:`MAX_DOFS`,
:data:`MAX_MESH_LEVELS`, the scene's ``discretization.max_elements``).  A tolerance out of reach ends the run
with the last level's figures (a :class:`~ngcontact.errors.ConvergenceError`: exit 3, nothing written), as a
cell's and a macro scene's refinements do.

Which step: the order while it pays, then the mesh where the error is
    The order ladder that estimates the error (orders ``p - 1, p, p + 1`` on one mesh) also measures what
    one order more buys: the observed ratio ``rho`` of its successive differences predicts
    ``e_{p+1} ~ rho e_p``, at ``c_p = ((p + 2) / (p + 1))^2`` times the unknowns (2D).  Where the error
    is held by a singular point (the profile's re-entrant corners on ``S_C^eps``, the corners where a
    clamped or displaced face meets a free one) or by the edges of the closed set (where the penetration's
    positive part puts a kink inside an element), the p-error falls algebraically and a local refinement
    there pays better: halving the few elements around such a point removes at least half of a first-order
    error at a fraction of the unknowns.  One order more is taken where it buys more per unknown than that
    halving at twice the unknowns, ``rho c_p < 1`` (the error times the unknowns falls); where it does not,
    where an unmet quantity's ladder gives no estimate (its difference does not shrink with the order), or
    at :data:`MAX_REFINED_ORDER`, the mesh is refined at the order reached.  Every unmet quantity must pay
    for the order to be raised: the slowest rules.

The mesh step (what converged, and why not the interface alone)
    Each mesh level refines, in place, the elements that carry the error (:func:`flags`): the fewest with
    the largest stress error indicator whose squares hold half of its total (Doerfler marking of
    :func:`ngcontact.macro.error_indicator.indicator`, the Zienkiewicz-Zhu recovery on each body plus the
    jump of the two bodies' recovered normal stress across ``S_C^eps``, which puts the interface's
    elements first and grades towards every corner), and every element beside a boundary element of
    ``S_C^eps`` that is partly closed (an edge of the closed set, whose position the contact fraction
    measures).  Netgen's local refinement places the new boundary vertices on the geometry and the mesh
    is curved again at the order.  The interface alone is not enough: on the shipped rectangular valleys
    the contact force's error sits in the far field (halving ``maxh`` removes most of it, doubling
    ``elements_per_period`` next to none), at the corners where the displaced and clamped faces meet the
    free sides, which the indicator reaches after the valleys' corners.
    Each mesh level is estimated by the order ladder on its mesh and by the sequence of mesh levels at that
    order with its observed rate (:func:`ngcontact.macro.mesh_sequence.combined`): the larger of the two, or
    the sequence's alone where the ladder has none.  A quantity growing with every level without an estimate
    has no limit: the refinement stops there and says so
    (:func:`ngcontact.drivers.macro_refinement.h_stop_reason`).

A level of the order that the ladder finds within the tolerance is confirmed by one uniform refinement of its
mesh at its order (:func:`ngcontact.drivers.resolved_accuracy.guarded`: the larger of the two estimates), since
on a closed set whose edges lie inside elements the orders' values oscillate and the ladder alone may fall
below the error; where the confirmation misses, the mesh is refined.

A scene that states no tolerance is not refined: it is judged against the default one
(:func:`ngcontact.drivers.resolved_accuracy.h_step_estimates`) and costs what it did plus that estimate.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from types import SimpleNamespace
from typing import Any, Callable

import ngsolve as ng
import numpy as np

from ngcontact.drivers import macro_refinement as MR
from ngcontact.drivers import resolved_accuracy as RA
from ngcontact.errors import ConvergenceError
from ngcontact.fem import two_body
from ngcontact.fem.quadrature import kink_order
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import error_indicator as EI
from ngcontact.macro import mesh_sequence as MS
from ngcontact.resolved import resolved_problem as D
from ngcontact.scene.schema import MAX_ORDER

progress = logging.getLogger("ngcontact.progress")

#: the highest order a refinement reports (its estimate solves one order more)
MAX_REFINED_ORDER = 4
#: the most unknowns of the highest order a level's estimate solves
MAX_DOFS = 1_000_000
#: the most mesh levels after the order
MAX_MESH_LEVELS = 8
#: what the report's ``accuracy.refinement.method`` says
METHOD = ("p while it pays, then h: the polynomial order raised by one on the scene's mesh while the observed "
          "ratio of the order ladder times the unknowns' growth stays below 1, then the mesh refined where the "
          "stress error indicator is large and at the edges of the closed set, interface first "
          "(ngcontact.macro.error_indicator, Doerfler marking), at that order, until every headline quantity's "
          "estimated error is within discretization.tolerance (ngcontact.drivers.resolved_refinement)")

Solve = Callable[[D.DirectProblem], D.DirectSolution]


@dataclass(frozen=True)
class Refined:
    """The solution that met the tolerance, its estimates and the levels on the way."""

    solution: D.DirectSolution
    estimates: list[DE.Estimate]
    history: list[dict[str, Any]]

    def record(self) -> dict[str, Any]:
        """``results.accuracy.refinement``: the method, its bounds, the levels and what met the tolerance."""
        last = self.history[-1]
        return {"method": METHOD, "max_order": MAX_REFINED_ORDER, "max_dofs": MAX_DOFS,
                "max_mesh_levels": MAX_MESH_LEVELS, "marking_bulk": EI.BULK, "scene_order": self.history[0]["order"],
                "order": last["order"], "h_level": last["h_level"], "elements": last["elements"],
                "ndof": last["ndof"], "levels": self.history}


def unmet(found: list[DE.Estimate], tolerance: float) -> list[DE.Estimate]:
    """The estimates that miss ``tolerance`` (the contact fraction absolutely, the force relatively)."""
    return [e for e in found if not e.quantity(tolerance, e.name in RA.FRACTIONS)["met"]]


def level(sol: D.DirectSolution, found: list[DE.Estimate], tolerance: float, h_level: int) -> dict[str, Any]:
    """One level as the report lists it: order, mesh level (0: the scene's mesh), elements, unknowns, each
    quantity's value and error (absolute) and whether all met the tolerance."""
    return {"order": sol.problem.order, "h_level": h_level, "elements": sol.problem.mesh.ne, "ndof": sol.ndof,
            "met": not unmet(found, tolerance), "values": {e.name: e.value for e in found},
            "errors": {e.name: e.error for e in found}}


def top_dofs(problem: D.DirectProblem) -> int:
    """The unknowns of the highest order the estimate at ``problem``'s order solves on its mesh."""
    top = DE.ladder(problem.order, MAX_ORDER)[-1]
    return int(two_body.spaces(problem.mesh, problem.setting, ("rough", "counter"), problem.supports, top,
                               periodic=problem.periodic).ndof)


def order_pays(sol: D.DirectSolution, missed: list[DE.Estimate]) -> str | None:
    """Why the order is not raised (``None``: it is; module docstring)."""
    p = sol.problem.order
    nxt = p + 1
    if nxt > MAX_REFINED_ORDER:
        return f"order {nxt} is beyond the refinement's bound (order <= {MAX_REFINED_ORDER})"
    growth = ((p + 2) / (p + 1)) ** 2
    for e in missed:
        if e.error is None:
            return f"{e.name} has no order estimate ({e.how.split(': ')[-1]})"
        if e.ratio * growth >= 1.0:
            return (f"one order buys {e.name} a factor {e.ratio:.2g} at {growth:.2f} times the unknowns, less "
                    "than a local refinement")
    dofs = top_dofs(replace(sol.problem, order=nxt))
    if dofs > MAX_DOFS:
        return f"order {nxt}'s estimate would solve {dofs} unknowns, beyond the refinement's bound of {MAX_DOFS}"
    return None


def out_of_reach(tolerance: float, history: list[dict[str, Any]], missed: list[DE.Estimate], why: str) -> str:
    """The message of a tolerance out of reach: the last level's figures and what to do."""
    last = history[-1]
    figures = ", ".join(f"{e.name} {e.value:.6g} " + ("(no estimate)" if e.error is None else f"+/- {e.error:.3g}")
                        for e in missed)
    return (f"discretization.tolerance = {tolerance:g} not met: at order {last['order']}, mesh level "
            f"{last['h_level']} ({last['elements']} elements, {last['ndof']} unknowns; levels "
            + " -> ".join(f"p{h['order']}/h{h['h_level']}" for h in history)
            + f") the estimate misses it on {figures}; {why}; loosen the tolerance or make the mesh finer "
            "(discretization.maxh, elements_per_period)")


def refine(scene, sol: D.DirectSolution, length: float, solve: Solve) -> Refined | None:
    """Refine ``sol`` until its headline quantities meet ``scene.discretization.tolerance`` (module docstring);
    ``length``: the macro length the contact fraction is taken per; ``solve(problem)`` solves as the scene
    does.  ``None``: the scene states no tolerance, and ``sol`` stands as it is.  The mesh is refined in place.

    Raises
    ------
    ConvergenceError
        The tolerance is out of reach; the message gives the last level's order, mesh level, unknowns and
        estimates, ``history["refinement"]`` every level.
    """
    if scene.discretization.tolerance is None:
        return None
    tolerance = float(scene.discretization.tolerance)
    history: list[dict[str, Any]] = []
    while True:
        found = RA.estimates(sol, length, solve)
        history.append(level(sol, found, tolerance, 0))
        missed = unmet(found, tolerance)
        _progress(history[-1], missed, tolerance)
        if not missed:
            found = RA.guarded(found, RA.h_step_estimates(sol, length, solve))
            missed = unmet(found, tolerance)
            history[-1] = level(sol, found, tolerance, 0)
            if not missed:
                return Refined(sol, found, history)
            why = "the order ladder meets the tolerance, but not the estimate of the mesh refined uniformly once"
            break
        paid = order_pays(sol, missed)
        if paid is not None:
            why = paid
            break
        order = sol.problem.order + 1
        sol.problem.mesh.Curve(order)
        sol = solve(replace(sol.problem, order=order))
    progress.info("resolved: %s; the mesh is refined where the error indicator is large", why)
    return refine_mesh(scene, Refined(sol, found, history), length, solve, tolerance)


def refine_mesh(scene, start: Refined, length: float, solve: Solve, tolerance: float) -> Refined:
    """Mesh levels at the order ``start`` reached, refined where :func:`flags` marks (module docstring)."""
    sol, history = start.solution, list(start.history)
    values = {e.name: [e.value] for e in start.estimates}
    missed = unmet(start.estimates, tolerance)
    for h_level in range(1, MAX_MESH_LEVELS + 2):
        why = MR.h_stop_reason(missed, values, h_level - 1, MAX_MESH_LEVELS)
        if why is not None:
            raise ConvergenceError(out_of_reach(tolerance, history, missed, why), {"refinement": history})
        problem = replace(sol.problem)
        EI.refine_marked(problem.mesh, flags(sol), problem.order)
        dofs = top_dofs(problem)
        bound = scene.discretization.max_elements
        if dofs > MAX_DOFS or problem.mesh.ne > bound:
            raise ConvergenceError(out_of_reach(tolerance, history, missed,
                                                f"mesh level {h_level} has {problem.mesh.ne} elements (bound "
                                                f"discretization.max_elements = {bound}) and its estimate would "
                                                f"solve {dofs} unknowns (bound {MAX_DOFS})"),
                                   {"refinement": history})
        sol = solve(problem)
        ladder = RA.estimates(sol, length, solve)
        for e in ladder:
            values[e.name].append(e.value)
        found = [MS.combined(e, values[e.name]) for e in ladder]
        history.append(level(sol, found, tolerance, h_level))
        missed = unmet(found, tolerance)
        _progress(history[-1], missed, tolerance)
        if not missed:
            return Refined(sol, found, history)
    raise AssertionError("unreachable: the loop ends at the mesh levels' bound")  # pragma: no cover


def flags(sol: D.DirectSolution) -> np.ndarray:
    """The volume elements a mesh level refines (module docstring): Doerfler marking of the stress error
    indicator, and the elements beside a partly closed boundary element of ``S_C^eps``."""
    p = sol.problem
    as_macro = SimpleNamespace(problem=SimpleNamespace(mesh=p.mesh, setting=p.setting, order=p.order,
                                                       materials=p.materials, rough="rough", counter="counter",
                                                       interface=p.contact),
                               u_rough=sol.u_rough, u_counter=sol.u_counter)
    return EI.marked(EI.indicator(as_macro)) | closed_set_edges(sol)  # type: ignore[arg-type]


def closed_set_edges(sol: D.DirectSolution) -> np.ndarray:
    """The volume elements beside a boundary element of ``S_C^eps`` that is closed on part of it only (the
    closed set's edge lies inside it), as a boolean array."""
    p = sol.problem
    mesh = p.mesh
    on = mesh.Boundaries(p.contact)
    closed = np.asarray(ng.Integrate(D.closed_indicator(sol), mesh, ng.BND, definedon=on, element_wise=True,
                                     order=kink_order(p.order)))
    size = np.asarray(ng.Integrate(ng.CF(1.0), mesh, ng.BND, definedon=on, element_wise=True, order=1))
    out = np.zeros(mesh.ne, dtype=bool)
    partly = (closed > 1e-9 * size) & (closed < (1.0 - 1e-9) * size)
    for el in mesh.Elements(ng.BND):
        if el.mat == p.contact and partly[el.nr]:
            for vol in mesh[el.edges[0]].elements:
                out[vol.nr] = True
    return out


def _progress(last: dict[str, Any], missed: list[DE.Estimate], tolerance: float) -> None:
    progress.info("resolved order %d, mesh level %d (%d unknowns): %s", last["order"], last["h_level"],
                  last["ndof"], "tolerance met" if not missed
                  else f"{len(missed)} quantities beyond {tolerance:g}")
