"""A wrong answer is never reported as converged.

Each case was reported with exit 0 and ``converged: true`` before the gate:
Newton's quadratic path did not check its residual, and its round-off stop
grew with ``|u|`` so that a runaway iterate passed it.  Each now ends with
one line on stderr, a non-zero exit and no output.
"""
import os

import pytest

from ngcontact import cli

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

SHIPPED_BLOCK = open(os.path.join(ROOT, "geometries", "macro", "block_on_sawtooth.toml")).read()


def block(*, law: str, components: str, pressure: str) -> str:
    """The shipped block on a base with another interface law, base supports and top load."""
    text = SHIPPED_BLOCK
    for old, new in (('cell = "sawtooth_cell.toml"', law), ("cell_length_unit = 1e-4", ""),
                     ('boundary = "bottom"', f'boundary = "bottom"\n{components}'),
                     ("pressure = 10e6\ntraction = [2e6, 0.0]", f"pressure = {pressure}")):
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def run(tmp_path, capsys, text):
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    out = tmp_path / "out"
    code = cli.main(["run", str(scene), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert not out.exists(), "a failed run writes nothing"
    return code, err


def test_a_base_held_only_in_x_is_refused_and_its_singular_solve_fails(tmp_path, capsys):
    """Was: residual rose from 1.07e5 to 2.21e5, 'converged', 15.26 MPa peak under 10 MPa applied.

    The scene is refused before the solve (no support fixes y); the same problem built through the
    API, past the scene's check, is refused by the problem's rigid-motion check before any solve."""
    from dataclasses import replace

    import ngcontact
    from ngcontact.drivers.run_macro import build_geometry, problem_of
    from ngcontact.errors import ModelError
    from ngcontact.fem.two_body import Support
    from ngcontact.macro import macro_problem as M

    law = 'law = "linear"\nkn = 1e12\nkt = 1e11'
    code, err = run(tmp_path, capsys, block(law=law, components='components = ["x"]', pressure="10e6"))
    assert code == 2 and "no support fixes component 'y'" in err, err
    scene_path = tmp_path / "held.toml"
    scene_path.write_text(block(law=law, components="", pressure="10e6"))
    scene = ngcontact.load(str(scene_path))
    problem, _ = problem_of(scene, build_geometry(scene))
    loose = replace(problem, supports=(Support(label="bottom", components=("x",)),))
    with pytest.raises(ModelError, match="leave a rigid-body motion free: .*translation in y"):
        M.solve(loose)
    assert M.solve(problem).history["converged"]


HELD_SIDEWAYS = '\n\n[[supports]]\nboundary = "block_sides"\ncomponents = ["x"]\n'


def test_a_body_the_interface_cannot_hold_fails(tmp_path, capsys):
    """Was: pull-off with a normal-only law (jumps of 4.6e9 m), 'converged'.

    The block's sides are held in x, so only the normal direction is left to the law."""
    law = 'law = "bundle"\ndirections = [[1.0, 0.0]]\nweights = [1e12]'
    code, err = run(tmp_path, capsys, block(law=law, components="", pressure="-10e6") + HELD_SIDEWAYS)
    assert code == 3 and "solver failed" in err, err


def test_an_interface_too_soft_to_hold_anything_is_refused_before_the_solve(tmp_path, capsys):
    """Was: k_n = 1e-300 under 10 MPa, jumps of 2.2e9 m, 'converged'; then a solver failure (exit 3).  Now the
    weights' k h / E below 1e-8 (ngcontact.scene.magnitudes) is refused before the solve, naming them."""
    law = 'law = "bundle"\ndirections = [[1.0, 0.0]]\nweights = [1e-300]'
    code, err = run(tmp_path, capsys, block(law=law, components="", pressure="10e6") + HELD_SIDEWAYS)
    assert code == 2 and "interface.weights = [1e-300]: sum(weights) = 1e-300, sum(weights) h / E = " in err \
        and "must be at least 1e-08" in err, err


def test_a_shear_load_on_a_normal_only_law_is_refused_before_the_solve(tmp_path, capsys):
    """Was: with a shear traction too, a slip of 2.9e8 m and a zero resultant under the applied load, exit 0.

    A normal-only law holds nothing tangentially: the block's x translation is free, named before any solve."""
    law = 'law = "bundle"\ndirections = [[1.0, 0.0]]\nweights = [1e12]'
    code, err = run(tmp_path, capsys, block(law=law, components="", pressure="-10e6\ntraction = [2e6, 0.0]"))
    assert code == 2 and err.endswith("leave a rigid-body motion free: body 'block': translation in x; the "
                                      "system would be singular: fix more components or boundaries\n"), err


@pytest.mark.parametrize("k_n", ["1.0e16", "1.0e30"])
def test_a_penalty_far_beyond_the_material_is_refused_before_the_solve(tmp_path, capsys, k_n):
    """Was: a flat cell (E = 1, p = 0.01) with k_n = 1e16 reported a mean contact pressure of 0.0163
    while transmitting 0.01 (63 % equilibrium error); with 1e30 a far-face jump of 1e-31."""
    text = open(os.path.join(ROOT, "geometries", "cells", "flat_patch.toml")).read()
    assert "k_n = 1.0e3" in text
    code, err = run(tmp_path, capsys, text.replace("k_n = 1.0e3", f"k_n = {k_n}"))
    assert code == 2 and f"contact.k_n = {float(k_n)!r}: k_n h / E = " in err and "must stay below 1e+10" in err, err


def test_a_penalty_just_below_the_limit_gives_the_right_answer(tmp_path):
    """k_n h / E = 9.75e9: the laminate's far-face jump p (2 H / M + 1 / k_n) and equilibrium, to the
    round-off that a tangent of condition ~1e10 allows (observed 2.4e-6 relative)."""
    import json

    from ngcontact.verification.moduli import p_wave_modulus

    text = open(os.path.join(ROOT, "geometries", "cells", "flat_patch.toml")).read()
    scene = tmp_path / "scene.toml"
    scene.write_text(text.replace("k_n = 1.0e3", "k_n = 3.9e10"))
    assert cli.main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    loads = json.loads((tmp_path / "out" / "report.json").read_text())["results"]["loads"]
    for load in loads:
        p = load["transmitted_pressure"]
        assert load["far_face_jump"][1] == pytest.approx(p * (2.0 / p_wave_modulus(1.0, 0.3) + 1 / 3.9e10), rel=1e-5)
        assert load["mean_pressure"] == pytest.approx(p, rel=1e-4) and load["equilibrium_error"] < 1e-4


def test_the_cell_equilibrium_check_holds_for_a_solution_and_catches_a_state_that_is_not_one():
    """The interface force balances the far-face traction to round-off at a solution; a disturbed
    state is refused by the measurement with the figures."""
    import ngcontact
    from ngcontact.cell.fe import measures
    from ngcontact.errors import ConvergenceError

    report, outcome = ngcontact.solve(os.path.join(ROOT, "geometries", "cells", "flat_patch.toml"))
    assert all(load["equilibrium_error"] < 1e-10 for load in report["results"]["loads"])
    from ngcontact.drivers.build import build_cell, cell_loads, model_of
    from ngcontact.cell.fe.cell_problem import CellProblem

    scene = ngcontact.load(os.path.join(ROOT, "geometries", "cells", "flat_patch.toml"))
    problem = CellProblem(build_cell(scene), model_of(scene))
    load = cell_loads(scene)[0]
    problem.solve(load, measure=False)
    t = measures.mean_traction(problem, load)
    assert measures.equilibrium_error(problem, t) < 1e-10
    problem.gfu.vec.data *= 1.5          # 50 % more penetration: the interface now pushes harder
    assert measures.equilibrium_error(problem, t) > 0.1
    with pytest.raises(ConvergenceError, match="not in equilibrium"):
        measures.measure(problem, load)
