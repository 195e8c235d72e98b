"""The second discretization of a flat 3D cell with exact contact: meshes refined along the contact edge.

On the flat periodic 3D cell with exact non-penetration (paper eqs. 49-51 in the rigid limit of eq. 65) the
contact fraction's error is made at the contact edge: the node-to-node contact set places the edge within a
part of the element size there (:mod:`ngcontact.cell.fe.exact_contact_set`), an error of first order in that
size (:mod:`ngcontact.cell.fe.contact_edge_mesh`, "Why the edge").  Halving ``interface_maxh`` everywhere
(:class:`~ngcontact.cell.fe.second_discretization.InterfaceHalving`) multiplies the elements of ``S_C`` by
four per level, nearly all of them on open surface or inside the patches.

:class:`ContactEdgeRefinement` keeps the scene's ``maxh`` and ``interface_maxh`` and halves the element size
at the contact edge only: level 0 is the scene's cell, level ``k >= 1`` the cell of
:func:`~ngcontact.cell.fe.contact_edge_mesh.edge_refined_cell` with
``edge_maxh = interface_maxh / 2^k`` at the edge points (:func:`~ngcontact.cell.fe.contact_edge_mesh.edge_points`)
of the spectral twin's solutions at the sweep's loads (the same layers and gap on a periodic grid).  The
sequence's element size at the edge is thus ``h, h/2, h/4, ...`` as for the halving, and its answers converge
at the same first order, so the estimate takes the same rule
(:data:`~ngcontact.cell.fe.second_discretization.HALVING_RATE`), but for the contact fraction: from three
refined levels on it is reported as the Richardson extrapolation in the edge size of the last three
(:mod:`ngcontact.cell.fe.edge_size_extrapolation`, levels ``k >= 1`` only: level 0 is not refined at the
edge), with that module's estimate (the grid convergence index of the last level), the refiner answering
:class:`~ngcontact.cell.fe.second_discretization.Extrapolating`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ngcontact.cell.fe.contact_edge_mesh import edge_points
from ngcontact.cell.fe.edge_size_extrapolation import EdgeSizeExtrapolation, extrapolate
from ngcontact.cell.fe.observed_rate import Convergence
from ngcontact.cell.fe.second_discretization import HALVING_RATE


#: the refined levels whose contact fractions are extrapolated (the last ones)
EXTRAPOLATED_LEVELS = 3


def twin_edge_points(pressures: list[np.ndarray], period: float) -> np.ndarray:
    """The edge points of every pressure grid of the twin (one per load), together."""
    pts = [edge_points(p, period) for p in pressures]
    return np.concatenate(pts) if pts else np.empty((0, 2))


@dataclass
class ContactEdgeRefinement:
    """Level ``k``: the scene's cell, then its mesh refined to ``interface_maxh / 2^k`` along the twin's
    contact edges (module docstring).

    ``scene_cell`` is level 0; ``pressures()`` gives the twin's pressure grids at the loads (asked once, on
    the first refined level); ``cell_at(points, edge_maxh)`` the cell (``sweep``, ``unknowns``) on the mesh
    refined at ``points``; ``period`` the cell's period.
    """

    scene_cell: Any
    pressures: Callable[[], list[np.ndarray]]
    cell_at: Callable[[np.ndarray, float], Any]
    interface_maxh: float
    period: float
    rule: Convergence = HALVING_RATE
    _points: list[np.ndarray] = field(default_factory=list, repr=False)

    def points(self) -> np.ndarray:
        """The twin's edge points at the loads (computed once)."""
        if not self._points:
            self._points.append(twin_edge_points(self.pressures(), self.period))
        return self._points[0]

    def edge_maxh(self, k: int) -> float:
        return self.interface_maxh / 2 ** k

    def level(self, k: int) -> Any:
        return self.scene_cell if k == 0 else self.cell_at(self.points(), self.edge_maxh(k))

    def extrapolated(self, heads: list[list[dict[str, float]]]) -> dict[str, list[EdgeSizeExtrapolation | None]]:
        """Per load the contact fraction extrapolated from the last three refined levels (module docstring);
        ``None`` per load before three refined levels."""
        refined = list(range(1, len(heads)))[-EXTRAPOLATED_LEVELS:]
        if len(refined) < EXTRAPOLATED_LEVELS:
            return {}
        sizes = [self.edge_maxh(k) for k in refined]
        out: list[EdgeSizeExtrapolation | None] = []
        for load in range(len(heads[-1])):
            values = [heads[k][load]["contact_fraction"] for k in refined if "contact_fraction" in heads[k][load]]
            out.append(extrapolate(sizes, values) if len(values) == len(sizes) else None)
        return {"contact_fraction": out}

    def describe(self, k: int) -> str:
        if k == 0:
            return f"interface_maxh {self.interface_maxh:g}"
        return f"edge_maxh {self.edge_maxh(k):g} along the contact edge (interface_maxh {self.interface_maxh:g})"

