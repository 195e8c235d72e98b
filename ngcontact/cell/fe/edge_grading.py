"""Interface meshes graded towards the contact edges, refined until a tolerance is met.

Near the edge ``a`` of a smooth contact patch the pressure behaves like
``sqrt(a - x)`` and the gap like ``(x - a)^(3/2)`` (the edge of Hertz and
Westergaard contact, ngcontact.verification.westergaard): polynomials on a uniform mesh resolve
neither, and the contact fraction of the cell (paper Sec. 3.2.2, the real
contact set of eq. 34) converges slowly and not monotonically under uniform
refinement.  A mesh whose interface vertices crowd geometrically towards the
edges, ``a +- h0 r^k`` for ``k = 1 .. L``, isolates the singular behaviour in
elements of size ``h0 r^L``, as hp-FEM does at corners.

The edges are not known in advance, so meshing and solving alternate:

1. solve on the scene's mesh (level 0) and locate the edges (the roots of
   the penetration polynomial, :func:`contact_edges`);
2. mesh the cell again with ``LEVELS_PER_STEP`` more grading levels
   towards the edges just found (each is then a mesh vertex), solve from the
   previous level's state (:func:`carry_over`), locate the edges again;
3. when the contact fraction changes between two levels by at most the
   tolerance (``|f_k - f_(k-1)| <= tol``), or the grading has gone as far as
   it goes, solve the finer level once more at one order higher, and again
   at one more: the bulk away from the edges is smooth, and raising the
   order there is what checks (and reduces) its error; stop when the level
   comparison changed the contact fraction by at most the tolerance, the
   last order changes both the contact fraction and the mean closure by at
   most it (``|c_k - c_(k-1)| <= tol |c_k|``), and the estimate of every
   headline quantity meets it (the stiffness and the coefficients of eq. 34
   too: :mod:`~ngcontact.cell.fe.grading_estimate`); where one misses it by
   its edges' part (the grading's tail, the contact set's share, which no
   order reduces: :func:`~ngcontact.cell.fe.grading_estimate.edges_miss`),
   grade once more at the order graded and check the new mesh by its own
   orders, as where the orders are spent before it is met (an edge inside
   its element converges only algebraically in the order); else continue
   grading at the raised order, or, at the finest grading, raise the order
   again.
   The answer reported is the highest order on the finest mesh; its
   estimate is the observed-rate tail of the orders on that mesh
   (:data:`ORDER_RATE`, :mod:`ngcontact.cell.fe.observed_rate`):
   ``p``-refinement on one fixed mesh converges to the exact solution, not to
   a mesh-dependent limit, so the tail of its sequence bounds the error of
   the smooth bulk.  An edge that lies inside its element (the vertex was
   put where the previous level found it) carries a ``sqrt`` singularity
   inside the element, where ``p``-refinement converges algebraically and
   not monotonically (on Westergaard and Hertz the last order is often
   worse than the one before): that error is the grading's, bounded by
   its own tail (:func:`~ngcontact.cell.fe.grading_estimate.grading_tail`).

The first mesh from the spectral twin.  With the penalty, a flat cell has
a spectral twin (:mod:`ngcontact.cell.spectral_start`): the same
layers and ``k_n`` on a grid, solved with FFTs in a fraction of a second.
Its contact edges, known to half its grid spacing
(:func:`~ngcontact.cell.spectral_start.twin_edges`), replace step 1's
uniform solve: the first mesh is graded towards them by as many levels as
bring its smallest element down to the spacing (:func:`seed_levels`), and
the loop goes on from there.  And every level, the order raise included,
starts afresh from the twin's contact set instead of the previous level's
state (a frictionless energy has one minimizer; the carried state has
holes in its contact set where the interpolation between unrelated meshes
shifts the tiny penetration ``p/k_n`` across zero).  On the shipped scene
``westergaard_graded.toml`` the seeded first mesh saves levels and the
fresh starts save Newton steps on each, the errors against
Westergaard the same.

A full contact has no edge: the interface mesh is halved instead.  With the penalty enforcement the model *is* the
Winkler layer ``k_n`` (paper eqs. 7, 9), whose own difference from rigid
contact is not part of the estimate.

For cells whose contact surface is the flat line ``y = 0`` (the
small-slope model: a flat interface with an initial gap) in 2D.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import ngsolve as ng

from ngcontact.cell.fe.measures import contact_pieces
from ngcontact.cell.fe.load_start import starts_afresh
from ngcontact.cell.cell_solver import Refinement
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.fe.grading_estimate import (LEVELS_PER_STEP, ORDER_RATE, RATIO, edge_cells, edges_miss, merged,
                                                  order_estimate, out_of_reach, set_move, stiffness_edges)
from ngcontact.cell.fe.observed_rate import DISAGREE
from ngcontact.errors import ConvergenceError, ModelError, SceneError
from ngcontact.geometry.cell2d import flat_cell

log = logging.getLogger(__name__)

#: steps before the tolerance is declared out of reach: the smallest element is then
#: h0 r^8 ~ 1.5e-5 h0 (Netgen fails on segments some 1e-8 of the period long)
MAX_STEPS = 4
#: order raises (after the grading has settled) before the tolerance is declared out of reach
MAX_ORDER_RAISES = 2
#: Netgen's grading of the graded meshes: elements may grow by about this fraction away from the edges
#: (0.5 halved the dofs of Westergaard's graded meshes against Netgen's default 0.3 at the same error)
MESH_GRADING = 0.5


def contact_edges(problem) -> np.ndarray:
    """Abscissae of the contact edges: where the real contact set ``{J.n - g >= 0}`` begins or ends.

    On each boundary element of ``S_C`` the penetration is a polynomial of
    the reference coordinate; its roots split the element into pieces in
    and out of contact (the construction of
    :func:`ngcontact.cell.fe.measures.contact_pieces`).  An edge is a point
    where the state changes between consecutive pieces along ``x``
    (periodically), inside an element or at a vertex.
    """
    return _edges(contact_pieces(problem))


def _edges(pieces) -> np.ndarray:
    """The edges of :func:`contact_edges` from the pieces of :func:`~ngcontact.cell.fe.measures.contact_pieces`."""
    pieces = sorted((min(a, b), max(a, b), on) for a, b, on, _ in pieces)
    if not pieces:
        return np.empty(0)
    edges = [p[1] for p, q in zip(pieces, pieces[1:] + pieces[:1]) if p[2] != q[2]]
    return np.asarray(edges, dtype=float)


@dataclass
class GradedSolve:
    """The outcome of :func:`solve_to_tolerance`: the finest level's problem and solution, and the history."""

    problem: Any
    solution: Any
    #: the entries of the orders solved on the finest graded mesh, lowest first (the last is the answer)
    orders: list[dict[str, Any]]
    #: the change of the contact fraction over the last grading step (at the order graded), or ``None``
    grading_change: float | None = None
    history: list[dict[str, Any]] = field(default_factory=list)
    #: the Newton histories of every level's solve, in order, each with its ``"level"`` and ``"order"``
    newton: list[dict[str, Any]] = field(default_factory=list)
    #: why the loop stopped before the tolerance at a size bound (``max_dofs``), else ""
    stopped: str = ""

    @property
    def estimate(self) -> dict[str, float]:
        """The error of the answer per quantity: the observed-rate tail of the orders on its mesh
        (:func:`order_estimate`)."""
        return order_estimate(self.orders, self.grading_change)[0]

    @property
    def remark(self) -> str:
        """Where the orders' ratios disagree or a guard acted, in words ("" otherwise)."""
        return order_estimate(self.orders, self.grading_change)[1]


def edge_offset(edges, ends: np.ndarray) -> float:
    """The largest distance of a contact edge from its nearest interface vertex (0 without edges): where the
    mesh put its vertices against the edges found on it, recorded per level (not part of the estimate)."""
    if len(edges) == 0:
        return 0.0
    vertices = np.unique(ends)
    return float(max(np.min(np.abs(vertices - e)) for e in edges))


def graded_vertices(edges, h0: float, levels: int, period: float) -> list[float]:
    """Interface vertices ``a``, ``a +- h0 r^k`` (``k = 1 .. levels``) for every edge ``a``, wrapped into the period.

    No two vertices (nor a vertex and the period's ends) closer than half the finest element ``h0 r^levels``:
    a vertex nearer the last one kept is dropped.  Edges found a few 1e-9 apart (the penetration's sign
    flickering at a contact edge) would otherwise give segments of that length, on which Netgen's mesher
    did not return (Westergaard at p/p* = 0.5, order 2: vertices 6.4e-9 apart).
    """
    pts = []
    for a in edges:
        pts.append(a % period)
        for k in range(1, levels + 1):
            d = h0 * RATIO ** k
            pts += [(a - d) % period, (a + d) % period]
    gap = 0.5 * h0 * RATIO ** levels
    out: list[float] = []
    for p in sorted(pts):
        if gap <= p <= period - gap and (not out or p - out[-1] >= gap):
            out.append(float(p))
    return out


def graded_flat_cell(period: float, h_rough: float, h_counter: float, *, maxh: float, interface_maxh: float,
                     order: int, vertices):
    """The flat 2D cell with these interface vertices (Netgen's default grading without any)."""
    return flat_cell(period, h_rough, h_counter, maxh=maxh, interface_maxh=interface_maxh, order=order,
                     vertices=vertices, grading=MESH_GRADING if len(vertices) else 0.3)


def _interface_elements(mesh) -> np.ndarray:
    """``(n, 2)`` end abscissae of the interface elements."""
    rule = ng.IntegrationRule([(0.0,), (1.0,)], [0.0, 0.0])
    mips = mesh.MapToAllElements(rule, mesh.Boundaries("contact"))
    return np.sort(np.asarray(ng.x(mips)).reshape(-1, 2), axis=1)



def carry_over(old, new) -> None:
    """Start ``new`` (another mesh of the same cell) from the state of ``old``.

    Each body's displacement is interpolated body by body (``Set`` restricted
    to the body's region, so that no point of one body reads the other's
    field across the interface) and the far-face translation is copied.
    Newton then starts next to the solution instead of at the rigid
    predictor, with the active set nearly right.  With exact enforcement the
    multiplier is carried too, interpolated linearly between the old nodes
    along the flat ``S_C``: Uzawa's first pass then starts from the old
    level's pressure instead of the penalty's (fewer Newton steps per load
    summed over the levels, e.g. on ``westergaard_graded.toml`` run with
    exact enforcement).
    """
    for k, region in enumerate(("rough", "counter")):
        new.gfu.components[k].Set(old.gfu.components[k], definedon=new.mesh.Materials(region))
    for a, b in zip(old.u_dofs, new.u_dofs):
        new.gfu.vec[b] = old.gfu.vec[a]
    if old.multiplier is not None and new.multiplier is not None:
        # exact enforcement: the multiplier too, linear between the old nodes along the flat S_C (periodic in x)
        x_old, lam = old.multiplier.at_points(ng.x), old.multiplier.point_values()
        order = np.argsort(x_old, kind="stable")
        period = float(old.cell.period[0])
        new.multiplier.set_point_values(np.maximum(
            np.interp(new.multiplier.at_points(ng.x), x_old[order], lam[order], period=period), 0.0))


def seed_levels(h0: float, spacing: float) -> int:
    """Grading levels of a first mesh seeded with edges known to ``spacing``: the fewest steps of
    ``LEVELS_PER_STEP`` whose smallest element ``h0 r^L`` is no larger than ``spacing`` (finer elements would
    crowd around the seed's error, not the edge), one step at least, and one step short of the last."""
    levels = LEVELS_PER_STEP
    while h0 * RATIO ** levels > spacing and levels < (MAX_STEPS - 1) * LEVELS_PER_STEP:
        levels += LEVELS_PER_STEP
    return levels


def _solve_level(make_problem, load, vertices: list[float], p: int, level: int, before, history: list,
                 newton: list, max_dofs: int | None = None, towards: tuple[Any, float] | None = None):
    """Solve ``load`` on a new mesh (grading ``level``, order ``p``), from ``before = (problem, entry)`` when
    given (carried over unless the problem starts afresh); record the changes against it in ``history`` and
    the Newton histories in ``newton``; ``towards = (contact set, period)``: the contact set of the level whose
    edges the mesh was graded towards, the entry's ``set_move`` measured from it
    (:func:`~ngcontact.cell.fe.grading_estimate.set_move`).  Returns the problem, the solution, its
    contact edges and its entry.
    :class:`OverBudget` where the mesh holds more than ``max_dofs`` unknowns (not solved)."""
    try:
        problem = make_problem(vertices, p)
    except (ModelError, SceneError) as exc:
        if max_dofs is None:
            raise
        raise OverBudget(f"grading level {level} at order {p} cannot be meshed ({exc})") from exc
    if max_dofs is not None and problem.ndof > max_dofs:
        raise OverBudget(f"grading level {level} at order {p} would have {problem.ndof} dofs, beyond {max_dofs}")
    fresh = before is None or starts_afresh(problem, load)
    if not fresh:
        carry_over(before[0], problem)
    sol = problem.solve(load, first=fresh)
    pieces = contact_pieces(problem)
    edges = _edges(pieces)
    contact = merged([(a, b) for a, b, on, _ in pieces if on])
    ends = _interface_elements(problem.mesh)
    f, c = sol.results["contact_fraction"], sol.results["mean_closure"]
    entry = {"level": level, "order": p, "ndof": problem.ndof, "edges": [float(e) for e in edges],
             "smallest_element": float(np.min(ends[:, 1] - ends[:, 0])), "edge_offset": edge_offset(edges, ends),
             "contact_set": contact.tolist(), "penalty": problem.multiplier is None,
             "set_move": None if towards is None else set_move(contact, towards[0], towards[1]),
             "contact_fraction": f,
             "mean_closure": c, "newton_iterations": sol.iterations, "fraction_change": None,
             "closure_change": None, "headline": headline(sol.results), "changes": None,
             "edge_cells": edge_cells(problem, edges), "k_n": float(problem.model.k_n),
             "stiffness_edges": stiffness_edges(sol.results),
             "length": float(np.sum(ends[:, 1] - ends[:, 0]))}
    if before is not None:
        entry["fraction_change"] = abs(f - before[1]["contact_fraction"])
        entry["closure_change"] = abs(c - before[1]["mean_closure"]) / max(abs(c), 1e-300)
        then = before[1].get("headline", {})
        entry["changes"] = {name: abs(v - then[name]) for name, v in entry["headline"].items() if name in then}
    history.append(entry)
    newton.extend(dict(h, level=level, order=p) for h in sol.newton)
    log.info("grading level %d, order %d: %d dofs, contact fraction %.10g, change %s", level, p,
             problem.ndof, f, entry["fraction_change"])
    return problem, sol, edges, entry


def _agreed_ratio(changes: list[float]) -> float | None:
    """The contraction of the last grading steps where their last two ratios agree (within
    :data:`~ngcontact.cell.fe.observed_rate.DISAGREE`): the larger; else ``None`` (one ratio, or two that
    disagree, as before the asymptotic range: the theory's rate stands, module docstring)."""
    if len(changes) < 3 or min(changes[-3:-1]) <= 0.0:
        return None
    ratios = [changes[-2] / changes[-3], changes[-1] / changes[-2]]
    return max(ratios) if max(ratios) <= DISAGREE * min(ratios) else None


class OverBudget(Exception):
    """A level's mesh holds more unknowns than the refinement may solve (``max_dofs`` of
    :func:`solve_to_tolerance`), or cannot be built where the refinement is bounded so."""


def _stopped(why: str, problem, sol, entry: dict[str, Any], orders: list[dict[str, Any]],
             graded: dict[str, Any] | None, history: list, newton: list) -> GradedSolve:
    """The last level solved when the next is beyond the size bound: with the orders on its mesh, or alone
    where no order raise has checked it (its estimate then the last grading step's changes)."""
    log.info("graded refinement stopped: %s", why)
    if not orders or orders[-1] is not entry:
        orders, graded = [entry], None
    return GradedSolve(problem=problem, solution=sol, orders=orders, history=history, newton=newton,
                       grading_change=graded["fraction_change"] if graded is not None else None, stopped=why)


def solve_to_tolerance(make_problem: Callable[[list[float], int], Any], load, tolerance: float, h0: float,
                       period: float, order: int, seed: tuple[np.ndarray, float] | None = None,
                       required: bool = True, max_dofs: int | None = None) -> GradedSolve:
    """Solve ``load`` on meshes graded towards the contact edges until the estimate meets ``tolerance``.

    The loop of the module docstring: grading levels until the contact
    fraction settles, then one order more on the same mesh; the estimate is
    the larger of the two changes.  If the order changes the answer by more
    than the tolerance, the grading continues at the raised order (at the
    finest grading, the order is raised again).

    Parameters
    ----------
    make_problem
        ``(vertices, order) -> CellProblem`` on a flat cell with those interface vertices.
    load
        The :class:`~ngcontact.cell.cell_load.CellLoad`.
    tolerance
        Bound of the estimated errors: absolute for the contact fraction,
        relative for the mean closure.
    h0
        The interface mesh size of level 0 (the first grading element).
    order
        The scene's polynomial order (the first levels').
    seed
        Contact edges known beforehand and their accuracy, ``(edges, spacing)``: the spectral twin's
        (:func:`ngcontact.cell.spectral_start.twin_edges`).  The first mesh is then graded towards them
        by :func:`seed_levels` levels instead of being the scene's uniform mesh.
    required
        ``False``: out of reach, the finest level's solution with the last comparisons as its estimate
        (over the tolerance) instead of the error.
    max_dofs
        With ``required = False``: no level after the first whose mesh holds more unknowns is solved; the
        loop stops there as out of reach (``None``: no bound but the steps and raises).

    Raises
    ------
    ConvergenceError
        ``required`` and ``MAX_STEPS`` grading steps and ``MAX_ORDER_RAISES`` order raises did
        not reach the tolerance (the figures in the message).
    """
    history: list[dict[str, Any]] = []
    newton: list[dict[str, Any]] = []
    vertices: list[float] = []
    step = raises = 0
    graded: dict[str, Any] | None = None  # the last level-against-level comparison checked by an order raise
    orders: list[dict[str, Any]] = []     # the entries of successive orders on the last graded mesh

    towards: tuple[Any, float] | None = None   # the edges the current mesh is graded towards, and the period
    steps: list[tuple[int, float]] = []        # (order, contact fraction change) of each grading step

    def run(vertices: list[float], p: int, level: int, before=None):
        return _solve_level(make_problem, load, vertices, p, level, before, history, newton,
                            None if required or before is None else max_dofs, towards)

    def met(entry) -> bool:
        return entry["fraction_change"] is not None and max(entry["fraction_change"],
                                                            entry["closure_change"]) <= tolerance

    if seed is not None:
        levels = seed_levels(h0, seed[1])
        step = levels // LEVELS_PER_STEP
        vertices = graded_vertices(seed[0], h0, levels, period)
    problem, sol, edges, entry = run(vertices, order, step * LEVELS_PER_STEP)
    if seed is not None:
        entry["seed"] = {"edges": [float(e) for e in seed[0]], "spacing": float(seed[1])}
    try:
        while True:
            change = entry["fraction_change"]
            if change is not None and (change <= tolerance or step == MAX_STEPS):
                # the edges are resolved (or graded as far as they go): one order more on the same mesh
                # checks, and reduces, the error of the smooth bulk; repeated while the order changes the
                # answer and raises remain
                graded = entry
                orders = [entry]
                entry["grading_ratio"] = _agreed_ratio([c for p, c in steps if p == entry["order"]])
                while raises < MAX_ORDER_RAISES + 1:
                    order += 1
                    raises += 1
                    problem, sol, edges, entry = run(vertices, order, entry["level"], (problem, entry))
                    orders.append(entry)
                    if graded["fraction_change"] <= tolerance and met(entry):
                        # the changes meet it: a third order shows the rate, whose tail must meet it too, for
                        # every counted quantity; one missing it by its edges' part is graded further
                        tail = order_estimate(orders, graded["fraction_change"])[0]
                        if len(orders) >= 3 and max(tail.values()) <= tolerance:
                            return GradedSolve(problem=problem, solution=sol, orders=orders, history=history,
                                               newton=newton, grading_change=graded["fraction_change"])
                        if len(orders) >= 3 and step < MAX_STEPS and edges_miss(orders, graded["fraction_change"],
                                                                                 tail, tolerance):
                            order, raises = graded["order"], 0     # the new mesh checked by its own orders
                            break
                    elif step < MAX_STEPS:
                        break
                else:
                    if step < MAX_STEPS:     # the orders spent: an edge's singularity inside its element converges
                        order, raises = graded["order"], 0    # algebraically in the order; grade once more
            if step == MAX_STEPS or raises > MAX_ORDER_RAISES:
                break
            step += 1
            if len(edges) == 0:  # full (or no) contact: no edge to grade towards; halve the interface mesh instead
                n = int(round(period / h0)) * 2 ** step
                vertices = [period * (i + 0.5) / n for i in range(n)]
                towards = None
            else:
                vertices = graded_vertices(edges, h0, step * LEVELS_PER_STEP, period)
                towards = (entry["contact_set"], period)
            problem, sol, edges, entry = run(vertices, order, step * LEVELS_PER_STEP, (problem, entry))
            steps.append((order, entry["fraction_change"]))
    except OverBudget as over:         # the levels solved stay; the answer is the last one solved
        return _stopped(str(over), problem, sol, entry, orders, graded, history, newton)
    if not required and graded is not None:
        return GradedSolve(problem=problem, solution=sol, orders=orders, history=history, newton=newton,
                           grading_change=graded["fraction_change"])
    worst = orders[0]["fraction_change"] if len(orders) > 1 else entry["fraction_change"]
    tail = order_estimate(orders, worst)[0] if len(orders) > 1 else order_estimate([entry])[0]
    raise ConvergenceError(out_of_reach(tolerance, tail, entry, step, raises, worst), {"levels": history})


def _named(k: int, n: int) -> str:
    """The prefix of load ``k``'s remark in a sweep of ``n`` loads (none for a load alone)."""
    return f"load {k} " if n > 1 else ""


def graded_refinement(solves: list[GradedSolve]) -> Refinement:
    """A sweep's loads, each solved on its graded meshes, as the sweep's refinement: the highest order's
    answer per load with its estimate (:func:`solve_to_tolerance`), the meshes and Newton steps per load."""
    n = len(solves)
    remarks = [f"{_named(k, n)}{g.remark}" for k, g in enumerate(solves) if g.remark]
    remarks += [f"{_named(k, n)}stopped: {g.stopped}" for k, g in enumerate(solves) if g.stopped]
    return Refinement(solutions=[g.solution for g in solves], estimates=[g.estimate for g in solves],
                      per_load=[{"mesh_history": g.history,
                                 # the Newton steps of every level the load was solved on
                                 "newton_iterations": sum(h["newton_iterations"] for h in g.history)}
                                for g in solves],
                      histories=[g.newton for g in solves],
                      how="; ".join(["each load on meshes graded towards its contact edges, then higher orders "
                                     "on the finest; the highest reported, its error " + ORDER_RATE.describe()]
                                    + remarks))
