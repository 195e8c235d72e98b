"""Accuracy study: the work-precision diagram of a user's own scene.

Each level of the ladder (:mod:`ngcontact.scene.refinement_ladder`: one knob of the discretization
refined per level, every other key as the user wrote it) is run as ``ngcontact run`` runs the scene (the
``solve`` the runner hands in, a whole run with its report), and its headline quantities are read from
that report (:mod:`ngcontact.drivers.headline_quantities`), with the errors the report estimates where it
has them.  The levels are independent runs: one batch on the run's executor
(:mod:`ngcontact.parallel.executor`); a level that appears in several ladders (the scene's own) runs once.
A level that fails is reported with its reason and left out.

**Reference.** No converged answer is known, so each knob's finest level stands in for it: the error of a
level is ``|q - q_ref|`` (a fraction: absolute; any other quantity: relative to ``|q_ref|``), which
measures what refining that knob further would change, not the error the finest level itself keeps.  The
reference's own error is the smaller the faster the knob converges; the knob's observed **rate** is the
least-squares slope of ``log error`` against ``log x`` over its other levels (``x``: each knob's variable,
``maxh``, the grid step, ``1/k_n``, a tolerance, or ``1/ndof`` for the order), and near the reference that
slope is too steep (the difference to the reference shrinks faster than the error itself), so it is an upper estimate
of the rate; two levels only give a two-point slope, which the report says.  An indicator of a two-scale
run (the loop's residual, the cell table's interpolation error: relative errors themselves) is not compared
with the reference: its value is its error, and its rate is the slope of that value.

**Other knobs.** A level changes one knob; every other knob keeps the scene's setting and with it that
knob's share of the error, which the scene's own level measures in that knob's ladder.  Errors add to first
order, so a level's error in all its knobs is its error along its own knob plus the scene's own level's
errors along the others (``error_other_knobs``).

**Target.** With a target ``T``, a level meets it when, for every headline quantity, its error in all
knobs, and the error the level's own report estimates (where it has one; in the quantity's measure), are at
most ``T``.  The reference levels cannot be judged against themselves and are not
candidates.  The cheapest level meeting ``T`` (by wall time) is written as a runnable scene
(``recommended.toml``: the level's table, its file paths made absolute); else the report says that no
level met it and how close the best came.
"""
from __future__ import annotations

import contextlib
import logging
import math
from typing import Any, Callable

import numpy as np

from ngcontact.drivers.headline_quantities import headline, measure
from ngcontact.output import plots
from ngcontact.output.report import Outcome
from ngcontact.parallel import executor
from ngcontact.scene.refinement_ladder import KNOBS, Level
from ngcontact.scene.scene_text import dumps, with_absolute_paths

log = logging.getLogger(__name__)

CSV_HEADER = ["knob", "level", "setting", "reference", "own_scene", "seconds", "ndof", "quantity", "value",
              "measure", "error", "error_other_knobs", "estimated_error"]


def level_member(job: tuple) -> dict:
    """Member of the batch of levels: ``(solve, scene)`` -> the level's headline quantities, wall time and
    unknowns, or its failure (``solve(scene)`` is the report of a whole run)."""
    solve, scene = job
    try:
        report = solve(scene)
    except Exception as exc:   # a level that fails (solver, mesher) is reported with its reason, not fatal
        return {"failed": f"{type(exc).__name__}: {exc}"}
    return {"quantities": headline(report), "seconds": float(report["timings"]["total"]),
            "ndof": int(report["ndof"])}


def run_levels(levels: list[Level], solve: Callable, clock=None) -> dict[str, dict]:
    """Run every distinct level once, as one batch, the largest first (the batch's longest members start first,
    and the first run of a process, which pays its warm-up, is the one that hides it best); ``{level key:
    member result}``."""
    distinct: dict[str, Level] = {}
    for lv in levels:
        distinct.setdefault(lv.key, lv)
    order = sorted(distinct, key=lambda k: -(distinct[k].size or 1.0))
    jobs = [(solve, distinct[k].scene) for k in order]
    names = [f"{distinct[k].knob}: {distinct[k].setting}" for k in order]
    with clock.stage("levels") if clock is not None else contextlib.nullcontext():
        runs = executor.current().map(level_member, jobs, names, label="accuracy levels")
    return dict(zip(order, runs))


def error_of(name: str, value: float, ref: float) -> float:
    """``|value - ref|`` in the quantity's measure (relative to ``|ref|``, absolute where ``ref`` is 0)."""
    diff = abs(value - ref)
    return diff / abs(ref) if measure(name) == "relative" and ref != 0 else diff


def estimate_of(name: str, entry: dict) -> float | None:
    """The report's estimated error of a quantity, in the quantity's measure (None where it has none; an
    indicator's is its value, a relative error already)."""
    e, v = entry.get("estimate"), entry.get("value")
    if e is None or v is None:
        return None
    return e / abs(v) if measure(name) == "relative" and v != 0 else e


def observed(q: dict) -> float | None:
    """What a level's quantity shows along its knob: its error against the reference, or an indicator's own
    value (it has no error against another level)."""
    return q["estimated_error"] if q["measure"] == "indicator" else q["error"]


def level_rows(levels: list[Level], runs: dict[str, dict], own_key: str) -> list[dict]:
    """One record per level: its knob, setting, run, and per quantity value, error and estimate."""
    rows = []
    for knob in dict.fromkeys(lv.knob for lv in levels):
        mine = [lv for lv in levels if lv.knob == knob]
        done = [lv for lv in mine if "failed" not in runs[lv.key]]
        ref = done[-1] if done else None
        for lv in mine:
            run = runs[lv.key]
            row: dict[str, Any] = {"knob": knob, "level": lv.index, "setting": lv.setting, "key": lv.key,
                                   "parameter": lv.parameter, "size_estimate": lv.size, "reference": lv is ref,
                                   "own_scene": lv.key == own_key}
            if "failed" in run:
                rows.append({**row, "failed": run["failed"]})
                continue
            ref_q = runs[ref.key]["quantities"] if ref is not None else {}
            quantities = {}
            for name, entry in run["quantities"].items():
                r = ref_q.get(name, {}).get("value")
                compared = r is not None and measure(name) != "indicator"
                quantities[name] = {"value": entry["value"], "measure": measure(name),
                                    "error": error_of(name, entry["value"], r) if compared else None,
                                    "estimated_error": estimate_of(name, entry)}
            rows.append({**row, "seconds": run["seconds"], "ndof": run["ndof"], "quantities": quantities})
    add_other_knobs(rows)
    return rows


def add_other_knobs(rows: list[dict]) -> None:
    """Set each quantity's ``error_other_knobs``: the scene's own level's errors in the other knobs' ladders
    (see the module docstring; 0 where the scene's own level is not in a ladder)."""
    own = {r["knob"]: r["quantities"] for r in rows if r["own_scene"] and "quantities" in r}
    for r in rows:
        for name, q in (r.get("quantities") or {}).items():
            q["error_other_knobs"] = sum((qs.get(name) or {}).get("error") or 0.0
                                         for knob, qs in own.items() if knob != r["knob"])


def slope(x: list[float], e: list[float]) -> float | None:
    """Least-squares slope of ``log e`` against ``log x`` (None with fewer than 2 points)."""
    pts = [(a, b) for a, b in zip(x, e) if a > 0 and b > 0]
    if len(pts) < 2 or len({a for a, _ in pts}) < 2:
        return None
    return float(np.polyfit(np.log([a for a, _ in pts]), np.log([b for _, b in pts]), 1)[0])


#: an error at most this (in its measure) is round-off: the quantity does not depend on the knob (a resultant
#: that equilibrium fixes), so it has no rate
ROUNDOFF = 1e-9


def rates(rows: list[dict]) -> dict[str, dict]:
    """Per knob: its variable, the number of levels fitted and per quantity the observed rate (None where the
    errors sit at round-off, :data:`ROUNDOFF`, or fewer than two levels remain)."""
    variables = {k.name: k.variable for k in KNOBS}
    out = {}
    for knob in dict.fromkeys(r["knob"] for r in rows):
        fit = [r for r in rows if r["knob"] == knob and "quantities" in r and not r["reference"]]
        x = [r["parameter"] if r["parameter"] is not None else 1.0 / max(r["ndof"], 1) for r in fit]
        names = dict.fromkeys(n for r in fit for n in r["quantities"])
        per = {}
        for name in names:
            pairs = [(xi, e) for xi, e in zip(x, (observed(r["quantities"][name]) if name in r["quantities"]
                                                  else None for r in fit)) if e is not None and e > ROUNDOFF]
            per[name] = slope([p for p, _ in pairs], [e for _, e in pairs])
        out[knob] = {"variable": variables[knob], "levels_fitted": len(fit), "two_point": len(fit) == 2,
                     "rates": per}
    return out


def level_error(row: dict) -> float:
    """The largest error of a level over its quantities: in all knobs (:func:`add_other_knobs`) and as its
    report estimates."""
    errors = [max((q["error"] or 0.0) + q["error_other_knobs"], q["estimated_error"] or 0.0)
              for q in row["quantities"].values()]
    return max(errors) if errors else math.inf


def recommendation(rows: list[dict], levels: list[Level], target: float | None, base_dir: str,
                   title: str) -> tuple[dict, dict[str, str]]:
    """The target's verdict (``results.target``) and the recommended scene's text, if a level meets it."""
    if target is None:
        return {}, {}
    candidates = [r for r in rows if "quantities" in r and not r["reference"] and r["quantities"]]
    meeting = sorted((r for r in candidates if level_error(r) <= target), key=lambda r: r["seconds"])
    if not meeting:         # a miss is never silent: one warning line besides the report's verdict
        best = min(candidates, key=level_error, default=None)
        statement = (f"no level of the study met the target {target:g}"
                     + ("" if best is None else f"; the closest, {best['knob']}: {best['setting']}, has error "
                        f"{level_error(best):.3g}") + "; the finest levels are the references and cannot be judged "
                     "against themselves: make a reference level the scene and study it again")
        log.warning("accuracy study: %s", statement)
        return {"target": target, "met": False, "statement": statement}, {}
    best = meeting[0]
    level = next(lv for lv in levels if lv.key == best["key"])
    text = dumps(with_absolute_paths(level.data, base_dir),
                 f"{title or 'scene'}: the cheapest level of 'ngcontact study accuracy' meeting the target "
                 f"{target:g}\n({best['knob']}: {best['setting']}; error {level_error(best):.3g} against the "
                 f"finest level of each knob's ladder; {best['seconds']:.3g} s)")
    return {"target": target, "met": True, "knob": best["knob"], "setting": best["setting"],
            "error": level_error(best), "seconds": best["seconds"], "ndof": best["ndof"],
            "file": "recommended.toml",
            "statement": f"the cheapest level meeting {target:g}: {best['knob']}: {best['setting']}"
                         + (" (the scene as it is)" if best["own_scene"] else "")
                         + f" (error {level_error(best):.3g}, {best['seconds']:.3g} s); written as recommended.toml"
            }, {"recommended.toml": text}


def table(rows: list[dict]) -> tuple[list[str], list[list]]:
    """The CSV table: one line per level and quantity (a failed level: one line without numbers)."""
    out = []
    for r in rows:
        head = [r["knob"], r["level"], r["setting"], int(r["reference"]), int(r["own_scene"])]
        if "quantities" not in r:
            out.append(head + ["", "", f"failed: {r['failed']}", "", "", "", "", ""])
            continue
        for name, q in r["quantities"].items():
            out.append(head + [r["seconds"], r["ndof"], name, q["value"], q["measure"],
                               "" if q["error"] is None else q["error"], q["error_other_knobs"],
                               "" if q["estimated_error"] is None else q["estimated_error"]])
    return CSV_HEADER, out


def figures(rows: list[dict], target: float | None) -> dict[str, Callable]:
    """One work-precision plot per quantity: error against wall time, one line per knob."""
    names = dict.fromkeys(n for r in rows if "quantities" in r for n in r["quantities"])
    out: dict[str, Callable] = {}
    for name in names:
        series: dict[str, tuple[list, list]] = {}
        for r in rows:
            q = (r.get("quantities") or {}).get(name)
            if q is not None and not r["reference"] and observed(q) is not None:
                s = series.setdefault(r["knob"], ([], []))
                s[0].append(r["seconds"])
                s[1].append(observed(q))
        out[f"accuracy_{name}"] = (lambda path, name=name, series=series:
                                   plots.work_precision(path, name, measure(name), series, target))
    return out


def run_study(scene, levels: list[Level], dropped: list[str], solve: Callable, *, own_key: str,
              target: float | None = None, clock=None) -> Outcome:
    """The accuracy study of ``scene`` over ``levels``; no file I/O (see the module docstring).

    ``results``: ``reference`` (what the errors are measured against), ``ladder`` (per knob its levels'
    settings), ``dropped`` (levels and knobs left out, with the reason), ``levels`` (per level its setting,
    wall time, unknowns and per quantity value, error and estimated error, or its failure), ``rates``
    (per knob), ``target`` (with a target: the verdict and the recommended level).
    """
    runs = run_levels(levels, solve, clock)
    rows = level_rows(levels, runs, own_key)
    verdict, texts = recommendation(rows, levels, target, scene.base_dir, getattr(scene, "title", ""))
    results = {"reference": "each knob's finest level: a level's error is its difference to that level "
                            "(fractions absolute, other quantities relative), not the error of the finest "
                            "level itself; error_other_knobs adds the scene's own level's errors along the "
                            "other knobs, which the level keeps",
               "ladder": {k: [lv.setting for lv in levels if lv.knob == k] for k in dict.fromkeys(
                   lv.knob for lv in levels)},
               "dropped": dropped, "levels": [{k: v for k, v in r.items() if k != "key"} for r in rows],
               "rates": rates(rows), "distinct_runs": len(runs),
               "seconds_all_levels": sum(r.get("seconds", 0.0) for r in runs.values())}
    if verdict:
        results["target"] = verdict
    own = [r for r in rows if r["own_scene"] and "seconds" in r]
    if own:
        results["seconds_own_scene"] = own[0]["seconds"]
        results["cost_over_own_scene"] = results["seconds_all_levels"] / own[0]["seconds"]
    return Outcome(results=results, ndof=max((r.get("ndof", 0) for r in rows), default=0),
                   tables={"accuracy_study": table(rows)}, plots=figures(rows, target), texts=texts)
