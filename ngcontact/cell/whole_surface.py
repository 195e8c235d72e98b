"""The accuracy verdict of a cell without loads: its whole-surface coefficients and their estimated errors.

A cell scene with ``contact.geometric_only = true`` reports only the coefficients of its whole contact
surface (paper eq. 34 with ``w = 1``, eqs. 42-43; :mod:`ngcontact.cell.coefficients`).  Each method
estimates their discretization error (:meth:`~ngcontact.cell.cell_solver.CellSolver.whole_surface_error`:
the FE cell by one geometry order more, :mod:`ngcontact.cell.fe.whole_surface_error`; the spectral cell's flat
grid has none), and this verdict holds each coefficient's error as a coefficient of a load's real contact set
is held (:func:`~ngcontact.cell.cell_solution.measure`): relative to the largest magnitude of its group
(:data:`~ngcontact.cell.cell_solution.COEFFICIENT_GROUPS`: ``k_nt`` of a symmetric cell is zero and judged on
the scale of ``k_n``); the surface's measure ``|S_C| / |T|`` relative to itself.
"""
from __future__ import annotations

from typing import Any

from ngcontact.cell.cell_solution import COEFFICIENT_GROUPS

#: a coefficient zero to this fraction of its group's scale at both orders is a term the cell does not have
#: (no gap, no threshold, ``k_nt`` of a symmetric cell): not listed, as its relative error would be round-off's
ROUNDOFF = 1e-12
#: the report's prefix of a whole-surface quantity (as :func:`ngcontact.drivers.headline_quantities.cell_quantities`)
PREFIX = "whole_surface_"


def flat(whole: dict[str, Any]) -> dict[str, float]:
    """The scalar coefficients of a whole-surface record: a 3D tangential pair as ``_0``, ``_1``; the matrix
    ``K0`` and the ratio ``mu`` (two of the others) left out."""
    out: dict[str, float] = {}
    for key in [k for group in COEFFICIENT_GROUPS.values() for k in group] + ["contact_fraction"]:
        value = whole.get(key)
        if isinstance(value, (list, tuple)):
            out.update({f"{key}_{j}": float(v) for j, v in enumerate(value)})
        elif value is not None:
            out[key] = float(value)
    return out


def _scale(name: str, values: dict[str, float]) -> float:
    """The largest magnitude of ``name``'s group among ``values`` (its own value for the surface measure);
    1 where that vanishes (a group zero on the whole surface is measured absolutely)."""
    base = name.rsplit("_", 1)[0] if name[-2:] in ("_0", "_1") else name
    group = next((g for g in COEFFICIENT_GROUPS.values() if base in g), (base,))
    size = max((abs(v) for k, v in values.items() if (k.rsplit("_", 1)[0] if k[-2:] in ("_0", "_1") else k)
                in group), default=0.0)
    return size if size > 0 else 1.0


def verdict(whole: dict[str, Any], errors: dict[str, float] | None, tolerance: float, how: str) -> dict[str, Any]:
    """``results.accuracy`` of a cell without loads: per coefficient of ``whole`` its value and estimated error
    (``errors``, absolute; relative; and in its measure against ``tolerance``; not those zero to
    :data:`ROUNDOFF`), estimated as ``how`` says; where ``errors`` is ``None``, not estimated for the reason
    ``how`` and not met."""
    if errors is None:
        return {"tolerance": tolerance, "met": False, "estimated": False, "quantities": [], "checks": [],
                "how": f"not estimated: {how}"}
    values = flat(whole)
    quantities = []
    for name, error in errors.items():
        value, size = values[name], _scale(name, values)
        if max(abs(value), error) <= ROUNDOFF * size:
            continue
        quantities.append({"load": None, "name": PREFIX + name, "value": value, "error": error,
                           "relative_error": error / abs(value) if value != 0 else None,
                           "controlled": "relative" if name == "contact_fraction" else "relative to its group",
                           "scale": size, "controlled_error": error / size,
                           "met": error / size <= tolerance, "counted": True, "loose": None})
    return {"tolerance": tolerance, "met": all(q["met"] for q in quantities), "estimated": True,
            "quantities": quantities, "checks": [], "how": how}
