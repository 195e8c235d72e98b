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


def headline(results: dict[str, Any]) -> dict[str, float]:
    """The headline quantities of one load's results: the contact fraction, the mean closure and, where the
    results carry a finite effective stiffness, its normal entry (``n0``)."""
    out = {name: float(results[name]) for name in HEADLINE[:2] if name in results}
    K = results.get("effective_stiffness")
    if isinstance(K, dict) and K.get("matrix") is not None and "n0" in K.get("components", ()):
        i = K["components"].index("n0")
        out["normal_stiffness"] = float(K["matrix"][i][i])
    return out


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
