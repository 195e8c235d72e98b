"""The penalty's split quadrature on S_C (:mod:`ngcontact.cell.fe.contact_quadrature`): the high rule on the
contact edge's elements only, and the same energy, residual, tangent and solution as the high rule on all."""
import os

import numpy as np
import pytest

from ngcontact.cell.fe import cell_problem as cp
from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.cell.fe.contact_quadrature import ContactQuadrature, applies
from ngcontact.drivers.build import build_cell, cell_loads, model_of
from ngcontact.scene.loader import load
from ngcontact.solvers.linear_solver import LinearSolver

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))


def _problem(linear="direct"):
    return CellProblem(build_cell(SCENE, maxh=0.6, interface_maxh=0.12), model_of(SCENE),
                       linear=LinearSolver(linear))


@pytest.fixture(scope="module")
def solved():
    P = _problem()
    sol = P.solve(cell_loads(SCENE)[0], first=True, measure=False)
    return P, sol


def test_the_split_rule_gives_the_high_rule_s_energy_residual_and_tangent(solved):
    """At a state with open, closed and cut elements: only the cut ones carry the high rule, and the
    energy, residual and tangent equal the uniform high rule's (the Variation of the whole form's
    interface term) to round-off; dropping the high rule on the cut elements changes them."""
    P, _ = solved
    Q = P._quadrature
    assert isinstance(Q, ContactQuadrature)
    u = P.gfu.vec
    Q.restart(u)
    cut = [e for e in Q.contact if Q.cut[int(e)]]
    assert 0 < len(cut) < 0.5 * len(Q.contact)
    uniform = P._parts[1]            # the interface's Variation, the high rule on every element
    r_split, r_uniform = u.CreateVector(), u.CreateVector()

    def compare():
        Q.Apply(u, r_split)
        uniform.Apply(u, r_uniform)
        Q.AssembleLinearization(u)
        uniform.AssembleLinearization(u)
        a, b = r_split.FV().NumPy(), r_uniform.FV().NumPy()
        tangent = np.max(np.abs(Q.mat.AsVector().FV().NumPy() - uniform.mat.AsVector().FV().NumPy()))
        return (abs(Q.Energy(u) - uniform.Energy(u)) / abs(uniform.Energy(u)),
                np.max(np.abs(a - b)) / np.max(np.abs(b)),
                tangent / np.max(np.abs(uniform.mat.AsVector().FV().NumPy())))
    assert max(compare()) <= 1e-12
    for e in cut:                     # the low rule on the contact edge's elements too
        Q.cut.Clear(int(e))
        Q.smooth.Set(int(e))
    Q.state.vec.data = u
    Q.tangent.Assemble()
    r = u.CreateVector()
    Q.Apply(u, r)
    assert np.max(np.abs(r.FV().NumPy() - r_uniform.FV().NumPy())) > 1e-6 * np.max(np.abs(r_uniform.FV().NumPy()))
    Q.restart(u)


def test_a_cell_solved_with_the_split_rule_is_the_one_solved_with_the_high_rule(solved, monkeypatch):
    """The same solution and contact fraction as the uniform high rule, iteratively and directly."""
    P, sol = solved
    monkeypatch.setattr(cp, "quadrature_applies", lambda problem: False)
    for linear in ("direct", "iterative"):
        R = _problem(linear)
        assert R._quadrature is None
        ref = R.solve(cell_loads(SCENE)[0], first=True, measure=False)
        assert sol.results["contact_fraction"] == pytest.approx(ref.results["contact_fraction"], rel=1e-9)
        diff = np.linalg.norm(P.gfu.vec.FV().NumPy() - R.gfu.vec.FV().NumPy())
        assert diff <= 1e-7 * np.linalg.norm(R.gfu.vec.FV().NumPy())


def test_the_split_applies_only_where_the_penetration_is_a_polynomial_per_element():
    """Frictionless penalty on straight elements with the gap interpolated: yes; friction, exact
    enforcement or a curved mesh: the high rule everywhere."""
    from dataclasses import replace

    from ngcontact.laws.friction import Tresca
    assert applies(_problem())
    model = model_of(SCENE)
    for changed in (replace(model, friction=Tresca(w=1e-4, G=0.01)),
                    replace(model, interpolate_gap=False)):
        assert not applies(CellProblem(build_cell(SCENE, maxh=0.6, interface_maxh=0.25), changed))
    curved = build_cell(SCENE, maxh=0.6, interface_maxh=0.25)
    curved.mesh.Curve(2)
    assert not applies(CellProblem(curved, model))


def test_a_state_that_cuts_new_elements_widens_the_high_rule_and_the_solve_goes_on(solved, monkeypatch):
    """``covers`` adds the elements a moved contact edge cuts (and says it had to); a solve whose final
    state was not covered continues Newton from there and reports the steps of both runs."""
    P, solution = solved
    Q = P._quadrature
    u = P.gfu.vec
    Q.restart(u)
    before = {int(e) for e in Q.contact if Q.cut[int(e)]}
    moved = u.CreateVector()
    moved.data = u
    moved[P.u_dofs[P.dim - 1]] -= 2e-3          # the counter face 2e-3 further away: the edge moves
    assert not Q.covers(moved)
    after = {int(e) for e in Q.contact if Q.cut[int(e)]}
    assert before < after and Q.covers(moved)
    assert all(not Q.smooth[e] for e in after)

    R = _problem()
    calls = []
    real = ContactQuadrature.covers

    def first_time_not(self, vec):      # the first check after a solve finds an element outside C
        calls.append(1)
        return real(self, vec) and len(calls) > 1
    monkeypatch.setattr(ContactQuadrature, "covers", first_time_not)
    sol = R.solve(cell_loads(SCENE)[0], first=True, measure=False)
    assert len(calls) == 2 and all(h["converged"] for h in sol.newton)
    # against the module's solve of the same cell and load (the fixture's)
    assert sol.results["contact_fraction"] == pytest.approx(solution.results["contact_fraction"], rel=1e-9)


def test_the_split_energy_has_the_residual_as_its_derivative_at_order_3():
    """From order 3 on ``2p`` exceeds ``Integrate``'s own default order: the energy integrates each element
    by the residual's rule, so it equals the uniform high rule's and its slope along a direction is the
    residual's (a Newton step's line search would otherwise judge the step by another energy)."""
    from dataclasses import replace

    from ngcontact.cell.fe.predictor import set_start
    P = CellProblem(build_cell(SCENE, maxh=0.6, interface_maxh=0.25), replace(model_of(SCENE), order=3))
    load0 = cell_loads(SCENE)[0]
    P._apply_load(load0)
    set_start(P, load0)                  # the rigid start: open, closed and cut elements
    Q, uniform, u = P._quadrature, P._parts[1], P.gfu.vec
    Q.restart(u)
    assert any(Q.cut[int(e)] for e in Q.contact)
    assert Q.Energy(u) == pytest.approx(uniform.Energy(u), rel=1e-12)
    rng = np.random.default_rng(0)
    d, r, trial = u.CreateVector(), u.CreateVector(), u.CreateVector()
    d.FV().NumPy()[:] = rng.standard_normal(len(d)) * 1e-3 * np.max(np.abs(u.FV().NumPy()))
    Q.Apply(u, r)
    h = 1e-4
    trial.data = u + h * d
    plus = Q.Energy(trial)
    trial.data = u - h * d
    slope = (plus - Q.Energy(trial)) / (2.0 * h)
    assert slope == pytest.approx(float(np.dot(d.FV().NumPy(), r.FV().NumPy())), rel=1e-6)
