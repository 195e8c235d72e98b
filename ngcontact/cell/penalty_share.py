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
"""
from __future__ import annotations

import logging
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
    fractions = [e for e in entries if e["name"] == "contact_fraction" and e["relative_share"] is not None]
    progress.info("penalty k_n = %g (the model, not the discretization): its share of the contact fraction %s %%",
                  cell.penalty(), " / ".join(f"{100 * e['relative_share']:+.2f}" for e in fractions))
    return {"name": "penalty", "k_n": cell.penalty(), "how": how, "counted": False,
            "meaning": "the same quantity at the exact limit (non-penetration, k_n without bound): the penalty's share "
                       "of the answer "
                       "(paper eq. 65, the model, not its discretization)", "quantities": entries}
