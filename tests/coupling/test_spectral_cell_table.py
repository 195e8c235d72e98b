"""The two-scale loop's cell solved by the spectral small-slope cell (``two_scale.cell_method``).

The groove cell of the femur is small-slope: a flat interface with the grooves in
its initial gap.  Its FE cell and its spectral cell solve the same equations;
the table they give and the macro state the loop reaches with each must agree
to their discretization error, and the spectral cell must be what the report
and the cache say it is.
"""
import os
import pickle
import dataclasses
from functools import partial

import numpy as np
import pytest

from ngcontact.coupling import pressure_table as PT
from ngcontact.drivers import run_two_scale as R
from ngcontact.drivers.build import cell_scene_of
from ngcontact.macro import macro_measures as MM
from ngcontact.scene.loader import load

from fe_cells import FE

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GROOVES = os.path.join(ROOT, "geometries", "cells", "stem_grooves.toml")
#: the groove cell's FE discretization (fe_cells.FE) as a two-scale loop's cell keys
FE_MESH = {k: v for k, v in FE["stem_grooves"].items() if k != "method"}


def test_the_spectral_groove_cell_answers_like_the_fe_cell():
    # the cell scene's own method: "auto", the spectral cell of this small-slope cell; the FE cell by its mesh
    assert R.PressureSolve(GROOVES, 1.0).method == "spectral"
    fe = R.PressureSolve(GROOVES, 1.0, method="fe", discretization=FE_MESH)
    spectral = R.PressureSolve(GROOVES, 1.0, method="spectral")
    assert fe.method == "fe" and spectral.method == "spectral"
    assert fe.key != spectral.key                                    # two tables, two cache entries
    k_n = cell_scene_of(GROOVES, key="two_scale.cell").contact.k_n
    for p in (1e6, 5e6):
        a, b = fe(p), spectral(p)
        # the FE cell (100 quadratic elements a period) and the grid (1024 points) locate the contact edges
        # to about 1 % of the fraction; the closure is an integral and agrees far closer
        assert b["contact_fraction"] == pytest.approx(a["contact_fraction"], rel=1.5e-2)
        assert b["closure"] == pytest.approx(a["closure"], rel=1e-3)
        assert b["k_n0"] == pytest.approx(k_n * b["contact_fraction"], rel=1e-14)
        assert b["g_n0"] == pytest.approx(b["k_n0"] * b["closure"] - p, rel=1e-12)
    assert spectral.size() == {"method": "spectral", "grid_points": 1024}
    assert fe.size()["method"] == "fe" and fe.size()["ndof"] > 1000


def test_a_worker_copy_solves_the_spectral_cell_from_scratch():
    task = R.PressureSolve(GROOVES, 1.0, method="spectral")
    first = task(2e6)
    task(3e7)                                       # an earlier solve leaves no state behind
    copy = pickle.loads(pickle.dumps(task))
    assert copy.method == "spectral" and copy.key == task.key
    again, copied = task(2e6), copy(2e6)
    for key in PT.KEYS:
        assert again[key] == pytest.approx(first[key], rel=1e-12)
        assert copied[key] == pytest.approx(first[key], rel=1e-12)


def test_the_femur_loop_reaches_the_same_state_with_either_cell(tmp_path):
    """The shipped femur two-scale scene solves its cell spectrally; with the FE cell the loop takes as many
    updates and cell solves and reaches the same interface pressure (1e-4 of its peak, measured 7e-6)."""
    from ngcontact.drivers import run_macro as D
    shipped = load(os.path.join(ROOT, "geometries", "femur_stem_two_scale.toml"))
    assert shipped.two_scale.cell_method == "spectral"
    geo = D.build_geometry(shipped)
    runs = {}
    for method in ("fe", "spectral"):
        # the FE cell by the groove cell's FE mesh (the shipped cell scene leaves its method to "auto")
        mesh = {f"cell_{k}": v for k, v in FE_MESH.items()} if method == "fe" else {}
        scene = dataclasses.replace(shipped, strength=None,
                                    two_scale=dataclasses.replace(shipped.two_scale, cell_method=method, **mesh))
        object.__setattr__(scene, "base_dir", shipped.base_dir)
        problem, _ = D.problem_of(scene, geo)
        sol, res = R.couple(scene, problem, partial(D.solve_scene, scene), map_tasks=PT.serial_map,
                            cache_dir=str(tmp_path / method))
        runs[method] = (MM.interface_profile(sol)["pressure"], res)
    (p_fe, fe), (p_sp, sp) = runs["fe"], runs["spectral"]
    assert fe["converged"] and sp["converged"]
    assert fe["iterations"] == sp["iterations"] and fe["cell_solves"] == sp["cell_solves"]
    assert np.max(np.abs(p_sp - p_fe)) <= 1e-4 * np.max(p_fe)
    assert fe["cell"]["method"] == "fe" and fe["cell"]["ndof"] > 1000 and "grid_points" not in fe["cell"]
    assert sp["cell"]["method"] == "spectral" and sp["cell"]["grid_points"] == 1024 and "ndof" not in sp["cell"]
    assert sp["table"]["error_estimate"] <= shipped.two_scale.table_tol
