"""The cell's boundary layer: the oscillating part ``eps u^1(x, x/eps)`` of the first-order corrector.

Paper eqs. 49-51: ``u^1(x, xi)`` solves the cell problem loaded by the macro state at ``x`` (the macro
interface traction ``sigma^0 n``), periodic in the tangential variable ``xi_t``.  The FE cell of
:class:`ngcontact.cell.fe.cell_problem.CellProblem`, scaled to the period ``eps`` and loaded by the mean
macro traction of one period of ``S_0`` (a *station*), gives the displacement ``w_B`` of each body ``B``:
the rough body's is zero on its far face ``y = -h_r``, the counter's is the far face's translation ``U``
on ``y = h_c`` plus its fluctuation.  Far from ``S_0`` each body carries the uniform strain of the traction,
``w_B -> w_B(far face) + (y - y_B) g_B`` with ``g_B`` the constant gradient along the normal; what is left,

    eps u^1_B(xi) = w_B(xi) - w_B(far face) - (y - y_B) g_B,

decays away from ``S_0`` with the period as length scale: the boundary layer.  ``g_B`` is read off the
solution itself, the mean of ``w_B`` over the line half-way between ``S_0`` and the far face (the layer
has decayed there by ``exp(-pi h / eps)``).  The translation of the counter against the rough body that the
cell adds to the law's jump (the asperities' compliance, ``O(eps)``) is not part of ``u^1``: it changes the
macro solution everywhere, which a local corrector cannot carry.

Between stations ``eps u^1`` is interpolated linearly along ``S_0`` (the macro traction is smooth along
it); beyond the first and the last station it is the nearest station's.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ng
import numpy as np

__all__ = ["CellBoundaryLayer", "StationCell"]


def _evaluate(cf, mesh: ng.Mesh, points: np.ndarray) -> np.ndarray:
    if len(points) == 0:
        return np.zeros((0, 2))
    return np.asarray(cf(mesh(points[:, 0], points[:, 1]))).reshape(-1, 2)


def _line_mean(cf, mesh: ng.Mesh, period: float, y: float, samples: int = 64) -> np.ndarray:
    xs = (np.arange(samples) + 0.5) * period / samples
    return _evaluate(cf, mesh, np.column_stack([xs, np.full(samples, y)])).mean(axis=0)


@dataclass(frozen=True)
class StationCell:
    """The boundary layer of one station: the solved cell's two displacement fields and their far fields.

    ``u_rough`` is zero on ``y = -h_rough``; ``u_counter`` is the counter's whole displacement (its far face's
    translation included).  The cell spans ``0 <= x <= period``.
    """

    x: float
    mesh: ng.Mesh
    u_rough: ng.CoefficientFunction
    u_counter: ng.CoefficientFunction
    period: float
    h_rough: float
    h_counter: float

    def far_field(self) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]:
        """``((value at the far face, gradient g))`` of the rough and of the counter body (module docstring)."""
        top = _line_mean(self.u_counter, self.mesh, self.period, self.h_counter * (1.0 - 1e-9))
        half_r = _line_mean(self.u_rough, self.mesh, self.period, -0.5 * self.h_rough)
        half_c = _line_mean(self.u_counter, self.mesh, self.period, 0.5 * self.h_counter)
        return (np.zeros(2), half_r / (0.5 * self.h_rough)), (top, (top - half_c) / (0.5 * self.h_counter))

    def oscillation(self, xi: np.ndarray, body: np.ndarray) -> np.ndarray:
        """``eps u^1`` at cell points ``xi`` (shape ``(m, 2)``, ``0 <= xi_x < period``) of ``body``.

        A point on ``S_C`` may lie in the other body's element of the cell's mesh, where the field of its
        body is not defined: there (a set of measure zero) ``u^1`` is taken as zero; so it is beyond the
        cell's far faces, where the layer has decayed."""
        (r0, gr), (c0, gc) = self.far_field()
        out = np.zeros((len(xi), 2))
        cell_body = np.full(len(xi), -1)
        inside = (xi[:, 1] > -self.h_rough) & (xi[:, 1] < self.h_counter)
        if np.any(inside):
            counter = self.mesh.MaterialCF({"counter": 1.0}, default=0.0)
            found = np.asarray(counter(self.mesh(xi[inside, 0], xi[inside, 1]))).ravel()
            cell_body[inside] = np.rint(found).astype(int)
        for b, (cf, value, slope, face) in enumerate(((self.u_rough, r0, gr, -self.h_rough),
                                                      (self.u_counter, c0, gc, self.h_counter))):
            mask = (body == b) & (cell_body == b)
            out[mask] = _evaluate(cf, self.mesh, xi[mask]) - value - (xi[mask, 1:2] - face) * slope
        return out


@dataclass(frozen=True)
class CellBoundaryLayer:
    """``eps u^1(x, x/eps)`` from station cells along ``S_0`` (the line ``y = 0`` from ``x0``), period ``eps``.

    Satisfies :class:`ngcontact.coupling.first_order_corrector.BoundaryLayer`.
    """

    stations: tuple[StationCell, ...]
    eps: float
    x0: float = 0.0

    def __post_init__(self) -> None:
        if not self.stations:
            raise ValueError("a boundary layer needs at least one station cell")
        if any(abs(s.period - self.eps) > 1e-9 * self.eps for s in self.stations):
            raise ValueError(f"the station cells' periods differ from eps = {self.eps!r}")

    def at(self, points: np.ndarray, body: np.ndarray) -> np.ndarray:
        pts = np.asarray(points, float).reshape(-1, 2)
        body = np.asarray(body).reshape(-1)
        xi = np.column_stack([np.mod(pts[:, 0] - self.x0, self.eps), pts[:, 1]])
        xs = np.array([s.x for s in self.stations])
        out = np.zeros((len(pts), 2))
        for k, station in enumerate(self.stations):
            hat = np.zeros(len(self.stations))
            hat[k] = 1.0
            weight = np.interp(pts[:, 0], xs, hat)
            use = weight > 0
            if np.any(use):
                out[use] += weight[use, None] * station.oscillation(xi[use], body[use])
        return out
