"""Refinement of a macro solution towards ``discretization.tolerance``: the order raised on the scene's mesh.

A macro scene that states ``discretization.tolerance`` is not only judged against it: while the estimated
relative error of a headline quantity (:mod:`ngcontact.macro.discretization_error`) exceeds the tolerance,
the polynomial order is raised by one on the scene's mesh and the solution and its estimate are made
again, until every quantity meets it or a bound is reached (:data:`MAX_REFINED_ORDER`, :data:`MAX_DOFS`).
The report names the discretization that met it (``results.accuracy.refinement``); a tolerance out of
reach ends the run with the figures of the last level, as a cell's refinement does (a
:class:`~ngcontact.errors.ConvergenceError`: exit 3, nothing written).

Why the order (p), not the mesh near the interface (h)
    * The estimate is an order ladder on one mesh: at order ``p`` it has solved ``p - 1, p, p + 1``.
      Raising the order is the step the estimate itself measures, and its observed ratio ``rho``
      predicts the next error, ``e_{p+1} ~ rho e_p``; a refined mesh would start a new ladder of three
      solves whose first difference says nothing of the mesh's effect.
    * On a solution smooth on each element, which the macro problem's is away from corners (linear
      elasticity with a smooth interface law on a mesh curved to its geometry), the p-error falls
      geometrically: one order buys the observed factor ``rho``, where halving the
      interface elements buys ``2^-(p+1)`` at 4 (2D) or 8 (3D) times the unknowns near the interface.
    * A stress maximum at a corner that grows with every order is a singularity: the estimate has no
      error for it (``error = None``), and an h-refinement towards the interface would not make it
      converge either, so the refinement stops there at once and names the quantity and the corner: the
      tolerance cannot be met on it, whatever the discretization.  A difference that does not shrink
      away from any corner (pre-asymptotic orders) has no estimate either, but the next order may show
      the fall: the order is raised while the bounds allow.

Each level is the run of the scene at that order: the mesh is curved at the raised order
(``mesh.Curve``, as :func:`ngcontact.drivers.macro_geometry.build_geometry` curves a mesh of that
order; the vertices are the scene's), so the discretization that met the tolerance is reproduced by the
scene with ``discretization.order`` set to it.  The new order is solved from the last solution
interpolated into its space, and its neighbours from it.  With ``[two_scale]`` every level is solved with
the loop's converged law (as the estimate's neighbours are); the loop is not repeated.

A scene that states no tolerance is not refined: its run costs what it did.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from typing import Any, Callable

from ngcontact.drivers import macro_accuracy as MA
from ngcontact.errors import ConvergenceError
from ngcontact.macro import discretization_error as DE
from ngcontact.macro.macro_problem import MacroSolution, space_and_frame

progress = logging.getLogger("ngcontact.progress")

#: the highest order a refinement reports (its estimate solves one order more)
MAX_REFINED_ORDER = 4
#: the most unknowns of the highest order a level's estimate solves
MAX_DOFS = 2_000_000
#: what the report's ``accuracy.refinement.method`` says
METHOD = ("p: the polynomial order raised by one on the scene's mesh (curved at the order) until every headline "
          "quantity's estimated relative error is within discretization.tolerance (ngcontact.drivers.macro_refinement)")


@dataclass(frozen=True)
class Refined:
    """The solution that met the tolerance, its order ladder's samples and the levels on the way."""

    solution: MacroSolution
    samples: dict[int, dict[str, DE.Sample]]
    history: list[dict[str, Any]]

    def record(self) -> dict[str, Any]:
        """``results.accuracy.refinement``: the method, its bounds, the levels and the order that met it."""
        return {"method": METHOD, "max_order": MAX_REFINED_ORDER, "max_dofs": MAX_DOFS,
                "scene_order": self.history[0]["order"], "order": self.solution.problem.order,
                "ndof": self.solution.ndof, "levels": self.history}


def unmet(found: list[DE.Estimate], tolerance: float) -> list[DE.Estimate]:
    """The estimates that miss ``tolerance`` (relative) or have no error."""
    return [e for e in found if e.relative_error is None or e.relative_error > tolerance]


def level(sol: MacroSolution, found: list[DE.Estimate], tolerance: float) -> dict[str, Any]:
    """One level of the refinement as the report lists it: order, unknowns, each quantity's relative error."""
    missed = unmet(found, tolerance)
    return {"order": sol.problem.order, "ndof": sol.ndof, "met": not missed,
            "relative_errors": {e.name: e.relative_error for e in found}}


def top_dofs(sol: MacroSolution, order: int) -> int:
    """The unknowns of the highest order the estimate of ``order`` solves (``order + 1``) on ``sol``'s mesh."""
    fes, _ = space_and_frame(replace(sol.problem, order=order + 1))
    return int(fes.ndof)


def stop_reason(sol: MacroSolution, missed: list[DE.Estimate]) -> str | None:
    """Why the order cannot be raised further (``None``: it can)."""
    singular = [e for e in missed if e.singular_at is not None]
    if singular:
        e = singular[0]
        return (f"{e.name} has no error estimate ({e.how.split(': ')[-1]}), so no order can show it within the "
                "tolerance")
    nxt = sol.problem.order + 1
    if nxt > MAX_REFINED_ORDER:
        return f"order {nxt} is beyond the refinement's bound (order <= {MAX_REFINED_ORDER})"
    dofs = top_dofs(sol, nxt)
    if dofs > MAX_DOFS:
        return (f"order {nxt}'s estimate would solve order {nxt + 1} with {dofs} unknowns, beyond the refinement's "
                f"bound of {MAX_DOFS}")
    return None


def out_of_reach(tolerance: float, history: list[dict[str, Any]], missed: list[DE.Estimate], why: str) -> str:
    """The message of a tolerance out of reach: the last level's figures and what to do."""
    last = history[-1]
    figures = ", ".join(f"{e.name} {e.value:.4g} " + ("(no estimate)" if e.relative_error is None
                                                      else f"+/- {e.relative_error:.3g}") for e in missed)
    orders = " -> ".join(str(h["order"]) for h in history)
    return (f"discretization.tolerance = {tolerance:g} not met: at order {last['order']} ({last['ndof']} unknowns; "
            f"orders {orders}) the estimate misses it on {figures}; {why}; loosen the tolerance or make the mesh "
            "finer (discretization.maxh, interface_maxh)")


def raised(sol: MacroSolution, order: int, solve: Callable[..., MacroSolution]) -> MacroSolution:
    """The scene's problem at ``order`` on its mesh curved at ``order``, solved from ``sol``."""
    problem = replace(sol.problem, order=order)
    start = DE.start_at_order(sol, problem)
    problem.mesh.Curve(order)
    return solve(problem, start)


def refine(scene, sol: MacroSolution, solve: Callable[..., MacroSolution],
           safety_factor: Callable[[MacroSolution], float] | None = None) -> Refined | None:
    """Raise the order of ``sol`` until its headline quantities meet ``scene.discretization.tolerance``
    (module docstring); ``solve(problem, start)`` solves a problem as the scene does.  ``None``: the scene
    states no tolerance, and ``sol`` stands as it is.

    Raises
    ------
    ConvergenceError
        The tolerance is out of reach: a quantity without estimate, or a bound reached; the message gives
        the last level's order, unknowns and estimates.
    """
    if scene.discretization.tolerance is None:
        return None
    tolerance = float(scene.discretization.tolerance)
    history: list[dict[str, Any]] = []
    while True:
        samples = MA.order_samples(scene, sol, solve, safety_factor)
        found = MA.estimates(samples, sol)
        history.append(level(sol, found, tolerance))
        missed = unmet(found, tolerance)
        worst = max((e.relative_error for e in found if e.relative_error is not None), default=0.0)
        progress.info("macro order %d (%d unknowns): largest estimated relative error %.3g%s", sol.problem.order,
                      sol.ndof, worst, "" if not missed else f", {len(missed)} quantities beyond {tolerance:g}")
        if not missed:
            return Refined(solution=sol, samples=samples, history=history)
        why = stop_reason(sol, missed)
        if why is not None:
            raise ConvergenceError(out_of_reach(tolerance, history, missed, why), {"refinement": history})
        sol = raised(sol, sol.problem.order + 1, solve)
