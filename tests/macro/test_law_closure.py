"""The closure against the law (:mod:`ngcontact.macro.law_closure`): a reported interface state whose tractions
are its law's at its jumps passes; a Coulomb fixed point stopped early, or a threshold left stale, does not,
and the verdict (:func:`ngcontact.drivers.macro_accuracy.verdict`) then says so."""
import os
from dataclasses import replace

import ngsolve as ng

from ngcontact.drivers import macro_accuracy as MA
from ngcontact.fem.interpolants import piecewise_linear
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.femur import FemurStemDims, femur_stem
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.macro.law_closure import CLOSURE_RTOL, law_closure

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BALANCE = {"error": 1e-12, "tolerance": 1e-6}


def _femur(coulomb_rtol):
    """The axisymmetric stem in its bone, Coulomb friction mu = 0.3 solved by the paper's fixed point."""
    g = femur_stem(FemurStemDims(), maxh=0.008, interface_maxh=0.004)
    law = il.InterfaceLaw(normal=il.BundleLaw(weights=(3.2e10,), directions=((1.0, 0.0),)),
                          friction=il.Friction(mu=0.3, width=1e-6))
    prob = M.MacroProblem(mesh=g.mesh, setting="axisymmetric", rough="stem", counter="bone",
                          materials={"stem": isotropic(100e9, 0.3), "bone": isotropic(9e9, 0.27)},
                          law=law, gap=piecewise_linear(ng.y, [(0.05, 2e-5), (0.13, -5e-5)]), order=2,
                          supports=(M.Support(label="base"), M.Support(label="axis", components=("r",))),
                          loads=(M.Load(label="stem_top", pressure=1e6),))
    return M.solve(prob, coulomb="fixed_point", coulomb_rtol=coulomb_rtol)


def test_the_shipped_sawtooth_block_satisfies_its_bundle_law_at_every_sample(tmp_path, monkeypatch):
    from ngcontact.drivers.run_macro import build_geometry, checked_equilibrium, problem_of, solve_scene
    from ngcontact.scene import loader
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    sc = loader.load(os.path.join(ROOT, "geometries", "macro", "block_on_sawtooth.toml"))
    problem, _ = problem_of(sc, build_geometry(sc))
    sol = solve_scene(sc, problem)
    closure = law_closure(sol, sc.solver.coulomb_rtol)
    assert closure["samples"] > 0 and closure["scale"] > 0
    assert closure["error"] <= CLOSURE_RTOL == closure["tolerance"]
    acc = MA.verdict([], None, checked_equilibrium(sol), closure=closure)
    assert [(c["name"], c["ok"]) for c in acc["checks"]] == [("equilibrium", True), ("law_closure", True)]
    assert acc["met"]


def test_a_coulomb_fixed_point_stopped_early_misses_its_law_and_the_verdict_says_so(caplog):
    converged = law_closure(_femur(1e-10))
    assert converged["error"] <= CLOSURE_RTOL
    early = _femur(0.1)                      # stops while the pressure still moves by up to 10 %
    judged = law_closure(early)              # against the default solver's tolerance
    assert judged["error"] > 100 * CLOSURE_RTOL, judged
    # against the tolerance it was solved to, the same state is within its solver's bound
    assert judged["error"] <= law_closure(early, 0.1)["tolerance"] == 0.1
    acc = MA.verdict([], None, BALANCE, closure=judged)
    assert not acc["met"] and [c["ok"] for c in acc["checks"]] == [True, False]
    assert "law_closure" in MA.warning_line(acc)


def test_a_threshold_left_stale_is_caught():
    sol = _femur(1e-10)
    stale = replace(sol, threshold=1.01 * sol.threshold)      # G held at another state's pressure
    assert law_closure(stale)["error"] > 100 * CLOSURE_RTOL
