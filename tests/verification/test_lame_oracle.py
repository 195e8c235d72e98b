"""Lamé's rings and press fit of :mod:`ngcontact.verification.lame`, against an independent computation.

The press-fit pressure and both rings' displacements are compared with the
4x4 linear system of the ring boundary conditions, solved here; the limits
of a stiff and a soft interface layer and a uniformly compressed solid disk
complete the check.
"""
import math

import numpy as np
import pytest

from ngcontact.errors import ModelError
from ngcontact.verification.lame import lame_press_fit_pressure, lame_radial_displacement


def _lame_system(a, b, c, Ei, nui, Eo, nuo, delta, kn):
    """Solve the ring boundary conditions for ``u_r = A r + B/r`` in each ring (plane strain).

    Unknowns ``(A_in, B_in, A_out, B_out)``; rows: free bore (or a bounded
    centre, ``B_in = 0``), equal radial stress at ``b``, free mantle, and the
    interference taken up by both rings and the layer: ``u_out(b) - u_in(b) + p/k_n = delta``.
    """
    def lame(E_, nu_):
        lam = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_))
        return lam, E_ / (2 * (1 + nu_))

    li, mi = lame(Ei, nui)
    lo, mo = lame(Eo, nuo)

    def srr(lam, mu, r):          # sigma_rr coefficients of (A, B)
        return [2 * (lam + mu), -2 * mu / r ** 2]

    M = np.zeros((4, 4))
    rhs = np.zeros(4)
    M[0, :2] = srr(li, mi, a) if a > 0 else [0.0, 1.0]
    M[1, :2] = srr(li, mi, b)
    M[1, 2:] = [-v for v in srr(lo, mo, b)]
    M[2, 2:] = srr(lo, mo, c)
    comp = 0.0 if math.isinf(kn) else 1.0 / kn
    # p = -sigma_rr,out(b)
    M[3, 2:] = [b, 1 / b]
    M[3, 2:] -= comp * np.array(srr(lo, mo, b))
    M[3, :2] = [-b, -1 / b]
    rhs[3] = delta
    A_in, B_in, A_out, B_out = np.linalg.solve(M, rhs)
    p = -(srr(lo, mo, b)[0] * A_out + srr(lo, mo, b)[1] * B_out)
    return p, (A_in, B_in), (A_out, B_out)


CASES = [(0.5, 1.0, 2.0, 200.0, 0.3, 70.0, 0.25, 1e-3, 300.0),     # the tubes of tests/test_macro.py
         (0.0, 1.0, 1.5, 100e9, 0.3, 9e9, 0.27, 5e-5, 32e9),        # solid stem in bone, hip-like numbers
         (0.2, 0.3, 0.9, 1.0, 0.45, 3.0, 0.1, 0.01, math.inf)]      # rigid interface


@pytest.mark.parametrize("case", CASES)
def test_lame_press_fit_pressure_solves_the_ring_boundary_conditions(case):
    a, b, c, Ei, nui, Eo, nuo, delta, kn = case
    p_sys, (Ai, Bi), (Ao, Bo) = _lame_system(*case)
    p = lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta, k_n=kn)
    assert p > 0 and p == pytest.approx(p_sys, rel=1e-12)
    r_in = np.linspace(max(a, 1e-3 * b), b, 7)
    r_out = np.linspace(b, c, 7)
    np.testing.assert_allclose(lame_radial_displacement(r_in, a, b, Ei, nui, p_out=p), Ai * r_in + Bi / r_in,
                               rtol=1e-11, atol=1e-11 * abs(Ai * b + Bi / b))
    np.testing.assert_allclose(lame_radial_displacement(r_out, b, c, Eo, nuo, p_in=p), Ao * r_out + Bo / r_out,
                               rtol=1e-11, atol=1e-11 * abs(Ao * b + Bo / b))


def test_lame_interface_compliance_limits():
    a, b, c, Ei, nui, Eo, nuo, delta = CASES[0][:8]
    rigid = lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta)
    stiff = lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta, k_n=1e12)
    assert stiff == pytest.approx(rigid, rel=1e-8) and stiff < rigid
    for kn in (1e-3, 1e-5):      # soft layer: the rings barely deform, the layer takes it all
        soft = lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, delta, k_n=kn)
        assert soft == pytest.approx(kn * delta, rel=1e2 * kn)
    assert lame_press_fit_pressure(a, b, c, Ei, nui, Eo, nuo, -delta) == 0.0
    with pytest.raises(ModelError, match="need 0 <= a < b < c"):
        lame_press_fit_pressure(1.0, 1.0, 2.0, Ei, nui, Eo, nuo, delta)


def test_lame_solid_disk_under_external_pressure_is_uniformly_compressed():
    # plane strain, sigma_rr = sigma_tt = -p: eps = -p (1 + nu)(1 - 2 nu) / E in both directions
    r = np.array([0.0, 0.3, 1.0])
    u = lame_radial_displacement(r, 0.0, 1.0, 5.0, 0.2, p_out=2.0)
    np.testing.assert_allclose(u, -2.0 * 1.2 * 0.6 / 5.0 * r, rtol=1e-14, atol=0)
