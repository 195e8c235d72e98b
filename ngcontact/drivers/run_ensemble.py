"""Driver of a cell scene with ``[ensemble]``: the law of a random surface class, not of one sample.

Member ``m`` (``m = 0 .. M-1``) is the cell of the scene with the random
surface of ``geometry.spectrum`` (or of a measured file's spectrum, profile
``measured_spectrum``) drawn with the seed ``seed + m``
(:mod:`ngcontact.geometry.random_surface`); it is solved over the scene's
loads by the ``cell`` driver (:mod:`ngcontact.drivers.run_cell`, spectral or
FE as the scene says; on its own grid or mesh unless the scene states a
``discretization.tolerance``: the members are not refined to the default one,
but each is estimated there, :meth:`~ngcontact.cell.cell_solver.CellSolver.scene_estimate`:
the spectral cell from three coarser grids, at most a third of its solve more in
3D and seven eighths and its twin half a step over in 2D, the FE cell by one order more on its mesh, about
``((p + 1) / p)^d`` times its unknowns; ``discretization.estimate = "off"``
skips it), in a worker of the run's batch (:mod:`ngcontact.parallel.executor`), and returns per load the contact
fraction, ``k_n0`` on the real contact set (paper eq. 34), the normal
effective stiffness, the mean closure and the transmitted pressure, each
load with ``error_estimate`` (the absolute error of the quantities estimated;
``results.members``), and its accuracy verdict.  ``results.accuracy`` is the ensemble's
(:mod:`ngcontact.drivers.ensemble_accuracy`): per load and quantity the
largest member estimate beside the band's half-width, met where every
member's verdict is, one warning line where not; ``accuracy.cost`` the
seconds of the members' solves and of their estimates' extra solves (where
the method counts them).

Results: per load the mean of each quantity over the members and its 95 %
confidence band (:mod:`ngcontact.verification.confidence_band`), every member's
values, and the band's shrinkage with ``M`` (the relative standard error of
the mean of ``M, M/2, M/4, ...`` members on disjoint sub-ensembles and its
fitted rate, ``-1/2`` for independent members).  Tables ``ensemble.csv``,
``ensemble_members.csv``, ``ensemble_shrinkage.csv``; plots
``ensemble_law.png`` (the law with its band) and ``ensemble_band.png``.  Surfaces drawn with a scan's spectrum
(``measured_spectrum``) add the record ``topography`` of :func:`ngcontact.drivers.cell_gap.topography`
and its ``psd.png``.
"""
from __future__ import annotations

import time
from dataclasses import replace
from typing import Any

import numpy as np

from ngcontact.drivers import cell_gap, ensemble_accuracy, run_cell
from ngcontact.errors import ModelError
from ngcontact.output import cell_plots
from ngcontact.output import plots as figures
from ngcontact.output.report import Clock, Outcome
from ngcontact.parallel import executor
from ngcontact.verification import confidence_band

#: quantity -> its description in the report and the plots
QUANTITIES = {
    "contact_fraction": "contact fraction",
    "k_n0": "k_n0 on the real contact set (eq. 34)",
    "effective_stiffness": "effective normal stiffness",
    "mean_closure": "mean closure",
    "transmitted_pressure": "transmitted pressure",
}


def member_scene(scene, m: int):
    """The cell scene of member ``m``: the random surface's seed advanced by ``m``, no ensemble; its FE cell's
    symmetry decided anew for its own gap (as the member's run starts)."""
    member = replace(scene, ensemble=None, geometry=scene.geometry.reseeded(m), symmetry_choice=None)
    object.__setattr__(member, "base_dir", scene.base_dir)   # not a field of replace: a measured file's folder
    return member


def measured(entry: dict) -> dict[str, float]:
    """The ensemble's quantities of one load's results (:mod:`ngcontact.drivers.run_cell`)."""
    es = entry["effective_stiffness"]
    i = es["components"].index("n0")
    if es["matrix"] is None:
        raise ModelError("effective_stiffness = inf: a member in full contact under exact non-penetration has no "
                         "finite interface stiffness to average; use contact.enforcement = 'penalty'")
    return {"contact_fraction": float(entry["contact_fraction"]), "k_n0": float(entry["coefficients"]["k_n"]),
            "effective_stiffness": float(es["matrix"][i][i]), "mean_closure": float(entry["mean_closure"]),
            "transmitted_pressure": float(entry["transmitted_pressure"])}


def realization(job: tuple) -> dict:
    """Member of the batch: ``(scene, m)`` -> the seed, the number of unknowns, every load's quantities, its
    accuracy verdict (:func:`~ngcontact.drivers.ensemble_accuracy.member_record`) and its seconds (the
    estimate's extra solves where the method counts them)."""
    scene, m = job
    sc = member_scene(scene, m)
    t0 = time.perf_counter()
    outcome = run_cell.run(sc, Clock(), member=True)
    method = outcome.results.get("method") or {}
    accuracy = ensemble_accuracy.member_record(outcome.results["accuracy"])
    loads: list[dict[str, Any]] = [dict(measured(e)) for e in outcome.results["loads"]]
    for entry, estimate in zip(loads, ensemble_accuracy.member_estimates(accuracy, len(loads))):
        entry["error_estimate"] = estimate
    return {"seed": sc.geometry.random_seed, "ndof": int(outcome.ndof), "loads": loads, "accuracy": accuracy,
            "seconds": time.perf_counter() - t0, "estimate_seconds": method.get("estimate_seconds")}


def cost(members: list[dict]) -> dict:
    """``accuracy.cost``: the members' seconds summed, and of those their estimates' extra solves where known."""
    extra = [mem["estimate_seconds"] for mem in members if mem["estimate_seconds"] is not None]
    return {"member_seconds": float(sum(mem["seconds"] for mem in members)),
            "estimate_seconds": float(sum(extra)) if extra else None}


def run(scene, clock) -> Outcome:
    """Solve the ``M`` members of a cell scene with ``[ensemble]``; no file I/O."""
    M = scene.ensemble.members
    with clock.stage(f"{M} members"):
        members = executor.current().map(realization, [(scene, m) for m in range(M)],
                                         [f"member {m} (seed {scene.geometry.random_seed + m})" for m in range(M)],
                                         label="ensemble")
    n = len(members[0]["loads"])
    samples = {q: np.array([[mem["loads"][k][q] for k in range(n)] for mem in members]) for q in QUANTITIES}
    bands = {q: confidence_band.band(x) for q, x in samples.items()}
    # the transmitted pressure is the load (a pressure sweep): its spread is rounding, not a band to shrink
    shrink = {q: confidence_band.shrinkage(x) for q, x in samples.items() if q != "transmitted_pressure"}
    loads = [{q: {key: float(b[key][k]) for key in b} for q, b in bands.items()} for k in range(n)]
    results = {"ensemble": {"members": M, "seeds": [mem["seed"] for mem in members],
                            "confidence_level": confidence_band.LEVEL,
                            "quantities": QUANTITIES,
                            "band": "mean -+ t(0.975, M-1) s / sqrt(M), s the sample standard deviation"},
               "loads": loads, "shrinkage": shrink,
               "members": [mem["loads"] for mem in members],
               "accuracy": dict(ensemble_accuracy.verdict(members, loads), cost=cost(members),
                                method=run_cell.method_choice(scene))}
    header = ["load"] + [f"{q}_{key}" for q in QUANTITIES for key in ("mean", "low", "high", "half_width")]
    rows = [[k] + [loads[k][q][key] for q in QUANTITIES for key in ("mean", "low", "high", "half_width")]
            for k in range(n)]
    member_rows = [[m, mem["seed"], k] + [mem["loads"][k][q] for q in QUANTITIES]
                   for m, mem in enumerate(members) for k in range(n)]
    sizes = shrink["contact_fraction"]["members"]
    shrink_rows = [[s] + [shrink[q]["relative_standard_error"][j] for q in shrink] for j, s in enumerate(sizes)]
    tables = {"ensemble": (header, rows),
              "ensemble_members": (["member", "seed", "load"] + list(QUANTITIES), member_rows),
              "ensemble_shrinkage": (["members"] + [f"{q}_relative_standard_error" for q in shrink], shrink_rows)}
    pressure = bands["transmitted_pressure"]["mean"].tolist()
    law = {q: {key: bands[q][key].tolist() for key in ("mean", "low", "high")} for q in QUANTITIES
           if q != "transmitted_pressure"}
    plots = {"ensemble_law": lambda path: figures.ensemble_law(path, pressure, law, QUANTITIES, M)}
    topography = cell_gap.topography(scene)     # surfaces drawn with a scan's spectrum: its record
    if topography is not None:
        results["topography"] = topography
        psd, title = topography["psd"], f"{topography['file']} ({topography['source']})"
        plots["psd"] = lambda path: cell_plots.topography_psd(path, psd, title)
    spread = {q: s for q, s in shrink.items() if s["rate"] is not None}
    if spread and len(sizes) >= 2:
        plots["ensemble_band"] = lambda path: figures.ensemble_band(path, spread)
    return Outcome(results=results, ndof=max(mem["ndof"] for mem in members), tables=tables, plots=plots)
