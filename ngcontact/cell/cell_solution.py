"""What one load of a cell problem gives, whichever method solved it.

A cell solver (:mod:`ngcontact.cell.cell_solver`) answers a :class:`~ngcontact.cell.cell_load.CellLoad`
with a :class:`CellSolution`: the load's results as plain numbers (contact fraction, mean pressure and
closure, the coefficients of paper eq. 34 on the real contact set, ...), the distribution along the
contact surface ``S_C``, the grid fields where the method has a grid, and the record of the iterations
that produced them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ngcontact.cell.cell_load import CellLoad

#: the columns of a surface distribution besides its coordinates, in the order a table shows them
SURFACE_COLUMNS = ("pressure", "slip", "gap", "closure")
#: the headline quantities of a load whose errors are estimated and reported (:func:`headline`)
HEADLINE = ("contact_fraction", "mean_closure", "normal_stiffness")
#: the coefficients of paper eqs. 34, 42-43 on the real contact set among them, by group: a coefficient's error
#: is measured against the largest magnitude of its group on the whole contact surface (:func:`scale`)
COEFFICIENT_GROUPS = {"stiffness": ("k_n", "k_t", "k_nt"), "gap": ("g_n", "g_t"), "threshold": ("G_n", "G_t")}
#: the prefix of a coefficient's headline name (``coefficient_g_n``; 3D tangential ones ``coefficient_k_t_0``)
COEFFICIENT = "coefficient_"


def headline(results: dict[str, Any]) -> dict[str, float]:
    """The headline quantities of one load's results: the contact fraction, the mean closure, where the
    results carry a finite effective stiffness its normal entry (``n0``), and the coefficients of eqs. 34,
    42-43 on the real contact set (``coefficient_k_n``, ...; a 3D tangential pair as ``_0``, ``_1``; the
    ratio ``mu = k_nt / k_n`` follows from two of them and is not listed).  The load's pressure-closure
    pair is its prescribed pressure and its mean closure."""
    out = {name: float(results[name]) for name in HEADLINE[:2] if name in results}
    K = results.get("effective_stiffness")
    if isinstance(K, dict) and K.get("matrix") is not None and "n0" in K.get("components", ()):
        i = K["components"].index("n0")
        out["normal_stiffness"] = float(K["matrix"][i][i])
    coefficients = results.get("coefficients")
    if isinstance(coefficients, dict):
        for key in (k for group in COEFFICIENT_GROUPS.values() for k in group if k in coefficients):
            value = coefficients[key]
            if isinstance(value, (list, tuple)):
                out.update({f"{COEFFICIENT}{key}_{j}": float(v) for j, v in enumerate(value)})
            else:
                out[COEFFICIENT + key] = float(value)
    return out


#: how the error of each headline quantity is measured (:func:`scale`)
ABSOLUTE, RELATIVE, GROUP = "absolute", "relative", "relative to its group"


def measure(name: str) -> str:
    """The measure of a headline quantity's error, as a scene's ``discretization.tolerance`` holds it: the
    contact fraction (a share of the period, in [0, 1]) absolute; a coefficient of eqs. 34, 42-43 on the real
    contact set relative to the largest magnitude of its group (:data:`COEFFICIENT_GROUPS`) on the whole
    contact surface (eq. 34 with ``w = 1``): the coefficient ranges from zero (no contact) to its
    whole-surface value (full contact) as the contact fraction ranges over [0, 1], and an entry small or zero
    at a small load (``g_n`` grows like the cube of a patch's width) or by symmetry (``k_nt``, ``g_t`` of a
    symmetric cell) is judged on the scale at which the macro law uses it; every other quantity relative to
    its own value."""
    if name == "contact_fraction":
        return ABSOLUTE
    return GROUP if name.startswith(COEFFICIENT) else RELATIVE


def worst_estimate(estimates: list[dict[str, float]], skip: tuple[str, ...] = ()) -> str:
    """The largest of the per-load ``estimates`` (each in its quantity's :func:`measure`) with the quantity
    and load that hold it, e.g. ``"0.0166 (mean_closure, relative, at load 0)"``: what keeps a refinement
    from its tolerance.  ``skip``: quantities not held to the tolerance."""
    found = [(e, name, k) for k, per_load in enumerate(estimates) for name, e in per_load.items() if name not in skip]
    if not found:
        return "no estimate"
    e, name, k = max(found)
    return f"{e:.3g} ({name}, {measure(name)}, at load {k})"


def scale(name: str, head: dict[str, float], whole: dict[str, Any] | None = None) -> float:
    """The size a headline quantity's absolute error is divided by in its :func:`measure`: 1 where that is
    absolute; the value where relative; for a coefficient the largest magnitude of its group among the
    ``whole``-surface coefficients (``{"k_n": ..., "k_t": [...], ...}``), or among the load's own where those
    are not given or vanish (the Coulomb threshold ``mu p`` has no whole-surface value without a pressure).
    A zero size is replaced by 1 (a quantity zero on its scale is measured absolutely)."""
    how = measure(name)
    if how == ABSOLUTE:
        return 1.0
    if how == RELATIVE:
        size = abs(head[name])
    else:
        group = _group(name)
        size = 0.0
        if whole is not None:
            values = [whole[k] for k in COEFFICIENT_GROUPS[group] if k in whole]
            size = max((abs(float(v)) for x in values for v in (x if isinstance(x, (list, tuple)) else [x])),
                       default=0.0)
        if size == 0:
            size = max(abs(v) for n, v in head.items() if n.startswith(COEFFICIENT) and _group(n) == group)
    return size if size > 0 else 1.0


def _group(name: str) -> str:
    """The group of a coefficient's headline name (``coefficient_k_t_1``: ``stiffness``)."""
    key = name[len(COEFFICIENT):]
    return next(g for g, keys in COEFFICIENT_GROUPS.items() if any(key == k or key.startswith(k + "_") for k in keys))


@dataclass
class CellSolution:
    """Results of one load (plain numbers and arrays).

    Attributes
    ----------
    load
        The load solved.
    results
        The load's quantities (:mod:`ngcontact.cell.fe.measures`,
        :mod:`ngcontact.cell.spectral.grid_measures`); compression positive.
    surface
        Samples along ``S_C``: coordinates ``x`` (``y``, ``z``) and some of :data:`SURFACE_COLUMNS`, as
        1D arrays of one length (empty where not measured).
    fields
        Grid fields of a method that has a grid (``pressure``, ``gap``, ``shear``, ``slip``; ``[y, x]`` in
        3D), else empty.
    newton
        The iterations' histories, each a dict with at least ``"iterations"``.
    coulomb_iterations
        Updates of the Coulomb threshold (0 without Coulomb friction, or where the method takes the
        threshold within its own iteration).
    """

    load: CellLoad
    results: dict[str, Any]
    surface: dict[str, np.ndarray] = field(default_factory=dict)
    fields: dict[str, np.ndarray] = field(default_factory=dict)
    newton: list[dict[str, Any]] = field(default_factory=list)
    coulomb_iterations: int = 0

    @property
    def iterations(self) -> int:
        """All iterations of the load, summed over its histories."""
        return sum(h["iterations"] for h in self.newton)

    def surface_table(self) -> tuple[list[str], list[tuple]]:
        """The surface distribution as a table: column names and rows (coordinates first)."""
        columns: list[str] = [k for k in ("x", "y", "z") if k in self.surface]
        columns += [k for k in SURFACE_COLUMNS if k in self.surface]
        return columns, list(zip(*[self.surface[k] for k in columns]))
