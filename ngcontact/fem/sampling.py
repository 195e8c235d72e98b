"""Values of coefficient functions at the quadrature points of a boundary.

A field on an interface is sampled on the boundary elements themselves
(an ``IntegrationRuleSpaceSurface`` defined on the label), never by point
evaluation, which on an internal interface can pick the element of the
wrong body.  Each body's trace is thus unambiguous.

Inside a body, away from interfaces, :func:`probe` evaluates at points.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np


def boundary_samples(mesh: ng.Mesh, label: str, fields: dict, order: int) -> dict[str, np.ndarray]:
    """``{name: values}`` of each field at the order-``order`` quadrature points of boundary ``label``.

    Vector fields give arrays of shape ``(dim, points)``, scalars ``(points,)``;
    all fields are set in one pass on a product space, so their points agree.
    """
    S = ng.comp.IntegrationRuleSpaceSurface(mesh, order=order, definedon=mesh.Boundaries(label))
    flat: list = []
    for cf in fields.values():
        if cf.dim > 1:
            flat.extend(cf[i] for i in range(cf.dim))
        else:
            flat.append(cf)
    gf = ng.GridFunction(S ** len(flat)) if len(flat) > 1 else ng.GridFunction(S)
    gf.Set(ng.CF(tuple(flat)) if len(flat) > 1 else flat[0], definedon=mesh.Boundaries(label))
    arr = gf.vec.FV().NumPy().reshape(len(flat), -1)
    out, k = {}, 0
    for name, cf in fields.items():
        out[name] = arr[k:k + cf.dim].copy() if cf.dim > 1 else arr[k].copy()
        k += cf.dim
    return out


def boundary_values(mesh: ng.Mesh, label: str, cf, order: int) -> np.ndarray:
    """The scalar ``cf`` at the order-``order`` quadrature points of boundary ``label``."""
    return boundary_samples(mesh, label, {"value": cf}, order)["value"]


def probe(mesh, u, points) -> np.ndarray:
    """Displacement ``u`` at ``points`` (an array ``(m, 2)``), one row per point."""
    pts = np.asarray(points, float).reshape(-1, 2)
    return np.array([np.asarray(u(mesh(float(x), float(y)))).ravel() for x, y in pts])
