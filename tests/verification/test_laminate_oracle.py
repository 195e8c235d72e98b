"""Laminate and penalty bar of :mod:`ngcontact.verification.laminate`, against independent computations.

The laminate is read off the 3D isotropic stiffness matrix (which also
checks :func:`~ngcontact.verification.moduli.p_wave_modulus` and
:func:`~ngcontact.verification.moduli.shear_modulus`); the bar is an
explicit two-spring equilibrium.
"""
import numpy as np
import pytest

from ngcontact.errors import ModelError
from ngcontact.verification.laminate import laminate_stiffness, penalty_bar_force


def _isotropic_voigt(E_, nu_):
    lam = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_))
    mu = E_ / (2 * (1 + nu_))
    C = np.zeros((6, 6))
    C[:3, :3] = lam
    C[np.arange(3), np.arange(3)] += 2 * mu
    C[np.arange(3, 6), np.arange(3, 6)] = mu
    return C


def test_laminate_is_two_springs_in_series_read_off_the_3d_stiffness():
    h1, E1, nu1, h2, E2, nu2 = 0.3, 2.0, 0.25, 0.7, 50.0, 0.45
    C1, C2 = _isotropic_voigt(E1, nu1), _isotropic_voigt(E2, nu2)
    # uniaxial strain along 3: sigma_33 = C33 eps_33; simple shear 13: sigma_13 = C55 gamma_13
    kn = 1 / (h1 / C1[2, 2] + h2 / C2[2, 2])
    kt = 1 / (h1 / C1[4, 4] + h2 / C2[4, 4])
    K2 = laminate_stiffness(h1, E1, nu1, h2, E2, nu2)
    np.testing.assert_allclose(K2, np.diag([kn, kt]), rtol=1e-13)
    K3 = laminate_stiffness(h1, E1, nu1, h2, E2, nu2, dim=3)
    np.testing.assert_allclose(K3, np.diag([kn, kt, kt]), rtol=1e-13)
    np.testing.assert_allclose(laminate_stiffness(h2, E2, nu2, h1, E1, nu1), K2, rtol=1e-14)
    # one material split into two layers is one layer of the summed thickness
    np.testing.assert_allclose(laminate_stiffness(0.2, E1, nu1, 0.5, E1, nu1),
                               np.diag([C1[2, 2] / 0.7, C1[4, 4] / 0.7]), rtol=1e-13)
    # an interface spring adds its compliance: the far-face jump of tests/test_hard_cases.py
    Kk = laminate_stiffness(h1, E1, nu1, h2, E2, nu2, k_n=1e3, k_t=4e2)
    np.testing.assert_allclose(1 / np.diag(Kk), 1 / np.diag(K2) + [1e-3, 1 / 4e2], rtol=1e-13)
    with pytest.raises(ModelError, match="dim"):
        laminate_stiffness(h1, E1, nu1, h2, E2, nu2, dim=1)

# ------------------------------------------------------------------------ bar
def test_penalty_bar_force_patch_values_and_equilibrium():
    # L/(EA) = 2/(4 * 0.5) = 1, 1/(kA) = 1/(8 * 0.5) = 0.25: F = (3 - 1)/1.25
    assert penalty_bar_force(3.0, 1.0, 2.0, 4.0, 0.5, 8.0) == pytest.approx(1.6, rel=1e-15)
    assert penalty_bar_force(1.0, 1.0, 2.0, 4.0, 0.5, 8.0) == 0.0
    assert penalty_bar_force(0.5, 1.0, 2.0, 4.0, 0.5, 8.0) == 0.0
    # the contact end u: bar force E A (d - u)/L equals layer force k A (u - g0)
    d, g0, L, E_, A, k = 2e-3, 5e-4, 0.3, 70e9, 1e-4, 1e13
    u = np.linalg.solve([[E_ * A / L + k * A]], [E_ * A / L * d + k * A * g0])[0]
    F = penalty_bar_force(d, g0, L, E_, A, k)
    assert F == pytest.approx(E_ * A * (d - u) / L, rel=1e-12) and F == pytest.approx(k * A * (u - g0), rel=1e-9)
    # rigid-wall limit: the bar alone
    assert penalty_bar_force(d, g0, L, E_, A, 1e30) == pytest.approx(E_ * A * (d - g0) / L, rel=1e-12)
