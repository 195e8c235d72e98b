"""The accuracy verdict of a ``direct`` run (``results.accuracy``): its headline quantities with their errors.

The resolved problem's headline quantities (:mod:`ngcontact.drivers.headline_quantities`): the
contact fraction of the resolved surface ``S_C^eps`` (the measure of ``{J.n - g >= 0}`` per unit macro
length, a number of order one, so its error is held to the tolerance as an absolute one, as a cell's
contact fraction is) and the
magnitude of the contact force through it.  Their discretization error is estimated as a macro run's
(:mod:`ngcontact.macro.discretization_error`): the same problem solved at the neighbouring orders on
the run's mesh (``p - 1, p, p + 1``; an order-1 run's neighbours on its mesh curved at order 2), and
the rule ``1.5 max(g, min(m, 2 g))`` on the two differences, or no error where they do not shrink.

The contact fraction is an integral of an indicator over ``S_C^eps`` whose edge (where the gap closes)
moves with the order inside an element: its p-convergence is algebraic at best, and where its
differences do not shrink the verdict says so rather than give a number.  The verdict has the macro
run's format (:func:`ngcontact.drivers.macro_accuracy.verdict`) without its equilibrium check, and is
held to the scene's ``discretization.tolerance`` (towards which the run is refined first,
:mod:`ngcontact.drivers.resolved_refinement`), else to
:data:`~ngcontact.cell.admissibility.DEFAULT_TOLERANCE`: a miss is one warning line, the terminal's
accuracy line and ``report.html``'s top say it.  The epsilon study's modelling error is another quantity,
in its own report.
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Callable

import numpy as np

from ngcontact.drivers import macro_accuracy as MA
from ngcontact.macro import discretization_error as DE
from ngcontact.resolved import resolved_problem as D
from ngcontact.scene.schema import MAX_ORDER

#: how the verdict's errors are estimated (the report's ``accuracy.how``)
HOW = ("discretization error of the resolved contact fraction (absolute) and of the contact force's magnitude "
       "from solves at the neighbouring polynomial orders on the run's mesh (ngcontact.drivers.resolved_accuracy, "
       "the rules of ngcontact.macro.discretization_error)")
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


def accuracy(sol: D.DirectSolution, length: float, solve: Callable[[D.DirectProblem], D.DirectSolution],
             tolerance: float | None = None, found: list[DE.Estimate] | None = None) -> dict[str, Any]:
    """``results.accuracy`` of the resolved solution ``sol`` (module docstring); ``length``: the macro length
    the contact fraction is taken per; ``tolerance``: the scene's (``None``: the default); ``found``: the
    estimates a refinement made already (else made here)."""
    if found is None:
        found = estimates(sol, length, solve)
    return MA.verdict(found, tolerance, None, how=HOW, absolute=FRACTIONS)
