"""The penalty's share of a cell's answer: the same quantities at the exact limit ``k_n -> infinity``.

With ``contact.enforcement = "penalty"`` the interface is the paper's Winkler layer ``p = k_n [J.n - g]_+``
(eq. 65): a model of the interface's own compliance, not a discretization.  Its answer differs from that
of rigid non-penetration by a share that no refinement of the mesh or grid removes, so it is reported
beside the discretization's estimate (:mod:`ngcontact.cell.admissibility`) and not counted against the
scene's tolerance.

The limit is found by the cell protocol, whatever the method, on the cell's
:meth:`~ngcontact.cell.cell_solver.CellSolver.share_solver`: the share is a property of the model, so it
may be taken from any discretization of the same model that resolves it.  An FE cell of the small-slope
model measures it on its spectral twin (same layers, same ``k_n``) on a fine grid: the share is a shift of
the contact edges by a fraction of an element, which a uniform mesh's own edge error (its edges cut
elements anywhere) would swamp.  On that discretization
(:meth:`~ngcontact.cell.cell_solver.CellSolver.varied`):

* where the method has exact enforcement on the same discretization, the load sweep is solved again with
  it: ``q_inf`` is that sweep's value (the same discretization error in both, so the difference is the
  penalty's alone);
* otherwise the sweep is solved again with ``2 k_n``.  The penalty adds the compliance ``1/k_n`` in series
  with the bodies' (paper eq. 65: the jump is ``J.n = g + p/k_n`` on the contact set), so each quantity is
  smooth in ``1/k_n`` with a first-order leading term, and the linear extrapolation through ``1/k_n`` and
  ``1/(2 k_n)`` gives ``q_inf = 2 q(2 k_n) - q(k_n)`` (it misses the share's own higher-order part, so
  exact enforcement is preferred where the method has it).

The share of quantity ``q`` at a load is ``(q(k_n) - q_inf) / |q_inf|`` (relative; absolute where
``q_inf = 0``).

**The contact fraction's share where the penalty's length is not resolved.** The Winkler layer moves a contact edge
by more than ``1/k_n``: its compression ``p / k_n`` acts on the rigid contact as a change of the gap, and with
``p`` growing like the square root of the distance ``s`` from an edge that change has a slope like ``s^(-1/2)``,
whose weight against the edge's own ``s^(-1/2)`` diverges like ``ln s``; it is cut off at the length ``lambda =
E*/k_n`` (``1/E* = sum (1 - nu^2)/E`` over the two bodies) below which the layer, not the bodies, carries the
pressure. So the edge moves by ``lambda (A ln(1/lambda) + B)``, ``A`` and ``B`` set by the geometry (on
Westergaard's sinusoid the share per edge, on grids that resolve ``lambda``, grows linearly in
``ln(1/lambda)``). Most of that move lies within a few ``lambda`` of the edge, which a grid whose step is not
well below ``lambda`` does not see: its edges are located on points farther away
(:mod:`ngcontact.cell.spectral.contact_edges`, the penalty zone), and its penalized sweep minus its exact one
misses most of the share where ``lambda`` is a fraction of its step. A share model that says so
(:meth:`~ngcontact.cell.cell_solver.CellSolver.share_resolution`: the 2D spectral cell whose ``lambda`` spans fewer
than 32 of its steps) is solved again on a grid of at least 32,768 points, exactly and at the two softer penalties
``k_1`` and ``k_1 / 2`` whose lengths span 32 and 64 of its steps (``k_1 = k_n`` where ``lambda`` itself does), and
the two shares ``s_1``, ``s_2`` fix ``A`` and ``B``:

    s(k_n) = (k_1 / k_n) [s_1 + (s_1 - s_2 / 2) ln(k_n / k_1) / ln 2].

``tests/cell/test_penalty_edges.py`` holds it against the share on a grid that resolves ``lambda``.
The mean closure, an integral of the jump that the edges' zone barely moves, keeps the difference of the two sweeps.
"""
from __future__ import annotations

import logging
import math
from typing import Any

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.cell_solver import CellSolver
from ngcontact.errors import ConvergenceError

log = logging.getLogger(__name__)
#: the run's progress lines (printed as its stage lines)
progress = logging.getLogger("ngcontact.progress")

#: the quantities whose share is reported (the effective stiffness is the penalty itself at full contact)
SHARED = ("contact_fraction", "mean_closure")
#: the penalty of the second sweep over the scene's, where the method has no exact enforcement
STIFFER = 2.0


def limit_values(cell: CellSolver, loads: list[CellLoad]) -> tuple[list[dict[str, float]], str] | None:
    """Per load, the headline quantities (:func:`~ngcontact.cell.cell_solution.headline`) at the exact limit,
    or at ``STIFFER k_n``, and how they were found (module docstring); ``None`` where the cell is not
    penalized or no second sweep is possible."""
    k_n = cell.penalty()
    if k_n is None:
        return None
    exact = cell.varied(enforcement="exact")
    if exact is not None:
        return [headline(s.results) for s in exact.sweep(loads)], EXACT
    stiffer = cell.varied(k_n=STIFFER * k_n)
    if stiffer is None:
        return None
    how = f"k_n and {STIFFER:g} k_n, extrapolated linearly in 1/k_n"
    return [headline(s.results) for s in stiffer.sweep(loads)], how


#: how the limit was found where the method has exact enforcement
EXACT = "exact enforcement on the same discretization"


def shares(per_load: list[dict[str, Any]], base: list[dict[str, float]], limit: list[dict[str, float]],
           extrapolate: bool) -> list[dict[str, Any]]:
    """The report's entries: per load and quantity the reported value, its exact limit and the penalty's share.

    ``base`` and ``limit``: the penalized and the limit sweep on one discretization (the share is their
    difference, free of the discretization's error); ``extrapolate``: ``limit`` holds the values at
    ``STIFFER k_n``, extrapolated here to ``1/k_n = 0`` (``q(k_n) - q_inf = 2 (q(k_n) - q(2 k_n))``).
    """
    out = []
    for k, (results, at, second) in enumerate(zip(per_load, base, limit)):
        for name in (n for n in SHARED if n in second):
            value = headline(results)[name]
            share = (at[name] - second[name]) * (STIFFER / (STIFFER - 1) if extrapolate else 1.0)
            inf = value - share
            out.append({"load": k, "name": name, "value": value, "exact_limit": inf, "share": share,
                        "relative_share": share / abs(inf) if inf != 0 else None, "counted": False})
    return out


def resolved_fraction(entries: list[dict[str, Any]], loads: list[CellLoad], twin: CellSolver, k_1: float,
                      k_n: float) -> str:
    """Replace in place the contact fraction's share in ``entries`` by the one extrapolated from the penalties
    ``k_1`` and ``k_1 / 2`` on ``twin``, whose lengths it resolves, to ``k_n`` (module docstring); returns how."""
    solvers = (twin.varied(enforcement="exact"), twin.varied(k_n=k_1), twin.varied(k_n=k_1 / 2))
    if any(solver is None for solver in solvers):
        return ""
    exact, first, second = ([headline(s.results)["contact_fraction"] for s in solver.sweep(loads)]
                            for solver in solvers if solver is not None)
    for entry in (e for e in entries if e["name"] == "contact_fraction"):
        s_1, s_2 = first[entry["load"]] - exact[entry["load"]], second[entry["load"]] - exact[entry["load"]]
        share = (k_1 / k_n) * (s_1 + (s_1 - s_2 / 2) * math.log(k_n / k_1) / math.log(2))
        inf = entry["value"] - share
        entry.update(share=share, exact_limit=inf, relative_share=share / abs(inf) if inf != 0 else None)
    return (f"; the contact fraction's share extrapolated as lambda (A ln(1/lambda) + B), lambda = E*/k_n, from "
            f"k_n = {k_1:.4g} and {k_1 / 2:.4g} on {twin.unknowns()} grid points (lambda at least 32 steps)")


def penalty_share(cell: CellSolver, loads: list[CellLoad], per_load: list[dict[str, Any]], refined: bool = False
                  ) -> dict[str, Any] | None:
    """``results.accuracy.model`` of a penalized cell: the penalty's share of each load's quantities (module
    docstring), reported and printed, not counted against the tolerance; ``None`` for exact enforcement.

    ``refined``: the reported loads come from another discretization than the cell's variants (a refinement),
    so the penalized sweep is solved again on theirs.  The sweeps run on the cell's
    :meth:`~ngcontact.cell.cell_solver.CellSolver.share_solver`.
    """
    if cell.penalty() is None:
        return None
    model = cell.share_solver()
    try:
        found = limit_values(model, loads)
    except ConvergenceError as exc:     # the limit is a second model: its failure is not the answer's
        log.warning("the penalty's share is not known: its second sweep failed (%s)", exc)
        return {"name": "penalty", "k_n": cell.penalty(), "how": f"not measured: the second sweep failed ({exc})",
                "counted": False, "quantities": []}
    if found is None:
        return None
    limit, how = found
    if model is not cell:
        how += f" ({model.size()['method']} twin of {model.unknowns()} unknowns)"
    base = [headline(r) for r in per_load]
    if refined or model is not cell:
        base = [headline(s.results) for s in model.sweep(loads)]
    entries = shares(per_load, base, limit, extrapolate=not how.startswith(EXACT))
    resolution = model.share_resolution() if how.startswith(EXACT) else None
    if resolution is not None:
        how += resolved_fraction(entries, loads, *resolution, k_n=float(cell.penalty() or 0.0))
    fractions = [e for e in entries if e["name"] == "contact_fraction" and e["relative_share"] is not None]
    progress.info("penalty k_n = %g (the model, not the discretization): its share of the contact fraction %s %%",
                  cell.penalty(), " / ".join(f"{100 * e['relative_share']:+.2f}" for e in fractions))
    return {"name": "penalty", "k_n": cell.penalty(), "how": how, "counted": False,
            "meaning": "the same quantity at the exact limit (non-penetration, k_n without bound): the penalty's share "
                       "of the answer "
                       "(paper eq. 65, the model, not its discretization)", "quantities": entries}
