"""The coupled Newton on equations without an energy: a non-symmetric, nonlinear problem with a known solution.

Without a frozen energy it globalizes by backtracking on the residual (its macro use); direct and GMRES+BDDC
tangent solves agree.  Its Coulomb use with the frozen Tresca energy: tests/cell/test_coulomb_friction.py.
"""
import math

import ngsolve as ng
import numpy as np
import pytest
from netgen.geom2d import unit_square

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.linear_solver import LinearSolver
from ngcontact.solvers.coulomb_newton import coupled_newton

EXACT = ng.sin(math.pi * ng.x) * ng.sin(math.pi * ng.y)
BETA = ng.CF((3.0, 1.0))


def _convection_reaction(maxh=0.1, order=3):
    """-lap u + beta . grad u + u^3 = f on the unit square, u = 0 on its boundary; f from EXACT.

    The convection term makes the Jacobian non-symmetric, and no energy has
    this equation as its gradient.
    """
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=maxh))
    V = ng.H1(mesh, order=order, dirichlet=".*")
    u, v = V.TnT()
    grad_exact = ng.CF((math.pi * ng.cos(math.pi * ng.x) * ng.sin(math.pi * ng.y),
                        math.pi * ng.sin(math.pi * ng.x) * ng.cos(math.pi * ng.y)))
    f = 2 * math.pi ** 2 * EXACT + BETA * grad_exact + EXACT ** 3
    form = ng.BilinearForm(V, symmetric=False)
    form += (ng.grad(u) * ng.grad(v) + (BETA * ng.grad(u)) * v + u ** 3 * v - f * v) * ng.dx
    return mesh, form, ng.GridFunction(V)


def test_converges_quadratically_to_the_manufactured_solution():
    mesh, form, gfu = _convection_reaction()
    hist = coupled_newton(form, gfu, rtol=1e-12)
    assert hist["converged"] and hist["iterations"] <= 6
    r = hist["residuals"]
    assert r[-1] <= 1e-12 * r[0]
    # quadratic: the last step squares the relative residual of the one before (up to a moderate factor)
    assert r[-1] / r[0] <= 1e3 * (r[-2] / r[0]) ** 2 or r[-1] <= 1e-14 * r[0]
    assert all(s == 1.0 for s in hist["step_lengths"])
    err = math.sqrt(ng.Integrate((gfu - EXACT) ** 2, mesh))
    assert err < 1e-4, err


def test_gmres_with_bddc_gives_the_factorization_s_answer():
    _, form_d, u_d = _convection_reaction(maxh=0.15)
    _, form_i, u_i = _convection_reaction(maxh=0.15)
    coupled_newton(form_d, u_d, rtol=1e-12)
    linear = LinearSolver("iterative", rtol=1e-12)
    coupled_newton(form_i, u_i, rtol=1e-12, linear=linear)
    a, b = u_d.vec.FV().NumPy(), u_i.vec.FV().NumPy()
    assert np.max(np.abs(a - b)) <= 1e-9 * np.max(np.abs(a))
    summary = linear.summary()
    assert summary["method"] == "gmres+bddc" and len(summary["cg_iterations"]) == summary["solves"] > 0


def test_equations_without_a_root_end_in_an_error_with_the_history():
    """R(u) = int e^u v dx has no root: every Newton step lowers u by 1 and |R| by e, without end."""
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.5))
    V = ng.H1(mesh, order=1)
    u, v = V.TnT()
    form = ng.BilinearForm(V, symmetric=False)
    form += ng.exp(u) * v * ng.dx
    gfu = ng.GridFunction(V)
    with pytest.raises(ConvergenceError, match="did not converge in 8 steps") as info:
        coupled_newton(form, gfu, max_iter=8)
    res = info.value.history["residuals"]
    np.testing.assert_allclose(np.array(res[1:]) / np.array(res[:-1]), math.exp(-1), rtol=1e-8)
