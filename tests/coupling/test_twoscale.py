"""The two-scale coupling loop (paper Sec. 3.5) and its tabulated cell response."""
import math

import numpy as np
import pytest

from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.macro import macro_measures as MM
from ngcontact.coupling import pressure_table as PT
from ngcontact.coupling import two_scale as T
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.fe_cell import FECell
from ngcontact.geometry import profiles as pr
from ngcontact.geometry import bodies as gm
from ngcontact.fem.materials import isotropic
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_p_star

import ngsolve as ng

K_N = 600.0  # micro penalty; plane summits over half the period give k_n0 = 300


def _summit_cell():
    prof = pr.rectangular_valley(0.5, 0.2, 1.0)
    cell = pr.profile_cell(prof, arrangement="summit", h_rough=0.6, h_counter=0.6, maxh=0.2,
                           interface_maxh=0.1, order=2)
    return CellProblem(cell, CellModel(rough=isotropic(200.0, 0.3), counter=isotropic(70.0, 0.25),
                                       k_n=K_N, order=2))


def _press_fit(law):
    g = gm.coaxial_plane_strain(0.5, 1.0, 2.0, maxh=0.3, order=3)
    sup = (M.Support(label="sym_x", components=("x",)), M.Support(label="sym_y", components=("y",)))
    return M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="inner", counter="outer",
                          materials={"inner": isotropic(200.0, 0.3), "outer": isotropic(70.0, 0.25)},
                          law=law, gap=-1e-3, supports=sup, order=3)


def test_fixed_contact_set_stops_after_one_update_and_reproduces_the_one_shot_solution():
    """Plane summits in compression: the contact set is the plateaus at every pressure."""
    P = _summit_cell()
    one_shot_law = il.InterfaceLaw(normal=il.BundleLaw(weights=(0.5 * K_N,), directions=((1.0, 0.0),)))
    problem = _press_fit(one_shot_law)
    one_shot = MM.interface_profile(M.solve(problem))["pressure"]
    assert one_shot.min() > 0  # all in compression
    table = PT.CellTable(lambda p: FECell.of(P).response(p), tol=1e-3)
    out = T.couple(problem, table, tol=1e-6 * one_shot.max(), max_iter=5)
    assert out.converged and out.macro_solves == 2, out.history   # start + one update
    assert np.allclose(table.as_dict()["contact_fraction"], 0.5, atol=1e-9)
    assert np.allclose(table.as_dict()["k_n0"], 0.5 * K_N, rtol=1e-9)
    assert np.max(np.abs(table.as_dict()["g_n0"])) < 1e-8 * one_shot.max()
    p = MM.interface_profile(out.solution)["pressure"]
    assert np.max(np.abs(p - one_shot)) < 1e-8 * one_shot.max()


def _westergaard_cell():
    cell = pr.profile_cell(pr.flat(1.0), h_rough=1.0, h_counter=1.0, maxh=0.25, interface_maxh=0.01, order=2)
    gap = 2 * 0.01 * ng.sin(math.pi * ng.x) ** 2
    return CellProblem(cell, CellModel(rough=isotropic(1.0, 0.3), counter=isotropic(1.0, 0.3), k_n=1e3,
                                       gap=gap, order=2))


def test_tabulated_response_is_within_its_tolerance_of_direct_solves_at_random_pressures():
    P = _westergaard_cell()
    p_star = westergaard_p_star(e_star(1.0, 0.3, 1.0, 0.3), 0.01, 1.0)
    tol = 0.02
    table = PT.CellTable(lambda p: FECell.of(P).response(p), tol=tol)
    table.cover(0.05 * p_star, 0.8 * p_star)
    assert table.error_estimate <= tol
    d = table.as_dict()
    f = np.array(d["contact_fraction"])
    assert np.all(np.diff(f) > 0)  # the real contact area grows with the pressure
    scale = {"contact_fraction": f.max(), "closure": np.max(np.abs(d["closure"]))}
    solves = table.solves
    rng = np.random.default_rng(7)
    for p in rng.uniform(0.05 * p_star, 0.8 * p_star, 4):
        direct = FECell.of(P).response(p)
        interp = table(p)
        for key, s in scale.items():
            err = abs(float(interp[key]) - direct[key]) / s
            assert err <= tol, f"{key} at p = {p:.3e}: relative error {err:.3e} > {tol}"
    assert table.solves == solves  # evaluating the table solves no cell problem


def test_table_grows_only_where_the_range_is_extended():
    calls = []

    def response(p):
        calls.append(p)
        return {"contact_fraction": math.sqrt(p), "k_n0": math.sqrt(p), "g_n0": p ** 1.5, "closure": p ** 0.7}

    table = PT.CellTable(response, tol=1e-3)
    table.cover(0.01, 1.0)
    n = len(calls)
    table.cover(0.02, 0.9)
    assert len(calls) == n
    table.cover(0.01, 2.0)
    assert len(calls) > n and max(calls) == 2.0
    assert table.solves == len(calls)
    x = np.linspace(0.01, 2.0, 101)
    exact = np.sqrt(x)
    assert np.max(np.abs(table(x)["contact_fraction"] - exact)) / exact.max() <= 1e-3


@pytest.mark.slow
def test_loop_converges_on_the_shipped_scene_with_falling_changes():
    from ngcontact.drivers import run_macro as D
    from ngcontact.output.report import Clock
    from ngcontact.scene.loader import effects, load
    scene = load("geometries/femur_stem_two_scale.toml")
    assert "two_scale_coupling" in effects(scene)
    out = D.run(scene, Clock())
    ts = out.results["two_scale"]
    changes = [h["max_change"] for h in ts["history"][1:]]
    assert ts["converged"] and changes[-1] < scene.two_scale.tol
    assert all(b < a for a, b in zip(changes, changes[1:])), changes
    assert ts["table"]["error_estimate"] <= scene.two_scale.table_tol
    assert ts["law"]["interpolation"] == "monotone_cubic" and len(ts["law"]["closure"]) == ts["table"]["nodes"] + 1
    f = np.asarray(ts["interface_coefficients"]["contact_fraction"])
    assert f.max() > 2 * f[f > 0].min()  # the real contact area varies along the interface
    # the strength check of the converged state, joined with the loop's figures
    summary = ts["summary"]
    assert summary["safety_factor"] == out.results["strength"]["safety_factor"] > 0
    assert summary["cell_solves"] == ts["cell_solves"] and summary["table_error_estimate"] <= scene.two_scale.table_tol
    assert set(summary["critical_points"]) == {"rough", "counter"}


@pytest.mark.slow
def test_warm_and_cold_starts_reach_the_same_two_scale_state(tmp_path):
    """Every macro solve warm-started from the previous one, or each cold: the same converged interface (1e-8)."""
    from ngcontact.drivers import run_macro as D
    from ngcontact.drivers import run_two_scale as R
    from ngcontact.scene.loader import load
    scene = load("geometries/femur_stem_two_scale.toml")
    geo = D.build_geometry(scene)
    problem, _ = D.problem_of(scene, geo)
    runs = {}
    for warm in (True, False):
        steps = []

        def solve(prob, start, rtol=None):
            sol = D.solve_scene(scene, prob, start, rtol)
            steps.append((start is not None, sol.history["newton_iterations"]))
            return sol
        cache = tmp_path / ("warm" if warm else "cold")   # each run from an empty cache: the same loop
        sol, res = R.couple(scene, problem, solve, map_tasks=PT.serial_map, cache_dir=str(cache), warm=warm)
        runs[warm] = (MM.interface_profile(sol)["pressure"], steps)
    (p_warm, s_warm), (p_cold, s_cold) = runs[True], runs[False]
    assert np.max(np.abs(p_warm - p_cold)) <= 1e-8 * np.max(p_cold)
    assert any(w for w, _ in s_warm) and not any(w for w, _ in s_cold)
    assert sum(n for _, n in s_warm) < sum(n for _, n in s_cold)


def test_a_table_past_its_cell_solve_bound_exits_3_naming_the_key(tmp_path, monkeypatch, capsys):
    """``two_scale.max_cell_solves`` bounds each of the loop's tables in one run: the shipped two-scale femur
    with a bound of 3 ends in exit 3, the message naming the key and the solves made, and nothing written;
    the bound of the key is the table's (a run whose tables need fewer solves is not touched by it)."""
    import os
    from ngcontact import cli
    from ngcontact.drivers import run_two_scale as R

    root = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "geometries")
    text = open(os.path.join(root, "femur_stem_two_scale.toml")).read()
    assert "\nmax_iter = 20\n" in text
    bounded = text.replace("\nmax_iter = 20\n", "\nmax_iter = 20\nmax_cell_solves = 3\n", 1)
    (tmp_path / "cells").mkdir()
    for name in ("stem_grooves.toml", "hip_hills.toml"):
        (tmp_path / "cells" / name).write_text(open(os.path.join(root, "cells", name)).read())
    scene = tmp_path / "scene.toml"
    scene.write_text(bounded)
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))       # a fresh table: every node a solve
    seen = []
    original = R.cached_table

    def spy(*args, **kwargs):
        table, found = original(*args, **kwargs)
        seen.append(table.max_solves)
        return table, found
    monkeypatch.setattr(R, "cached_table", spy)
    out = tmp_path / "out"
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 3
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert "more than 3 cell solves" in err and "two_scale.max_cell_solves" in err, err
    assert seen == [3] and not out.exists()
