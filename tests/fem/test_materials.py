"""Elastic laws, strain embeddings and stress measures (paper eqs. 1, 77) against hand values."""
import numpy as np
import ngsolve as ng
import pytest
from netgen.geom2d import SplineGeometry

from ngcontact.fem import elasticity
from ngcontact.fem.materials import (anisotropic, isotropic, plane_strain_modulus, principal_stresses,
                                 tresca, von_mises)

E, NU = 200.0, 0.25


def random_strains(n=5, seed=3):
    a = np.random.default_rng(seed).normal(size=(n, 3, 3))
    return 0.5 * (a + np.swapaxes(a, 1, 2))


def test_lame_constants_and_uniaxial_strain():
    law = isotropic(E, NU)
    lam, mu = law.lame
    assert mu == pytest.approx(E / (2 * (1 + NU)))
    assert lam == pytest.approx(E * NU / ((1 + NU) * (1 - 2 * NU)))
    # uniaxial stress sigma_11 = s: eps = s/E diag(1, -nu, -nu)
    s = 7.0
    eps = s / E * np.diag([1.0, -NU, -NU])
    assert np.allclose(law.stress(eps), np.diag([s, 0.0, 0.0]), atol=1e-12)
    assert plane_strain_modulus(E, NU) == pytest.approx(E / (1 - NU ** 2))


def test_voigt_law_of_an_isotropic_matrix_agrees_with_the_isotropic_law():
    iso = isotropic(E, NU)
    voigt = anisotropic(iso.matrix)
    assert voigt.lame is None
    eps = random_strains()
    assert np.allclose(voigt.stress(eps), iso.stress(eps), rtol=1e-12, atol=1e-12)


def test_voigt_and_isotropic_agree_as_coefficient_functions():
    iso = isotropic(E, NU)
    voigt = anisotropic(iso.matrix)
    mesh = ng.Mesh(ng.unit_square.GenerateMesh(maxh=0.5))
    eps_np = random_strains(1)[0]
    eps = ng.CF(tuple(eps_np.ravel()), dims=(3, 3))
    mip = mesh(0.3, 0.4)
    a = np.array(iso.stress(eps)(mip)).reshape(3, 3)
    b = np.array(voigt.stress(eps)(mip)).reshape(3, 3)
    assert np.allclose(a, b, rtol=1e-12)
    assert np.allclose(a, iso.stress(eps_np), rtol=1e-12)


def test_voigt_convention_uses_engineering_shear():
    C = np.eye(6)
    eps = np.zeros((3, 3))
    eps[0, 1] = eps[1, 0] = 0.5  # gamma_12 = 1
    assert anisotropic(C).stress(eps)[0, 1] == pytest.approx(1.0)


@pytest.mark.parametrize("C, rule", [(np.eye(5), "6x6"), (np.diag([1, 1, 1, 1, 1, -1.0]), "positive definite"),
                                     (np.triu(np.ones((6, 6))) + np.eye(6), "symmetric")])
def test_anisotropic_rejects_bad_matrices(C, rule):
    with pytest.raises(ValueError, match=rule):
        anisotropic(C)


@pytest.mark.parametrize("E_, nu", [(-1.0, 0.3), (1.0, 0.5), (1.0, -1.0)])
def test_isotropic_rejects_bad_constants(E_, nu):
    with pytest.raises(ValueError):
        isotropic(E_, nu)


# ----------------------------------------------------------- stress measures
S, TAU, P = 120.0, 50.0, 30.0
UNIAXIAL = np.diag([S, 0.0, 0.0])
SHEAR = np.array([[0.0, TAU, 0.0], [TAU, 0.0, 0.0], [0.0, 0.0, 0.0]])
HYDROSTATIC = -P * np.eye(3)


@pytest.mark.parametrize("sigma, principal, mises, tresca_value", [
    (UNIAXIAL, [S, 0.0, 0.0], S, S),
    (SHEAR, [TAU, 0.0, -TAU], np.sqrt(3.0) * TAU, 2 * TAU),
    (HYDROSTATIC, [-P, -P, -P], 0.0, 0.0),
])
def test_stress_measures_against_hand_values(sigma, principal, mises, tresca_value):
    assert np.allclose(principal_stresses(sigma), principal, atol=1e-12)
    assert von_mises(sigma) == pytest.approx(mises, abs=1e-12)
    assert tresca(sigma) == pytest.approx(tresca_value, abs=1e-12)


def test_stress_measures_are_invariant_under_rotation_and_vectorized():
    t = 0.7
    R = np.array([[np.cos(t), -np.sin(t), 0], [np.sin(t), np.cos(t), 0], [0, 0, 1.0]])
    stack = np.stack([UNIAXIAL, R @ UNIAXIAL @ R.T, SHEAR])
    assert np.allclose(von_mises(stack), [S, S, np.sqrt(3) * TAU])
    assert np.allclose(tresca(stack), [S, S, 2 * TAU])


def test_von_mises_coefficient_function_matches_numpy():
    mesh = ng.Mesh(ng.unit_square.GenerateMesh(maxh=0.5))
    sigma = random_strains(1, seed=8)[0]
    cf = von_mises(ng.CF(tuple(sigma.ravel()), dims=(3, 3)))
    assert cf(mesh(0.5, 0.5)) == pytest.approx(von_mises(sigma), rel=1e-12)


# ----------------------------------------------------------- strain embeddings
def strain_at(u_cf, setting, point):
    geo = SplineGeometry()
    geo.AddRectangle((0.0, 0.0), (1.0, 1.0))
    mesh = ng.Mesh(geo.GenerateMesh(maxh=0.5))
    gfu = ng.GridFunction(ng.VectorH1(mesh, order=2))
    gfu.Set(u_cf)
    return np.array(elasticity.strain(gfu, setting)(mesh(*point))).reshape(3, 3)


def test_plane_strain_embedding():
    a, b, c, d = 0.1, -0.3, 0.2, 0.05
    eps = strain_at(ng.CF((a * ng.x + b * ng.y, c * ng.x + d * ng.y)), "plane_strain", (0.3, 0.6))
    expected = np.array([[a, (b + c) / 2, 0], [(b + c) / 2, d, 0], [0, 0, 0]])
    assert np.allclose(eps, expected, atol=1e-12)


def test_axisymmetric_embedding_has_the_hoop_strain():
    # u_r = alpha r + gamma r z, u_z = beta z: eps_tt = u_r / r = alpha + gamma z
    alpha, beta, gamma = 0.02, -0.01, 0.03
    r, z = 0.4, 0.7
    eps = strain_at(ng.CF((alpha * ng.x + gamma * ng.x * ng.y, beta * ng.y)), "axisymmetric", (r, z))
    expected = np.array([[alpha + gamma * z, gamma * r / 2, 0],
                         [gamma * r / 2, beta, 0],
                         [0, 0, alpha + gamma * z]])
    assert np.allclose(eps, expected, atol=1e-12)


def test_axisymmetric_weight_gives_the_volume_of_a_cylinder():
    geo = SplineGeometry()
    geo.AddRectangle((0.0, 0.0), (2.0, 3.0))
    mesh = ng.Mesh(geo.GenerateMesh(maxh=0.5))
    assert ng.Integrate(elasticity.weight("axisymmetric"), mesh) == pytest.approx(np.pi * 4 * 3, rel=1e-12)
