"""Tangent solves: BDDC-preconditioned CG against the sparse factorization, and the policy by size."""
import json
import math
import os

import ngsolve as ng
import numpy as np
import pytest

from ngcontact import cli
from ngcontact.fem.materials import isotropic
from ngcontact.geometry import bodies as gm
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.macro import macro_problem as M
from ngcontact.solvers.linear_solver import LinearSolver, match_free_dofs

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _press_fit_3d(policy, law):
    g = gm.coaxial_3d(0.5, 1.0, 1.6, 1.0, maxh=0.35, order=2)
    linear = LinearSolver(policy)
    sol = M.solve(M.MacroProblem(mesh=g.mesh, setting="3d", rough="inner", counter="outer",
                                 materials={"inner": isotropic(200.0, 0.3), "outer": isotropic(70.0, 0.25)},
                                 law=law, gap=-1e-3, order=2,
                                 supports=(M.Support(label="bottom"), M.Support(label="sym_x", components=("x",)),
                                           M.Support(label="sym_y", components=("y",))),
                                 loads=(M.Load(label="top", pressure=0.1),)), linear=linear)
    mesh = sol.problem.mesh
    p = ie.pressure(law.normal, sol.local_jump, 1e-3)
    force = ng.Integrate(p, mesh, ng.BND, definedon=mesh.Boundaries("interface"))
    return sol, force, linear


@pytest.mark.parametrize("law", [il.InterfaceLaw(normal=il.LinearLaw(kn=300.0, kt=100.0)),
                                 il.InterfaceLaw(normal=il.TabulatedLaw(closure=(0.0, 5e-4, 2e-3),
                                                                        pressure=(0.0, 0.05, 0.5), kt=100.0))],
                         ids=["linear law", "tabulated law (Newton)"])
def test_iterative_and_direct_agree_on_a_3d_press_fit(law):
    sol_d, f_d, lin_d = _press_fit_3d("direct", law)
    sol_i, f_i, lin_i = _press_fit_3d("iterative", law)
    assert lin_d.summary()["method"].startswith("direct") and lin_i.summary()["method"] == "cg+bddc"
    assert all(0 < k < 500 for k in lin_i.iterations)
    du = sol_i.gfu.vec.FV().NumPy() - sol_d.gfu.vec.FV().NumPy()
    assert np.linalg.norm(du) <= 1e-8 * np.linalg.norm(sol_d.gfu.vec.FV().NumPy())
    assert f_i == pytest.approx(f_d, rel=1e-8)


def test_a_3d_cell_solved_iteratively_equals_the_direct_solve():
    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.drivers.build import build_cell, cell_loads, model_of
    from ngcontact.scene.loader import load
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    out = {}
    for policy in ("direct", "iterative"):
        cell = build_cell(scene, maxh=0.6, interface_maxh=0.25)
        P = CellProblem(cell, model_of(scene), linear=LinearSolver(policy))
        sol = P.solve(cell_loads(scene)[0], first=True, measure=False)
        out[policy] = (sol.results, P.gfu.vec.FV().NumPy().copy(), P.linear)
    (a, ua, _), (b, ub, lin) = out["direct"], out["iterative"]
    assert lin.summary()["method"] == "cg+bddc" and len(lin.iterations) == lin.solves > 0
    assert b["contact_fraction"] == pytest.approx(a["contact_fraction"], rel=1e-9)
    assert np.linalg.norm(ub - ua) <= 1e-7 * np.linalg.norm(ua)


@pytest.mark.parametrize("enforcement", ["penalty", "exact"])
def test_the_effective_stiffness_by_cg_equals_the_factorized_one_and_the_next_load_still_solves(enforcement):
    """A large 3D cell's effective stiffness is measured without factorizing its matrix (CG with BDDC on the
    free dofs without the far-face translations, exact contact's rigid limit included): the
    direct numbers to 1e-9, and the next load's Newton solve, whose kept BDDC that assembly replaced,
    converges as the direct one does."""
    from dataclasses import replace

    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.drivers.build import build_cell, model_of
    from ngcontact.scene.loader import load
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    model = replace(model_of(scene), enforcement=enforcement, order=1 if enforcement == "exact" else 2)
    out = {}
    for policy in ("direct", "iterative"):
        cell = build_cell(scene, maxh=0.6, interface_maxh=0.25)
        P = CellProblem(cell, model, linear=LinearSolver(policy))
        sols = [P.solve(cell_load(3, pressure=p), first=(k == 0)) for k, p in enumerate((0.004, 0.008))]
        out[policy] = [np.array(s.results["effective_stiffness"]["total"]) for s in sols], sols, P.linear
    (direct, _, _), (iterative, sols, lin) = out["direct"], out["iterative"]
    assert lin.preconditioned(P.energy())
    for a, b in zip(direct, iterative):
        assert np.max(np.abs(b - a)) <= 1e-9 * np.max(np.abs(a)), (a, b)
    assert all(h["converged"] for h in sols[1].newton)
    assert sols[1].results["contact_fraction"] == pytest.approx(out["direct"][1][1].results["contact_fraction"],
                                                                rel=1e-8)


def test_a_kept_bddc_gives_the_state_of_one_rebuilt_at_every_step(monkeypatch):
    """The split energy keeps BDDC across Newton steps (only CG's iterations may grow); rebuilt at every
    step (growth limit 0) it gives the same cell state to Newton's tolerance, and the record says which."""
    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.drivers.build import build_cell, cell_loads, model_of
    from ngcontact.scene.loader import load
    from ngcontact.solvers import linear_solver
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    out, default = {}, linear_solver.REBUILD_GROWTH
    for growth in (default, 0.0):
        monkeypatch.setattr(linear_solver, "REBUILD_GROWTH", growth)
        P = CellProblem(build_cell(scene, maxh=0.6, interface_maxh=0.2), model_of(scene),
                        linear=LinearSolver("iterative"))
        sol = P.solve(cell_loads(scene)[0], first=True, measure=False)
        out[growth] = (sol, P.gfu.vec.FV().NumPy().copy(), P.linear.summary())
    (kept, u_kept, s_kept), (every, u_every, s_every) = out[default], out[0.0]
    assert s_kept["bddc_kept"] >= 1
    assert s_every["bddc_kept"] == 0 and s_every["bddc_rebuilt_for_growth"] == every.iterations - 1
    assert kept.results["contact_fraction"] == pytest.approx(every.results["contact_fraction"], rel=1e-9)
    assert np.linalg.norm(u_kept - u_every) <= 1e-7 * np.linalg.norm(u_every)


def test_inexact_newton_reaches_the_same_cell_state_with_fewer_cg_iterations():
    """Eisenstat-Walker forcing against a fixed CG tolerance of 1e-10: the same state to Newton's tolerance."""
    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.solvers.linear_solver import ETA_MAX
    from ngcontact.drivers.build import build_cell, cell_loads, model_of
    from ngcontact.scene.loader import load
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    from dataclasses import replace
    scene = replace(scene, discretization=replace(scene.discretization, symmetry="off"))   # the whole period
    out = {}
    for forcing in (False, True):
        P = CellProblem(build_cell(scene, maxh=0.6, interface_maxh=0.2), model_of(scene),
                        linear=LinearSolver("iterative", forcing=forcing))
        sol = P.solve(cell_loads(scene)[0], first=True, measure=False)
        out[forcing] = (sol, P.gfu.vec.FV().NumPy().copy(), P.linear)
    (exact, u_exact, lin_exact), (inexact, u_inexact, lin_inexact) = out[False], out[True]
    assert sum(lin_inexact.iterations) < 0.75 * sum(lin_exact.iterations)
    assert min(lin_exact.tolerances) == max(lin_exact.tolerances) == 1e-10
    # each step's tolerance: at most ETA_MAX, unless the last steps' floor target / (2 |r_k|) is above it
    r = inexact.newton[-1]["residuals"]
    target = max(P.rtol * r[0], P.atol)
    assert len(lin_inexact.tolerances) == len(r) - 1
    assert all(t <= max(ETA_MAX, 0.5 * target / rk) * (1 + 1e-12) for t, rk in zip(lin_inexact.tolerances, r))
    assert lin_inexact.summary()["inexact_newton"] and len(lin_inexact.summary()["krylov_tolerances"]) > 0
    assert inexact.results["contact_fraction"] == pytest.approx(exact.results["contact_fraction"], rel=1e-9)
    assert np.linalg.norm(u_inexact - u_exact) <= 1e-7 * np.linalg.norm(u_exact)
    assert inexact.iterations <= exact.iterations + 2


def test_the_forcing_term_follows_the_residual_and_never_over_solves():
    from ngcontact.solvers.linear_solver import ETA_MAX, ETA_MIN, forcing_term
    assert forcing_term(1.0, None, None, 1e-10) == ETA_MAX                  # first step: two digits
    assert forcing_term(0.1, 1.0, ETA_MAX, 1e-12) == pytest.approx(0.9e-2)  # faster decrease: tighter
    assert forcing_term(1e-3, 1.0, ETA_MAX, 1e-12) == ETA_MIN               # quadratic phase: three digits
    assert forcing_term(0.9, 1.0, ETA_MAX, 1e-12) == ETA_MAX                # slow phase: capped
    assert forcing_term(1e-9, 1e-5, 1e-3, 1e-10) == pytest.approx(0.05)     # the last step: to the target only


CELL = os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml")


def _cell_report(tmp_path, name, solver):
    text = open(CELL).read().replace("maxh = 0.4\ninterface_maxh = 0.12",
                                     "maxh = 0.6\ninterface_maxh = 0.25\nestimate = \"off\"\n"   # not about accuracy
                                     "symmetry = \"off\"")                     # the whole period's dofs
    path = tmp_path / f"{name}.toml"
    path.write_text(text + "\n[solver]\n" + solver)
    assert cli.main(["run", str(path), "--out", str(tmp_path / name), "--quiet"]) == 0
    return json.loads((tmp_path / name / "report.json").read_text())


def test_the_policy_goes_iterative_above_its_threshold_and_the_report_says_so(tmp_path):
    below = _cell_report(tmp_path, "below", 'linear = "auto"\n')
    above = _cell_report(tmp_path, "above", 'linear = "auto"\niterative_from = 1000\n')
    assert below["solver"]["linear"]["method"] == "direct (sparsecholesky)"
    lin = above["solver"]["linear"]
    assert lin["policy"] == "auto" and lin["method"] == "cg+bddc" and lin["threshold"] == 1000
    assert len(lin["cg_iterations"]) == lin["solves"] > 0
    for a, b in zip(below["results"]["loads"], above["results"]["loads"]):
        assert b["contact_fraction"] == pytest.approx(a["contact_fraction"], rel=1e-8)
        assert b["mean_closure"] == pytest.approx(a["mean_closure"], rel=1e-7)


def test_auto_solves_2d_problems_directly():
    mesh = ng.Mesh(ng.unit_square.GenerateMesh(maxh=0.5))
    free = ng.H1(mesh, order=1).FreeDofs()
    assert LinearSolver("auto", threshold=1).method(free, dim=2) == "direct"
    assert LinearSolver("auto", threshold=1).method(free, dim=3) == "iterative"


def test_the_space_takes_the_free_dofs_of_the_solve():
    mesh = ng.Mesh(ng.unit_square.GenerateMesh(maxh=0.5))
    V = ng.H1(mesh, order=1, dirichlet="left")
    free = ng.BitArray(V.FreeDofs())
    free.Clear(int(np.flatnonzero([free[i] for i in range(len(free))])[0]))
    match_free_dofs(V, free)
    assert [V.FreeDofs()[i] for i in range(V.ndof)] == [free[i] for i in range(V.ndof)]


def test_an_unknown_policy_is_refused():
    with pytest.raises(ValueError, match="policy = 'cg'"):
        LinearSolver("cg")
    assert math.isfinite(LinearSolver("auto").threshold)


@pytest.mark.parametrize("symmetric", [True, False])
def test_a_direct_solve_of_the_same_matrix_and_free_dofs_refreshes_its_factorization(symmetric):
    """Newton's tangents share one sparsity: the second factorization is the first one refreshed
    (``Update``), and it solves the changed matrix as a fresh one does; other free dofs factorize afresh."""
    from netgen.geom2d import unit_square
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.2))
    V = ng.H1(mesh, order=2, dirichlet="bottom")
    u, v = V.TnT()
    c = ng.Parameter(1.0)
    form = ng.BilinearForm(V, symmetric=symmetric)
    form += (ng.grad(u) * ng.grad(v) + c * u * v + (0.0 if symmetric else 0.3) * ng.grad(u)[0] * v) * ng.dx
    solver = LinearSolver("direct")
    form.Assemble()
    first = solver.prepare(form, V.FreeDofs(), symmetric=symmetric).inverse
    c.Set(40.0)
    form.Assemble()
    second = solver.prepare(form, V.FreeDofs(), symmetric=symmetric).inverse
    assert second is first
    x = ng.GridFunction(V).vec
    x.FV().NumPy()[:] = np.random.default_rng(2).normal(size=V.ndof)
    free = np.array([V.FreeDofs()[i] for i in range(V.ndof)])
    x.FV().NumPy()[~free] = 0.0
    rhs, y = x.CreateVector(), x.CreateVector()
    rhs.data = form.mat * x
    y.data = second * rhs
    assert np.max(np.abs(y.FV().NumPy() - x.FV().NumPy())) < 1e-12
    other = ng.BitArray(V.FreeDofs())
    other.Clear(int(np.flatnonzero(free)[0]))
    assert solver.prepare(form, other, symmetric=symmetric).inverse is not first


def test_a_direct_solve_of_a_matrix_with_the_values_of_its_factorization_keeps_it():
    """The same matrix assembled again with the same values (an augmented tangent whose contact set stayed)
    is not refactorized but counted as kept; once its values change it is refreshed; every solve is that of
    the matrix as it is."""
    from netgen.geom2d import unit_square
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.2))
    V = ng.H1(mesh, order=2, dirichlet="bottom")
    u, v = V.TnT()
    c = ng.Parameter(1.0)
    form = ng.BilinearForm(V, symmetric=True)
    form += (ng.grad(u) * ng.grad(v) + c * u * v) * ng.dx
    solver = LinearSolver("direct")
    x = ng.GridFunction(V).vec
    free = np.array([V.FreeDofs()[i] for i in range(V.ndof)])
    x.FV().NumPy()[:] = np.where(free, np.random.default_rng(3).normal(size=V.ndof), 0.0)
    rhs, y = x.CreateVector(), x.CreateVector()
    kept = []
    for value in (1.0, 1.0, 1.0, 7.0, 7.0):
        c.Set(value)
        form.Assemble()
        inv = solver.prepare(form, V.FreeDofs()).inverse
        kept.append(solver.kept)
        rhs.data = form.mat * x
        y.data = inv * rhs
        assert np.max(np.abs(y.FV().NumPy() - x.FV().NumPy())) < 1e-11
    assert kept == [0, 1, 2, 2, 3] and solver.summary()["factorizations_kept"] == 3


def test_a_3d_cell_s_coarse_problem_holds_the_vertices_and_its_tangent_not_the_bubble_term():
    """A 3D cell's BDDC is built from its preconditioning form (the tangent plus the bubble term on S_C), so
    the contact surface's edge dofs stay interface dofs; the tangent CG multiplies by is the energy's own
    (the whole form's assembly at the state, to round-off).  Coulomb with the penalty, whose coupled residual
    is no energy, keeps the whole contact surface on the wirebasket."""
    from dataclasses import replace

    from ngcontact.cell.fe.cell_problem import CellProblem
    from ngcontact.laws.friction import Coulomb
    from ngcontact.drivers.build import build_cell, cell_loads, model_of
    from ngcontact.scene.loader import load
    scene = load(os.path.join(ROOT, "geometries", "cells", "bisinusoid.toml"))
    WB = ng.COUPLING_TYPE.WIREBASKET_DOF
    cell = build_cell(scene, maxh=0.6, interface_maxh=0.25)
    P = CellProblem(cell, model_of(scene), linear=LinearSolver("iterative"))
    P.solve(cell_loads(scene)[0], first=True, measure=False)
    contact = P.mesh.Boundaries("contact")
    edge_dofs = {d for el in contact.Elements() for e in el.edges for d in P.X.GetDofNrs(e) if d >= 0}
    assert edge_dofs and not any(P.X.CouplingType(d) == WB for d in edge_dofs)
    assert P.linear.preconditioned(P.energy()) and P.energy().preconditioning is not None
    tangent = P.energy().mat.AsVector().FV().NumPy().copy()
    P.form.AssembleLinearization(P.gfu.vec)
    whole = P.form.mat.AsVector().FV().NumPy()
    assert np.max(np.abs(tangent - whole)) <= 1e-12 * np.max(np.abs(whole))

    coulomb = replace(model_of(scene), friction=Coulomb(w=1e-4, mu=0.3))
    Q = CellProblem(build_cell(scene, maxh=0.6, interface_maxh=0.25), coulomb, linear=LinearSolver("iterative"))
    edge_dofs = {d for el in Q.mesh.Boundaries("contact").Elements() for e in el.edges
                 for d in Q.X.GetDofNrs(e) if d >= 0}
    assert all(Q.X.CouplingType(d) == WB for d in edge_dofs) and Q.energy().preconditioning is None
