"""Newton with line search: NaN/Inf never enter the iterate; failures carry their history."""
import math

import ngsolve as ng
import pytest
from netgen.geom2d import unit_square

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.newton import minimize


@pytest.fixture(scope="module")
def scalar():
    """One global unknown u (NumberSpace) on the unit square: energies are functions of u."""
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.5))
    return ng.NumberSpace(mesh)


def energy_form(space, density):
    u = space.TrialFunction()
    form = ng.BilinearForm(space, symmetric=True)
    form += ng.Variation(density(u) * ng.dx)
    return form


def test_steps_into_nan_are_backtracked(scalar):
    """E(u) = -3u - log(1 - u): the full Newton step from 0 lands at u = 2 (log of a negative)."""
    form = energy_form(scalar, lambda u: -3 * u - ng.log(1 - u))
    gfu = ng.GridFunction(scalar)
    hist = minimize(form, gfu, rtol=1e-12)
    assert hist.converged
    assert gfu.vec[0] == pytest.approx(2.0 / 3.0, rel=1e-10)
    assert hist.steps[0] == 0.25          # 1 -> u = 2 (NaN), 1/2 -> u = 1 (inf), 1/4 accepted
    assert all(math.isfinite(e) for e in hist.energies)


def test_no_descent_direction_fails_with_history(scalar):
    """A concave energy has a negative tangent: no Newton descent direction exists."""
    form = energy_form(scalar, lambda u: -(u - 1) ** 2)
    gfu = ng.GridFunction(scalar)
    with pytest.raises(ConvergenceError, match="no descent direction") as info:
        minimize(form, gfu)
    hist = info.value.history
    assert hist["converged"] is False and len(hist["residuals"]) == 1


def test_non_convergence_reports_history(scalar):
    """|u|^1.5 has a singular tangent at its minimum; 2 steps cannot reach 1e-14."""
    form = energy_form(scalar, lambda u: ng.sqrt(u * u + 1e-12) ** 3 + 0.1 * u)
    gfu = ng.GridFunction(scalar)
    gfu.vec[0] = 1.0
    with pytest.raises(ConvergenceError, match="did not converge in 2 steps") as info:
        minimize(form, gfu, rtol=1e-14, max_iter=2)
    assert len(info.value.history["residuals"]) == 3


def test_quadratic_energy_takes_one_linear_solve(scalar):
    form = energy_form(scalar, lambda u: 0.5 * 4.0 * u * u - 2.0 * u)
    gfu = ng.GridFunction(scalar)
    hist = minimize(form, gfu, quadratic=True)
    assert hist.converged and hist.iterations == 1 and hist.linear
    assert gfu.vec[0] == pytest.approx(0.5, rel=1e-12)


def test_cycle_detector_flags_a_flip_flop_with_a_stagnating_residual():
    from ngcontact.solvers.newton import ActiveSetCycle
    d = ActiveSetCycle()
    seq = ["A", "B", "A", "B", "A"]
    msgs = [d.step(k + 1, s, 1.0) for k, s in enumerate(seq)]
    assert msgs[:4] == [None, None, None, None]
    assert msgs[4] == ("the active set of step 3 recurred at step 5 (period 2, 2 recurrences) "
                       "while the residual stagnated (1.000e+00 -> 1.000e+00)")


def test_cycle_detector_ignores_progress_and_new_states():
    from ngcontact.solvers.newton import ActiveSetCycle
    d = ActiveSetCycle()
    # the same flip-flop, but the residual falls tenfold per step: a converging iteration
    assert all(d.step(k + 1, s, 10.0 ** -k) is None for k, s in enumerate("ABABABAB"))
    d = ActiveSetCycle()
    assert all(d.step(k + 1, s, 1.0) is None for k, s in enumerate("ABCDEFGH"))
    d = ActiveSetCycle()   # staying in one state is no cycle
    assert all(d.step(k + 1, "A", 1.0) is None for k in range(8))


def test_cell_newton_records_the_active_set_and_finds_no_false_cycle():
    import math as m

    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
    from ngcontact.geometry.cell2d import flat_cell
    from ngcontact.fem.materials import isotropic

    law = isotropic(1.0, 0.3)
    c = flat_cell(maxh=0.2, interface_maxh=0.02, order=1)
    gap = 0.02 * ng.sin(m.pi * ng.x) ** 2
    P = CellProblem(c, CellModel(rough=law, counter=law, k_n=1e3, order=2, gap=gap))
    (sol,) = P.sweep([cell_load(2, pressure=0.002)])
    last = sol.newton[-1]                       # one history per Newton solve of this load
    sizes = last["active_set_sizes"]
    assert len(sizes) == last["iterations"] and sizes[-1] > 0
    total = len(P.active_set()) * 8
    assert 0 < sizes[-1] < total      # partial contact: some points in, some out


@pytest.mark.parametrize("chunk", [1 << 19, 37])
@pytest.mark.parametrize("symmetric_storage", [False, True])
def test_the_roundoff_floor_is_eps_times_abs_k_times_abs_u_on_the_free_dofs(symmetric_storage, chunk, monkeypatch):
    """``ROUNDOFF eps || |K| |u| ||`` over the free dofs, from either storage of ``K`` (a dense check), the
    matrix taken whole or in blocks of ``chunk`` stored entries."""
    import numpy as np
    from ngcontact.solvers import roundoff
    from ngcontact.solvers.roundoff import ROUNDOFF, roundoff_floors
    monkeypatch.setattr(roundoff, "CHUNK", chunk)
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.25))
    V = ng.VectorH1(mesh, order=2, dirichlet="bottom")
    u, v = V.TnT()
    a = ng.BilinearForm(V, symmetric=True, symmetric_storage=symmetric_storage)
    a += (ng.InnerProduct(ng.Grad(u), ng.Grad(v)) - 0.3 * ng.InnerProduct(u, v)) * ng.dx
    a.Assemble()
    g = ng.GridFunction(V)
    g.vec.FV().NumPy()[:] = np.random.default_rng(1).normal(size=V.ndof)
    fixed = ~np.array([V.FreeDofs()[i] for i in range(V.ndof)])
    dense = np.zeros((V.ndof, V.ndof))
    e, col = g.vec.CreateVector(), g.vec.CreateVector()
    full = ng.BilinearForm(V, symmetric=True)
    full += (ng.InnerProduct(ng.Grad(u), ng.Grad(v)) - 0.3 * ng.InnerProduct(u, v)) * ng.dx
    full.Assemble()
    for j in range(V.ndof):
        e[:] = 0.0
        e[j] = 1.0
        col.data = full.mat * e
        dense[:, j] = col.FV().NumPy()
    absu = np.abs(g.vec.FV().NumPy())
    m = np.abs(dense) @ absu
    energy_expected = ROUNDOFF * np.finfo(float).eps * (0.7 + 0.5 * absu @ m)
    m[fixed] = 0.0
    expected = ROUNDOFF * np.finfo(float).eps * np.linalg.norm(m)
    assert roundoff_floors(a.mat, g.vec, fixed)[0] == pytest.approx(expected, rel=1e-12)
    assert roundoff_floors(a.mat, g.vec, fixed, -0.7) == pytest.approx((expected, energy_expected), rel=1e-12)


@pytest.mark.parametrize("offset", [0.0, 3e2, 1e3, 3e4])
def test_steps_below_the_energy_roundoff_are_judged_by_the_residual(offset):
    """A smooth nonlinear field offset by a constant: near the solution the energy's change is below its round-off.

    ``Pi = int |grad u|^2/2 + v^4/4 + v^2/2 - f v`` with ``v = u - offset``:
    the offset leaves the problem unchanged but makes the energy a
    difference of large terms.  Newton converges quadratically in 4 steps
    whatever the offset; with Armijo's test on the energy alone it took 16
    and 14 steps at offsets 3e2 and 1e3 (steps halved at random) and did not
    converge in 30 at 3e4.
    """
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.1))
    fes = ng.H1(mesh, order=2, dirichlet="left|right")
    u = fes.TrialFunction()
    v = u - offset
    a = ng.BilinearForm(fes, symmetric=True)
    a += ng.Variation((0.5 * ng.grad(u) * ng.grad(u) + 0.25 * v ** 4 + 0.5 * v * v - 10 * ng.sin(3 * ng.x) * v)
                      * ng.dx)
    g = ng.GridFunction(fes)
    g.Set(ng.CF(offset))
    h = minimize(a, g, rtol=1e-13, max_iter=30)
    assert h.converged and h.iterations <= 5, (h.iterations, h.residuals)
    g0 = ng.GridFunction(fes)
    g0.Set(ng.CF(0.0))
    a0 = ng.BilinearForm(fes, symmetric=True)
    w = fes.TrialFunction()
    a0 += ng.Variation((0.5 * ng.grad(w) * ng.grad(w) + 0.25 * w ** 4 + 0.5 * w * w - 10 * ng.sin(3 * ng.x) * w)
                       * ng.dx)
    minimize(a0, g0, rtol=1e-13)
    assert ng.Integrate((g - offset - g0) ** 2, mesh) ** 0.5 <= 1e-8 * max(1.0, offset)
