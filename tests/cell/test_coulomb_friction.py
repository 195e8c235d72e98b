"""Coulomb friction on the cell: the coupled Newton against the fixed point.

The coupled Newton (:func:`ngcontact.solvers.coulomb_newton.coupled_newton`)'s
tangent is the derivative of its residual (central differences), it differs
from the symmetric Tresca tangent where points slip, it reaches the fixed
point's solution in fewer Newton steps, and its tangent solves by GMRES with
BDDC give the factorization's solution.
"""
from pathlib import Path

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.cell.fe.cell_energy import coulomb_residual
from ngcontact.drivers.build import build_cell, cell_loads, model_of
from ngcontact.solvers.linear_solver import LinearSolver
from ngcontact.scene import loader

SCENE = Path(__file__).resolve().parents[2] / "geometries" / "cells" / "rectangular_coulomb.toml"


@pytest.fixture(scope="module")
def valley():
    scene = loader.load(SCENE)
    return build_cell(scene, maxh=0.3, interface_maxh=0.1), model_of(scene), cell_loads(scene)


def _sweep(valley, method):
    cell, model, loads = valley
    P = CellProblem(cell, model, coulomb=method)
    return P, P.sweep(loads)


def test_coupled_tangent_is_the_derivative_of_the_residual(valley):
    """K_c v against (R(u + h v) - R(u - h v)) / 2h at a sheared state with slipping points."""
    P, sols = _sweep(valley, "newton")
    assert sols[-1].surface["slip"].max() > P.model.friction.w      # points slip: the coupling is active
    R = coulomb_residual(P)
    u = P.gfu.vec
    free = P.X.FreeDofs()
    rng = np.random.default_rng(1)
    v = u.CreateVector()
    v.FV().NumPy()[:] = rng.standard_normal(len(v)) * np.array([free[i] for i in range(len(v))])
    v.data *= 1e-7 * ng.Norm(u) / ng.Norm(v)
    up, um, rp, rm, Kv = (u.CreateVector() for _ in range(5))
    up.data, um.data = u + v, u - v
    R.Apply(up, rp)
    R.Apply(um, rm)
    fd = 0.5 * (rp.FV().NumPy() - rm.FV().NumPy())
    R.AssembleLinearization(u)
    Kv.data = R.mat * v
    assert np.linalg.norm(Kv.FV().NumPy() - fd) <= 1e-5 * np.linalg.norm(fd)
    # negative control: the Tresca tangent (threshold frozen at u) misses the coupling
    P.coulomb_previous.vec.data = u
    P.form.AssembleLinearization(u)
    Kv.data = P.form.mat * v
    assert np.linalg.norm(Kv.FV().NumPy() - fd) >= 1e-3 * np.linalg.norm(fd)


def test_coupled_newton_reaches_the_fixed_point_in_fewer_steps(valley):
    """Same states (to the fixed point's tolerance) and contact fractions; fewer Newton steps per load."""
    P, newton = _sweep(valley, "newton")
    Q, fixed = _sweep(valley, "fixed_point")
    a, b = P.gfu.vec.FV().NumPy(), Q.gfu.vec.FV().NumPy()
    assert np.max(np.abs(a - b)) <= 1e-6 * np.max(np.abs(b))
    for x, y in zip(newton, fixed):
        assert x.results["contact_fraction"] == pytest.approx(y.results["contact_fraction"], abs=1e-8)
        assert x.results["mean_pressure"] == pytest.approx(y.results["mean_pressure"], rel=1e-7)
        assert [h.get("stage") for h in x.newton][-1] == "coulomb_newton"
    # friction keeps the rigid continuation before a shear load (the frictionless restart does not apply)
    assert [s.newton[0].get("stage") for s in newton[1:]] == ["rigid_continuation"] * 2
    assert sum(s.iterations for s in newton) < sum(s.iterations for s in fixed)
    assert all(x.iterations <= y.iterations for x, y in zip(newton, fixed))


def test_coupled_newton_solves_iteratively_with_the_factorization_s_answer(valley):
    """solver.linear = 'iterative': the non-symmetric tangent by GMRES+BDDC, no fallback to the fixed point."""
    P, direct = _sweep(valley, "newton")
    cell, model, loads = valley
    Q = CellProblem(cell, model, coulomb="newton", linear=LinearSolver("iterative", rtol=1e-12))
    iterative = Q.sweep(loads)
    a, b = Q.gfu.vec.FV().NumPy(), P.gfu.vec.FV().NumPy()
    assert np.max(np.abs(a - b)) <= 1e-7 * np.max(np.abs(b))
    for x, y in zip(iterative, direct):
        assert [h.get("stage") for h in x.newton] == [h.get("stage") for h in y.newton]
        assert x.iterations == y.iterations
    assert "gmres+bddc" in Q.linear.summary()["method"]


def test_unknown_coulomb_method_is_rejected(valley):
    cell, model, _ = valley
    with pytest.raises(ValueError, match="coulomb = 'picard'"):
        CellProblem(cell, model, coulomb="picard")
