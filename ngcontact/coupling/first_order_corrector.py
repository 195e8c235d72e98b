"""The first-order corrector: the homogenized solution rebuilt in the rough layer of the resolved bodies.

Paper Sec. 3.4.1 and Sec. 4.1: near the interface the resolved solution has the two-scale expansion

    u^eps(x) = u^0(x) + eps u^1(x, x/eps) + O(eps^2),

``u^0`` the solution of the homogenized problem (paper eqs. 46-48, 69-71) on the bodies with the flat
interface ``S_0``, ``u^1(x, xi)`` periodic in the tangential cell variable ``xi_t`` and decaying
(exponentially, with the period as length scale) away from ``S_0``: the cell's response to the macro
interface state (paper eqs. 49-51; eq. 72 for the linear law).

In this package the interface law is a penalty law of stiffness ``k_n`` independent of ``eps`` (the
bundle of paper eqs. 31-34): the jump ``[u^0]`` across ``S_0`` is of order one, not of order ``eps``.
In the layer of thickness ``O(eps)`` between the valleys and the summits (``-depth eps < y < 0`` for a
rough body with summits on ``S_0``) a point of the counter's teeth carries the counter's displacement in
the resolved solution, while ``u^0`` there is the rough body's: they differ by the jump, ``O(1)`` on a set
of measure ``O(eps)``.  The corrector therefore evaluates, at a point ``x`` of resolved body ``B``,

    u^c(x) = E_B u^0(x) + eps u^1(x, x/eps),      E_B u^0(x) = u^0_B(x_0) + (y - y_0) d_n u^0_B(x_0),

``E_B u^0`` the extension of body ``B``'s macro field across ``S_0`` by its Taylor polynomial of degree
one along the normal (``x_0`` the projection of ``x`` on ``S_0``, the line ``y = y_0``), and
``eps u^1`` the cell's oscillating boundary-layer field (:class:`BoundaryLayer`), zero where none is
given.  On its own side of ``S_0`` a point keeps its body's ``u^0`` (the extension is needed only
across ``S_0``); outside the layer ``|y - y_0| > width`` the corrector is ``u^0`` itself.

Rates theory gives (``u^0`` smooth up to ``S_0`` on each side, a fixed contact set; a boundary layer of
the lateral faces of the bodies aside), with ``Omega_B`` a whole body and ``Omega_B^delta`` the body
without the layer ``|y - y_0| < delta`` of a few periods ``delta = c eps``:

==============================  ==================  ============================
norm                            ``u^0`` alone       ``u^0 + eps u^1`` (corrector)
==============================  ==================  ============================
L2 over each body ``Omega_B``   ``eps^(1/2)``       ``eps``
L2 over ``Omega_B^delta``       ``eps``             ``eps``
H1 over ``Omega_B^delta``       ``eps``             ``eps``
H1 over ``Omega_B``             ``O(1)``            ``eps^(1/2)``
a probe outside the layer       ``eps``             ``eps``
==============================  ==================  ============================

The ``eps^(1/2)`` of the L2 norm without corrector is the jump carried by the wrong body on the layer
(``||.||^2 ~ |[u^0]|^2 eps``); the corrector replaces it by the right body's field, and what remains is
``O(eps)`` everywhere: the layer's own compliance shifts the far faces by ``O(eps)`` against the law's
jump (the term the effective-stiffness law of :mod:`ngcontact.cell.fe.stiffness` puts into the macro
problem), a correction of the macro solution, not of the layer.  ``u^1`` decays exponentially with
``|y - y_0| / eps``: away from a layer of a few periods it changes no norm beyond ``exp(-c)``, and on a
probe outside the layer it changes nothing.

The bound over ``Omega_B^delta`` holds with a constant of the region: when ``delta = c eps`` shrinks with
``eps`` the region grows towards ``S_0``, where the error is largest, and the ratio of two levels reads as
a rate below one until ``delta`` is small against the body; over one fixed region (the epsilon study's
``h1``, :mod:`ngcontact.drivers.modelling_error`) the rate is the table's.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import ngsolve as ng
import numpy as np

from ngcontact.macro.macro_problem import MacroSolution

__all__ = ["BoundaryLayer", "FirstOrderCorrector", "extension"]


class BoundaryLayer(Protocol):
    """The oscillating part ``eps u^1(x, x/eps)`` of the corrector at points of a resolved body."""

    def at(self, points: np.ndarray, body: np.ndarray) -> np.ndarray:
        """``eps u^1`` at ``points`` (shape ``(m, 2)``) of the resolved bodies ``body`` (0 rough, 1 counter)."""
        ...


def _values(gf: ng.GridFunction, mesh: ng.Mesh, points: np.ndarray) -> np.ndarray:
    if len(points) == 0:
        return np.zeros((0, 2))
    return np.asarray(gf(mesh(points[:, 0], points[:, 1]))).reshape(-1, 2)


def _gradients(gf: ng.GridFunction, mesh: ng.Mesh, points: np.ndarray) -> np.ndarray:
    if len(points) == 0:
        return np.zeros((0, 2, 2))
    return np.asarray(ng.Grad(gf)(mesh(points[:, 0], points[:, 1]))).reshape(-1, 2, 2)


def extension(gf: ng.GridFunction, mesh: ng.Mesh, points: np.ndarray, side: float, y0: float = 0.0, *,
              offset: float) -> np.ndarray:
    """``u(x_0) + (y - y_0) d_y u(x_0)`` of the field ``gf`` of one body, ``x_0 = (x, y0)``.

    ``gf`` is evaluated just inside its body (``y0 + side * offset``, ``side`` +1 above ``S_0``, -1 below),
    so that its value and normal derivative are the body's traces on ``S_0``; ``offset`` must exceed the
    mesh's point-location tolerance (a point closer to ``S_0`` may be found in the other body's element,
    where ``gf`` vanishes).
    """
    pts = np.asarray(points, float).reshape(-1, 2)
    trace = np.column_stack([pts[:, 0], np.full(len(pts), y0 + side * offset)])
    u = _values(gf, mesh, trace)
    dy = _gradients(gf, mesh, trace)[:, :, 1]
    return u + (pts[:, 1:2] - trace[:, 1:2]) * dy


@dataclass(frozen=True)
class FirstOrderCorrector:
    """``u^0 + eps u^1`` of a homogenized solution on bodies whose ``S_0`` is the line ``y = y0``.

    Attributes
    ----------
    macro
        The homogenized solution ``u^0`` (regions ``rough`` below ``S_0``, ``counter`` above).
    eps
        Period of the resolved roughness.
    width
        Half-width of the layer around ``S_0`` where the corrector acts; outside it ``u^c = u^0``.
    layer
        The oscillating part ``eps u^1`` (:class:`BoundaryLayer`); ``None``: the extensions alone.
    y0
        Height of ``S_0``.
    """

    macro: MacroSolution
    eps: float
    width: float
    layer: BoundaryLayer | None = None
    y0: float = 0.0

    def __post_init__(self) -> None:
        if not (self.eps > 0 and self.width > 0):
            raise ValueError(f"eps = {self.eps!r} and width = {self.width!r} must be > 0")

    def at(self, points, body) -> np.ndarray:
        """``u^c`` at ``points`` (shape ``(m, 2)``), each of the resolved body ``body`` (0 rough, 1 counter).

        On its own side of ``S_0`` a point takes its body's homogenized field, across ``S_0`` (the counter's
        teeth in the rough body's valleys) the extension :func:`extension`; within ``width`` of ``S_0`` the
        boundary layer is added.
        """
        pts = np.asarray(points, float).reshape(-1, 2)
        body = np.asarray(body).reshape(-1)
        mesh = self.macro.problem.mesh
        out = np.zeros((len(pts), 2))
        above = pts[:, 1] > self.y0
        for b, (gf, side) in enumerate(((self.macro.u_rough, -1.0), (self.macro.u_counter, 1.0))):
            own = (body == b) & (above == (side > 0))
            out[own] = _values(gf, mesh, pts[own])
            across = (body == b) & ~own
            out[across] = extension(gf, mesh, pts[across], side, self.y0, offset=1e-6 * self.width)
        near = np.abs(pts[:, 1] - self.y0) < self.width
        if self.layer is not None and np.any(near):
            out[near] += self.layer.at(pts[near], body[near])
        return out

    def homogenized(self, points) -> np.ndarray:
        """``u^0`` alone at ``points``: each point takes the field of the body on its side of ``S_0``."""
        pts = np.asarray(points, float).reshape(-1, 2)
        out = np.zeros((len(pts), 2))
        mesh = self.macro.problem.mesh
        below = pts[:, 1] < self.y0
        out[below] = _values(self.macro.u_rough, mesh, pts[below])
        out[~below] = _values(self.macro.u_counter, mesh, pts[~below])
        return out
