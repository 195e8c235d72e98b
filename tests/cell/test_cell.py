"""The cell contact solver on the flat two-body cell.

Patch test, the 1/k_n penalty law, periodicity and friction (stick below the
threshold, slide with the threshold as reaction beyond it).
"""
import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.laws.friction import Coulomb, Tresca
from ngcontact.cell.fe.measures import contact_fraction
from ngcontact.cell.fe.stiffness import reference_stiffness
from ngcontact.errors import ConvergenceError
from ngcontact.geometry.cell2d import flat_cell
from ngcontact.fem.materials import isotropic
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_p_star

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
    """Far-face closure minus that of the flat bonded laminate equals p/k_n: slope -1 in log-log."""
    p = 0.01
    kns = np.array([1e1, 1e2, 1e3, 1e4])
    errs = []
    bonded = None
    for kn in kns:
        P = CellProblem(cell, CellModel(rough=LAW, counter=LAW, k_n=kn, order=2))
        (sol,) = P.sweep([cell_load(2, pressure=p)])
        if bonded is None:
            bonded = p / reference_stiffness(P)[1, 1]
        errs.append(sol.results["far_face_jump"][1] - bonded)
    slope = np.polyfit(np.log(kns), np.log(errs), 1)[0]
    assert abs(slope + 1.0) < 1e-6, f"observed slope {slope:.8f}, expected -1"


def test_fluctuation_periodic_and_shift_invariant():
    h, kn = 0.01, 1e3
    nu = 0.3
    ps = westergaard_p_star(e_star(1.0, nu, 1.0, nu), h, 1.0)
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
    fr = Tresca(w=w, G=0.3 * p) if law == "tresca" else Coulomb(w=w, mu=0.3)
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
    fr = Tresca(w=w, G=0.3 * p) if law == "tresca" else Coulomb(w=w, mu=0.3)
    G = 0.3 * p
    P = _friction_problem(cell, fr)
    (sol,) = P.sweep([cell_load(2, pressure=p, tangential_jump=(-20 * w,))])
    assert sol.surface["slip"].min() > w
    shear = sol.results["mean_traction"][0]
    assert abs(shear) == pytest.approx(G, rel=1e-8)


def test_traction_beyond_threshold_has_no_equilibrium(cell):
    p, w = 0.01, 1e-3
    P = _friction_problem(cell, Tresca(w=w, G=0.3 * p))
    with pytest.raises(ConvergenceError):
        P.sweep([cell_load(2, pressure=p, shear=(0.5 * p,))])


def test_frictionless_flat_cell_rejects_shear(cell):
    P = CellProblem(cell, CellModel(rough=LAW, counter=LAW, k_n=1e3, order=1))
    with pytest.raises(ValueError, match="shear"):
        P.sweep([cell_load(2, pressure=0.01, shear=(0.001,))])


def test_macro_strain_gives_laminate_stresses():
    """Two materials stacked along y, macro strain ``e_xx`` and pressure ``p``.

    The interface is flat and closed, nothing varies along x, so each layer
    is a homogeneous plane-strain state with ``eps_xx = e_xx``,
    ``eps_xy = 0``, ``eps_zz = 0`` and ``sigma_yy = -p``.  From
    ``lambda (eps_xx + eps_yy) + 2 mu eps_yy = -p``:

        eps_yy   = -(lambda e_xx + p) / (lambda + 2 mu)
        sigma_xx = E/(1 - nu^2) e_xx - nu/(1 - nu) p
        sigma_zz = nu E/(1 - nu^2) e_xx - nu/(1 - nu) p   (= nu (sigma_xx + sigma_yy))

    per layer with its own ``E, nu``: the stress jumps across the interface
    while ``sigma_yy`` is continuous.  Quadratic elements hold the linear
    displacements exactly.
    """
    from ngcontact.fem.materials import isotropic as iso
    mats = {"rough": (1.0, 0.3), "counter": (3.0, 0.2)}
    exx, p = 1e-3, 2e-3
    c = flat_cell(maxh=0.3, order=1)
    model = CellModel(rough=iso(*mats["rough"]), counter=iso(*mats["counter"]), k_n=1e3, order=2,
                      macro_strain=True)
    P = CellProblem(c, model)
    (sol,) = P.sweep([cell_load(2, pressure=p, macro_strain=(exx,))])
    comps = P.gfu.components
    for k, (name, y) in enumerate((("rough", -0.4), ("counter", 0.6))):
        E, nu = mats[name]
        law = model.rough if name == "rough" else model.counter
        sig = law.stress(P.body_strain(comps[k]))
        got = np.array(sig(c.mesh(0.37, y))).reshape(3, 3)
        want = np.zeros((3, 3))
        want[0, 0] = E / (1 - nu ** 2) * exx - nu / (1 - nu) * p
        want[1, 1] = -p
        want[2, 2] = nu * E / (1 - nu ** 2) * exx - nu / (1 - nu) * p
        assert np.max(np.abs(got - want)) <= 1e-9 * np.max(np.abs(want)), f"{name}: {got} vs {want}"
    assert sol.results["contact_fraction"] == pytest.approx(1.0, abs=1e-12)


def test_predictor_and_exact_line_search_cut_newton_steps():
    """First load of a Westergaard-type sweep: the rigid predictor needs fewer steps.

    Both starts must reach the same solution; the old start (everything
    closed, backtracking only) creeps towards the contact edge.
    """
    h = 0.01
    pstar = westergaard_p_star(e_star(1.0, 0.3, 1.0, 0.3), h, 1.0)
    c = flat_cell(maxh=0.3, interface_maxh=0.02, order=2)
    gap = 2 * h * ng.sin(np.pi * ng.x) ** 2
    out = {}
    for key, kw in (("new", {}), ("old", {"start": "closed", "line_search": "armijo"})):
        P = CellProblem(c, CellModel(rough=LAW, counter=LAW, k_n=1e3, gap=gap, order=2), **kw)
        sol = P.solve(cell_load(2, pressure=0.1 * pstar), first=True, measure=False)
        out[key] = (sol.iterations, contact_fraction(P), P.gfu.vec.FV().NumPy().copy())
    assert out["new"][0] <= 10
    assert out["new"][0] < out["old"][0]
    assert out["new"][1] == pytest.approx(out["old"][1], rel=1e-10)
    assert np.allclose(out["new"][2], out["old"][2], rtol=0, atol=1e-9 * np.max(np.abs(out["old"][2])))


def test_umfpack_and_sparse_cholesky_agree():
    """UMFPACK reads one triangle of symmetric storage only; the cell must not hand it one."""
    import ngsolve as ng
    c = flat_cell(maxh=0.2, interface_maxh=0.05, order=2)
    gap = 0.02 * ng.sin(np.pi * ng.x) ** 2
    out = {}
    for inv in ("sparsecholesky", "umfpack"):
        P = CellProblem(c, CellModel(rough=LAW, counter=LAW, k_n=1e3, order=2, gap=gap), inverse=inv)
        (s,) = P.sweep([cell_load(2, pressure=0.002)])
        out[inv] = np.array([s.results["contact_fraction"], s.results["far_face_jump"][1]])
    assert np.allclose(out["umfpack"], out["sparsecholesky"], rtol=1e-10, atol=0)
