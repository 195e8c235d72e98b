"""The 2D spectral cell's normal stiffness on the contact set with its edges located between points (issue 35).

The tangent problem is a flat punch; its closed form on a period of two half-planes (half-width ``a``, period 1)
is ``K = pi E* / (2 ln(1 / sin(pi a)))`` (module docstring of :mod:`~ngcontact.cell.spectral.grid_measures`),
and Westergaard's sinusoid gives ``a`` at each load (:mod:`ngcontact.verification.westergaard`).
"""
import numpy as np
import pytest
from scipy.optimize import brentq

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.spectral.grid_measures import PUNCH_EDGE, edge_stiffness, effective_stiffness
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_half_width, westergaard_p_star

NU, H = 0.3, 0.01
#: the contact modulus of the two equal bodies
E_PAIR = e_star(1.0, NU, 1.0, NU)


def _punch(a: float) -> float:
    """The stiffness of the periodic flat punch of half-width ``a`` on a period 1 (module docstring)."""
    return np.pi * E_PAIR / (2 * np.log(1 / np.sin(np.pi * a)))


def _cell(n: int, gap=None) -> SpectralCell:
    """Two layers two periods deep: their finite depth changes the half-plane answer by e^(-8 pi)."""
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 2.0), counter=Layer(1.0, NU, 2.0),
                        gap=np.zeros(n) if gap is None else gap, k_n=1e3, enforcement="exact", tol=1e-12,
                        max_iter=100000)


@pytest.mark.parametrize("n", [1024, 4096])
def test_the_collocated_punch_is_the_continuous_one_with_its_edges_0_31_steps_beyond_its_last_points(n):
    x = np.arange(n) / n
    for a in (0.1, 0.25, 0.4):
        on = np.abs(x - 0.5) <= a + 1e-12                     # a centred set of points, its edges on points
        K = effective_stiffness(_cell(n), on)["matrix"][0][0]
        width = brentq(lambda s: _punch(s) - K, 1e-4, 0.4999)  # the half-width whose punch has that stiffness
        offset = (width - (on.sum() - 1) / (2 * n)) * n
        assert offset == pytest.approx(PUNCH_EDGE, abs=1e-3), (a, offset)


def test_the_located_stiffness_of_a_punch_with_its_edges_between_points_converges_at_second_order():
    errors = {}
    for n in (1024, 4096):
        x = np.arange(n) / n
        for a in (0.1, 0.4):
            for shift in (0.0, 0.7):                           # the true edges a step fraction beyond the points
                A = a + shift / n
                on = np.abs(x - 0.5) <= A + 1e-12
                # a gap opening like (x - A)^(3/2): its 2/3 power is linear, its root at the true edge
                gap = np.where(on, 0.0, np.maximum(np.abs(x - 0.5) - A, 0.0) ** 1.5)
                stiffness = edge_stiffness(_cell(n), on, gap)
                exact = _punch(A)
                errors[n, a, shift] = (abs(stiffness["located"] / exact - 1), abs(stiffness["set"] / exact - 1))
                assert effective_stiffness(_cell(n), on, gap)["matrix"][0][0] == stiffness["located"]
    for (n, a, shift), (located, grid_set) in errors.items():
        assert located <= (1e-4 if n == 1024 else 1e-5), (n, a, shift, located)
        assert located <= grid_set / 20, (n, a, shift, located, grid_set)
    largest = {n: max(e[0] for key, e in errors.items() if key[0] == n) for n in (1024, 4096)}
    assert largest[4096] <= largest[1024] / 8                                   # 16 at second order


def test_on_westergaards_sinusoid_the_reported_stiffness_is_the_punchs_of_the_exact_contact_width():
    n = 2048
    p_star = westergaard_p_star(E_PAIR, H, 1.0)                # the gap 2 H sin^2(pi x)
    cell = _cell(n, 2 * H * np.sin(np.pi * np.arange(n) / n) ** 2)
    for ratio in (0.05, 0.2, 0.5):
        sol = cell.solve(cell_load(2, pressure=ratio * p_star))
        exact = _punch(westergaard_contact_half_width(ratio * p_star, p_star, 1.0))
        K = sol.results["effective_stiffness"]["matrix"][0][0]
        on_points = effective_stiffness(cell, sol.fields["pressure"] > 0)["matrix"][0][0]
        assert abs(K / exact - 1) <= 2e-5, (ratio, K, exact)
        assert abs(on_points / exact - 1) >= 10 * abs(K / exact - 1), (ratio, on_points, K, exact)
