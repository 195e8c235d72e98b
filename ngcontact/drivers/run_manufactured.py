"""Driver of the ``manufactured`` kind: convergence rates of the elasticity solver.

For every order ``p`` and level ``k = 1..levels`` it solves the manufactured
problem of :mod:`ngcontact.verification.manufactured` on the mesh refined ``k`` times and
measures the L2 and H1-seminorm errors; :mod:`ngcontact.verification.rates` fits the
observed rates (expected ``p + 1`` and ``p``).  Each level also estimates its two errors without ``u*``, from
one order more on the same mesh (:func:`ngcontact.verification.manufactured.level_runner`), and the report
holds each estimate against its true error: ``l2_effectivity``, ``h1_effectivity`` per row (none where the
error is at round-off, :data:`ROUNDOFF_ERROR`, and the ratio meaningless) and their range,
``results.estimate``.  Each level is one linear
solve (assembled ``BilinearForm``/``LinearForm``, sparse direct factorization);
its relative residual ``|f - A u| / |f|`` on the free dofs is the solver
history.  A residual above :data:`LINEAR_RTOL` means the factorization failed
(e.g. a singular matrix) and raises :class:`~ngcontact.errors.ConvergenceError`.
"""
from __future__ import annotations

import logging

import ngsolve as ng
import numpy as np

from ngcontact.parallel import executor
from ngcontact.verification import manufactured
from ngcontact.verification import rates as studies
from ngcontact.drivers.scene_laws import body_laws
from ngcontact.errors import ConvergenceError
from ngcontact.output import plots as figures
from ngcontact.output.report import Outcome, VtkField

log = logging.getLogger(__name__)

LINEAR_RTOL = 1e-8
TABLE_KEYS = studies.ROW_KEYS + ("l2_estimate", "h1_estimate", "l2_effectivity", "h1_effectivity", "solve_seconds",
                                  "relative_residual")
#: how a level's errors are estimated (``results.estimate.how``)
ESTIMATE_HOW = ("|u_p - u_(p+1)| / (1 - 0.75), u_(p+1) the same problem at one order more on the same mesh (the "
                "saturation assumption), in the L2 norm and the H1 seminorm")


#: Errors below this fraction of the study's largest error (of the same norm) are round-off, not discretization
#: error: the smooth solution at order 8 sits at 4e-12 of it, order 4's finest level at 1.6e-8.
ROUNDOFF_ERROR = 1e-10
#: Errors below this fraction of the norm of u* itself are round-off whatever the study's largest error (an order
#: alone at round-off has no larger error to compare with): in plane strain at maxh = 0.25 order 10 sits at 3e-14
#: (L2) and 2e-13 (H1) of the norms on every level, order 6 at 1e-13 (L2) from the second level on.
SOLUTION_ROUNDOFF = 1e-12


def laws_of(scene) -> dict:
    """Region name -> elastic law for the scene's setting."""
    m = scene.manufactured
    if m.setting == "periodic_cell":
        return body_laws(scene, {"rough": m.body, "counter": m.second_body})
    return body_laws(scene, {"body": m.body})


def level_member(job: tuple) -> tuple[dict, np.ndarray | None]:
    """Member of the batch of levels: order ``p`` on the mesh refined ``k`` times, solved on its own.

    Returns the level's row and, for the level the VTK output shows (``keep``), the solution vector.
    """
    scene, p, k, keep = job
    m = scene.manufactured
    kept: dict = {}
    level = manufactured.level_runner(m.setting, laws_of(scene), m.maxh, inverse=scene.solver.inverse, keep=kept)
    (row,) = studies.h_refinement(level, setting=m.setting, orders=(p,), maxh=m.maxh, refinements=(k,))
    return row, (kept["solution"].gfu.vec.FV().NumPy().copy() if keep else None)


def run(scene, clock) -> Outcome:
    """Solve every (order, level), fit rates and collect tables, plots and VTK.

    The levels are independent solves: one batch (:mod:`ngcontact.parallel.executor`), so they run on
    the run's workers; the finest level of the highest order comes back as a vector for the VTK file.
    """
    m = scene.manufactured
    jobs = [(scene, p, k, (p, k) == (m.orders[-1], m.levels)) for p in m.orders for k in range(1, m.levels + 1)]
    with clock.stage("levels"):
        out = executor.current().map(level_member, jobs, [f"order {p}, level {k}" for _, p, k, _ in jobs],
                                     label="levels")
    rows = [row for row, _ in out]
    for (_, p, k, _), row in zip(jobs, rows):
        residual = row["relative_residual"]
        if not residual <= LINEAR_RTOL:
            raise ConvergenceError(
                f"linear solve for order {p}, level {k}: relative residual {residual:.3e} "
                f"> {LINEAR_RTOL:g}", _solver_info(rows, scene, converged=False))
    # Levels whose error is at the round-off of the solve carry no rate: an order that reproduces the
    # smooth solution to round-off on every level is exact, not a failed rate (rates.judge).
    norms = dict(zip(("l2", "h1"), manufactured.exact_norms(
        manufactured.problem(m.setting, laws_of(scene), m.maxh, order=m.orders[-1]))))
    floor = {n: max(ROUNDOFF_ERROR * max(r[n] for r in rows), SOLUTION_ROUNDOFF * norms[n]) for n in ("l2", "h1")}
    for row in rows:       # each estimate against its true error, where that is above round-off
        for n in ("l2", "h1"):
            row[f"{n}_effectivity"] = row[f"{n}_estimate"] / row[n] if row[n] > floor[n] else None
    judged = studies.judge(rows, floor, m.rate_tolerance)
    rates, expected, verified = judged["rates"], judged["expected_rates"], judged["verified"]
    if not verified or judged["orders_without_rate"]:
        log.warning("%s", judged["verdict"])
    results = {
        "setting": m.setting,
        "solution": "smooth manufactured displacement (see ngcontact.verification.exact_fields.smooth_field)",
        "errors": "l2 = |u_h - u*|_L2, h1 = |grad(u_h - u*)|_L2 (axisymmetric: weighted by 2 pi r, "
                  "with the hoop term)",
        "rows": rows,
        "rates": {str(p): r for p, r in rates.items()},
        "expected_rates": {str(p): r for p, r in expected.items()},
        "max_rate_deviation": judged["max_rate_deviation"],
        "orders_at_roundoff": judged["orders_at_roundoff"],
        "orders_without_rate": {str(p): n for p, n in judged["orders_without_rate"].items()},
        "roundoff_error_floor": floor,
        "estimate": {"how": ESTIMATE_HOW, "effectivity": {n: effectivity_range(rows, n) for n in ("l2", "h1")}},
        "solution_norms": norms,
        "rate_tolerance": m.rate_tolerance,
        "verified": verified,
        "verdict": judged["verdict"],
    }
    prob, gfu = finest_solution(scene, out[-1][1])
    error = gfu - prob.exact
    vtk = {"finest": VtkField(mesh=prob.mesh, subdivision=min(max(m.orders) - 1, 2),
                              fields={"displacement": gfu, "exact": prob.exact, "error": error,
                                      "error_norm": ng.Norm(error)})}
    return Outcome(results=results, ndof=max(r["ndof"] for r in rows),
                   solver=_solver_info(rows, scene, converged=True),
                   tables={"convergence": studies.table(rows, TABLE_KEYS),
                           "rates": _rates_table(rates, expected)},
                   vtk=vtk, plots={"convergence": lambda path: figures.convergence(path, rows, rates)})


def effectivity_range(rows: list[dict], norm: str) -> dict:
    """The smallest and largest effectivity of ``norm``'s estimates over the rows above round-off, and how many
    (``None`` where every row is at round-off)."""
    found = [r[f"{norm}_effectivity"] for r in rows if r[f"{norm}_effectivity"] is not None]
    return {"min": min(found) if found else None, "max": max(found) if found else None, "rows": len(found)}


def finest_solution(scene, vec: np.ndarray | None) -> tuple[manufactured.Problem, ng.GridFunction]:
    """The last level's problem rebuilt here (meshing is deterministic) with the member's solution vector."""
    m = scene.manufactured
    prob = manufactured.problem(m.setting, laws_of(scene), m.maxh, refinements=m.levels, order=m.orders[-1])
    gfu = ng.GridFunction(manufactured.space(prob, m.orders[-1]))
    values = gfu.vec.FV().NumPy()
    if vec is None or len(vec) != len(values):
        raise RuntimeError(f"the finest level came back with {0 if vec is None else len(vec)} dofs, its rebuilt "
                           f"space has {len(values)}: the mesh was not rebuilt identically")
    values[:] = vec
    return prob, gfu


def _solver_info(rows, scene, converged: bool) -> dict:
    return {"type": "linear", "method": f"direct ({scene.solver.inverse})",
            "linear_solve_only": True, "iterations": len(rows), "converged": converged,
            "residuals": [r["relative_residual"] for r in rows],
            "residual_measure": "|f - A u| / |f| on the free dofs, one entry per linear solve"}


def _rates_table(rates: dict, expected: dict):
    header = ["order", "l2_rate", "l2_expected", "h1_rate", "h1_expected"]
    return header, [[p, r["l2"], expected[p]["l2"], r["h1"], expected[p]["h1"]] for p, r in rates.items()]
