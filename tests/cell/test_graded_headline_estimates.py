"""The graded FE cell estimates every headline quantity, not the contact fraction and closure only.

Westergaard's sinusoid ``g0 = 2h sin^2(pi x)`` (period 1) between two layers twice the period deep, exact
contact: the closed forms give the contact fraction ``2a``, ``k_n0 = k_n 2a`` and ``g_n = k_n h (2a - sin(2 pi
a) / pi)`` (:mod:`ngcontact.verification.westergaard`); the normal effective stiffness is the periodic flat
punch's of the contact's half-width, which the spectral cell's stiffness of the set with its edges located meets
on 2^14 points to 1e-6.  Each
estimate of the graded solve (:mod:`ngcontact.cell.fe.grading_estimate`) is at least its true error in its
measure, and every one meets the tolerance: the refinement holds them all.
"""
import math
from dataclasses import replace

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline, scale
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.edge_grading import graded_flat_cell, solve_to_tolerance
from ngcontact.cell.fe.grading_estimate import (GRADING_RATE, alternating, edges_miss, order_estimate, orders_tail,
                                                set_share)
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.fem.materials import isotropic
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

H, NU, K_N, RATIO = 0.01, 0.3, 1e3, 0.5
PSTAR = westergaard_p_star(e_star(1.0, NU, 1.0, NU), H, 1.0)
LAW = isotropic(1.0, NU)
MODEL = CellModel(rough=LAW, counter=LAW, k_n=K_N, gap=2 * H * ng.sin(math.pi * ng.x) ** 2, order=2,
                  enforcement="exact")


def _make(vertices, order):
    cell = graded_flat_cell(1.0, 2.0, 2.0, maxh=0.3, interface_maxh=0.02, order=order, vertices=vertices)
    return CellProblem(cell, replace(MODEL, order=order), max_iter=100)


def _punch_stiffness(pressure):
    """The normal stiffness of the contact of half-width ``a``: the periodic flat punch's, ``pi E* / (2 ln(1 /
    sin(pi a)))`` (:mod:`ngcontact.cell.spectral.grid_measures`), beside the spectral cell's of the set with its
    edges located on 2^14 points, whose distance from it is the reference's spread."""
    a = math.asin(math.sqrt(pressure / PSTAR)) / math.pi
    punch = math.pi * e_star(1.0, NU, 1.0, NU) / (2 * math.log(1 / math.sin(math.pi * a)))
    n = 2 ** 14
    cell = SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 2.0), counter=Layer(1.0, NU, 2.0),
                        gap=2 * H * np.sin(np.pi * np.arange(n) / n) ** 2, k_n=K_N, enforcement="exact",
                        tol=1e-13, max_iter=100000)
    spectral = headline(cell.solve(cell_load(2, pressure=pressure)).results)["normal_stiffness"]
    assert abs(spectral / punch - 1) <= 1e-6              # the two agree: the reference is resolved
    return punch, abs(spectral - punch)


@pytest.fixture(scope="module")
def graded():
    return solve_to_tolerance(_make, cell_load(2, pressure=RATIO * PSTAR), 1e-2, 0.02, 1.0, 2)


def test_every_headline_quantity_of_a_graded_solve_is_estimated_and_meets_the_tolerance(graded):
    est = graded.estimate
    assert set(est) == {"contact_fraction", "mean_closure", "normal_stiffness", "coefficient_k_n",
                        "coefficient_g_n"}       # k_t, k_nt, g_t, G_n, G_t: zero on every order (flat, frictionless)
    assert max(est.values()) <= 1e-2            # every counted quantity held, g_n and the stiffness too
    assert "the contact set's share" in graded.remark


def test_the_graded_estimates_bound_the_errors_against_westergaard_and_the_spectral_cell(graded):
    head = headline(graded.solution.results)
    two_a = westergaard_contact_fraction(RATIO * PSTAR, PSTAR)
    stiffness, spread = _punch_stiffness(RATIO * PSTAR)
    exact = {"contact_fraction": two_a, "coefficient_k_n": K_N * two_a,
             "coefficient_g_n": K_N * H * (two_a - math.sin(math.pi * two_a) / math.pi),
             "normal_stiffness": stiffness}
    for name, value in exact.items():
        error = abs(head[name] - value) / scale(name, head)
        if name == "normal_stiffness":       # resolved by the reference: above a tenth of its last change
            assert error > 0.1 * spread / abs(value), (error, spread)
        assert graded.estimate[name] >= error, (name, graded.estimate[name], error, graded.remark)


def test_an_alternating_last_order_bounds_the_error_by_its_change():
    assert alternating([1.0, 1.2, 1.15]) == pytest.approx(0.05)
    assert alternating([1.0, 1.2, 1.25]) == 0.0 and alternating([1.0, 1.2]) == 0.0


def test_the_set_share_is_the_fractions_error_weighted_as_eq_34_weighs_the_set():
    entry = {"edge_cells": [[1e-3, 0.004], [2e-3, 0.006]], "k_n": K_N}
    assert set_share(entry, "coefficient_k_n", 1e-5) == pytest.approx(K_N * 1e-5)
    assert set_share(entry, "coefficient_g_n", 1e-5) == pytest.approx(K_N * 0.006 * 1e-5)   # the larger gap
    assert set_share(entry, "normal_stiffness", 1e-5) == 0.0 and set_share({}, "coefficient_k_n", 1e-5) == 0.0


def test_a_quantity_missing_by_its_edges_part_is_graded_further_one_missing_by_its_orders_raised():
    """:func:`edges_miss`: g_n's set share (k_n g_e times the fraction's estimate, over g_n) or the fraction's
    grading tail above the tolerance: a grading step reduces them; a miss of the orders' part alone: no."""
    entry = {"headline": {"contact_fraction": 0.3, "coefficient_g_n": 100.0}, "edge_cells": [[1e-3, 0.004]],
             "k_n": K_N, "set_move": None, "changes": None}
    orders = [entry, entry, entry]
    assert not edges_miss(orders, 1e-6, {"contact_fraction": 1e-6, "coefficient_g_n": 3e-2}, 1e-4)   # 4e-8
    assert edges_miss(orders, 1e-6, {"contact_fraction": 1e-2, "coefficient_g_n": 3e-2}, 1e-4)       # 4e-4
    assert edges_miss(orders, 3e-3, {"contact_fraction": 1e-6, "coefficient_g_n": 1e-6}, 1e-4)       # 3e-3 / 15


def test_a_penalty_stiffness_takes_its_orders_and_grading_tails_summed_and_no_set_share():
    """A penalty's stiffness, the derivative of its discrete response, is estimated by its own sequences: the
    orders' tail plus the grading tail of its own change (``rho / (1 - rho)`` of it at ``rho = 1/16``), however
    large the contact fraction's estimate; exact contact's keeps the set's share (module docstring of
    :mod:`ngcontact.cell.fe.grading_estimate`)."""
    stiffness, fraction = [2.0, 2.0001, 2.00011], [0.5, 0.50001, 0.500011]
    orders = [{"headline": {"contact_fraction": f, "mean_closure": 0.01, "normal_stiffness": k,
                            "coefficient_k_n": K_N * f},
               "edge_cells": [[1e-3, 0.004]], "k_n": K_N, "set_move": 1e-3, "stiffness_edges": None,
               "changes": {"normal_stiffness": 1.5e-4}} for k, f in zip(stiffness, fraction)]
    own = GRADING_RATE / (1.0 - GRADING_RATE) * 1.5e-4 / stiffness[-1]
    for penalty in (True, False):
        for entry in orders:
            entry["penalty"] = penalty
        estimate, _ = order_estimate(orders)
        share = estimate["contact_fraction"] / fraction[-1]              # k_n's set share relative to k_n
        if penalty:
            assert estimate["normal_stiffness"] == pytest.approx(orders_tail(stiffness, stiffness[-1])[0] + own)
            assert estimate["normal_stiffness"] < 0.1 * share           # the fraction's 6.7e-5 does not enter
        else:
            assert estimate["normal_stiffness"] == pytest.approx(share)
