"""The local frame of the macro interface ``S_0`` in which the laws are written.

The paper decomposes a micro normal as ``n = beta_1 n0 + beta_hat . tau0``
with ``tau0 = (t_1, ..., t_{n-1})`` the unit tangents of ``S_0`` (the text
between eqs. 31 and 32; eq. 39 likewise for the micro tangents).  The local
jump is ``a = (J . n0, J . t0)`` in 2D and axisymmetry and
``a = (J . n0, J . t1, J . t2)`` in 3D, where

    2D, axisymmetry:  t0 = (n0_y, -n0_x)            (n0 turned clockwise)
    3D:               t1 = P r / |P r|,   P = I - n0 n0^T,   t2 = n0 x t1

with ``r`` a reference direction (``e_x`` by default), replaced where it is
nearly normal (``|P r|^2 <= 1/4``) by a second unit direction orthogonal to
it.  ``n0`` points from ``rough`` into ``counter``.
"""
from __future__ import annotations

import numpy as np


def local_frame(n0, dim: int, reference=(1.0, 0.0, 0.0)) -> list:
    """Local basis ``[n0, t0]`` (2D) or ``[n0, t1, t2]`` (3D) as CoefficientFunctions.

    2D and axisymmetric: ``t0 = (n0_y, -n0_x)``, i.e. ``n0`` turned clockwise,
    so that ``n0 = e_y`` gives ``t0 = e_x`` as in the cells; on the stem's
    cylinder (``n0 = e_r``) ``t0 = -e_z``.  3D: ``t1`` is the unit
    projection of ``reference`` on the tangent plane (``e_y`` where
    ``reference`` is nearly normal), ``t2 = n0 x t1``.
    """
    import ngsolve as ng
    if dim == 2:
        return [n0, ng.CF((n0[1], -n0[0]))]
    r1 = ng.CF(tuple(float(c) for c in reference))
    alt = np.cross(reference, (0.0, 0.0, 1.0))
    if np.linalg.norm(alt) < 0.5:
        alt = np.cross(reference, (0.0, 1.0, 0.0))
    r2 = ng.CF(tuple(float(c) for c in alt / np.linalg.norm(alt)))
    p1 = r1 - ng.InnerProduct(r1, n0) * n0
    p2 = r2 - ng.InnerProduct(r2, n0) * n0
    use1 = ng.InnerProduct(p1, p1) - 0.25
    t = ng.IfPos(use1, 1, 0) * p1 + ng.IfPos(use1, 0, 1) * p2
    t1 = t / ng.sqrt(ng.InnerProduct(t, t))
    t2 = ng.Cross(n0, t1)
    return [n0, t1, t2]
