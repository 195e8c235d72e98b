"""The accuracy verdict of an ensemble: each member's discretization error beside the band of the mean.

An ensemble's member is the cell of one realization solved on the scene's own discretization
(:mod:`ngcontact.drivers.run_ensemble`), its error estimated there and not refined
(:meth:`ngcontact.cell.cell_solver.CellSolver.scene_estimate`: the spectral cell from three coarser grids, the
FE cell by one order more on its mesh), or refined to a ``discretization.tolerance`` the scene states.  Each
member's verdict is the cell's (:func:`ngcontact.drivers.run_cell.accuracy_verdict`, its warnings left to
this one).  The ensemble's mean of a quantity ``q`` over ``M`` members has two errors:

* the statistical one, the half-width of its 95 % band (:mod:`ngcontact.verification.confidence_band`):
  the surface class's spread, which more members shrink like ``M^(-1/2)``;
* the discretization's: ``|mean(q_m) - mean(q_m*)| <= mean |q_m - q_m*| <= max_m E_m`` with ``E_m`` member
  ``m``'s estimated (absolute) error, which more members do not shrink.

Per load and quantity the verdict lists the mean, the largest member estimate (absolute, relative to the
mean, and in the measure the cell's tolerance holds, :func:`ngcontact.cell.cell_solution.measure`, as the
member's own verdict measured it), which member holds it, and the band's half-width beside it.  The ensemble
meets its tolerance (the scene's, else :data:`ngcontact.cell.admissibility.DEFAULT_TOLERANCE`) where every
member's verdict does: each member's numbers within it, so the mean's and the band's discretization error
too.  A miss is one warning line naming the largest estimate and the half-width beside it.
"""
from __future__ import annotations

import logging
from typing import Any

log = logging.getLogger(__name__)

#: the ensemble's quantity -> the cell's headline quantity whose estimate it carries
#: (:func:`ngcontact.cell.cell_solution.headline`; the transmitted pressure is the load, not estimated)
HEADLINE = {"contact_fraction": "contact_fraction", "k_n0": "coefficient_k_n",
            "effective_stiffness": "normal_stiffness", "mean_closure": "mean_closure"}


def member_record(accuracy: dict[str, Any]) -> dict[str, Any]:
    """What a member hands on of its verdict (``results.accuracy`` of its cell run): met, estimated, how, the
    failed checks and the estimated quantities."""
    keys = ("load", "name", "error", "controlled", "scale", "controlled_error", "met", "counted")
    return {"met": bool(accuracy["met"]), "estimated": bool(accuracy["estimated"]), "how": accuracy["how"],
            "tolerance": accuracy["tolerance"], "tolerance_from": accuracy["tolerance_from"],
            "failed": [c for c in accuracy["checks"] if not c["ok"]],
            "quantities": [{k: q[k] for k in keys} for q in accuracy["quantities"]]}


def member_estimates(accuracy: dict[str, Any], n: int) -> list[dict[str, float]]:
    """Per load of a member's ``accuracy`` (:func:`member_record`) the estimated absolute error of each
    ensemble quantity it estimates (:data:`HEADLINE`)."""
    out: list[dict[str, float]] = [{} for _ in range(n)]
    for name, head in HEADLINE.items():
        for q in (q for q in accuracy["quantities"] if q["name"] == head):
            out[q["load"]][name] = q["error"]
    return out


def quantities(members: list[dict[str, Any]], loads: list[dict[str, dict[str, float]]],
               tolerance: float) -> list[dict[str, Any]]:
    """Per load and estimated quantity of the ensemble (:data:`HEADLINE`) the mean, the largest member
    estimate and the band's half-width beside it (module docstring); a quantity some member did not estimate
    is not listed."""
    out = []
    for k, band in enumerate(loads):
        for name, head in HEADLINE.items():
            found = [(q, m) for m, mem in enumerate(members) for q in mem["accuracy"]["quantities"]
                     if q["load"] == k and q["name"] == head]
            if len(found) != len(members):
                continue
            q, m = max(found, key=lambda qm: qm[0]["controlled_error"])
            worst_abs = max(f["error"] for f, _ in found)
            mean = band[name]["mean"]
            out.append({"load": k, "name": name, "value": mean, "error": worst_abs,
                        "relative_error": worst_abs / abs(mean) if mean != 0 else None,
                        "controlled": q["controlled"], "controlled_error": q["controlled_error"],
                        "member": m, "met": q["controlled_error"] <= tolerance,
                        "counted": all(f["counted"] for f, _ in found),
                        "statistical_error": band[name]["half_width"]})
    return out


def verdict(members: list[dict[str, Any]], loads: list[dict[str, dict[str, float]]]) -> dict[str, Any]:
    """``results.accuracy`` of an ensemble (module docstring) from its ``members`` (each with the
    ``accuracy`` of :func:`member_record`) and its ``loads`` (per load the band of each quantity); one
    warning line where it is not met."""
    first = members[0]["accuracy"]
    tolerance = first["tolerance"]
    listed = quantities(members, loads, tolerance)
    unmet = [m for m, mem in enumerate(members) if not mem["accuracy"]["met"]]
    how = first["how"]
    out = {"tolerance": tolerance, "tolerance_from": first["tolerance_from"], "met": not unmet,
           "estimated": all(mem["accuracy"]["estimated"] for mem in members), "quantities": listed,
           "how": ("each member on its own discretization, the mean's discretization error at most the largest "
                   f"member's estimate, beside the band's half-width (the surface class's spread); a member: {how}"),
           "unmet_members": unmet}
    if unmet:
        warn(out, members, unmet)
    return out


def warn(out: dict[str, Any], members: list[dict[str, Any]], unmet: list[int]) -> None:
    """The one warning line of an ensemble whose verdict is not met (:func:`verdict`): the largest counted
    member estimate beyond the tolerance, with the band's half-width of its quantity beside it where the
    ensemble reports one, else the first unmet member's failed check or why it is not estimated."""
    fix = ("; state discretization.tolerance to refine every member (each one a refinement), or a finer "
           "discretization")
    missed = [(q, m) for m in unmet for q in members[m]["accuracy"]["quantities"] if q["counted"] and not q["met"]]
    if missed:
        q, m = max(missed, key=lambda qm: qm[0]["controlled_error"])
        band = next((e["statistical_error"] for e in out["quantities"]
                     if e["load"] == q["load"] and HEADLINE[e["name"]] == q["name"]), None)
        beside = f"the mean's 95 % half-width {band:.3g} beside it; " if band is not None else ""
        log.warning("accuracy not met: the estimated error %.3g (%s) of member %d's %s at load %d exceeds the %s "
                    "tolerance %g (%s%d of %d members miss it)%s", q["controlled_error"], q["controlled"], m,
                    q["name"], q["load"], out["tolerance_from"], out["tolerance"], beside, len(unmet), len(members),
                    fix)
        return
    acc = members[unmet[0]]["accuracy"]
    why = f"{acc['failed'][0]['name']} = {acc['failed'][0]['value']:.3g}" if acc["failed"] else acc["how"]
    log.warning("accuracy not met: member %d of %d (%d miss the %s tolerance %g): %s%s", unmet[0], len(members),
                len(unmet), out["tolerance_from"], out["tolerance"], why, fix)
