"""The error of an FE cell's answer on the scene's own mesh, from one order more (the saturation assumption).

A cell scene that states no ``discretization.tolerance`` is held to the default one
(:data:`ngcontact.cell.admissibility.DEFAULT_TOLERANCE`) and first keeps its discretization: order ``p`` on
its mesh, whose answer ``q_p`` is reported where its estimate meets that tolerance.  Its error is
estimated by solving the same sweep once more at order ``p + 1`` on the same mesh (a curved interface
meshed at the new order's geometry).  Where the higher order leaves at most a fraction ``beta < 1`` of
the lower order's error (the *saturation assumption* of hierarchical a posteriori estimators: the enriched
space is closer to the solution by a fixed factor),

    |q_p - q| <= |q_p - q_(p+1)| + |q_(p+1) - q| <= d + beta |q_p - q|,     so     |q_p - q| <= d / (1 - beta),

with ``d = |q_(p+1) - q_p|`` in each quantity's measure (:func:`ngcontact.cell.cell_solution.measure`: the
contact fraction absolute, the mean closure and the normal effective stiffness relative to their value, a
coefficient of eq. 34 on the real contact set relative to the largest of its group on the whole contact
surface, as every cell estimate measures them).  The estimate is that bound at ``beta =``
:data:`SATURATION`, for every headline quantity the cell reports
(:func:`ngcontact.cell.cell_solution.headline`; a coefficient zero at both orders, ``k_t`` of a flat
interface, is exactly zero and not estimated).

Why one order more, and ``q_p`` reported:

* the bound needs only that the second discretization be the better one, which ``p + 1`` on the same mesh
  is for every quantity: the same mesh holds the same geometry (a curved one more closely), and on it the
  enriched space contains the scene's (``p``-refinement converges to the exact solution, not to a
  mesh-dependent limit; :mod:`ngcontact.cell.fe.edge_grading`);
* reporting ``q_(p+1)`` instead would need its own error, ``beta / (1 - beta) d`` at a rate two values do
  not show (:mod:`ngcontact.cell.fe.observed_rate` needs three); reporting ``q_p`` keeps the scene's numbers
  and bounds their error from the one difference;
* one order less (cheaper) bounds the error of ``q_(p-1)``, many times that of ``q_p`` for the smooth
  quantities, and order 1 has none below it; a halved interface mesh moves the contact edges within their
  elements, so the contact fraction converges under it neither monotonically nor at a fixed ratio
  (:mod:`ngcontact.cell.fe.second_discretization` holds that ratio to a floor over three levels), and a
  single difference may vanish by chance; the solves the run already makes (the load continuation, the
  spectral predictor) are of the same discretization and measure the solver, not the discretization;
  the distance of a contact edge from its nearest vertex measures where the mesh put its vertices, which
  on a mesh not graded towards the edges (up to half an element) is not the error of the edge;
* the cost is one sweep on the enriched space, about ``((p + 1) / p)^d`` times the scene's unknowns.

Why ``beta = 3/4``: the mean closure is a smooth functional of the displacement, whose error one order
more divides many times over (then the estimate is about ``4`` times the error); the contact fraction is
set by the contact edges, where the pressure behaves like ``sqrt(a - x)`` inside an element and one order
more moves the edge by an algebraic, not geometric, fraction: on the oracles of ``scripts/fe_effectivity.py``
(Westergaard, the stem grooves and the 3D bisinusoid against their converged spectral twins;
``docs/benchmarks.md``, FE effectivity) order ``p + 1`` keeps up to about half the error of order ``p``.
``3/4`` bounds that with a margin, and keeps the estimate within ten times the error.  The other headline
quantities follow the same two: the coefficients of eq. 34 on the real contact set (``k_n`` times the
contact set's measure, ``k_n`` times the gap integrated over it, eq. 34 with ``w`` the contact set's
indicator) are set by the same contact edges as the fraction; the normal effective stiffness, the inverse of
the cell's compliance less the bonded laminate's, carries the bulk's smooth error and, through the pressure's
square root at the edges, the edges' error, amplified by the difference of nearly equal compliances.  On
the stem-groove cell against its spectral twin (``tests/cell/test_fe_default_estimate.py``, orders 1 and 2)
the estimate is 4.0 and 4.3 times the stiffness's error, 3.4 times the coefficients' at order 2 and 9.1
(``k_n``, as the fraction) to 9.3 (``g_n``) times at order 1, where order 2 is further from the limit than
order 1 (a bound, loose where the coarse order is right by chance); on the Westergaard cell (its five loads,
both orders) every quantity's between 1.6 and 6.6.  That holds because both sides put the contact edges
where the fraction does: the coefficients are integrated over the pieces in contact, the edges cut inside
the elements, with the scene's gap (:func:`ngcontact.cell.fe.measures.real_contact_coefficients`), and the
stiffness's tangent is integrated exactly up to the edges (:func:`ngcontact.cell.fe.stiffness.edge_correction`).
An indicator integrated by quadrature puts each edge at a quadrature point, a change between the two
orders' rules that is not the error of either: ``k_n``'s estimate was 36 times its error, the stiffness's
22 times (Westergaard, order 2); the penalty's interpolant of the gap added an error to ``g_n`` that at
order 1 cancelled the edges' (15 times).

The estimate itself does not refine: a sweep whose estimate exceeds the default tolerance is refined within
the scene's budget (:mod:`ngcontact.cell.fe.default_refinement`), or, with ``discretization.estimate =
"estimate"``, reported with ``accuracy.met = false`` and one warning line (:mod:`ngcontact.drivers.run_cell`);
stating ``discretization.tolerance`` refines it (:meth:`~ngcontact.cell.fe.fe_cell.FECell.refine_to`).
Where the order cannot rise (the scene's checks refuse it, or the enriched sweep fails), the answer is
reported not estimated, with the reason, and not met.
"""
from __future__ import annotations

import logging
import time
from typing import Any

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.cell_solution import COEFFICIENT, CellSolution, headline, scale
from ngcontact.cell.cell_solver import Refinement
from ngcontact.errors import ConvergenceError, ModelError

log = logging.getLogger(__name__)
#: the run's progress lines
progress = logging.getLogger("ngcontact.progress")

#: the saturation assumption: order ``p + 1`` on the same mesh keeps at most this fraction of the error of
#: order ``p`` (module docstring)
SATURATION = 0.75
#: the rule in words, for the report's ``accuracy.how``
RULE = (f"d / (1 - {SATURATION:g}), d the change one order more on the same mesh makes (the saturation "
        f"assumption: order p + 1 keeps at most {SATURATION:g} of the error of order p)")


def saturation_estimates(lower: list[dict[str, float]], higher: list[dict[str, float]],
                         whole: dict[str, Any] | None = None) -> list[dict[str, float]]:
    """Per load the estimated error of each quantity of ``lower`` (the reported order's headline quantities)
    from ``higher`` (one order more): ``|higher - lower| / (1 - SATURATION)`` divided by the quantity's
    :func:`~ngcontact.cell.cell_solution.scale` at ``lower`` (a coefficient's group on the ``whole``-surface
    coefficients where given); a quantity missing from either, or a coefficient zero in both, is not
    estimated."""
    out = []
    for low, high in zip(lower, higher):
        estimate = {}
        for name in (n for n in low if n in high):
            if name.startswith(COEFFICIENT) and low[name] == 0 and high[name] == 0:
                continue
            estimate[name] = abs(high[name] - low[name]) / scale(name, low, whole) / (1.0 - SATURATION)
        out.append(estimate)
    return out


def not_estimated(solutions: list[CellSolution], why: str) -> Refinement:
    """The scene's sweep without an estimate: the reason in ``how``, not met."""
    return Refinement(solutions=solutions, estimates=[],
                      per_load=[{"newton_iterations": s.iterations} for s in solutions],
                      histories=[s.newton for s in solutions], how=f"not estimated: {why}", met=False,
                      scene_discretization=True)


def estimate_on_scene(cell: Any, loads: list[CellLoad]) -> Refinement:
    """The scene's sweep (``cell``: an :class:`~ngcontact.cell.fe.fe_cell.FECell` on the scene's
    discretization) and its error from the same sweep one order more on the same mesh (module docstring).
    The cell keeps the scene's problem: the reported solutions, fields and displacements are its own."""
    solutions = cell.sweep(loads)
    order = int(cell.model.order)
    enriched = cell.variant(order=order + 1) if cell.variant is not None else None
    if enriched is None:
        return not_estimated(solutions, f"the scene refuses order {order + 1}, the one more that estimates the "
                             "error of its order; set discretization.tolerance to refine")
    t0 = time.perf_counter()
    try:
        higher = enriched.sweep(loads)
    except (ConvergenceError, ModelError) as exc:
        log.warning("the error estimate's sweep at order %d failed: %s", order + 1, exc)
        return not_estimated(solutions, f"the sweep at order {order + 1} on the same mesh failed ({exc})")
    ndof = int(enriched.unknowns())
    progress.info("FE error estimate, order %d on the same mesh: %d dofs, %.2f s", order + 1, ndof,
                  time.perf_counter() - t0)
    heads = [headline(s.results) for s in solutions]
    # the coefficients' scale: the whole surface's (eq. 34 with w = 1), where a load reports them
    whole = cell.whole_surface() if any(n.startswith(COEFFICIENT) for h in heads for n in h) else None
    estimates = saturation_estimates(heads, [headline(s.results) for s in higher], whole)
    per_load = [{"newton_iterations": s.iterations,
                 "next_order": dict(headline(h.results), order=order + 1, ndof=ndof)}
                for s, h in zip(solutions, higher)]
    how = (f"the scene's discretization (order {order}, {cell.unknowns()} dofs), its error {RULE}, order "
           f"{order + 1} with {ndof} dofs")
    scales = [{name: scale(name, head, whole) for name in e} for e, head in zip(estimates, heads)]
    return Refinement(solutions=solutions, estimates=estimates, per_load=per_load,
                      histories=[s.newton for s in solutions], how=how, scene_discretization=True, scales=scales)
