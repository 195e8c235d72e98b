"""The cell contact solver on the flat two-body cell.

Patch test, the 1/k_n penalty law, periodicity and friction (stick below the
threshold, slide with the threshold as reaction beyond it).
"""
import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell import CellModel, CellProblem, Friction, cell_load
from ngcontact.errors import ConvergenceError
from ngcontact.geometry.cell2d import flat_cell
from ngcontact.materials import isotropic

LAW = isotropic(1.0, 0.3)


@pytest.fixture(scope="module")
def cell():
    return flat_cell(maxh=0.3, order=1)


def test_patch_uniform_pressure(cell):
    kn, p = 1e3, 0.01
    P = CellProblem(cell, CellModel(rough=LAW, counter=LAW, k_n=kn, order=2))
    (sol,) = P.sweep([cell_load(2, pressure=p)])
    s = sol.surface
    closure = s["closure"]
    assert np.max(np.abs(s["pressure"] - kn * closure)) <= 1e-10 * p
    assert np.max(np.abs(s["pressure"] - p)) <= 1e-10 * p
    assert sol.results["contact_fraction"] == pytest.approx(1.0, abs=1e-12)
    assert sol.results["mean_pressure"] == pytest.approx(p, rel=1e-10)
    # interface stiffness with asperity (here: none) compliance is k_n itself
    K = sol.results["effective_stiffness"]
    assert K["components"] == ["n0"]
    assert K["matrix"][0][0] == pytest.approx(kn, rel=1e-8)


def test_penalty_error_follows_inverse_kn(cell):
    """Far-face closure minus its bonded limit equals p/k_n: slope -1 in log-log."""
    p = 0.01
    kns = np.array([1e1, 1e2, 1e3, 1e4])
    errs = []
    bonded = None
    for kn in kns:
        P = CellProblem(cell, CellModel(rough=LAW, counter=LAW, k_n=kn, order=2))
        (sol,) = P.sweep([cell_load(2, pressure=p)])
        if bonded is None:
            bonded = p / P.bonded_stiffness()[1, 1]
        errs.append(sol.results["far_face_jump"][1] - bonded)
    slope = np.polyfit(np.log(kns), np.log(errs), 1)[0]
    assert abs(slope + 1.0) < 1e-6, f"observed slope {slope:.8f}, expected -1"


def test_fluctuation_periodic_and_shift_invariant():
    h, kn = 0.01, 1e3
    nu = 0.3
    ps = np.pi * h / (2 * (1 - nu ** 2))
    c = flat_cell(maxh=0.15, interface_maxh=0.03, order=1)
    out = []
    for shift in (0.0, 0.3):
        gap = 2 * h * ng.sin(np.pi * (ng.x - shift)) ** 2
        P = CellProblem(c, CellModel(rough=LAW, counter=LAW, k_n=kn, gap=gap, order=2))
        (sol,) = P.sweep([cell_load(2, pressure=0.4 * ps)])
        ur, uc = P.gfu.components[0], P.gfu.components[1]
        mesh = c.mesh
        for y in (-0.7, -0.2):
            a, b = ur(mesh(0.0, y)), ur(mesh(1.0, y))
            assert np.max(np.abs(np.subtract(a, b))) <= 1e-13
        for y in (0.2, 0.7):
            a, b = uc(mesh(0.0, y)), uc(mesh(1.0, y))
            assert np.max(np.abs(np.subtract(a, b))) <= 1e-13
        out.append(sol.results)
    # a shifted gap on the same mesh: same response up to discretization error
    assert out[1]["mean_closure"] == pytest.approx(out[0]["mean_closure"], rel=2e-3)
    assert out[1]["contact_fraction"] == pytest.approx(out[0]["contact_fraction"], abs=0.04)


def _friction_problem(cell, friction):
    return CellProblem(cell, CellModel(rough=LAW, counter=LAW, k_n=1e3, order=2, friction=friction))


@pytest.mark.parametrize("law", ["tresca", "coulomb"])
def test_friction_stick_below_threshold(cell, law):
    p, w = 0.01, 1e-3
    fr = Friction("tresca", w=w, G=0.3 * p) if law == "tresca" else Friction("coulomb", w=w, mu=0.3)
    G = 0.3 * p
    P = _friction_problem(cell, fr)
    (sol,) = P.sweep([cell_load(2, pressure=p, shear=(0.5 * G,))])
    slip = sol.surface["slip"]
    assert slip.max() <= w
    # stick: a tangential spring G/w carries the shear, |J_t| = T w / G
    assert slip == pytest.approx(np.full_like(slip, 0.5 * w), rel=1e-8)


@pytest.mark.parametrize("law", ["tresca", "coulomb"])
def test_friction_slide_beyond_threshold(cell, law):
    p, w = 0.01, 1e-3
    fr = Friction("tresca", w=w, G=0.3 * p) if law == "tresca" else Friction("coulomb", w=w, mu=0.3)
    G = 0.3 * p
    P = _friction_problem(cell, fr)
    (sol,) = P.sweep([cell_load(2, pressure=p, tangential_jump=(-20 * w,))])
    assert sol.surface["slip"].min() > w
    shear = sol.results["mean_traction"][0]
    assert abs(shear) == pytest.approx(G, rel=1e-8)


def test_traction_beyond_threshold_has_no_equilibrium(cell):
    p, w = 0.01, 1e-3
    P = _friction_problem(cell, Friction("tresca", w=w, G=0.3 * p))
    with pytest.raises(ConvergenceError):
        P.sweep([cell_load(2, pressure=p, shear=(0.5 * p,))])


def test_frictionless_flat_cell_rejects_shear(cell):
    P = CellProblem(cell, CellModel(rough=LAW, counter=LAW, k_n=1e3, order=1))
    with pytest.raises(ValueError, match="shear"):
        P.sweep([cell_load(2, pressure=0.01, shear=(0.001,))])
