"""Westergaard's periodic sinusoidal contact (DESIGN Sec. 8) on the shipped scene.

Gap ``2h sin^2(pi x)``, ``p* = pi E* h``; partial contact of half-width ``a``
with ``p = p* sin^2(pi a)`` and pressure
``2 p |cos(pi x)| sqrt(sin^2(pi a) - sin^2(pi x)) / sin^2(pi a)``; full
contact ``p + p* cos(2 pi x)``.  The scene's penalty ``k_n = 1e3`` shifts
the contact fraction by about +0.1 to +0.3 % (the tolerance is 0.5 %).
"""
import math
import os

import ngsolve as ng
import numpy as np
import pytest

from ngcontact import scene as scene_mod
from ngcontact.cell import CellProblem
from ngcontact.drivers.cell import build_cell, model_of
from ngcontact.kinds.cell import loads

pytestmark = pytest.mark.slow  # ~30-60 s: 15k dofs, five loads

SCENE = os.path.join(os.path.dirname(__file__), "..", "geometries", "cells", "westergaard.toml")


@pytest.fixture(scope="module")
def solved():
    sc = scene_mod.load(SCENE)
    mat = sc.materials["solid"]
    estar = mat.E / (2 * (1 - mat.nu ** 2))
    pstar = math.pi * estar * sc.contact.gap.h / sc.geometry.period
    P = CellProblem(build_cell(sc), model_of(sc), rtol=sc.solver.rtol, max_iter=sc.solver.max_iter)
    sols = []
    for k, load in enumerate(loads(sc)):
        sol = P.solve(load, first=(k == 0))
        pbar = -load.traction[-1]
        sols.append((pbar / pstar, sol, _pressure_error(P, pbar, pstar)))
    return sols


def _exact_pressure(pbar, pstar):
    s2 = ng.sin(math.pi * ng.x) ** 2
    if pbar >= pstar:
        return pbar + pstar * ng.cos(2 * math.pi * ng.x)
    sa = pbar / pstar
    c = ng.cos(math.pi * ng.x)
    return ng.IfPos(sa - s2, 2 * pbar * ng.sqrt(ng.IfPos(sa - s2, sa - s2, 0)) * ng.IfPos(c, c, -c) / sa, 0)


def _pressure_error(P, pbar, pstar):
    ex = _exact_pressure(pbar, pstar)
    e2 = P._contact_integral((P.pressure - ex) ** 2, order=40)
    n2 = P._contact_integral(ex ** 2, order=40)
    return math.sqrt(e2 / n2)


def test_partial_contact_fraction_and_pressure(solved):
    for ratio, sol, perr in solved:
        if ratio >= 1:
            continue
        exact = 2 * math.asin(math.sqrt(ratio)) / math.pi
        got = sol.results["contact_fraction"]
        assert abs(got - exact) <= 5e-3 * exact, f"p/p* = {ratio}: contact fraction {got} vs {exact}"
        assert perr <= 0.02, f"p/p* = {ratio}: relative L2 pressure error {perr:.3%}"


def test_full_contact(solved):
    ratio, sol, perr = solved[-1]
    assert ratio > 1
    assert sol.results["contact_fraction"] == pytest.approx(1.0, abs=1e-12)
    assert perr <= 0.01, f"relative L2 pressure error {perr:.3%}"


def test_mean_pressure_balances_the_load(solved):
    for ratio, sol, _ in solved:
        assert sol.results["mean_pressure"] == pytest.approx(sol.results["transmitted_pressure"], rel=1e-3)
        assert sol.iterations <= 40
