"""The accuracy verdict of a ``direct`` run (``results.accuracy``): its headline quantities with their errors.

The resolved problem's headline quantities (:mod:`ngcontact.drivers.headline_quantities`): the
contact fraction of the resolved surface ``S_C^eps`` (the measure of ``{J.n - g >= 0}`` per unit macro
length, a number of order one, so its error is held to the tolerance as an absolute one, as a cell's
contact fraction is) and the magnitude of the contact force through it.

The default estimate: one uniform refinement at the run's order (:func:`h_step_estimates`)
    A run without ``discretization.tolerance`` solves once more, at its own order, on a copy of its mesh
    refined uniformly once (every triangle into four, the new boundary vertices on the geometry, curved as
    the run's mesh is), and estimates the error of ``Q_h`` from the difference ``d = Q_{h/2} - Q_h`` by the
    rule the epsilon study uses too (:func:`ngcontact.drivers.richardson_tail.tail`): if the error contracts
    by a factor ``rho`` per halving of ``h``, ``e_h = d / (1 - rho)``; with ``rho <= 1/2`` (an error at
    least linear in ``h``, :data:`~ngcontact.drivers.richardson_tail.RATE`) ``|e_h| <= 2 |d|``, and the
    estimate is :data:`~ngcontact.macro.discretization_error.SAFETY` times that bound,

        e_h = 1.5 |Q_{h/2} - Q_h| / (1 - 1/2) = 3 |Q_{h/2} - Q_h|.

    Why ``rho <= 1/2``: both quantities are integrals over ``S_C^eps``, whose error is held by the
    elements where the solution is least smooth, the edges of the closed set (the traction's kink, where the
    gap closes inside an element) and the corners where the bodies' loaded, clamped and free faces meet.
    A corner singularity ``r^lambda`` of plane elasticity has ``lambda >= 1/2`` (1/2 at a crack tip, the
    worst), so an integral of the traction converges at least like ``h^(2 lambda) >= h``: at least half of
    the error goes per halving.  On the package's resolved oracles (the partly closed sinusoid at orders 1 to
    5, the rectangular valleys at 2 to 4, against much finer meshes) the observed contraction of the
    contact force is 0.28 to 0.52 and of the contact fraction 0.09 to 0.56, but for one run whose error is
    small by chance (smaller than its refined twin's), which no difference of the two can see.
    Where the two solutions agree to round-off (a closed set whose edges sit at the profile's corners, found
    exactly by every mesh) the estimate is the factor of safety times the difference.

Why not the order ladder on the run's mesh
    The error of a polynomial order ``p`` on a fixed mesh does not fall smoothly here: the edges of the
    closed set lie inside elements and move with the order, so ``Q_p`` oscillates about its limit (on the
    partly closed sinusoid of the tests, the contact force's errors at orders 3 to 8 on one mesh are
    1556, 567, 477, -125, 445, 0 [N/m]).  Two successive differences of three orders can then both be small by
    chance: the ladder ``3, 4, 5`` estimated 297 against a true error of 567 (effectivity 0.52), the
    contact fraction's ``2, 3, 4`` 0.00099 against 0.00265 (0.38).  A uniform refinement moves every
    element edge and halves the distance the closed set's edges can lie from a node: its change measures
    the error ``h`` holds, which is what limits the resolved solution.  It costs one solve at four times the
    unknowns (the resolved scenes are 2D), about what the ladder's two solves at ``p - 1`` and ``p + 1`` cost;
    the run's ``timings`` list it as ``discretization error``.

With a tolerance the run is refined first (:mod:`ngcontact.drivers.resolved_refinement`, the order ladder on
each level and the sequence of its mesh levels) and its estimates are those of the last level; a level that
meets the tolerance by the order ladder alone on the scene's mesh is held to the uniform refinement's estimate
too (:func:`guarded`), since the ladder alone may fall below the error as above.  The verdict
has the macro run's format (:func:`ngcontact.drivers.macro_accuracy.verdict`) without its equilibrium check,
held to the scene's ``discretization.tolerance``, else to
:data:`~ngcontact.cell.admissibility.DEFAULT_TOLERANCE`: a miss is one warning line, the terminal's
accuracy line and ``report.html``'s top say it.  The epsilon study's modelling error is another quantity,
in its own report.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Any, Callable

import ngsolve as ng
import numpy as np

from ngcontact.drivers import macro_accuracy as MA
from ngcontact.drivers.richardson_tail import of_values, presumed_ratio
from ngcontact.macro import discretization_error as DE
from ngcontact.resolved import resolved_problem as D
from ngcontact.scene.schema import MAX_ORDER

#: how the verdict's errors are estimated (the report's ``accuracy.how``)
HOW = ("discretization error of the resolved contact fraction (absolute) and of the contact force's magnitude: "
       "without a tolerance 3 x their change on the run's mesh refined uniformly once at its order (an error "
       "contracting by at least 1/2 per halving, times 1.5), with one the refinement's last level "
       "(ngcontact.drivers.resolved_accuracy)")
#: the uniform refinement of the default estimate halves ``h``
HALVING = 2.0
#: the quantities that are fractions: their error is held to the tolerance as it is
FRACTIONS = ("contact_fraction",)


def headlines(sol: D.DirectSolution, length: float) -> dict[str, DE.Sample]:
    """The contact fraction (its relative error taken against 1: a fraction) and the contact force's magnitude."""
    return {"contact_fraction": DE.Sample(D.contact_fraction(sol, length), scale=1.0),
            "contact_force": DE.Sample(float(np.linalg.norm(D.contact_force(sol))))}


def order_samples(sol: D.DirectSolution, length: float, solve: Callable[[D.DirectProblem], D.DirectSolution]
                  ) -> dict[int, dict[str, DE.Sample]]:
    """The headline quantities at the three orders of the ladder (``sol`` is the run's order; the other two are
    solved by ``solve(problem)`` on the same mesh)."""
    problem = sol.problem
    out = {problem.order: headlines(sol, length)}
    for q in DE.ladder(problem.order, MAX_ORDER):
        if q == problem.order:
            continue
        with DE.neighbour_mesh(problem.mesh, problem.order):
            out[q] = headlines(solve(replace(problem, order=q)), length)
    return dict(sorted(out.items()))


def estimates(sol: D.DirectSolution, length: float, solve: Callable[[D.DirectProblem], D.DirectSolution]
              ) -> list[DE.Estimate]:
    """The headline quantities of ``sol`` with their errors by the order ladder on its mesh."""
    samples = order_samples(sol, length, solve)
    order = sol.problem.order
    return [DE.estimate(name, {q: s[name] for q, s in samples.items()}, order) for name in samples[order]]


def refined_copy(mesh: ng.Mesh) -> ng.Mesh:
    """A copy of ``mesh`` refined uniformly once (Netgen's refinement: each triangle into four, the new boundary
    vertices on the geometry), curved at ``mesh``'s curve order; ``mesh`` is left as it is."""
    copy = ng.Mesh(mesh.ngmesh.Copy())
    copy.ngmesh.Refine()
    copy.Curve(mesh.GetCurveOrder())
    return copy


def h_step_estimate(name: str, coarse: DE.Sample, fine: DE.Sample, order: int) -> DE.Estimate:
    """The error of ``coarse`` (the run's mesh) from ``fine`` (the mesh refined once, the same order): module
    docstring, ``3 |d|``, or ``1.5 |d|`` where ``d`` is round-off."""
    d = fine.value - coarse.value
    scale = coarse.magnitude
    head = f"order {order} on the run's mesh and on it refined uniformly once: change {d:.3g}"
    error = of_values([coarse.value, fine.value], HALVING, member=0, noise=DE.NOISE * scale).estimate
    if abs(d) <= DE.NOISE * scale:
        rule = "the meshes agree to round-off and the solver's tolerance"
    else:
        q = presumed_ratio(HALVING)
        rule = (f"{DE.SAFETY:g} x |d| / (1 - {q:g}), an error that at least halves with h (ngcontact."
                "drivers.richardson_tail)")
    return DE.Estimate(name=name, value=coarse.value, error=error, scale=scale, ratio=math.nan,
                       orders=(order, order, order), how=f"{head}: {rule}")


def h_step_estimates(sol: D.DirectSolution, length: float, solve: Callable[[D.DirectProblem], D.DirectSolution]
                     ) -> list[DE.Estimate]:
    """The headline quantities of ``sol`` with their errors from one uniform refinement of its mesh at its order
    (module docstring); ``solve(problem)`` solves as the scene does."""
    problem = sol.problem
    fine = headlines(solve(replace(problem, mesh=refined_copy(problem.mesh))), length)
    coarse = headlines(sol, length)
    return [h_step_estimate(name, coarse[name], fine[name], problem.order) for name in coarse]


def guarded(ladder: list[DE.Estimate], h_step: list[DE.Estimate]) -> list[DE.Estimate]:
    """Per quantity the larger of the order ladder's estimate and the uniform refinement's (the verdict of a
    refinement that met its tolerance by the order alone, :mod:`ngcontact.drivers.resolved_refinement`)."""
    by_name = {e.name: e for e in h_step}
    out = []
    for e in ladder:
        h = by_name[e.name]
        if e.error is None or h.error is not None and h.error > e.error:
            out.append(replace(h, how=f"{h.how}; larger than the order ladder's ({e.how})"))
        else:
            out.append(replace(e, how=f"{e.how}; at least the uniform refinement's ({h.how})"))
    return out


def accuracy(sol: D.DirectSolution, length: float, solve: Callable[[D.DirectProblem], D.DirectSolution],
             tolerance: float | None = None, found: list[DE.Estimate] | None = None) -> dict[str, Any]:
    """``results.accuracy`` of the resolved solution ``sol`` (module docstring); ``length``: the macro length
    the contact fraction is taken per; ``tolerance``: the scene's (``None``: the default); ``found``: the
    estimates a refinement made already (else made here by :func:`h_step_estimates`)."""
    if found is None:
        found = h_step_estimates(sol, length, solve)
    return MA.verdict(found, tolerance, None, how=HOW, absolute=FRACTIONS)
