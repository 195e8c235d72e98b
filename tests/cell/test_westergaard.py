"""Westergaard's periodic sinusoidal contact (oracle: :mod:`ngcontact.verification.westergaard`).

Two tiers: the default tier solves the same problem on a coarser, higher-order
cell built here (order 3, interface mesh 0.01, about 15k dofs, a few seconds);
the slow tier solves the shipped scene (order 2, interface mesh 0.005).  Both
assert the tolerances stated with each test.

Gap ``2h sin^2(pi x)``, ``p* = pi E* h``; partial contact of half-width ``a``
with ``p = p* sin^2(pi a)`` and pressure
``2 p |cos(pi x)| sqrt(sin^2(pi a) - sin^2(pi x)) / sin^2(pi a)``; full
contact ``p + p* cos(2 pi x)``.  The scene's penalty ``k_n = 1e3`` shifts
the contact fraction by about +0.1 to +0.3 % (the tolerance is 0.5 %).
"""
import math
import os

import numpy as np
import ngsolve as ng
import pytest

from ngcontact.scene import loader as scene_mod
from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.measures import contact_integral
from ngcontact.drivers.build import build_cell, model_of
from ngcontact.geometry.cell2d import flat_cell
from ngcontact.drivers.build import cell_loads as loads
from ngcontact.fem.materials import isotropic
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

SCENE = os.path.join(os.path.dirname(__file__), "..", "..", "geometries", "cells", "westergaard.toml")


RATIOS = (0.05, 0.2, 0.5, 0.8, 1.2)


def _solve_all(P, load_list, pstar):
    sols = []
    for k, load in enumerate(load_list):
        sol = P.solve(load, first=(k == 0))
        pbar = -load.traction[-1]
        sols.append((pbar / pstar, sol, _pressure_error(P, pbar, pstar)))
    return sols


@pytest.fixture(scope="module")
def fast():
    """Unit period, gap 2h sin^2(pi x) with h = 0.01, E = 1, nu = 0.3, k_n = 1e3."""
    h, nu = 0.01, 0.3
    pstar = westergaard_p_star(e_star(1.0, nu, 1.0, nu), h, 1.0)
    cell = flat_cell(maxh=0.3, interface_maxh=0.01, order=3)
    gap = 2 * h * ng.sin(math.pi * ng.x) ** 2
    law = isotropic(1.0, nu)
    P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=1e3, gap=gap, order=3))
    return _solve_all(P, [cell_load(2, pressure=r * pstar) for r in RATIOS], pstar)


@pytest.fixture(scope="module")
def solved():
    sc = scene_mod.load(SCENE)
    mat = sc.materials["solid"]
    pstar = westergaard_p_star(e_star(mat.E, mat.nu, mat.E, mat.nu), sc.contact.gap.h, sc.geometry.period)
    P = CellProblem(build_cell(sc), model_of(sc), rtol=sc.solver.rtol, max_iter=sc.solver.max_iter)
    return _solve_all(P, loads(sc), pstar)


def _exact_pressure(pbar, pstar):
    s2 = ng.sin(math.pi * ng.x) ** 2
    if pbar >= pstar:
        return pbar + pstar * ng.cos(2 * math.pi * ng.x)
    sa = pbar / pstar
    c = ng.cos(math.pi * ng.x)
    return ng.IfPos(sa - s2, 2 * pbar * ng.sqrt(ng.IfPos(sa - s2, sa - s2, 0)) * ng.IfPos(c, c, -c) / sa, 0)


def _pressure_error(P, pbar, pstar):
    ex = _exact_pressure(pbar, pstar)
    e2 = contact_integral(P, (P.pressure - ex) ** 2, order=40)
    n2 = contact_integral(P, ex ** 2, order=40)
    return math.sqrt(e2 / n2)


def _check_partial(sols):
    checked = 0
    for ratio, sol, perr in sols:
        if ratio >= 1:
            continue
        exact = westergaard_contact_fraction(ratio, 1.0)
        got = sol.results["contact_fraction"]
        assert abs(got - exact) <= 5e-3 * exact, f"p/p* = {ratio}: contact fraction {got} vs {exact}"
        assert perr <= 0.02, f"p/p* = {ratio}: relative L2 pressure error {perr:.3%}"
        checked += 1
    assert checked == 4


def _check_full(sols):
    ratio, sol, perr = sols[-1]
    assert ratio > 1
    assert sol.results["contact_fraction"] == pytest.approx(1.0, abs=1e-12)
    assert perr <= 0.01, f"relative L2 pressure error {perr:.3%}"


def _check_balance(sols):
    for ratio, sol, _ in sols:
        assert sol.results["mean_pressure"] == pytest.approx(sol.results["transmitted_pressure"], rel=1e-3)


def test_fast_partial_contact_fraction_and_pressure(fast):
    _check_partial(fast)


def test_fast_full_contact(fast):
    _check_full(fast)


def test_fast_mean_pressure_balances_the_load(fast):
    _check_balance(fast)


@pytest.mark.slow  # ~15 s: the shipped scene, 15k dofs at order 2, five loads
def test_partial_contact_fraction_and_pressure(solved):
    _check_partial(solved)


@pytest.mark.slow
def test_full_contact(solved):
    _check_full(solved)


@pytest.mark.slow
def test_mean_pressure_balances_the_load(solved):
    _check_balance(solved)
    for _, sol, _ in solved:
        assert sol.iterations <= 40


def test_bernstein_coefficients_reproduce_the_polynomial_and_bound_it():
    """The one-sign filter of ``contact_pieces``: on ``[0, 1]`` a polynomial equals
    ``sum_k b_k C(n, k) t^k (1 - t)^(n - k)`` and so lies between its smallest and largest ``b_k``."""
    from math import comb
    from ngcontact.cell.fe.edge_cuts import _bernstein
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 1.0, 41)
    for n in (1, 2, 4, 6):
        a = rng.normal(size=n + 1)
        b = _bernstein(n) @ a
        basis = np.array([comb(n, k) * t**k * (1 - t)**(n - k) for k in range(n + 1)])
        values = np.polynomial.polynomial.polyval(t, a)
        assert np.allclose(b @ basis, values, atol=1e-13)
        assert np.all(values >= b.min() - 1e-13) and np.all(values <= b.max() + 1e-13)
