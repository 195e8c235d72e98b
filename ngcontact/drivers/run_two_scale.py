"""Driver part of ``[two_scale]`` (macro kind): the coupling loop of :mod:`ngcontact.coupling.two_scale`.

No file I/O.  ``results["two_scale"]``: ``converged``, ``iterations``
(coefficient updates), ``macro_solves``, ``cell_solves`` (cell problems
solved for the table), ``history`` (per iteration the largest macro
pressure [Pa], ``max_change`` = max |sigma_n(k) - sigma_n(k-1)| [Pa] at the
interface sampling points, cumulative cell solves, Newton iterations),
``tolerance`` [Pa], ``table`` (pressures [Pa], contact fraction, ``k_n0``
[Pa/m], ``g_n0`` [Pa], ``tolerance``, ``error_estimate``: the largest
relative midpoint discrepancy accepted), ``cell`` (scene, ndof) and the
coefficient profile along the interface (``contact_fraction``, ``k_n0``).
"""
from __future__ import annotations

import logging

import numpy as np

from ngcontact.coupling import two_scale as T
from ngcontact.macro.macro_measures import interface_profile
from ngcontact.scene.sections import resolve

log = logging.getLogger(__name__)


def couple(scene, problem, solve):
    """Run the loop of ``scene.two_scale`` from ``problem``; returns ``(solution, results)``."""
    from ngcontact.drivers.run_strength import cell_problem_of
    spec = scene.two_scale
    path = resolve(scene, spec.cell)
    _, P = cell_problem_of(path, key="two_scale.cell")
    table = T.CellTable(lambda p: T.cell_response(P, p, spec.cell_length_unit), tol=spec.table_tol)
    out = T.couple(problem, table, tol=spec.tol, max_iter=spec.max_iter, table_min=spec.table_min,
                   points_per_element=scene.output.points_per_element, solve=solve)
    p = interface_profile(out.solution, scene.output.points_per_element)["pressure"]
    coef = table(np.asarray(p))
    res = {"converged": out.converged, "iterations": len(out.history) - 1, "macro_solves": out.macro_solves,
           "cell_solves": table.solves, "tolerance": spec.tol, "history": out.history,
           "table": table.as_dict(), "cell": {"scene": path, "ndof": int(P.ndof)},
           "interface_coefficients": {"contact_fraction": coef["contact_fraction"], "k_n0": coef["k_n0"]}}
    return out.solution, res
