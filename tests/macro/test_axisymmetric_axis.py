"""Axisymmetric elements touching the axis r = 0 stay finite at every order.

Quadrature rules may sample points on the axis (the degree-2 triangle rule
uses edge midpoints), where the hoop strain ``u_r / r`` is 0/0.  A solid
cylinder under uniform end pressure ``q`` is in uniaxial stress:
``u_z = -q z / E``, ``u_r = nu q r / E`` -- linear, so every order must
reproduce it to round-off.
"""
import ngsolve as ng
import numpy as np
import pytest
from netgen.geom2d import SplineGeometry

from ngcontact.fem import elasticity as el
from ngcontact.fem.materials import isotropic

E, NU, Q = 2.0, 0.3, 1.0


@pytest.mark.parametrize("order", [1, 2, 3])
def test_cylinder_on_axis_uniaxial_stress_exact(order):
    geo = SplineGeometry()
    geo.AddRectangle((0, 0), (1, 2), bcs=["bottom", "right", "top", "axis"])
    mesh = ng.Mesh(geo.GenerateMesh(maxh=0.3))
    V = ng.VectorH1(mesh, order=order, dirichletx="axis", dirichlety="bottom")
    u, v = V.TnT()
    law = isotropic(E, NU)
    a = ng.BilinearForm(el.bilinear_integrand(law, u, v, "axisymmetric") * ng.dx).Assemble()
    f = ng.LinearForm(-Q * v[1] * el.weight("axisymmetric") * ng.ds("top")).Assemble()
    gfu = ng.GridFunction(V)
    gfu.vec.data = a.mat.Inverse(V.FreeDofs()) * f.vec
    assert np.isfinite(gfu.vec.FV().NumPy()).all()
    exact = ng.CF((NU * Q * ng.x / E, -Q * ng.y / E))
    err = ng.sqrt(ng.Integrate(ng.InnerProduct(gfu - exact, gfu - exact) * ng.x, mesh))
    assert err < 1e-11, f"order {order}: L2 error {err:.3e}"
