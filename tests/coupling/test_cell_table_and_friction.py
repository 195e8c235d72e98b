"""The two-scale table cache, warm starts, the cell's homogenized friction (paper eqs. 42-43) and the
contact overrides of a macro scene that takes its law from a cell."""
import math
import os
import shutil

import numpy as np
import pytest

from ngcontact.coupling import cell_law
from ngcontact.coupling import pressure_table as PT
from ngcontact.coupling import two_scale as T
from ngcontact.drivers import run_two_scale as R
from ngcontact.drivers.build import cell_scene_of
from ngcontact.errors import SceneError
from ngcontact.fem.materials import isotropic
from ngcontact.geometry import bodies as gm
from ngcontact.laws import homogenized as il
from ngcontact.laws.friction import Coulomb, Tresca
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import macro_problem as M
from ngcontact.scene.loader import from_dict, load

from fe_cells import FE

CELLS = os.path.join(os.path.dirname(__file__), "..", "..", "geometries", "cells")


def _press_fit(law, gap=-1e-3):
    g = gm.coaxial_plane_strain(0.5, 1.0, 2.0, maxh=0.35, order=2)
    sup = (M.Support(label="sym_x", components=("x",)), M.Support(label="sym_y", components=("y",)))
    return M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="inner", counter="outer",
                          materials={"inner": isotropic(200.0, 0.3), "outer": isotropic(70.0, 0.25)},
                          law=il.InterfaceLaw(normal=law), gap=gap, supports=sup, order=2)


def counting_response(calls):
    """A stiffening cell: closure 1e-3 (p/10)^0.6 (no cell problem behind it: the calls are counted)."""
    def response(p):
        calls.append(p)
        return {"contact_fraction": min(1.0, math.sqrt(p / 10)), "k_n0": 1.0, "g_n0": 0.0,
                "closure": 1e-3 * (p / 10) ** 0.6}
    return response


START = il.BundleLaw(weights=(300.0,), directions=((1.0, 0.0),))


@pytest.mark.parametrize("tol", [1e-2, 1e-3])
def test_the_table_and_its_law_are_within_the_tolerance_between_the_nodes(tol):
    """The checked interpolants (the monotone cubic in p of the fraction and the closure, and the macro
    law P(c)) are within the tolerance of a smooth response at pressures between the nodes (the check
    at the midpoints is an estimate: a kink of the response, e.g. where contact becomes complete, can
    hide a larger error between them)."""
    from ngcontact.laws import interface_energy as ie

    def response(p):
        return {"contact_fraction": math.sqrt(p / (p + 10.0)), "k_n0": 1.0, "g_n0": 0.0,
                "closure": 1e-3 * (p / 10) ** 0.6}
    table = PT.CellTable(response, tol=tol)
    table.cover(0.01, 20.0)
    law = PT.response_law(table)
    assert law.interpolation == "monotone_cubic" and table.error_estimate <= tol
    P = table.pressures
    f_max, c_max = max(response(q)["contact_fraction"] for q in P), max(response(q)["closure"] for q in P)
    for p in np.random.default_rng(3).uniform(P[0], P[-1], 200):
        truth, at = response(p), table(p)
        assert abs(float(at["contact_fraction"]) - truth["contact_fraction"]) <= tol * f_max
        assert abs(float(at["closure"]) - truth["closure"]) <= tol * c_max
        assert abs(float(ie.pressure(law, [truth["closure"], 0.0])) - p) <= tol * P[-1]


def test_warm_and_cold_starts_reach_the_same_solution():
    table = PT.CellTable(counting_response([]), tol=1e-3)
    table.cover(0.01, 20.0)
    problem = M.replace_law(_press_fit(START), il.InterfaceLaw(normal=PT.response_law(table)))
    start = M.solve(_press_fit(START))
    cold = M.solve(problem)
    warm = M.solve(problem, start=start.gfu.vec)
    assert warm.history.get("warm_start") and "warm_start" not in cold.history
    pc, pw = (MM.interface_profile(s)["pressure"] for s in (cold, warm))
    assert pc.max() > 0 and np.max(np.abs(pw - pc)) <= 1e-8 * pc.max()
    again = M.solve(problem, start=cold.gfu.vec)   # started at the solution: nothing left to do
    assert again.history["newton_iterations"] <= 1 < cold.history["newton_iterations"], again.history


def test_a_second_run_with_the_cached_table_solves_no_cell_problem_and_reproduces_the_first(tmp_path):
    results = []
    for run in range(2):
        calls: list = []
        table, cached = R.cached_table("k" * 64, counting_response(calls), 1e-3, PT.serial_map, str(tmp_path))
        out = T.couple(_press_fit(START), table, tol=1e-6, max_iter=6)
        if table.solves:
            R.store_table("k" * 64, table, str(tmp_path))
        results.append((cached, len(calls), table.solves, MM.interface_profile(out.solution)["pressure"]))
    (c1, n1, s1, p1), (c2, n2, s2, p2) = results
    assert not c1 and n1 == s1 > 0
    assert c2 and n2 == s2 == 0
    assert np.max(np.abs(p2 - p1)) <= 1e-12 * p1.max()


def test_table_cells_of_one_level_go_through_the_map_callable():
    batches: list = []

    def recording_map(task, items):
        batches.append(list(items))
        return [task(x) for x in items]

    calls: list = []
    table = PT.CellTable(counting_response(calls), tol=1e-3, map_tasks=recording_map)
    table.cover(0.01, 20.0)
    assert sum(len(b) for b in batches) == len(calls) == table.solves
    assert len(batches[0]) == 5 and max(len(b) for b in batches[1:]) > 1, [len(b) for b in batches]


def test_the_pressure_solve_task_is_picklable():
    import pickle
    task = R.PressureSolve(os.path.join(CELLS, "stem_grooves.toml"), 1.0, {"k_n": 1e15})
    again = pickle.loads(pickle.dumps(task))
    assert again.path == task.path and again.overrides == {"k_n": 1e15} and again._problem is None


def test_copies_of_a_pressure_solve_in_one_worker_share_its_cell_problem_and_its_numbers(monkeypatch):
    """Members of a table level arrive in a worker as pickled copies: they build the cell once (by the
    cell scene's content key), and a shared problem answers as a fresh one does."""
    import pickle
    monkeypatch.setattr(R, "_BUILT", {})
    path = os.path.join(CELLS, "stem_grooves.toml")
    mesh = {k: v for k, v in FE["stem_grooves"].items() if k != "method"}     # its FE cell (fe_cells)
    task = R.PressureSolve(path, 1.0, method="fe", discretization=mesh)
    first, second = (pickle.loads(pickle.dumps(task)) for _ in range(2))
    other_cell = pickle.loads(pickle.dumps(R.PressureSolve(path, 1.0, {"k_n": 1e15}, "fe", mesh)))
    assert first.problem() is second.problem() and other_cell.problem() is not first.problem()
    assert task.problem() is not first.problem()          # the submitting process keeps its own
    pressures = (40.0, 5.0)
    shared = [second(p) for p in pressures]               # the second after the first on one problem
    fresh = [R.PressureSolve(path, 1.0, method="fe", discretization=mesh)(p) for p in pressures[1:]]  # its own cell
    for key in PT.KEYS:
        assert shared[1][key] == pytest.approx(fresh[0][key], rel=1e-10, abs=1e-14), key


def test_a_changed_cell_scene_or_data_file_gives_another_table_key(tmp_path):
    for name in ("tabulated_gap.toml",):
        shutil.copy(os.path.join(CELLS, name), tmp_path / name)
    shutil.copytree(os.path.join(CELLS, "data"), tmp_path / "data")
    path = str(tmp_path / "tabulated_gap.toml")
    key = R.table_key(load(path), 1.0, 0.01)
    assert R.table_key(load(path), 1.0, 0.01) == key
    assert R.table_key(load(path), 1.0, 0.02) != key
    assert R.table_key(cell_scene_of(path, key="k", overrides={"k_n": 123.0}), 1.0, 0.01) != key
    gap_file = tmp_path / "data" / load(path).contact.gap.file.split("/")[-1]
    text = gap_file.read_text().splitlines()
    x, g = text[3].split(",")
    text[3] = f"{x},{float(g) * 1.5!r}"          # one gap value changed, the scene file untouched
    gap_file.write_text("\n".join(text) + "\n")
    assert R.table_key(load(path), 1.0, 0.01) != key


def test_homogenized_friction_of_a_flat_and_a_sawtooth_surface():
    """Eqs. 42-43 with |(I - n n^T) t0|: a surface all facing the counter body passes mu on (mu0 = mu) and
    its Tresca threshold per projected area (G0 = G); a face turned away carries none of mu."""
    k_n = 5.0
    ds = np.array([0.2, 0.3, 0.5])
    ang = np.radians([0.0, 30.0, -60.0])
    n = np.column_stack([np.cos(ang), np.sin(ang)])
    arrays = {"w": k_n * ds / np.cos(ang), "n": n}      # faces of projected lengths ds over |T| = 1
    f = cell_law.friction_from_bundle(arrays, k_n=k_n, friction=Coulomb(mu=0.4, w=1e-3))
    assert f == pytest.approx({"mu0": 0.4, "G0": 0.0}, rel=1e-12)
    f = cell_law.friction_from_bundle(arrays, k_n=k_n, friction=Tresca(G=7.0, w=1e-3))
    assert f == pytest.approx({"mu0": 0.0, "G0": 7.0}, rel=1e-12)
    away = {"w": np.array([k_n, k_n]), "n": np.array([[1.0, 0.0], [-0.6, 0.8]])}
    f = cell_law.friction_from_bundle(away, k_n=k_n, friction=Coulomb(mu=0.4, w=1e-3))
    assert f["mu0"] == pytest.approx(0.4, rel=1e-12)   # the facing-away direction carries no pressure


def _sawtooth_macro(**interface):
    base = os.path.join(os.path.dirname(__file__), "..", "..", "geometries", "macro")
    data = {"kind": "macro", "materials": {"steel": {"E": 210e9, "nu": 0.3}},
            "bodies": {"rough": "steel", "counter": "steel"},
            "geometry": {"shape": "block", "setting": "plane_strain",
                         "dimensions": {"length": 0.02, "h_block": 0.005, "h_base": 0.005}},
            "interface": {"cell": "sawtooth_cell.toml", "cell_length_unit": 1e-4, **interface},
            "supports": [{"boundary": "bottom"}],
            "loads": [{"boundary": "top", "pressure": 10e6, "traction": [1e6, 0.0]}],
            "discretization": {"order": 1, "maxh": 0.005}}
    return from_dict(data, base_dir=os.path.abspath(base))


def test_friction_from_the_cell_with_overridden_contact_is_in_the_law_and_the_report():
    from ngcontact.drivers.run_macro import interface_law_of
    scene = _sawtooth_macro(friction="from_cell", cell_friction="coulomb", cell_mu=0.25, cell_w=1e-3,
                            cell_k_n=2e12)
    law, info = interface_law_of(scene, 2)
    assert law.friction is not None and law.friction.mu == pytest.approx(0.25, rel=1e-9)
    assert info["friction"]["source"] == "cell" and info["friction"]["mu0"] == law.friction.mu
    assert info["cell_overrides"] == {"k_n": 2e12, "friction": "coulomb", "mu": 0.25, "w": 1e-3}
    plain, _ = interface_law_of(_sawtooth_macro(), 2)
    K, K2 = plain.normal.matrix(), law.normal.matrix()
    np.testing.assert_allclose(K2, 2 * K, rtol=1e-12)   # k_n doubled: the bundle's weights double


@pytest.mark.parametrize("interface, key, words", [
    ({"friction": "from_cell"}, "interface.friction", "no friction"),
    ({"friction": "from_cell", "cell_friction": "coulomb", "cell_mu": 0.2, "cell_w": 1e-3, "mu": 0.3},
     "interface.mu", "from_cell"),
    ({"cell_friction": "coulomb"}, "interface.cell_friction", "invalid"),
])
def test_bad_friction_or_override_keys_are_refused_by_name(interface, key, words):
    with pytest.raises(SceneError) as err:
        _sawtooth_macro(**interface)
    assert key in str(err.value) and words in str(err.value), str(err.value)


def test_overrides_without_a_cell_are_refused_and_3d_takes_two_scale_and_a_3d_strength_cell_only():
    data = {"kind": "macro", "materials": {"steel": {"E": 210e9, "nu": 0.3}},
            "bodies": {"rough": "steel", "counter": "steel"},
            "geometry": {"shape": "coaxial", "setting": "axisymmetric",
                         "dimensions": {"a": 0.5, "b": 1.0, "c": 2.0, "height": 1.0}},
            "interface": {"law": "linear", "kn": 1e12, "cell_k_n": 1e12},
            "supports": [{"boundary": "bottom", "components": ["z"]}]}
    with pytest.raises(SceneError, match="interface.cell_k_n.*names no cell"):
        from_dict(data)
    data["interface"] = {"law": "linear", "kn": 1e12}
    data["geometry"]["setting"] = "3d"
    data["supports"] = [{"boundary": "bottom"}]
    data["two_scale"] = {"cell": os.path.join(CELLS, "stem_grooves.toml"), "tol": 1.0}
    data["strength"] = {"cell": os.path.join(CELLS, "hip_hills.toml")}
    data["materials"]["steel"]["sigma_u"] = 500e6
    scene = from_dict(data)                       # the loop and the check with a 3D cell are accepted in 3D
    assert scene.two_scale is not None and scene.strength is not None
    # a 2D strength cell cannot take the two tangential tractions of a 3D interface: refused by name
    data["strength"] = {"cell": os.path.join(CELLS, "stem_grooves.toml")}
    with pytest.raises(SceneError) as err:
        from_dict(data)
    assert "strength.cell" in str(err.value) and "2D cell under a 3D macro scene" in str(err.value), str(err.value)
    # the cell's tabulated shear has one tangent: a frictional two-scale cell under from_cell is refused in 3D
    data["strength"] = {"cell": os.path.join(CELLS, "hip_hills.toml")}
    data["interface"] = {"law": "linear", "kn": 1e12, "friction": "from_cell", "cell_friction": "coulomb",
                         "cell_mu": 0.3, "cell_w": 1e-7}
    with pytest.raises(SceneError) as err:
        from_dict(data)
    assert "interface.friction" in str(err.value) and "one tangential jump" in str(err.value), str(err.value)
