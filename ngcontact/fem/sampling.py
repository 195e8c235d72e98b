"""Values of coefficient functions at the quadrature points of a boundary.

A field on an interface is sampled on the boundary elements themselves
(their quadrature points mapped element by element, the points of an
``IntegrationRuleSpaceSurface`` on the label), never by locating points in
the mesh, which on an internal interface can pick the element of the wrong
body.  Each body's trace is thus unambiguous.

Inside a body, away from interfaces, :func:`probe` evaluates at points.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np


def boundary_samples(mesh: ng.Mesh, label: str, fields: dict, order: int) -> dict[str, np.ndarray]:
    """``{name: values}`` of each field at the order-``order`` quadrature points of boundary ``label``.

    Vector fields give arrays of shape ``(dim, points)``, scalars ``(points,)``;
    every field is evaluated at the same mapped points, in the order of the
    dofs of an ``IntegrationRuleSpaceSurface`` of that order (setting the
    fields into that space gives the same numbers to round-off at hundreds
    of times the cost on a 3D cell).
    """
    rules = ng.comp.IntegrationRuleSpaceSurface(mesh, order=order, definedon=mesh.Boundaries(label))
    points = mesh.MapToAllElements(rules.GetIntegrationRules(), mesh.Boundaries(label))
    out = {}
    for name, cf in fields.items():
        values = np.asarray(cf(points))
        out[name] = values.T.copy() if cf.dim > 1 else values.reshape(-1).copy()
    return out


def boundary_values(mesh: ng.Mesh, label: str, cf, order: int) -> np.ndarray:
    """The scalar ``cf`` at the order-``order`` quadrature points of boundary ``label``."""
    return boundary_samples(mesh, label, {"value": cf}, order)["value"]


def probe(mesh, u, points) -> np.ndarray:
    """Displacement ``u`` at ``points`` (an array ``(m, 2)``), one row per point."""
    pts = np.asarray(points, float).reshape(-1, 2)
    return np.array([np.asarray(u(mesh(float(x), float(y)))).ravel() for x, y in pts])
