"""The headline quantities of a run's report, and the errors the report estimates for them.

What an engineer reads first of each kind, as ``{name: value}`` (plain numbers):

* cell: per load ``k`` the contact fraction ``contact_fraction_load{k}``, the mean closure
  ``mean_closure_load{k}`` and the normal effective stiffness ``effective_stiffness_load{k}`` (the
  ``n0 n0`` entry of the tangent of the mean traction, :mod:`ngcontact.cell.fe.stiffness`); a cell
  without loads: the whole-surface coefficients of paper eq. 34 (``whole_surface_k_n``, ...);
* macro: the peak interface pressure ``peak_pressure``, the magnitude of the interface
  resultant ``resultant``, the largest von Mises stress ``max_von_mises`` and, with ``[strength]``, the
  safety factor of paper eq. 78 ``safety_factor``;
* two-scale (a macro report with ``results.two_scale``): the macro ones and the loop's residual
  ``two_scale_residual``, ``max |sigma_n(k) - sigma_n(k-1)|`` of its last step relative to the peak
  pressure (paper Sec. 3.5), and, from the accuracy record, the cell table's interpolation error
  ``cell_table_interpolation`` and, with the scene's tolerance, its share of the macro quantities
  ``cell_table_share`` (:mod:`ngcontact.coupling.table_share`);
* direct: the resolved contact fraction ``contact_fraction`` and the magnitude of the contact force
  ``contact_force``.

A report that estimates its own errors lists them in ``results.accuracy.quantities`` (per quantity its
``name``, ``value``, absolute ``error`` and, for a load of a cell, ``load``): those quantities join the
headline ones under the same names (``{name}_load{k}`` for a load; a cell's ``normal_stiffness`` is its
``effective_stiffness``), with their estimated absolute error.

A fraction (contact fraction, contact area share) is compared in absolute terms, every other quantity
relative to its value (:func:`measure`), as a cell's ``discretization.tolerance`` controls them (a cell's
estimated coefficients of eq. 34 are not among them: :func:`estimated`).  The loop's residual and the
table's interpolation error are **indicators**: each is itself a relative error of the two-scale answer,
so its value is its own estimate (``estimate`` = ``value``), and it has no error against another level.
"""
from __future__ import annotations

import math
from typing import Any

from ngcontact.cell.cell_solution import COEFFICIENT

#: quantities compared in absolute terms (fractions in [0, 1]); every other one relative to its value
ABSOLUTE = ("contact_fraction", "contact_area", "whole_surface_contact_fraction")
#: quantities that are themselves relative errors of the answer (module docstring)
INDICATORS = ("two_scale_residual", "cell_table_interpolation", "cell_table_share")


def measure(name: str) -> str:
    """``indicator`` for a relative error of the answer, ``absolute`` for a fraction, else ``relative``."""
    if name in INDICATORS:
        return "indicator"
    return "absolute" if name.startswith(ABSOLUTE) else "relative"


def _number(x) -> float | None:
    return float(x) if isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) else None


def _get(tree, path: str):
    for part in path.split("."):
        if not isinstance(tree, dict):
            return None
        tree = tree.get(part)
    return tree


def _norm(value) -> float | None:
    """A scalar, or the Euclidean norm of a list or of a dict of components."""
    if isinstance(value, dict):
        value = list(value.values())
    if isinstance(value, list):
        parts = [_number(v) for v in value]
        return None if not parts or None in parts else math.sqrt(sum(v * v for v in parts))  # type: ignore
    return _number(value)


def _normal_stiffness(entry: dict) -> float | None:
    eff = entry.get("effective_stiffness")
    if not isinstance(eff, dict) or "n0" not in (eff.get("components") or []) or eff.get("matrix") is None:
        return None         # no finite stiffness (full contact under exact non-penetration)
    k = eff["components"].index("n0")
    return _number(eff["matrix"][k][k])


def cell_quantities(results: dict) -> dict[str, float | None]:
    loads = results.get("loads")
    if not loads:
        return {f"whole_surface_{k}": _number(v) for k, v in (results.get("whole_surface") or {}).items()}
    out: dict[str, float | None] = {}
    for k, entry in enumerate(loads):
        out[f"contact_fraction_load{k}"] = _number(entry.get("contact_fraction"))
        out[f"mean_closure_load{k}"] = _number(entry.get("mean_closure"))
        out[f"effective_stiffness_load{k}"] = _normal_stiffness(entry)
    return out


def macro_quantities(results: dict) -> dict[str, float | None]:
    out = {"peak_pressure": _number(_get(results, "maxima.pressure.pressure")),
           "resultant": _norm(results.get("resultant")),
           "max_von_mises": _number(_get(results, "maxima.von_mises.max.value")),
           "safety_factor": _number(_get(results, "strength.safety_factor"))}
    if isinstance(results.get("two_scale"), dict):
        out["two_scale_residual"] = loop_residual(results["two_scale"])
    return out


def loop_residual(two_scale: dict) -> float | None:
    """The two-scale loop's last change of the interface pressure relative to the peak pressure then."""
    history = two_scale.get("history") or [{}]
    change, peak = _number(history[-1].get("max_change") or 0.0), _number(history[-1].get("max_pressure"))
    return None if change is None or not peak else change / peak


def direct_quantities(results: dict) -> dict[str, float | None]:
    return {"contact_fraction": _number(results.get("contact_fraction")),
            "contact_force": _norm(results.get("contact_force"))}


QUANTITIES = {"cell": cell_quantities, "macro": macro_quantities, "direct": direct_quantities}


#: an estimated quantity's name in a cell's accuracy record -> its headline name
ALIASES = {"normal_stiffness": "effective_stiffness"}


def _name(entry: dict) -> str:
    load = entry.get("load")
    name = str(entry["name"])
    return ALIASES.get(name, name) + ("" if load is None else f"_load{load}")


def estimated(report: dict) -> list[dict[str, Any]]:
    """The entries of ``results.accuracy.quantities`` that name a quantity and give a finite error, but for a
    cell's coefficients of eq. 34: they carry the penalty ``k_n`` as their scale (``k_n0 = k_n`` times the
    contact fraction), which a study varies as a knob, so they are not one quantity across its levels."""
    entries = _get(report, "results.accuracy.quantities") or []
    return [e for e in entries if isinstance(e, dict) and isinstance(e.get("name"), str)
            and not e["name"].startswith(COEFFICIENT) and _number(e.get("error")) is not None]


def headline(report: dict) -> dict[str, dict[str, float | None]]:
    """``{name: {"value", "estimate"}}`` of a report: its kind's headline quantities and those its accuracy
    record estimates (``estimate``: the absolute error the report estimates, else None; an indicator's: its
    value, a relative error)."""
    results = report.get("results") or {}
    out = {name: {"value": v, "estimate": v if measure(name) == "indicator" else None}
           for name, v in QUANTITIES[report["kind"]](results).items() if v is not None}
    for entry in estimated(report):
        name = _name(entry)
        if measure(name) == "indicator":
            rel = _number(entry.get("relative_error"))
            if rel is not None:
                out[name] = {"value": rel, "estimate": rel}
            continue
        value = _number(entry.get("value"))
        if name in out or value is not None:
            out.setdefault(name, {"value": value, "estimate": None})["estimate"] = abs(float(entry["error"]))
    return out
