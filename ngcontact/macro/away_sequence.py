"""The error of the maxima away from the singular points from local refinements at those points.

The maxima away from the singular points (:mod:`ngcontact.macro.away_maxima`) converge, but the order
ladder on one mesh (:mod:`ngcontact.macro.discretization_error`) sees only part of their error: the
elements that touch a singular point carry the unbounded term ``|x - x_i|^(lambda - 1)`` or
``log |x - x_i|``, which no polynomial of any order on them resolves, so the displacement's error there
falls only algebraically with the order and pollutes the stress everywhere (Babuska-Guo: the p-version
converges algebraically on a mesh not graded towards a singular point).  The ladder's geometric
extrapolation from three orders misses that share.

Only smaller elements at the singular points remove it.  So the elements with a vertex at a singular
point (:func:`ngcontact.macro.singular_maxima.star`), those the balls' circles cross (where a maximum
away from a singular point is attained when the stress grows towards it; :data:`CIRCLE` points each) and
those holding the maxima away are refined
:data:`LEVELS` times (Netgen's local refinement, on copies of the mesh; each level solved at the scene's
order from the last level's solution interpolated into its space, as the corner check of
:mod:`ngcontact.macro.singular_maxima` does), and each maximum away is taken on every level
(``Q_0`` the scene's mesh, ``Q_1``, ``Q_2``).  Each level halves the elements at the singular points, so
the polluting share falls by a fixed factor per level and the sequence's geometric tail
(:func:`ngcontact.macro.mesh_sequence.sequence_error`, with the factor of safety) estimates what is left
of it on the finest level.  That factor is ``2^-lambda`` at a singular point of exponent ``lambda <= 1``
(the error in energy falls like ``h^lambda`` where the elements at the point are halved; a logarithm
has ``lambda = 1``), so at least :data:`SLOWEST` = 1/2: a smaller observed ratio is pre-asymptotic (the
first level moves the circle of the ball out of the elements that touch the point, a step larger than
the ones to come), and the tail is taken at ratio 1/2 at least, ``1.5 |Q_2 - Q_1|``.  Where the levels
move the value by more than the ladder's estimate of the scene's mesh (``|Q_2 - Q_0| > e_ladder``), that
estimate is contradicted: it saw only part of the error (on a coarse mesh the orders' differences have not
reached their rate), and the finest level's error is bounded by ``|Q_2 - Q_0|`` as long as the two levels
at least halve the error of the scene's mesh (the saturation assumption of a refinement); times the
factor of safety it is the least error taken.  A ladder without an estimate (a ball's circle inside the
elements at a singular point, where no order converges fast) leaves the sequence alone, whose levels
move the circle out of those elements.  So the finest level's value and location are reported, with the larger of
the ladder's error (the mesh away from the singular points is the scene's, so the polynomial error there
is the one the ladder measured) and the sequence's; a sequence that does not converge adds its last
difference (:func:`judged`).  The check costs about one solve of the scene (two warm-started solves on
meshes a little larger).
"""
from __future__ import annotations

from dataclasses import replace
from typing import Callable

import ngsolve as ng
import numpy as np

from ngcontact.macro import away_maxima as AM
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import error_indicator as EI
from ngcontact.macro import mesh_sequence as MS
from ngcontact.macro import singular_maxima as SM
from ngcontact.macro.macro_problem import MacroSolution

#: local refinements at the singular points (three values with the scene's mesh: an observed rate)
LEVELS = 2
#: points per ball's circle whose elements each level refines
CIRCLE = 64
#: the slowest fall per level the sequence's tail assumes at least (module docstring)
SLOWEST = 0.5

#: the safety factor away from the singular points of a solution, given which interface points count
Safety = Callable[[MacroSolution, Callable[[np.ndarray], np.ndarray]], dict[str, DE.Sample]]


def sampled(sol: MacroSolution, exclusion: AM.Exclusion, safety: Safety | None) -> dict[str, DE.Sample]:
    """The maxima away from the singular points of ``sol`` and, with ``safety``, the safety factor away."""
    out = AM.away_maxima(sol, exclusion)
    if safety is not None:
        out.update({k: v for k, v in safety(sol, exclusion.outside).items() if k.endswith(AM.AWAY)})
    return out


def levels(sol: MacroSolution, solve: Callable[..., MacroSolution], exclusion: AM.Exclusion,
           at: dict[str, DE.Sample], safety: Safety | None = None, count: int = LEVELS) -> list[dict[str, DE.Sample]]:
    """The maxima away (:func:`sampled`) on ``count`` levels, each a copy of the last level's mesh (the first:
    ``sol``'s) refined at the singular points and at the locations of ``at`` (the maxima on ``sol``), solved
    by ``solve(problem, start)`` at ``sol``'s order from the last level's solution."""
    order = max(sol.problem.order, 1)
    points = [s.location for s in at.values() if s.location is not None]
    circle = AM.circles(exclusion, CIRCLE)
    out = []
    for _ in range(count):
        mesh = ng.Mesh(sol.problem.mesh.ngmesh.Copy())
        marked = SM.star(mesh, exclusion.points) | EI.holding(mesh, points + [tuple(x) for x in circle])
        EI.refine_marked(mesh, marked, order)
        problem = replace(sol.problem, mesh=mesh)
        sol = solve(problem, DE.start_at_order(sol, problem))
        out.append(sampled(sol, exclusion, safety))
    return out


def judged(found: list[DE.Estimate], own: dict[str, DE.Sample], finer: list[dict[str, DE.Sample]]
           ) -> list[DE.Estimate]:
    """``found`` with each maximum away (not mesh dependent) judged by its value on the scene's mesh
    (``own``) and the local levels ``finer`` (module docstring): the value and location of the finest
    level; the other estimates unchanged."""
    out = []
    for e in found:
        if finer and e.name.endswith(AM.AWAY) and e.singular_at is None and e.name in own \
                and all(e.name in f for f in finer):
            e = _judged(e, [own[e.name].value] + [f[e.name].value for f in finer], finer[-1][e.name].location)
        out.append(e)
    return out


def _judged(e: DE.Estimate, values: list[float], location: tuple[float, ...] | None) -> DE.Estimate:
    """The error of the finest of ``values`` (the scene's mesh, then the levels; module docstring)."""
    shown = ", ".join(f"{v:.6g}" for v in values)
    seq, how = MS.sequence_error(values, e.scale)
    parts = [f"{e.how}; {len(values) - 1} local refinements at the singular points: {shown}, the last reported",
             how]
    last, moved, ladder = abs(values[-1] - values[-2]), abs(values[-1] - values[0]), e.error
    e = replace(e, value=values[-1], location=location)
    if seq is None and ladder is None:
        return replace(e, how="; ".join(parts))
    if seq is None:
        error = DE.SAFETY * last
        parts.append(f"at least {DE.SAFETY:g} x the last difference")
    else:
        error = max(seq, DE.SAFETY * last * SLOWEST / (1.0 - SLOWEST))
        parts.append(f"the tail at ratio {SLOWEST:g} at least: {error:.3g}")
    if ladder is not None and ladder >= error:
        error = ladder
        parts.append("below the order ladder's, which is taken")
    if ladder is not None and moved > ladder and DE.SAFETY * moved > error:
        error = DE.SAFETY * moved
        parts.append(f"the levels moved the value by {moved:.3g}, more than the order ladder's estimate of the scene's "
                     f"mesh, which so saw only part of its error: {DE.SAFETY:g} x that move (the levels at least "
                     "halve the error)")
    return replace(e, error=error, how="; ".join(parts))
