"""The 3D cell problem on the implant-coating cell (paper Fig. 6, Example 26).

Square hill of side 0.4 centred in a unit cell, plane summit at ``z = 0``,
counter body flat on the summit (summit arrangement), both bodies of a
titanium-like coating (E = 110 GPa, nu = 0.3), ``k_n = 200e9`` per unit
length, mean compression 10 MPa.  Frictionless: the summit is flat, so only
the normal component is determinate.

Checks
------
* The whole summit stays closed under compression: contact fraction
  ``|S_C_real| / |T| = 0.4^2 = 0.16``.
* Paper eq. 36 / Example 26 on the real contact set: ``k_n0 = 0.16 k_n``.
* The effective interface stiffness is finite, positive and at most
  ``k_n0``.  Why at most: with the contact pressure ``p(x)`` on the summit
  ``A`` and the mean traction ``t = (1/|T|) int_A p``, the penalty layer
  stores ``int_A p^2 / (2 k_n) >= (int_A p)^2 / (2 k_n |A|)
  = |T| t^2 / (2 k_n0)`` (Cauchy-Schwarz), so its compliance per unit
  ``|T|`` is at least ``1/k_n0``, with equality only for a uniform pressure.
  The pressure is not uniform (it concentrates at the summit's edges), so
  the inequality is strict.
* Equilibrium: the mean pressure on ``S_C`` equals the applied pressure.
"""
import math

import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.measures import sample_surface
from ngcontact.geometry.cell3d import square_hills_cell
from ngcontact.fem.materials import isotropic

K_N = 200e9
PRESSURE = 10e6


@pytest.fixture(scope="module")
def hip():
    cell = square_hills_cell(0.4, 0.2, period=1.0, arrangement="summit", h_rough=0.5,
                             h_counter=0.5, maxh=0.25)
    law = isotropic(110e9, 0.3)
    P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=K_N, order=2))
    (sol,) = P.sweep([cell_load(3, pressure=PRESSURE)])
    return P, sol


def test_summit_closed_and_example26_stiffness(hip):
    _, sol = hip
    r = sol.results
    assert r["contact_fraction"] == pytest.approx(0.16, rel=1e-8)
    assert r["coefficients"]["k_n"] == pytest.approx(0.16 * K_N, rel=1e-8)


def test_effective_stiffness_finite_and_below_kn0(hip):
    P, sol = hip
    K = sol.results["effective_stiffness"]
    assert K["components"] == ["n0"]
    keff = K["matrix"][0][0]
    kn0 = sol.results["coefficients"]["k_n"]
    assert math.isfinite(keff) and keff > 0
    assert keff < kn0, f"effective stiffness {keff:.4e} not below k_n0 = {kn0:.4e}"
    # the pressure is not uniform over the summit (the reason for the strict inequality)
    p = sample_surface(P, {"p": P.pressure})["p"]
    assert np.ptp(p) > 1e-3 * PRESSURE / 0.16


def test_pressure_balances_the_load(hip):
    _, sol = hip
    assert sol.results["mean_pressure"] == pytest.approx(PRESSURE, rel=1e-8)
    assert sol.results["transmitted_pressure"] == pytest.approx(PRESSURE, rel=1e-12)
    assert sol.iterations <= 10


def test_effective_stiffness_stays_finite_as_kn_grows():
    """Interface compliance = penalty part ~ 1/k_n + asperity part (finite as k_n -> oo).

    The reference is the flat bonded laminate, so the hills' own compliance
    remains when the penalty goes to infinity (effective stiffness, :mod:`ngcontact.cell.fe.stiffness`): the compliance
    decrements shrink tenfold per decade of ``k_n`` and the stiffness
    converges to a finite value.
    """
    cell = square_hills_cell(0.4, 0.2, period=1.0, arrangement="summit", h_rough=0.5,
                             h_counter=0.5, maxh=0.25)
    law = isotropic(110e9, 0.3)
    comp = []
    for kn in (2e12, 2e13, 2e14):
        P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=kn, order=2))
        (sol,) = P.sweep([cell_load(3, pressure=PRESSURE)])
        comp.append(sol.results["effective_stiffness"]["compliance"][0][0])
    d1, d2 = comp[0] - comp[1], comp[1] - comp[2]
    assert d1 > 0 and d2 > 0
    assert d1 / d2 == pytest.approx(10.0, rel=0.1), f"decrement ratio {d1 / d2:.3f}, expected ~10"
    asperity = comp[2] - d2 / 9.0          # geometric-series limit k_n -> infinity
    assert asperity > 0.5 * comp[2], "the asperity compliance must dominate at k_n = 2e14"
    assert 1.0 / asperity < 2 * (1.0 / comp[2])
