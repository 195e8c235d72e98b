"""An FE cell held to the default tolerance: its own answer where that meets it, else refined within a budget.

A cell scene that states no ``discretization.tolerance`` is held to the default one, ``tol =``
:data:`ngcontact.cell.admissibility.DEFAULT_TOLERANCE` (``discretization.estimate = "auto"``):

1. the scene's sweep at order ``p`` on its mesh, and its error from the same sweep at order ``p + 1`` on the
   same mesh (:mod:`ngcontact.cell.fe.saturation`: ``|q_p - q| <= |q_(p+1) - q_p| / (1 - beta)``, every
   headline quantity).  Where every load's estimate meets ``tol`` that answer is reported: no refinement
   solves fewer unknowns than the scene's own discretization, so it is the cheapest that meets the
   tolerance.  A cell refined by grading (below) is refined by default only where the contact fraction or
   the closure misses ``tol`` on the scene's mesh (:data:`DEFAULT_HELD`): a miss of the effective stiffness
   or of a coefficient of eq. 34 alone is reported with ``accuracy.met = false`` and one warning line (the
   one-order-more estimate of those on a coarse mesh, e.g. under a penalty near its limit ``k_n h / E ~
   1e10``, is no guide to where graded levels would end); a stated tolerance's graded levels hold them all
   (:mod:`ngcontact.cell.fe.grading_estimate`).  A quantity the graded levels do not estimate keeps the
   scene's estimate, carried to the refined answer (:func:`carried_over`);
2. else the sweep is refined towards ``tol`` as a stated tolerance refines it
   (:meth:`~ngcontact.cell.fe.fe_cell.FECell.default_refinement`), but no discretization holding more than
   the budget's unknowns (``discretization.budget_dofs``; :data:`ngcontact.cell.fe.fe_cell.DEFAULT_DOFS`)
   is solved: a flat 2D frictionless cell each load on meshes graded towards its contact edges and then
   orders ``p', p' + 1, p' + 2`` on the finest (:mod:`ngcontact.cell.fe.edge_grading`), any other cell the
   sweep on a sequence of finer interface meshes, ``h, h/2, h/4, ...`` (or along the contact edge only:
   :mod:`ngcontact.cell.fe.contact_edge_refinement`), whose level 0 is step 1's sweep, not solved again
   (:mod:`ngcontact.cell.fe.second_discretization`).  The last discretization is reported with its error
   from the observed rate of the sequence (:mod:`ngcontact.cell.fe.observed_rate`): where the differences
   ``d_j = |q_j - q_(j-1)|`` fall at least geometrically, ``d_(j+1) <= rho d_j``,

       |q_n - q| <= sum_(j > n) d_j <= d_n rho / (1 - rho),

   taken with the larger observed ``rho`` of the last two ratios, held to the knob's guaranteed floor and
   cap and multiplied by a safety factor (:data:`~ngcontact.cell.fe.grading_estimate.ORDER_RATE`,
   :data:`~ngcontact.cell.fe.second_discretization.HALVING_RATE`).

Why the sequences converge, so that the bound holds with ``rho < 1``: on one fixed (graded) mesh,
``p``-refinement converges to the exact solution of the cell problem, not to a mesh-dependent limit, and
geometrically in ``p`` for the smooth bulk and for edges that sit at vertices, which the grading puts them
at (an edge left inside its element is bounded separately, by the grading's tail of
:mod:`ngcontact.cell.fe.grading_estimate`); under a halved
interface element size the contact fraction's error is at least of first order in the size (an edge cuts
its elements anywhere, and the fraction counts the cut elements' share to first order) and the closure's of
higher order, so the ratio of successive errors tends to ``1/2`` or less, which the floor assumes.  The
effectivity of both (estimate over true error) is measured by ``scripts/fe_effectivity.py`` against
converged spectral twins and tested against Westergaard's closed form (``docs/benchmarks.md``, FE
effectivity).

3. Where the budget ends before ``tol`` is met, the finest answer is reported with its estimate,
   ``accuracy.met = false``, and the shortfall: the budget and what meeting ``tol`` would take, extrapolated
   from the observed rate.  Errors ``e_k`` on ``N_k`` unknowns falling like ``N^(-a)``, with ``a =
   log(e_(k-1) / e_k) / log(N_k / N_(k-1))`` observed on the last two levels (where one level has an
   estimate, the knob's assumed ratio per level and the growth of the unknowns from level to level), meeting
   ``tol`` takes ``N = N_n (e_n / tol)^(1/a)`` unknowns
   (:func:`~ngcontact.cell.fe.observed_rate.dofs_to_meet`); a sequence whose rate shows that beyond the budget
   stops there (nothing within the budget can meet it).  Where the budget allows no
   second discretization (or the refined one has no finite estimate), the scene's answer is reported with
   step 1's estimate and the shortfall.  Only a stated tolerance out of reach fails the run.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.cell_solution import GROUP, headline, measure, scale
from ngcontact.cell.cell_solver import Refinement
from ngcontact.cell.fe.edge_grading import GradedSolve
from ngcontact.cell.fe.grading_estimate import ORDER_RATE
from ngcontact.cell.fe.observed_rate import dofs_to_meet, exponent
from ngcontact.cell.fe.saturation import estimate_on_scene
from ngcontact.cell.fe.second_discretization import HALVING_RATE, Sequence, as_refinement

#: the quantities whose miss of the default tolerance on the scene's own mesh starts a graded refinement
#: (module docstring, step 1)
DEFAULT_HELD = ("contact_fraction", "mean_closure")
#: the scene key of the budget, as the warning names it
BUDGET_KEY = "discretization.budget_dofs"
#: unknowns beyond any machine this package runs on: a projection above it is said to be out of reach
OUT_OF_REACH = 1e9


def worst(estimates: list[dict[str, float]], names: tuple[str, ...] | None = None) -> float:
    """The largest estimate over the loads and quantities (0 without any); only of ``names`` where given."""
    return max((e for per_load in estimates for n, e in per_load.items() if names is None or n in names),
               default=0.0)


def carried_over(first: Refinement, refined: Refinement) -> Refinement:
    """``refined`` (graded solves) with the scene's saturation estimate of every quantity they do not estimate
    carried to the refined answer: ``|q_r - q| <= |q_0 - q| + |q_r - q_0|``,
    so ``E_r = (E_0 s_0 + |q_r - q_0|) / s_r`` in each quantity's measure (``s``: its scale, a coefficient's
    the whole surface's group, the same on both), a bound wherever the scene's is one."""
    estimates, scales = [], []
    for k, (sol, own) in enumerate(zip(refined.solutions, refined.estimates)):
        head, then = headline(sol.results), headline(first.solutions[k].results)
        out, size = dict(own), {n: scale(n, head) for n in own}
        if k < len(refined.scales):
            size.update(refined.scales[k])
        for name, e in first.estimates[k].items():
            if name in out or name not in head:
                continue
            s0 = first.scales[k][name]
            size[name] = s0 if measure(name) == GROUP else scale(name, head)
            out[name] = (e * s0 + abs(head[name] - then[name])) / size[name]
        estimates.append(out)
        scales.append(size)
    how = refined.how + ("; the other headline quantities: the scene's estimate one order more plus the change "
                         "to the refined answer")
    return replace(refined, estimates=estimates, scales=scales, how=how)


def shortfall(tolerance: float, budget: int, finest: str, estimate: float, need: tuple[float, float] | None,
              stop: str = "") -> str:
    """The shortfall in words: the budget, the finest discretization, the estimate, why the refinement stopped
    where that was not the budget, and what meeting the tolerance would take."""
    head = (f"after refining within {BUDGET_KEY} = {budget} (finest: {finest}; largest estimate {estimate:.3g} "
            f"against {tolerance:g}{'; stopped: ' + stop if stop else ''})")
    if need is None:
        return head + "; the estimates do not fall fast enough to extrapolate what meeting it would take"
    rate = f"the estimate falling like dofs^-{need[1]:.2g}, as observed, or as assumed where one level is estimated"
    if need[0] > OUT_OF_REACH:
        return (head + f"; at that rate ({rate}) meeting it would take more than {OUT_OF_REACH:.0e} dofs: out of "
                "reach of this refinement (another discretization.method or a looser tolerance)")
    return head + f"; meeting it would take about {need[0]:.2g} dofs ({rate})"


def sequence_shortfall(done: Sequence, tolerance: float, budget: int) -> str:
    """The shortfall of a sequence of finer discretizations (``""`` where it met the tolerance)."""
    if done.met:
        return ""
    levels = done.levels
    estimated = [lv for lv in levels if "estimate" in lv]
    growth = levels[-1]["ndof"] / levels[-2]["ndof"] if len(levels) >= 2 else 0.0
    a = exponent([lv["ndof"] for lv in estimated], [lv["estimate"] for lv in estimated],
                 (HALVING_RATE.assumed, growth))
    e = worst([{n: v for n, v in per_load.items() if n not in done.uncontrolled} for per_load in done.estimates])
    finest = f"{levels[-1]['discretization']}, {levels[-1]['ndof']} dofs"
    why = "" if done.beyond is not None or "would take about" in done.stop else done.stop
    return shortfall(tolerance, budget, finest, e, dofs_to_meet(levels[-1]["ndof"], e, tolerance, a), why)


def graded_shortfall(solves: list[GradedSolve], tolerance: float, budget: int) -> str:
    """The shortfall of graded solves (``""`` where every load met the tolerance): where a load stopped at the
    budget with its estimate within the tolerance, the level its check needed; else that of the load with the
    largest estimate, the exponent from each level's changes against the one before."""
    g = max(solves, key=lambda s: max(s.estimate.values()))
    e = max(g.estimate.values())
    last = g.history[-1]
    finest = f"grading level {last['level']} at order {last['order']}, {last['ndof']} dofs"
    if e <= tolerance:
        stopped = [s for s in solves if s.stopped]
        if not stopped:
            return ""
        return (f"after refining within {BUDGET_KEY} = {budget}: the estimates are within {tolerance:g} but the "
                f"refinement's check did not end ({stopped[0].stopped})")
    steps = [h for h in g.history if h["fraction_change"] is not None]
    growth = last["ndof"] / g.history[-2]["ndof"] if len(g.history) >= 2 else 0.0
    a = exponent([h["ndof"] for h in steps], [max(h["fraction_change"], h["closure_change"]) for h in steps],
                 (ORDER_RATE.assumed, growth))
    return shortfall(tolerance, budget, finest, e, dofs_to_meet(last["ndof"], e, tolerance, a))


def scene_shortfall(first: Refinement, tolerance: float, budget: int, ndof: int, beyond: int | None) -> str:
    """The shortfall where no refinement within the budget has an estimate: the scene's level and its
    saturation estimate, the next level's unknowns ``beyond`` the budget where known."""
    e = worst(first.estimates)
    a = exponent([ndof], [e], (HALVING_RATE.assumed, beyond / ndof if beyond else 0.0))
    return shortfall(tolerance, budget, f"the scene's own discretization, {ndof} dofs", e,
                     dofs_to_meet(ndof, e, tolerance, a))


def held_to_default(cell: Any, tolerance: float, loads: list[CellLoad]) -> Refinement:
    """The sweep of ``cell`` (an :class:`~ngcontact.cell.fe.fe_cell.FECell`) held to the default ``tolerance``
    (module docstring): its own answer where the saturation estimate meets it, else refined within
    ``cell.budget`` unknowns, with the shortfall where the budget ended first."""
    first = estimate_on_scene(cell, loads)
    graded = cell.default_refinement() == "graded"
    if not first.estimates or worst(first.estimates, DEFAULT_HELD if graded else None) <= tolerance:
        return first          # met on the scene's own discretization, or not estimable (said so)
    ndof, scene_problem = cell.unknowns(), cell.problem
    if graded:
        refined, solves = cell.graded_solves(tolerance, loads, False, cell.budget)
        estimable = all(math.isfinite(v) for e in refined.estimates for v in e.values())
        if estimable:        # a load stopped at the budget has not completed the check a tolerance needs
            return replace(carried_over(first, refined), met=not any(g.stopped for g in solves),
                           shortfall=graded_shortfall(solves, tolerance, cell.budget))
        cell.restore(scene_problem)
        return replace(first, shortfall=scene_shortfall(first, tolerance, cell.budget, ndof, None))
    done = cell.compared(tolerance, loads, cell.budget, False, first.solutions)
    if len(done.levels) == 1:
        return replace(first, shortfall=scene_shortfall(first, tolerance, cell.budget, ndof, done.beyond))
    return replace(as_refinement(done), shortfall=sequence_shortfall(done, tolerance, cell.budget))
