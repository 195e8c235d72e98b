"""Exactness: displacements that lie in the finite element space are reproduced.

A polynomial ``u*`` of degree ``q <= p`` (axisymmetric: ``u_r = r q(r, z)``,
regular at the axis) gives polynomial loads; Galerkin orthogonality then
makes the order-``p`` solution equal ``u*`` up to round-off on any mesh.
Degree ``p + 1`` must not be reproduced, which shows the check can fail.
"""
import numpy as np
import ngsolve as ng
import pytest

from ngcontact.verification import exact_fields, manufactured
from ngcontact.fem.materials import anisotropic, isotropic

LAW = isotropic(3.0, 0.3)


def orthotropic():
    C = np.zeros((6, 6))
    C[:3, :3] = [[30.0, 8.0, 7.0], [8.0, 20.0, 6.0], [7.0, 6.0, 15.0]]
    C[3, 3], C[4, 4], C[5, 5] = 5.0, 6.0, 7.0
    return anisotropic(C)


def relative_errors(setting, order, degree, law=LAW, maxh=0.4, inverse="sparsecholesky"):
    prob = manufactured.problem(setting, {"body": law}, maxh, solution="polynomial", degree=degree)
    sol = manufactured.solve(prob, order, inverse=inverse)
    l2, h1 = manufactured.errors(prob, sol.gfu)
    w = manufactured.elasticity.weight(prob.setting)
    norm = ng.Integrate(ng.InnerProduct(prob.exact, prob.exact) * w, prob.mesh, order=2 * degree + 2) ** 0.5
    return l2 / norm, h1 / norm


CASES = [("plane_strain", p) for p in (1, 2, 3, 4)] + \
        [("axisymmetric", p) for p in (1, 2, 3, 4)] + \
        [("3d", p) for p in (1, 2)]


@pytest.mark.parametrize("setting, order", CASES)
def test_polynomials_of_the_element_degree_are_exact(setting, order):
    maxh = 1.0 if setting == "3d" else 0.4
    for degree in range(1, order + 1):
        l2, h1 = relative_errors(setting, order, degree, maxh=maxh)
        assert l2 < 1e-11 and h1 < 1e-10, f"{setting}, p = {order}, degree {degree}: L2 {l2:.2e}, H1 {h1:.2e}"


@pytest.mark.parametrize("setting, order", [("plane_strain", 2), ("axisymmetric", 2), ("3d", 1)])
def test_one_degree_more_is_not_exact(setting, order):
    maxh = 1.0 if setting == "3d" else 0.4
    l2, h1 = relative_errors(setting, order, order + 1, maxh=maxh)
    assert l2 > 1e-6 and h1 > 1e-5, f"{setting}, p = {order}: L2 {l2:.2e}, H1 {h1:.2e}"


def test_anisotropic_law_is_exact_too():
    l2, h1 = relative_errors("plane_strain", 3, 3, law=orthotropic())
    assert l2 < 1e-11 and h1 < 1e-10, (l2, h1)


def test_umfpack_is_exact_too():
    """UMFPACK reads the full matrix (the Cholesky path stores one triangle)."""
    l2, h1 = relative_errors("axisymmetric", 2, 2, inverse="umfpack")
    assert l2 < 1e-11 and h1 < 1e-10, (l2, h1)


@pytest.mark.parametrize("setting", ["plane_strain", "3d"])
def test_navier_form_equals_the_divergence_of_the_stress(setting):
    prob = manufactured.problem(setting, {"body": LAW}, 1.0 if setting == "3d" else 0.4)
    navier = exact_fields.navier_body_force(LAW, prob.exact, setting)
    generic = exact_fields.stress_divergence_body_force(LAW, prob.exact, setting)
    diff = ng.Integrate(ng.InnerProduct(navier - generic, navier - generic), prob.mesh, order=6)
    size = ng.Integrate(ng.InnerProduct(generic, generic), prob.mesh, order=6)
    assert diff <= 1e-24 * size and size > 1.0
