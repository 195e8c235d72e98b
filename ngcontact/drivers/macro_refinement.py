"""Refinement of a macro solution towards ``discretization.tolerance``: the order first, then the mesh.

A macro scene that states ``discretization.tolerance`` is not only judged against it: while the estimated
relative error of a headline quantity (:mod:`ngcontact.macro.discretization_error`) exceeds the tolerance,
the polynomial order is raised by one on the scene's mesh and the solution and its estimate are made
again.  When raising the order no longer pays, the mesh is refined where the error indicator is large
(:mod:`ngcontact.macro.error_indicator`), level by level at that order, until every quantity meets the
tolerance or a bound is reached (:data:`MAX_REFINED_ORDER`, :data:`MAX_DOFS`, :data:`MAX_MESH_LEVELS`).
The report names the discretization that met it (``results.accuracy.refinement``: per level the order,
the mesh level, its elements, unknowns, values and estimates); a tolerance out of reach ends the run with
the figures of the last level, as a cell's refinement does (a :class:`~ngcontact.errors.ConvergenceError`:
exit 3, nothing written).

The order (p) first
    * The estimate is an order ladder on one mesh: at order ``p`` it has solved ``p - 1, p, p + 1``.
      Raising the order is the step the estimate itself measures, and its observed ratio ``rho``
      predicts the next error, ``e_{p+1} ~ rho e_p``.
    * On a solution smooth on each element, which the macro problem's is away from corners (linear
      elasticity with a smooth interface law on a mesh curved to its geometry), the p-error falls
      geometrically: one order buys the observed factor ``rho``, where halving the
      interface elements buys ``2^-(p+1)`` at 4 (2D) or 8 (3D) times the unknowns near the interface.
    * A difference that does not shrink away from any corner (pre-asymptotic orders) has no estimate,
      but the next order may show the fall: the order is raised while the bounds allow.

Then the mesh (h), where the order no longer pays
    * at the order bound (:data:`MAX_REFINED_ORDER`), or where the ladder finds a stress maximum at a
      corner growing with every order (a singular point: the order cannot show it within any
      tolerance, :func:`stop_reason`).  There the error is local, and only smaller elements near the
      corner reduce it: the mesh is refined where the indicator is large (its volume term grades towards
      corners, its interface term puts the interface's elements first) by Doerfler marking and Netgen's
      local refinement (:func:`ngcontact.macro.error_indicator.refine_marked`: new boundary vertices on
      the geometry, the mesh curved again at the order), and the scene is solved again at the same order.
    * Each mesh level is estimated by the order ladder on its mesh and by the sequence of mesh levels
      with its observed rate (:mod:`ngcontact.macro.mesh_sequence`), the larger of the two; a corner's
      maximum without a ladder estimate is estimated by the sequence alone once three levels exist.
      A stress maximum's sampling error is taken on a lattice reaching the elements' faces
      (:func:`ngcontact.macro.discretization_error.body_maxima` with :data:`FACE_INSET`): at the errors a
      tolerance beyond the order's reach asks for, the inset of the sample points from a boundary where
      the maximum sits is a share of the error.
    * A maximum that grows with every mesh level without an estimate is a true singularity (its value
      depends on the mesh and has no limit; :func:`ngcontact.macro.mesh_sequence.growing`, the test of the
      corner check and of the levels at the singular points): the refinement stops there and says so.
    * A scene with ``[two_scale]`` refines its mesh too: each mesh level runs the coupling loop again on
      the refined mesh from the tables the scene's loop made (``level_solve``,
      :class:`ngcontact.drivers.run_two_scale.Relevel`).  The cell's law is a function of the macro jump,
      not of the macro mesh, so the table is re-used as it stands where it covers the level's pressures
      and grows by the cell solves of the new range where a finer mesh finds higher ones.  The table itself
      was refined before, on the scene's mesh, until its share of the headline quantities met its part of
      the tolerance (:mod:`ngcontact.coupling.table_share`); a level that extends it has that share
      estimated again on the refined solution (:meth:`ngcontact.drivers.run_two_scale.Relevel.record`).

What is refined for
    Only the quantities the verdict counts (:func:`unmet`).  Where the interface ends closed on a boundary
    without support (:func:`ngcontact.macro.singular_maxima.closed_ends` on the scene's solution), every
    stress maximum over a whole body and the safety factor are mesh dependent on every level (in 3D also
    one attained within the tubes around the singular edges,
    :func:`ngcontact.macro.away_maxima.inside_tubes`): their counterparts away from the singular points
    (:mod:`ngcontact.macro.away_maxima`, the same balls or tubes on every level) converge, and they, not the
    mesh-dependent maxima, are refined for; each level judges them by local refinements at the singular
    points as well (:mod:`ngcontact.macro.away_sequence`), so a level's estimate of them has seen the
    mesh there.  A maximum once judged mesh dependent is never refined for, so no time is spent on a
    value without a limit.  Each level is judged by the verdict's rule
    (:func:`ngcontact.drivers.macro_accuracy.rejudged`, :func:`judged_level`): in 2D a point outside the
    balls where a maximum away grows (the safety factor away falls) with the local levels joins the singular
    points, the level is judged once more outside its ball too, and the levels after keep that region; the
    sequence of mesh levels of a maximum away starts again where its region changed, since its earlier
    values were taken over a larger set.

Each order level is the run of the scene at that order: the mesh is curved at the raised order
(``mesh.Curve``, as :func:`ngcontact.drivers.macro_geometry.build_geometry` curves a mesh of that
order; the vertices are the scene's), so the discretization that met the tolerance by the order alone is
reproduced by the scene with ``discretization.order`` set to it.  The new order is solved from the last
solution interpolated into its space, and its neighbours from it; a new mesh level is solved from the
start, as the scene is.  The scene's mesh is refined in place, so the run reports on the refined mesh.
With ``[two_scale]`` every order level and the estimate's neighbours are solved with the loop's converged
law; a mesh level runs the loop again from its tables (above).

A scene that states no tolerance is not refined: its run costs what it did.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from typing import Any, Callable

from ngcontact.drivers import macro_accuracy as MA
from ngcontact.errors import ConvergenceError
from ngcontact.macro import away_maxima as AM
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import error_indicator as EI
from ngcontact.macro import mesh_sequence as MS
from ngcontact.macro import singular_maxima as SM
from ngcontact.macro.macro_problem import MacroProblem, MacroSolution, space_and_frame
from ngcontact.scene.schema import MAX_ORDER

progress = logging.getLogger("ngcontact.progress")

#: the highest order a refinement reports (its estimate solves one order more)
MAX_REFINED_ORDER = 4
#: the most unknowns of the highest order a level's estimate solves
MAX_DOFS = 2_000_000
#: the most mesh levels the refinement makes after the order
MAX_MESH_LEVELS = 12
#: how far inwards a mesh level's stress maxima are sampled for their sampling error (module docstring):
#: at the elements' faces up to round-off, never on the axis ``r = 0`` of an axisymmetric body, where the
#: hoop strain ``u_r / r`` has no value
FACE_INSET = 1e-6
#: what the report's ``accuracy.refinement.method`` says
METHOD = ("p, then h: the polynomial order raised by one on the scene's mesh (curved at the order) while it "
          "pays, then the mesh refined where the stress error indicator is large, interface first "
          "(ngcontact.macro.error_indicator, Doerfler marking), until every headline quantity's estimated "
          "relative error is within discretization.tolerance (ngcontact.drivers.macro_refinement)")


@dataclass(frozen=True)
class Refined:
    """The solution that met the tolerance, its order ladder's samples and the levels on the way."""

    solution: MacroSolution
    samples: dict[int, dict[str, DE.Sample]]
    history: list[dict[str, Any]]
    estimates: list[DE.Estimate]
    exclusion: AM.Exclusion | None = None

    def record(self) -> dict[str, Any]:
        """``results.accuracy.refinement``: the method, its bounds, the levels and the order and mesh level
        that met it."""
        return {"method": METHOD, "max_order": MAX_REFINED_ORDER, "max_dofs": MAX_DOFS,
                "max_mesh_levels": MAX_MESH_LEVELS, "marking_bulk": EI.BULK,
                "scene_order": self.history[0]["order"], "order": self.solution.problem.order,
                "h_level": self.history[-1]["h_level"], "elements": self.history[-1]["elements"],
                "ndof": self.solution.ndof, "levels": self.history}


def unmet(found: list[DE.Estimate], tolerance: float) -> list[DE.Estimate]:
    """The counted estimates that miss ``tolerance`` (relative) or have no error."""
    return [e for e in found if e.counted and (e.relative_error is None or e.relative_error > tolerance)]


@dataclass(frozen=True)
class Singular:
    """What makes a maximum singular on every level: the interface's closed ends on the scene's solution
    (:func:`ngcontact.macro.singular_maxima.closed_ends`) and the balls (tubes) around the singular points
    (edges); ``globals_judged``: whether the maxima over whole bodies are judged by them (not with
    ``[two_scale]``, :mod:`ngcontact.drivers.macro_accuracy`)."""

    ends: list[tuple[tuple[float, ...], float]]
    exclusion: AM.Exclusion | None
    globals_judged: bool = True

    @classmethod
    def of(cls, scene, sol: MacroSolution) -> "Singular":
        exclusion = MA.exclusion_for(scene, sol)
        judged = scene.two_scale is None
        return cls(SM.closed_ends(sol) if exclusion is not None and judged else [], exclusion, judged)

    def judged(self, found: list[DE.Estimate]) -> list[DE.Estimate]:
        """``found`` with the maxima singular at a closed end (in 3D within the tubes) mesh dependent, those
        with a counterpart away from the singular points not counted
        (:func:`ngcontact.macro.away_maxima.settle`)."""
        tubes = self.exclusion if self.globals_judged else None
        return AM.settle(AM.inside_tubes(SM.at_closed_ends(found, self.ends), tubes), self.exclusion)


def judged_level(scene, sol: MacroSolution, solve: Callable[..., MacroSolution],
                 safety_factor: Callable[[MacroSolution], float] | None, singular: Singular,
                 component: str | None = None, dense_inset: float = 1e-3
                 ) -> tuple[list[DE.Estimate], dict[int, dict[str, DE.Sample]], Singular]:
    """The estimates of one level ``sol`` by the order ladder and the local refinements at the singular points
    (:func:`ngcontact.drivers.macro_accuracy.away_judged`), judged by the verdict's rule
    (:func:`ngcontact.drivers.macro_accuracy.rejudged`): in 2D a point where a maximum away grows with the
    local levels joins the singular points and the level is judged once more with it; the ladder's samples
    and ``singular`` with that region (kept by the levels after).  Before :meth:`Singular.judged`."""
    def judge(exclusion: AM.Exclusion | None) -> tuple[list[DE.Estimate], dict[int, dict[str, DE.Sample]]]:
        samples = MA.order_samples(scene, sol, solve, safety_factor, component, dense_inset, exclusion)
        return MA.away_judged(MA.estimates(samples, sol), sol, solve, exclusion, samples[sol.problem.order],
                              safety_factor), samples
    (found, samples), exclusion = MA.rejudged(judge, singular.exclusion, sol.problem.mesh)
    return found, samples, replace(singular, exclusion=exclusion)


def level(sol: MacroSolution, found: list[DE.Estimate], tolerance: float, h_level: int = 0) -> dict[str, Any]:
    """One level of the refinement as the report lists it: order, mesh level (0: the scene's mesh), elements,
    unknowns, each quantity's value and relative error."""
    missed = unmet(found, tolerance)
    return {"order": sol.problem.order, "h_level": h_level, "elements": sol.problem.mesh.ne, "ndof": sol.ndof,
            "met": not missed, "values": {e.name: e.value for e in found},
            "relative_errors": {e.name: e.relative_error for e in found}}


def top_dofs(sol: MacroSolution, order: int) -> int:
    """The unknowns of the highest order the estimate of ``order`` solves (``order + 1``) on ``sol``'s mesh."""
    fes, _ = space_and_frame(replace(sol.problem, order=order + 1))
    return int(fes.ndof)


def top_dofs_of(problem: MacroProblem) -> int:
    """The unknowns of the highest order the estimate of ``problem``'s order solves on its mesh."""
    fes, _ = space_and_frame(replace(problem, order=DE.ladder(problem.order, MAX_ORDER)[-1]))
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
    orders = " -> ".join(str(h["order"]) for h in history if h["h_level"] == 0)
    mesh = f", mesh level {last['h_level']}" if last["h_level"] else ""
    return (f"discretization.tolerance = {tolerance:g} not met: at order {last['order']}{mesh} ({last['ndof']} "
            f"unknowns; orders {orders}) the estimate misses it on {figures}; {why}; loosen the tolerance or make "
            "the mesh finer (discretization.maxh, interface_maxh)")


def raised(sol: MacroSolution, order: int, solve: Callable[..., MacroSolution]) -> MacroSolution:
    """The scene's problem at ``order`` on its mesh curved at ``order``, solved from ``sol``."""
    problem = replace(sol.problem, order=order)
    start = DE.start_at_order(sol, problem)
    problem.mesh.Curve(order)
    return solve(problem, start)


def h_refusal(scene) -> str | None:
    """Why the mesh of ``scene`` is not refined (``None``: it may be)."""
    if MAX_MESH_LEVELS < 1:
        return f"the refinement's bound allows no mesh level ({MAX_MESH_LEVELS})"
    return None


def refine(scene, sol: MacroSolution, solve: Callable[..., MacroSolution],
           safety_factor: Callable[[MacroSolution], float] | None = None,
           level_solve: Callable[..., MacroSolution] | None = None) -> Refined | None:
    """Refine ``sol`` until its headline quantities meet ``scene.discretization.tolerance`` (module
    docstring): the order first, then the mesh; ``solve(problem, start)`` solves a problem as the scene
    does, ``level_solve`` a new mesh level (default ``solve``; a two-scale scene's loop on the refined mesh).
    ``None``: the scene states no tolerance, and ``sol`` stands as it is.

    Raises
    ------
    ConvergenceError
        The tolerance is out of reach: a bound reached, or a quantity without estimate on every mesh; the
        message gives the last level's order, mesh level, unknowns and estimates.
    """
    if scene.discretization.tolerance is None:
        return None
    tolerance = float(scene.discretization.tolerance)
    history: list[dict[str, Any]] = []
    singular = Singular.of(scene, sol)
    while True:
        ladder, samples, singular = judged_level(scene, sol, solve, safety_factor, singular)
        found = singular.judged(ladder)
        history.append(level(sol, found, tolerance))
        missed = unmet(found, tolerance)
        _progress(sol, found, missed, tolerance, 0)
        if not missed:
            return Refined(solution=sol, samples=samples, history=history, estimates=found,
                           exclusion=singular.exclusion)
        why = stop_reason(sol, missed)
        if why is not None:
            break
        sol = raised(sol, sol.problem.order + 1, solve)
    refusal = h_refusal(scene)
    if refusal is not None:
        raise ConvergenceError(out_of_reach(tolerance, history, missed, f"{why}; {refusal}"),
                               {"refinement": history})
    progress.info("macro: %s; the mesh is refined where the error indicator is large", why)
    return refine_mesh(scene, Refined(solution=sol, samples=samples, history=history, estimates=found), solve,
                       safety_factor, tolerance, singular, level_solve)


def _progress(sol: MacroSolution, found: list[DE.Estimate], missed: list[DE.Estimate], tolerance: float,
              h_level: int) -> None:
    worst = max((e.relative_error for e in found if e.relative_error is not None), default=0.0)
    progress.info("macro order %d, mesh level %d (%d unknowns): largest estimated relative error %.3g%s",
                  sol.problem.order, h_level, sol.ndof, worst,
                  "" if not missed else f", {len(missed)} quantities beyond {tolerance:g}")


def h_stop_reason(missed: list[DE.Estimate], values: dict[str, list[float]], h_level: int,
                  bound: int | None = None) -> str | None:
    """Why the mesh is not refined beyond level ``h_level`` (``None``: it is); ``bound``: the most mesh levels
    (default :data:`MAX_MESH_LEVELS`)."""
    bound = MAX_MESH_LEVELS if bound is None else bound
    growing = [e for e in missed if e.error is None and SM.growing(e, values[e.name])]
    if growing:
        e = growing[0]
        return (f"{e.name} grows with every mesh level ({', '.join(f'{v:.4g}' for v in values[e.name][-3:])}) "
                "without an estimate: a singularity, whose value depends on the mesh and does not converge")
    if h_level >= bound:
        return f"mesh level {h_level + 1} is beyond the refinement's bound ({bound} levels)"
    return None


def refine_mesh(scene, start: Refined, solve: Callable[..., MacroSolution],
                safety_factor: Callable[[MacroSolution], float] | None, tolerance: float,
                singular: Singular = Singular([], None),
                level_solve: Callable[..., MacroSolution] | None = None) -> Refined:
    """The mesh refined where :func:`ngcontact.macro.error_indicator.indicator` is large, at the order
    ``start`` reached, level by level until the tolerance is met (module docstring); ``singular``: what
    makes a maximum singular on every level; ``level_solve``: how a new level is solved (default ``solve``)."""
    sol, history = start.solution, list(start.history)
    values = {e.name: [e.value] for e in start.estimates}
    component = next(n for n in values if n.startswith("resultant_")).removeprefix("resultant_")
    h_level = 0
    while True:
        at = [start.samples[sol.problem.order][e.name].location for e in unmet(start.estimates, tolerance)]
        flags = EI.marked(EI.indicator(sol)) | EI.holding(sol.problem.mesh, [x for x in at if x is not None])
        problem = replace(sol.problem)
        EI.refine_marked(problem.mesh, flags, problem.order)
        h_level += 1
        dofs = top_dofs_of(problem)
        if dofs > MAX_DOFS:
            raise ConvergenceError(out_of_reach(tolerance, history, unmet(start.estimates, tolerance),
                                                f"mesh level {h_level}'s estimate would solve {dofs} unknowns, "
                                                f"beyond the refinement's bound of {MAX_DOFS}"),
                                   {"refinement": history})
        sol = (level_solve or solve)(problem, None)
        ladder, samples, judged = judged_level(scene, sol, solve, safety_factor, singular, component, FACE_INSET)
        if judged.exclusion is not singular.exclusion:
            values.update({name: [] for name in values if name.endswith(AM.AWAY)})
        singular = judged
        for e in ladder:
            values[e.name].append(e.value)
        found = singular.judged([MS.combined(e, values[e.name]) for e in ladder])
        history.append(level(sol, found, tolerance, h_level))
        missed = unmet(found, tolerance)
        _progress(sol, found, missed, tolerance, h_level)
        if not missed:
            return Refined(solution=sol, samples=samples, history=history, estimates=found,
                           exclusion=singular.exclusion)
        why = h_stop_reason(missed, values, h_level)
        if why is not None:
            raise ConvergenceError(out_of_reach(tolerance, history, missed, why), {"refinement": history})
        start = Refined(solution=sol, samples=samples, history=history, estimates=found)
