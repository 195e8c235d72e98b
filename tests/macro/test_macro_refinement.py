"""A macro scene that states ``discretization.tolerance`` is refined towards it (the order raised on its mesh;
the mesh levels after it in ``test_mesh_refinement.py``):
met on Lame's press fit against the closed form, exit 3 with the figures when out of reach, and a scene
without a tolerance is run as it was."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ngcontact.drivers import macro_refinement as MR
from ngcontact.drivers import run_macro as D
from ngcontact.errors import ConvergenceError
from ngcontact.fem.materials import tresca, von_mises
from ngcontact.macro import discretization_error as DE
from ngcontact.output.report import Clock, accuracy_line
from ngcontact.scene import loader
from ngcontact.verification.lame import lame_press_fit_pressure

A, B, C = 0.5, 1.0, 2.0
E_IN, NU_IN, E_OUT, NU_OUT = 200.0, 0.3, 70.0, 0.25
K_N, DELTA = 300.0, 1e-3

PRESS_FIT = f"""\
kind = "macro"

[materials.inner]
E = {E_IN}
nu = {NU_IN}

[materials.outer]
E = {E_OUT}
nu = {NU_OUT}

[bodies]
rough = "inner"
counter = "outer"

[geometry]
shape = "coaxial"
setting = "plane_strain"

[geometry.dimensions]
a = {A}
b = {B}
c = {C}

[interface]
law = "linear"
kn = {K_N}
gap = {-DELTA}

[[supports]]
boundary = "sym_x"
components = ["x"]

[[supports]]
boundary = "sym_y"
components = ["y"]

[discretization]
order = 2
maxh = 0.3
"""


def _scene(tmp_path, tolerance: float | None):
    path = tmp_path / "press_fit.toml"
    path.write_text(PRESS_FIT + ("" if tolerance is None else f"tolerance = {tolerance}\n"))
    return path


def _ring_stress(r, r1, r2, p_in, p_out, nu):
    a = (p_in * r1 ** 2 - p_out * r2 ** 2) / (r2 ** 2 - r1 ** 2)
    b = (p_in - p_out) * r1 ** 2 * r2 ** 2 / (r2 ** 2 - r1 ** 2)
    srr, stt = a - b / r ** 2, a + b / r ** 2
    return np.diag([srr, stt, nu * (srr + stt)])


def _lame() -> dict[str, float]:
    """The closed form of every headline quantity (the quarter's resultant is ``p b`` in each component)."""
    p = lame_press_fit_pressure(A, B, C, E_IN, NU_IN, E_OUT, NU_OUT, DELTA, K_N)
    inner, outer = _ring_stress(A, A, B, 0.0, p, NU_IN), _ring_stress(B, B, C, p, 0.0, NU_OUT)
    return {"peak_pressure": p, "resultant_x": p * B, "resultant_y": p * B,
            "von_mises_inner": float(von_mises(inner)), "tresca_inner": float(tresca(inner)),
            "von_mises_outer": float(von_mises(outer)), "tresca_outer": float(tresca(outer))}


def test_a_tolerance_is_met_by_raising_the_order_and_the_closed_form_agrees(tmp_path):
    tolerance = 0.1
    out = D.run(loader.load(_scene(tmp_path, tolerance)), Clock())
    acc = out.results["accuracy"]
    refinement = acc["refinement"]
    assert acc["met"] and acc["tolerance_from"] == "scene"
    assert [lv["order"] for lv in refinement["levels"]] == [2, 3]
    assert refinement["scene_order"] == 2 and refinement["order"] == 3 and out.ndof == refinement["ndof"]
    assert [lv["met"] for lv in refinement["levels"]] == [False, True]
    exact = _lame()
    for q in acc["quantities"]:
        assert q["relative_error"] <= tolerance
        assert abs(q["value"] - exact[q["name"]]) <= tolerance * abs(exact[q["name"]]), q
    # the reported fields are those of the refined order
    assert out.results["maxima"]["pressure"]["pressure"] == pytest.approx(
        next(q["value"] for q in acc["quantities"] if q["name"] == "peak_pressure"))
    assert "met at order 3 (refined from order 2)" in accuracy_line(out.results)
    # the discretization that met it is the scene's at that order: the same numbers
    path = tmp_path / "order3.toml"
    path.write_text(PRESS_FIT.replace("order = 2", "order = 3"))
    again = D.run(loader.load(path), Clock()).results
    assert again["maxima"]["pressure"]["pressure"] == pytest.approx(out.results["maxima"]["pressure"]["pressure"],
                                                                    rel=1e-10)
    assert again["maxima"]["von_mises"]["max"]["value"] == pytest.approx(
        out.results["maxima"]["von_mises"]["max"]["value"], rel=1e-10)


def test_a_tolerance_out_of_reach_ends_the_run_with_the_figures(tmp_path, monkeypatch):
    """A :class:`ConvergenceError`, which the command line ends with exit 3 and nothing written
    (``tests/test_cli.py``), as a cell's tolerance out of reach."""
    monkeypatch.setattr(MR, "MAX_REFINED_ORDER", 3)
    monkeypatch.setattr(MR, "MAX_MESH_LEVELS", 0)     # the mesh levels: tests/macro/test_mesh_refinement.py
    with pytest.raises(ConvergenceError) as info:
        D.run(loader.load(_scene(tmp_path, 1e-3)), Clock())
    err = str(info.value)
    assert "discretization.tolerance = 0.001 not met: at order 3" in err and "orders 2 -> 3" in err
    assert "von_mises_inner" in err and "order 4 is beyond the refinement's bound (order <= 3)" in err
    assert [lv["order"] for lv in info.value.history["refinement"]] == [2, 3]


def test_a_quantity_without_estimate_stops_the_refinement_at_once():
    corners = np.array([[1.0, 0.0]])
    at = (1.0, 0.0)
    singular = DE.estimate("von_mises_base", {k: DE.Sample(v, at) for k, v in zip((1, 2, 3), (1.0, 1.6, 2.1))},
                           2, corners, h=0.1)
    assert singular.error is None
    why = MR.stop_reason(None, MR.unmet([singular], 0.01))  # type: ignore[arg-type]
    assert why is not None and "von_mises_base has no error estimate" in why and "singularity" in why
    # a difference that does not shrink away from any corner: the next order may show the fall, up to the bound
    growing = DE.estimate("peak_pressure", {k: DE.Sample(v) for k, v in zip((1, 2, 3), (1.0, 1.1, 1.25))}, 2)
    assert growing.error is None and growing.singular_at is None
    at_bound = SimpleNamespace(problem=SimpleNamespace(order=MR.MAX_REFINED_ORDER))
    why = MR.stop_reason(at_bound, MR.unmet([growing], 0.01))  # type: ignore[arg-type]
    assert why == f"order {MR.MAX_REFINED_ORDER + 1} is beyond the refinement's bound (order <= {MR.MAX_REFINED_ORDER})"


def test_a_scene_without_a_tolerance_keeps_its_order(tmp_path):
    """The default run is judged against 0.01, never refined: its ladder is its own order's."""
    out = D.run(loader.load(_scene(tmp_path, None)), Clock())
    acc = out.results["accuracy"]
    assert "refinement" not in acc and acc["tolerance_from"] == "default"
    assert {tuple(q["orders"]) for q in acc["quantities"]} == {(1, 2, 3)}
