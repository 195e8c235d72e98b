"""Micro-stress recovery and the strength check (paper eqs. 74-78)."""
import numpy as np
import pytest

from ngcontact.coupling import strength as S
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.laws.friction import Tresca
from ngcontact.errors import SceneError
from ngcontact.geometry import profiles as pr
from ngcontact.fem.materials import isotropic, tresca, von_mises
from ngcontact.scene.loader import from_dict, load

K_N = 50.0


def _summit_cell(friction=None):
    """Plane summits (rectangular hills, summit arrangement): in compression the
    contact set is the summit plateaus and cannot change."""
    prof = pr.rectangular_valley(0.5, 0.2, 1.0)
    cell = pr.profile_cell(prof, arrangement="summit", h_rough=0.6, h_counter=0.6, maxh=0.15,
                           interface_maxh=0.05, order=2)
    model = CellModel(rough=isotropic(1.0, 0.3), counter=isotropic(0.5, 0.25), k_n=K_N, order=2,
                      macro_strain=True, friction=friction)
    return CellProblem(cell, model)


@pytest.mark.parametrize("case", ["frictionless", "stick"])
def test_linear_correctors_superpose_to_the_direct_cell_solution(case):
    """Pressure, shear (stick) and macro strain: eq. 75 against the nonlinear cell solve."""
    if case == "stick":
        # Tresca in its stick zone is the tangential spring G/w on S_C
        k_t, fr, load = 40.0, Tresca(w=0.05, G=2.0), [0.004, 0.02, -0.003]
    else:
        k_t, fr, load = 0.0, None, [0.0, 0.02, 0.003]
    P = _summit_cell(fr)
    C = S.linear_correctors(P, tangential_stiffness=k_t)
    lin = C.stress(load)
    direct, sol = S.nonlinear_stress(P, load)
    assert sol.results["contact_fraction"] == pytest.approx(0.5, abs=1e-9)  # the summits, all closed
    for b in S.BODIES:
        assert np.array_equal(C.points[b], direct[b]["points"])
        scale = np.abs(direct[b]["stress"]).max()
        err = np.abs(lin[b] - direct[b]["stress"]).max() / scale
        assert err < 1e-8, f"{b}: relative stress difference {err:.2e}"
    # the superposed displacement state reproduces the direct one as well
    v = C.state(load)
    diff = max(abs(a - c) for a, c in zip(v, P.gfu.vec))
    assert diff < 1e-8 * max(abs(c) for c in P.gfu.vec)


@pytest.mark.parametrize("chunk", [None, 1])
def test_strength_map_and_check_locate_the_largest_equivalent_stress(chunk, monkeypatch):
    """Against the stress superposed load by load; also with one macro point per block (``chunk = 1``)."""
    if chunk is not None:
        monkeypatch.setattr(S, "CHUNK_ENTRIES", chunk)
    P = _summit_cell()
    C = S.linear_correctors(P)
    loads = np.array([[0.0, 0.01, 0.0], [0.0, 0.03, 0.001], [0.0, 0.02, -0.002]])
    for crit, fn in (("von_mises", von_mises), ("tresca", tresca)):
        smap = S.strength_map(C, loads, crit)
        for b in S.BODIES:
            direct = [fn(C.stress(l)[b]) for l in loads]
            assert np.allclose(smap.values[b], [d.max() for d in direct], rtol=1e-13)
            assert np.array_equal(smap.cell_point[b], [C.points[b][int(np.argmax(d))] for d in direct])
        res = S.check(smap, {"rough": 1.0, "counter": 0.02}, np.arange(6.0).reshape(3, 2))
        worst = {b: int(np.argmax(smap.values[b])) for b in S.BODIES}
        for b, su in (("rough", 1.0), ("counter", 0.02)):
            e = res["bodies"][b]
            assert e["safety_factor"] == pytest.approx(su / smap.values[b][worst[b]])
            assert e["macro_point"]["index"] == worst[b]
        sf = min(res["bodies"][b]["safety_factor"] for b in S.BODIES)
        assert res["safety_factor"] == sf and res["holds"] == (sf > 1)


def test_strength_check_without_ultimate_stress_is_a_scene_error(tmp_path):
    import tomllib
    with open("geometries/femur_stem.toml", "rb") as fh:
        data = tomllib.load(fh)
    assert "strength" in data
    del data["materials"]["bone"]["sigma_u"]
    base = str(load("geometries/femur_stem.toml").base_dir)
    with pytest.raises(SceneError) as exc:
        from_dict(data, base_dir=base)
    assert exc.value.path == "materials.bone.sigma_u"


def test_nonlinear_recovery_agrees_with_the_correctors_where_the_contact_set_is_fixed():
    """``recovery = "nonlinear"`` re-solves the contact cell at the worst interface points.

    With the hip cell's plane summits pressed (the contact set cannot change)
    and no tangential transfer (``tangential_stiffness = 0``: the frictionless
    summit cell carries no shear, which is then dropped), the nonlinear solves
    must reproduce the superposed correctors (eq. 75) at those points.
    """
    import tomllib

    from ngcontact.drivers.run_macro import build_geometry, problem_of, solve_scene
    from ngcontact.drivers.run_strength import evaluate

    with open("geometries/femur_stem.toml", "rb") as fh:
        data = tomllib.load(fh)
    data["strength"].update(recovery="nonlinear", tangential_stiffness=0.0, nonlinear_points=3)
    scene = from_dict(data, base_dir=str(load("geometries/femur_stem.toml").base_dir))
    problem, _ = problem_of(scene, build_geometry(scene))
    sol = solve_scene(scene, problem)
    res = evaluate(scene, sol)["results"]
    solved = res["nonlinear"]
    assert len(solved) == 3
    for entry in solved:
        assert entry["contact_fraction"] == pytest.approx(0.16, rel=1e-8)
        for b, v in entry["bodies"].items():
            assert v["nonlinear"] == pytest.approx(v["linear"], rel=1e-7), (b, entry["index"])
    assert res["recovery"] == "nonlinear" and res["safety_factor"] > 0
