"""The macro problem: Lame press fit, patch test, friction, equilibrium, axisymmetric vs 3D."""
import math

import numpy as np
import ngsolve as ng
import pytest

from ngcontact.errors import ConvergenceError
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.fem.interpolants import piecewise_linear
from ngcontact.macro import macro_problem as M
from ngcontact.macro import macro_measures as MM
from ngcontact.geometry import bodies as gm
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.femur import FemurStemDims, femur_stem

# ----------------------------------------------------------- Lame press fit
A, B, C = 0.5, 1.0, 2.0          # bore, interface, mantle radii
E_IN, NU_IN, E_OUT, NU_OUT = 200.0, 0.3, 70.0, 0.25
K_N = 300.0                       # interface stiffness, stress / length
DELTA = 1e-3                      # radial interference


def lame_pressure(a, b, c, Ei, nui, Eo, nuo, k, delta):
    """Contact pressure of a press fit of two tubes through a compliant interface (plane strain).

    Plane strain, ``u_r = A r + B / r`` and ``sigma_rr = 2 (lam + mu) A - 2 mu B / r^2``
    in each tube.  The outer tube ``b < r < c`` with ``sigma_rr(b) = -p``,
    ``sigma_rr(c) = 0`` moves its bore outward by

        u_o = p * b (1 + nu_o) ((1 - 2 nu_o) b^2 + c^2) / (E_o (c^2 - b^2)) = p * C_o,

    the inner tube ``a < r < b`` with ``sigma_rr(a) = 0``, ``sigma_rr(b) = -p``
    moves its mantle inward by

        -u_i = p * b (1 + nu_i) ((1 - 2 nu_i) b^2 + a^2) / (E_i (b^2 - a^2)) = p * C_i.

    The interface carries ``p = k (J_n - g)`` with the jump ``J_n = u_i - u_o``
    (inner = rough, ``n0 = e_r``) and the gap ``g = -delta``, so
    ``p / k = delta - p C_i - p C_o``: the compliances add in series,

        p = delta / (1/k + C_i + C_o).
    """
    Ci = b * (1 + nui) * ((1 - 2 * nui) * b ** 2 + a ** 2) / (Ei * (b ** 2 - a ** 2))
    Co = b * (1 + nuo) * ((1 - 2 * nuo) * b ** 2 + c ** 2) / (Eo * (c ** 2 - b ** 2))
    return delta / (1.0 / k + Ci + Co)


def _press_fit(setting, law):
    if setting == "axisymmetric":
        g = gm.coaxial_axisymmetric(A, B, C, 0.5, maxh=0.25)
        sup = (M.Support(label="bottom", components=("z",)), M.Support(label="top", components=("z",)))
    else:
        g = gm.coaxial_plane_strain(A, B, C, maxh=0.3, order=3)
        sup = (M.Support(label="sym_x", components=("x",)), M.Support(label="sym_y", components=("y",)))
    prob = M.MacroProblem(mesh=g.mesh, setting=setting, rough="inner", counter="outer",
                          materials={"inner": isotropic(E_IN, NU_IN), "outer": isotropic(E_OUT, NU_OUT)},
                          law=law, gap=-DELTA, supports=sup, order=3)
    return M.solve(prob)


@pytest.mark.parametrize("setting", ["plane_strain", "axisymmetric"])
def test_press_fit_matches_lame_with_interface_compliance_in_series(setting):
    """Long coaxial tubes (axisymmetric: u_z = 0 at both ends, i.e. plane strain)."""
    sol = _press_fit(setting, il.InterfaceLaw(normal=il.LinearLaw(kn=K_N)))
    assert sol.history["quadratic"] and sol.history["newton_iterations"] == 1
    prof = MM.interface_profile(sol)
    p_exact = lame_pressure(A, B, C, E_IN, NU_IN, E_OUT, NU_OUT, K_N, DELTA)
    err = np.abs(prof["pressure"] / p_exact - 1).max()
    assert err < 5e-3, f"{setting}: pressure off Lame's by {err:.2e}"
    # the finite interface stiffness matters: rigid-interface Lame is clearly different
    p_rigid = lame_pressure(A, B, C, E_IN, NU_IN, E_OUT, NU_OUT, 1e12, DELTA)
    assert abs(p_rigid / p_exact - 1) > 0.05
    assert set(prof["status"]) == {"slip"}  # no tangential stiffness, no friction
    np.testing.assert_allclose(prof["jump_n"] + DELTA, prof["pressure"] / K_N, rtol=1e-10)


def test_press_fit_unilateral_bundle_law_gives_the_same_pressure():
    """A closed one-direction bundle is the linear law: same Lame pressure, Newton converges."""
    law = il.InterfaceLaw(normal=il.BundleLaw(weights=(K_N,), directions=((1.0, 0.0),)))
    sol = _press_fit("axisymmetric", law)
    prof = MM.interface_profile(sol)
    p_exact = lame_pressure(A, B, C, E_IN, NU_IN, E_OUT, NU_OUT, K_N, DELTA)
    assert np.abs(prof["pressure"] / p_exact - 1).max() < 5e-3
    assert sol.history["converged"] and not sol.history["quadratic"]


# ------------------------------------------------------------ patch test
@pytest.mark.parametrize("normal,closure", [
    (il.LinearLaw(kn=5e11, kt=2e11), 2e6 / 5e11),
    (il.BundleLaw(weights=(5e11,), directions=((1.0, 0.0),)), 2e6 / 5e11),
    # table: 1 MPa at 2 um, then 1 MPa/um; P = 2 MPa is reached at 3 um
    (il.TabulatedLaw(closure=(0.0, 2e-6, 5e-6), pressure=(0.0, 1e6, 4e6)), 3e-6)])
def test_uniform_compression_transmits_a_uniform_pressure_exactly(normal, closure):
    """Block on a base, rollers on the sides, pressure P on top: p = P and the law's closure everywhere.

    The block (rough) lies above the base, so ``n0 = -e_y`` must be found on the
    internal interface for the closure to come out positive.
    """
    g = gm.block_on_plane(0.1, 0.03, 0.02, maxh=0.012)
    P = 2e6
    prob = M.MacroProblem(
        mesh=g.mesh, setting="plane_strain", rough="block", counter="base",
        materials={"block": isotropic(10e9, 0.3), "base": isotropic(70e9, 0.2)},
        law=il.InterfaceLaw(normal=normal), order=1,
        supports=(M.Support(label="bottom", components=("y",)),
                  M.Support(label="block_sides", components=("x",)),
                  M.Support(label="base_sides", components=("x",))),
        loads=(M.Load(label="top", pressure=P),))
    sol = M.solve(prob)
    prof = MM.interface_profile(sol, points_per_element=4)
    np.testing.assert_allclose(prof["pressure"], P, rtol=1e-10)
    np.testing.assert_allclose(prof["jump_n"], closure, rtol=1e-9)
    np.testing.assert_allclose(prof["shear"], 0.0, atol=1e-9 * P)
    n0 = np.asarray(sol.frame[0](g.mesh.MapToAllElements(ng.IntegrationRule([(0.5,)], [1.0]),
                                                         g.mesh.Boundaries("interface"))))
    np.testing.assert_allclose(n0.reshape(-1, 2), np.tile([0.0, -1.0], (len(n0), 1)), atol=1e-14)
    R = MM.resultant(sol)
    assert abs(R["y"] + P * 0.1) < 1e-9 * P * 0.1 and abs(R["x"]) < 1e-9 * P * 0.1


# -------------------------------------------------------------- friction
L_BLOCK, H_BLOCK = 0.1, 0.01
N_PRESS, MU, WIDTH = 1e6, 0.3, 1e-7


def _block(top_support=(), shear=0.0, coulomb="newton"):
    g = gm.block_on_plane(L_BLOCK, H_BLOCK, 0.02, maxh=0.01)
    law = il.InterfaceLaw(normal=il.LinearLaw(kn=1e12), friction=il.Friction(mu=MU, width=WIDTH))
    prob = M.MacroProblem(
        mesh=g.mesh, setting="plane_strain", rough="block", counter="base",
        materials={"block": isotropic(10e9, 0.3), "base": isotropic(10e9, 0.3)}, law=law, order=2,
        supports=(M.Support(label="bottom"),) + tuple(top_support),
        loads=(M.Load(label="top", pressure=N_PRESS, traction=(shear, 0.0)),))
    return M.solve(prob, coulomb_rtol=1e-9, coulomb=coulomb)


COULOMB = pytest.mark.parametrize("coulomb", ["newton", "fixed_point"])


@COULOMB
def test_block_under_small_shear_sticks_with_slip_below_the_width(coulomb):
    """T = 0.5 mu N: every point sticks, |J_t| <= w, the interface carries exactly T and N."""
    T = 0.5 * MU * N_PRESS
    sol = _block(shear=T, coulomb=coulomb)
    prof = MM.interface_profile(sol)
    assert set(prof["status"]) == {"stick"}
    assert np.abs(prof["jump_t"]).max() <= WIDTH
    assert np.all(np.abs(prof["shear"]) < MU * prof["pressure"])
    R = MM.resultant(sol)
    assert abs(R["x"] - T * L_BLOCK) < 1e-8 * T * L_BLOCK
    assert abs(R["y"] + N_PRESS * L_BLOCK) < 1e-8 * N_PRESS * L_BLOCK
    assert (sol.history["coulomb_iterations"] >= 1) == (coulomb == "fixed_point")


@COULOMB
def test_block_dragged_beyond_the_limit_slides_with_reaction_mu_N(coulomb):
    """Top dragged by 500 w (T would exceed mu N): everything slips, tangential reaction = mu N."""
    drag = (M.Support(label="top", components=("x",), value=(500 * WIDTH,)),)
    sol = _block(top_support=drag, coulomb=coulomb)
    prof = MM.interface_profile(sol)
    assert set(prof["status"]) == {"slip"}
    R = MM.resultant(sol)
    assert abs(R["y"] + N_PRESS * L_BLOCK) < 1e-8 * N_PRESS * L_BLOCK
    assert abs(R["x"] - MU * N_PRESS * L_BLOCK) < 1e-6 * MU * N_PRESS * L_BLOCK, R
    np.testing.assert_allclose(np.abs(prof["shear"]), MU * prof["pressure"], rtol=1e-5,
                               atol=1e-6 * MU * N_PRESS)


def test_block_sheared_beyond_what_friction_carries_is_refused_with_the_reason():
    """T = 2 mu N under a load (no drag): no equilibrium exists, and the message says why."""
    with pytest.raises(ConvergenceError, match="A tangential load larger than friction"):
        _block(shear=2 * MU * N_PRESS)


# ------------------------------------------------ femur: equilibrium, labels
def _femur(gap_table, pressure=1e6, mu=0.3, maxh=0.008, order=2, coulomb="newton"):
    d = FemurStemDims()
    g = femur_stem(d, maxh=maxh, interface_maxh=maxh / 2)
    law = il.InterfaceLaw(normal=il.BundleLaw(weights=(3.2e10,), directions=((1.0, 0.0),)),
                          friction=il.Friction(mu=mu, width=1e-6))
    prob = M.MacroProblem(mesh=g.mesh, setting="axisymmetric", rough="stem", counter="bone",
                          materials={"stem": isotropic(100e9, 0.3), "bone": isotropic(9e9, 0.27)},
                          law=law, gap=piecewise_linear(ng.y, gap_table), order=order,
                          supports=(M.Support(label="base"), M.Support(label="axis", components=("r",))),
                          loads=(M.Load(label="stem_top", pressure=pressure),))
    return d, M.solve(prob, coulomb=coulomb, coulomb_rtol=1e-10)


def test_femur_coupled_newton_and_fixed_point_reach_the_same_coulomb_solution():
    """Where both converge, both solve the same regularized Coulomb problem: same interface, 1e-7."""
    table = [(0.05, 2e-5), (0.13, -5e-5)]
    _, a = _femur(table, coulomb="newton")
    _, b = _femur(table, coulomb="fixed_point")
    pa, pb = MM.interface_profile(a), MM.interface_profile(b)
    for key in ("pressure", "shear", "jump_n", "jump_t"):
        scale = np.max(np.abs(pb[key]))
        assert np.max(np.abs(pa[key] - pb[key])) <= 1e-7 * scale, key
    assert list(pa["status"]) == list(pb["status"]) and {"stick", "slip"} <= set(pa["status"])
    assert a.history["coulomb"]["method"] == "coupled Newton" and b.history["coulomb_iterations"] > 1


def test_femur_stem_interface_carries_the_applied_load():
    """The stem is held only by the interface: its axial resultant equals the load on the top."""
    d = FemurStemDims()
    g = femur_stem(d, maxh=0.008, interface_maxh=0.004)
    law = il.InterfaceLaw(normal=il.BundleLaw(weights=(3.2e10,), directions=((1.0, 0.0),)),
                          friction=il.Friction(mu=0.3, width=1e-6))
    gap = piecewise_linear(ng.y, [(d.z_tip, 2e-5), (d.z_corner, -5e-5)])
    prob = M.MacroProblem(mesh=g.mesh, setting="axisymmetric", rough="stem", counter="bone",
                          materials={"stem": isotropic(100e9, 0.3), "bone": isotropic(9e9, 0.27)},
                          law=law, gap=gap, order=2,
                          supports=(M.Support(label="base"), M.Support(label="axis", components=("r",))),
                          loads=(M.Load(label="stem_top", pressure=1e6),))
    sol = M.solve(prob)
    F = 1e6 * math.pi * d.r_stem ** 2
    R = MM.resultant(sol)
    assert abs(R["z"] + F) < 1e-6 * F, (R, F)
    prof = MM.interface_profile(sol)
    assert prof["s"][0] == 0 and np.all(np.diff(prof["s"]) >= 0)
    assert abs(prof["z"][0] - d.z_bone_top) < 1e-12 and abs(prof["z"][-1] - d.z_tip) < 1e-12
    length = (d.z_bone_top - d.z_corner) + math.hypot(d.r_stem - d.r_tip, d.z_corner - d.z_tip)
    assert abs(prof["s"][-1] - length) < 1e-12
    assert np.all(prof["pressure"] >= 0)
    # detachment points separate open from closed samples
    for pt in MM.detachments(prof):
        assert d.z_tip <= pt["z"] <= d.z_bone_top
    fields = MM.stress_fields(sol)
    ext = MM.field_extrema(sol, fields)
    assert all(np.isfinite(v["max"]["value"]) for v in ext.values())


def test_unknown_boundary_label_is_rejected_with_the_existing_ones():
    g = gm.block_on_plane(1.0, 0.2, 0.2, maxh=0.2)
    prob = M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="block", counter="base",
                          materials={"block": isotropic(1.0, 0.3), "base": isotropic(1.0, 0.3)},
                          law=il.InterfaceLaw(normal=il.LinearLaw(kn=1.0)),
                          supports=(M.Support(label="floor"),))
    with pytest.raises(ValueError, match="floor.*bottom"):
        M.solve(prob)


# ------------------------------------------------------- axisymmetric vs 3D
@pytest.mark.slow
def test_axisymmetric_equals_3d_for_a_rotationally_symmetric_problem():
    """Press-fitted tubes, clamped at their bases, pressed on their tops: (r, z) model vs 3D quarter.

    The tubes differ in stiffness, so the interface carries shear as well as
    the press-fit pressure.  Compared (3D quarter x 4): ``int p w ds`` and
    ``int |J_t|^2 w ds`` on the interface, the axial displacement integrated
    over the top faces and the radial one over the mantle.  The pressure is
    ``k (J_n + delta)`` with ``|J_n|`` about 0.8 ``delta``, so its error is
    the displacement error amplified about five times; it gets a looser bound.
    The 3D discrepancy must shrink under refinement (it is discretization error).
    """
    a, b, c, h = 0.5, 1.0, 1.6, 1.0
    law = il.InterfaceLaw(normal=il.LinearLaw(kn=300.0, kt=100.0))
    mats = {"inner": isotropic(200.0, 0.3), "outer": isotropic(70.0, 0.25)}
    top = (M.Load(label="top", pressure=0.1),)

    def integrals(sol, factor):
        axi = sol.problem.setting == "axisymmetric"
        mesh = sol.problem.mesh
        w = factor * (2 * math.pi * ng.x if axi else ng.CF(1.0))
        p = ie.pressure(law.normal, sol.local_jump, -DELTA)
        jt2 = sum(t * t for t in sol.local_jump[1:])
        uz = sol.u_rough[1] if axi else sol.u_rough[2]
        r = ng.x if axi else ng.sqrt(ng.x ** 2 + ng.y ** 2)
        ur = sol.u_counter[0] if axi else (sol.u_counter[0] * ng.x + sol.u_counter[1] * ng.y) / r
        on = mesh.Boundaries
        return np.array([ng.Integrate(p * w, mesh, ng.BND, definedon=on("interface")),
                         ng.Integrate(jt2 * w, mesh, ng.BND, definedon=on("interface")),
                         ng.Integrate(uz * w, mesh, ng.BND, definedon=on("top")),
                         ng.Integrate(ur * w, mesh, ng.BND, definedon=on("mantle"))])

    g2 = gm.coaxial_axisymmetric(a, b, c, h, maxh=0.05)
    sol2 = M.solve(M.MacroProblem(mesh=g2.mesh, setting="axisymmetric", rough="inner", counter="outer",
                                  materials=mats, law=law, gap=-DELTA, order=3,
                                  supports=(M.Support(label="bottom"),), loads=top))
    I2 = integrals(sol2, 1.0)
    errors = []
    for maxh in (0.3, 0.2):
        g3 = gm.coaxial_3d(a, b, c, h, maxh=maxh, order=3)
        sol3 = M.solve(M.MacroProblem(mesh=g3.mesh, setting="3d", rough="inner", counter="outer",
                                      materials=mats, law=law, gap=-DELTA, order=3,
                                      supports=(M.Support(label="bottom"),
                                                M.Support(label="sym_x", components=("x",)),
                                                M.Support(label="sym_y", components=("y",))), loads=top))
        errors.append(np.abs(integrals(sol3, 4.0) / I2 - 1))
    coarse, fine = errors
    assert fine[0] < 0.025 and fine[1] < 0.015 and fine[2] < 0.005 and fine[3] < 0.005, fine
    assert fine[0] < coarse[0] and fine[2] < coarse[2] and fine[3] < coarse[3], (coarse, fine)


# ------------------------------------------------------------ scenes, driver
ROOT = __import__("os").path.dirname(__import__("os").path.dirname(__import__("os").path.dirname(__import__("os").path.abspath(__file__))))


def test_femur_stem_scene_runs_end_to_end(tmp_path):
    """The README's main job: report keys, equilibrium, a detachment on the cone, files written."""
    import json
    import os
    from ngcontact.cli import main
    out = tmp_path / "femur"
    assert main(["run", os.path.join(ROOT, "geometries", "femur_stem.toml"), "--out", str(out), "--quiet"]) == 0
    rep = json.loads((out / "report.json").read_text())
    res = rep["results"]
    dims = res["dimensions"]
    F = 1e6 * math.pi * dims["r_stem"] ** 2
    assert abs(res["resultant"]["z"] + F) < 1e-6 * F
    prof = res["interface"]
    assert set(prof) == {"s", "r", "z", "pressure", "shear", "jump_n", "jump_t", "status"}
    assert len({len(v) for v in prof.values()}) == 1
    assert set(prof["status"]) <= {"open", "stick", "slip"} and "open" in prof["status"]
    assert min(prof["pressure"]) >= 0.0
    peak = res["maxima"]["pressure"]
    assert peak["pressure"] == max(prof["pressure"])
    # the over-reamed distal canal opens: the stem detaches on the cone, below mid-cone
    assert res["detachment"]
    for pt in res["detachment"]:
        assert dims["z_tip"] < pt["z"] < dims["z_corner"]
    assert res["maxima"]["von_mises"]["max"]["value"] > 0
    for name in ("interface.csv", "interface.png", "stress.png", "stress.vtu"):
        assert (out / name).is_file(), name
    assert rep["solver"]["converged"]


def test_scene_with_an_unknown_boundary_names_the_existing_ones():
    import os
    from ngcontact.scene import loader as scene_mod
    from ngcontact.drivers.run_macro import build_geometry, problem_of
    from ngcontact.errors import SceneError
    sc = scene_mod.load(os.path.join(ROOT, "geometries", "femur_stem.toml"))
    bad = __import__("dataclasses").replace(sc.supports[0], boundary="floor")
    sc = __import__("dataclasses").replace(sc, supports=(bad,) + sc.supports[1:])
    with pytest.raises(SceneError, match=r"supports\[0\]\.boundary = 'floor'.*base.*interface"):
        problem_of(sc, build_geometry(sc, maxh=0.02))


def test_law_from_a_cell_is_its_bundle_with_the_cells_K0_and_is_cached(tmp_path, monkeypatch):
    """Sawtooth cell (Example 27): bundle K0 = closed form; the second call reads the cache."""
    import os
    from ngcontact.drivers import build as cell_law
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path))
    path = os.path.join(ROOT, "geometries", "macro", "sawtooth_cell.toml")
    law, info = cell_law.law_from_cell(path, dim=2)
    assert not info["cached"] and len(os.listdir(tmp_path)) == 1
    b1, b2 = math.radians(30), math.radians(60)
    a2 = 1.0 / (math.sin(b2) / math.sin(b1) * math.cos(b1) + math.cos(b2))   # face lengths of one period
    a1 = a2 * math.sin(b2) / math.sin(b1)
    kn = 1e12
    expected = kn * np.array([[a1 * math.cos(b1) ** 2 + a2 * math.cos(b2) ** 2,
                               a1 * math.cos(b1) * math.sin(b1) - a2 * math.cos(b2) * math.sin(b2)],
                              [0, a1 * math.sin(b1) ** 2 + a2 * math.sin(b2) ** 2]])
    expected[1, 0] = expected[0, 1]
    np.testing.assert_allclose(np.abs(law.matrix()), np.abs(expected), rtol=1e-10)
    assert abs(law.matrix()[0, 1]) > 0.1 * kn   # the asymmetric valley couples n0 and t0
    law2, info2 = cell_law.law_from_cell(path, dim=2)
    assert info2["cached"] and law2 == law
    lin, _ = cell_law.law_from_cell(path, dim=2, linear=True)
    assert isinstance(lin, il.LinearLaw) and abs(lin.kn - expected[0, 0]) < 1e-10 * kn


def test_block_on_a_sawtooth_cell_scene_transmits_the_load(tmp_path, monkeypatch):
    """Macro scene taking its law from a cell: equilibrium and a closed interface."""
    import os
    from ngcontact.scene import loader as scene_mod
    from ngcontact.drivers.run_macro import run
    from ngcontact.output.report import Clock
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path))
    sc = scene_mod.load(os.path.join(ROOT, "geometries", "macro", "block_on_sawtooth.toml"))
    out = run(sc, Clock())
    L = sc.geometry.dimensions["length"]
    R = out.results["resultant"]
    assert abs(R["x"] - 2e6 * L) < 1e-8 * 2e6 * L and abs(R["y"] + 10e6 * L) < 1e-8 * 10e6 * L
    assert "open" not in out.results["interface"]["status"]
    assert out.results["law"]["directions"] == 2
    # the modelling error of the cell's bundle law: C eps / L with eps = 1 cell unit of 0.1 mm, L = 20 mm
    model = out.results["accuracy"]["modelling"]
    assert model["estimated"] and model["eps_over_length"] == pytest.approx(1e-4 / L, rel=1e-9)
    assert model["relative_error"] == pytest.approx(0.48 * 1e-4 / L, rel=1e-9)


def test_femur_law_from_the_hip_cell_is_the_papers_32_GPa(tmp_path, monkeypatch):
    """The hip cell (square hills, a = 0.4, k_n = 200 GPa) gives k_n0 = 32 GPa (eq. 36) and the
    femur solved with the cell's bundle equals the one with the explicit number."""
    import os
    from ngcontact.scene import loader as scene_mod
    from ngcontact.drivers.run_macro import build_geometry, problem_of, solve_scene
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path))
    pressures = []
    for path in (("femur_stem.toml",), ("macro", "femur_stem_from_cell.toml")):
        sc = scene_mod.load(os.path.join(ROOT, "geometries", *path))
        geo = build_geometry(sc, maxh=0.008, interface_maxh=0.004)
        prob, info = problem_of(sc, geo, order=2)
        np.testing.assert_allclose(info["full_contact_K0"], [[32e9, 0.0], [0.0, 0.0]], rtol=1e-12, atol=1e-3)
        pressures.append(MM.interface_profile(solve_scene(sc, prob))["pressure"])
    np.testing.assert_allclose(pressures[1], pressures[0], rtol=1e-9, atol=1e-9 * pressures[0].max())


def test_strains_beyond_small_strain_elasticity_are_reported_with_a_warning(tmp_path, caplog):
    """Was: strains of ~7000 reported without a word.  A block under 1e11 Pa (half the steel's modulus, beyond
    small strain, within the bound of ngcontact.scene.magnitudes): solved, warned, exit 0; under 10 MPa: no
    warning.  (1e14 Pa, a strain of 476, is refused before the solve: tests/scene/test_absurd_magnitudes.py.)"""
    import json
    import os

    from ngcontact import cli

    text = open(os.path.join(ROOT, "geometries", "macro", "block_on_sawtooth.toml")).read()
    text = text.replace('cell = "sawtooth_cell.toml"', 'law = "linear"\nkn = 1e12\nkt = 1e11').replace(
        "cell_length_unit = 1e-4", "").replace("pressure = 10e6", "pressure = {p}")
    for p, warned in (("1e11", True), ("10e6", False)):
        scene = tmp_path / f"block_{p}.toml"
        scene.write_text(text.replace("{p}", p))
        out = tmp_path / f"out_{p}"
        caplog.clear()
        assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
        warnings = json.loads((out / "report.json").read_text())["results"]["warnings"]
        logged = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
        assert bool(warnings) == warned and any("exceeds 0.05" in m for m in logged) == warned, logged
        if warned:
            assert "linear (small-strain) elasticity does not hold" in warnings[0]
    assert os.path.exists(tmp_path / "out_10e6" / "report.json")


def test_every_body_balances_and_an_unconverged_state_is_refused_with_the_figures():
    """Each body's applied, interface and support forces cancel at the solution; a perturbed state fails."""
    from ngcontact.drivers.run_macro import checked_equilibrium
    from ngcontact.errors import ConvergenceError

    T = 0.5 * MU * N_PRESS
    sol = _block(shear=T)
    eq = checked_equilibrium(sol)
    assert eq["error"] < 1e-9
    block, base = eq["bodies"]["block"], eq["bodies"]["base"]
    assert block["y"]["applied"] == pytest.approx(-N_PRESS * L_BLOCK, rel=1e-10)
    assert block["x"]["applied"] == pytest.approx(T * L_BLOCK, rel=1e-10)
    assert block["y"]["interface"] == pytest.approx(N_PRESS * L_BLOCK, rel=1e-8)
    assert base["y"]["supports"] == pytest.approx(-base["y"]["interface"], rel=1e-8)
    assert block["x"]["supports"] == 0.0
    free = np.array(list(sol.gfu.space.FreeDofs()), dtype=bool)
    u = np.asarray(sol.gfu.vec)
    u[free] *= 1.01
    with pytest.raises(ConvergenceError, match=r"not in equilibrium: body '(block|base)' in [xy]: applied "):
        checked_equilibrium(sol)


def test_a_copy_with_another_law_reuses_the_bodies_and_solves_as_a_fresh_problem():
    """replace_law shares the law-independent parts (space, frame, assembled K): same solution to round-off."""
    from dataclasses import replace
    g = gm.block_on_plane(L_BLOCK, H_BLOCK, 0.02, maxh=0.01)
    first = il.InterfaceLaw(normal=il.LinearLaw(kn=1e12), friction=il.Friction(mu=MU, width=WIDTH))
    second = il.InterfaceLaw(normal=il.TabulatedLaw(closure=(0.0, 1e-6, 4e-6), pressure=(0.0, 2e5, 2e6),
                                                    interpolation="monotone_cubic"),
                             friction=il.Friction(mu=MU, width=WIDTH))
    prob = M.MacroProblem(
        mesh=g.mesh, setting="plane_strain", rough="block", counter="base",
        materials={"block": isotropic(10e9, 0.3), "base": isotropic(10e9, 0.3)}, law=first, order=2,
        supports=(M.Support(label="bottom"),), loads=(M.Load(label="top", pressure=N_PRESS, traction=(0.3 * MU * N_PRESS, 0.0)),))
    a = M.solve(prob)
    shared = M.replace_law(prob, second)
    assert shared.parts is prob.parts and ("bodies", False) in prob.parts      # K of the coupled equations
    K = prob.parts[("bodies", False)][1].mat
    b = M.solve(shared, start=a.gfu.vec)
    assert b.gfu.space is a.gfu.space and prob.parts[("bodies", False)][1].mat is K   # not assembled again
    fresh = replace(prob, law=second)
    assert fresh.parts == {} and fresh.parts is not prob.parts   # any other copy starts afresh
    c = M.solve(fresh, start=a.gfu.vec)
    pb, pc = MM.interface_profile(b), MM.interface_profile(c)
    for key in ("pressure", "shear", "jump_n", "jump_t"):
        assert np.max(np.abs(pb[key] - pc[key])) <= 1e-12 * np.max(np.abs(pc[key])), key
