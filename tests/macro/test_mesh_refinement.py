"""Past the order, the macro refinement towards ``discretization.tolerance`` refines the mesh where the
error indicator is large: on Lame's press fit the tolerance beyond order 4's reach is met on refined meshes
with estimates bounding the closed form's error; at a block's corner the levels and the estimate of the
peak pressure fall until the stress singularity ends the run with its figures."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ngcontact.drivers import macro_refinement as MR
from ngcontact.drivers import run_macro as D
from ngcontact.errors import ConvergenceError
from ngcontact.geometry import bodies as gm
from ngcontact.fem.materials import isotropic
from ngcontact.laws import homogenized as il
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import error_indicator as EI
from ngcontact.macro import macro_problem as M
from ngcontact.macro import mesh_sequence as MS
from ngcontact.output.report import Clock, accuracy_line
from ngcontact.scene import loader

from tests.macro.test_macro_refinement import PRESS_FIT, _lame

BLOCK = """\
kind = "macro"

[materials.soft]
E = 70e9
nu = 0.33

[materials.stiff]
E = 210e9
nu = 0.3

[bodies]
rough = "soft"
counter = "stiff"

[geometry]
shape = "block"
setting = "plane_strain"

[geometry.dimensions]
length = 1.0
h_block = 0.5
h_base = 0.5

[interface]
law = "linear"
kn = 1e11
kt = 4e10

[[supports]]
boundary = "bottom"
components = ["y"]

[[supports]]
boundary = "base_sides"
components = ["x"]

[[loads]]
boundary = "top"
pressure = 1e6

[discretization]
order = 2
maxh = 0.25
tolerance = 1e-3
"""


# ------------------------------------------------------------------ the estimate from the mesh levels
@pytest.mark.parametrize("rho", [0.2, 0.5, 0.8])
def test_a_geometric_fall_over_mesh_levels_is_bounded(rho):
    limit, e0 = 2.0, 0.3
    values = [limit + e0 * rho ** k for k in range(4)]
    err, how = MS.sequence_error(values, limit)
    assert err is not None and 1.0 <= err / abs(values[-1] - limit) <= 10.0 and "geometric tail" in how


def test_mesh_levels_that_disagree_in_rate_take_the_slower_and_say_so():
    values = [1.0 + e for e in (0.4, 0.2, 0.18, 0.17)]      # ratios 0.1 then 0.5
    err, how = MS.sequence_error(values, 1.0)
    assert "disagree in rate" in how and err == pytest.approx(DE.SAFETY * 0.01 * 0.5 / 0.5)


def test_a_value_growing_with_every_level_has_no_estimate_and_is_a_singularity():
    values = [1.0, 1.3, 1.7, 2.3]
    err, how = MS.sequence_error(values, 2.3)
    assert err is None and "not converging" in how
    assert MS.growing(values, 2.3) and not MS.growing([1.0, 1.3, 1.4], 1.4)


def test_the_larger_of_the_ladder_and_the_sequence_is_reported():
    ladder = DE.Estimate(name="q", value=1.1, error=1e-4, scale=1.1, ratio=0.1, orders=(3, 4, 5), how="ladder")
    seq = MS.combined(ladder, [1.3, 1.15, 1.1])               # ratio 1/3: tail 1.5 x 0.05 x 0.5
    assert seq.error == pytest.approx(DE.SAFETY * 0.05 * 0.5) and "larger than the order ladder's" in seq.how
    corner = DE.Estimate(name="q", value=1.1, error=None, scale=1.1, ratio=2.0, orders=(3, 4, 5),
                         how="orders: a stress singularity", singular_at=(0.0, 0.0))
    assert MS.combined(corner, [1.3, 1.15]).error is None
    settled = MS.combined(corner, [1.3, 1.15, 1.1])
    assert settled.error == pytest.approx(seq.error) and settled.singular_at is None


# ------------------------------------------------------------------ the indicator and the marking
def test_doerfler_marks_the_fewest_largest_elements_carrying_half_the_squares():
    eta = np.array([3.0, 1.0, 2.0, 0.5, 2.0])
    assert EI.marked(eta, bulk=0.45).tolist() == [True, False, False, False, False]   # 9 of 18.25
    assert EI.marked(eta).tolist() == [True, False, True, False, True]   # 9 + 4 >= 9.125; ties marked together
    assert not EI.marked(np.zeros(3)).any()


def test_the_indicator_is_largest_at_the_interface_corners_of_a_block():
    g = gm.block_on_plane(1.0, 0.5, 0.5, maxh=0.25)
    problem = M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="block", counter="base",
                             materials={"block": isotropic(70e9, 0.33), "base": isotropic(210e9, 0.3)},
                             law=il.InterfaceLaw(normal=il.LinearLaw(kn=1e11, kt=4e10)),
                             supports=(M.Support(label="bottom", components=("y",)),
                                       M.Support(label="base_sides", components=("x",))),
                             loads=(M.Load(label="top", pressure=1e6),), order=2)
    sol = M.solve(problem)
    eta = EI.indicator(sol)
    assert eta.shape == (g.mesh.ne,) and (eta >= 0).all()
    mesh = g.mesh
    worst = mesh[M.ng.ElementId(M.ng.VOL, int(np.argmax(eta)))]
    corners = [np.array(mesh[v].point) for v in worst.vertices]
    assert any(np.allclose(c, (0.0, 0.0)) or np.allclose(c, (1.0, 0.0)) for c in corners)
    # the interface term sits on the elements with an edge on the interface y = 0, and only there
    recovered = {r: EI.recovered_stress(sol, r, EI.elasticity.stress(problem.materials[r], u, problem.setting)
                                        .Reshape((9,))) for r, u in (("block", sol.u_rough), ("base", sol.u_counter))}
    share = EI.interface_share(sol, recovered)
    on_interface = np.array([sum(abs(mesh[v].point[1]) < 1e-12 for v in el.vertices) == 2
                             for el in mesh.Elements(M.ng.VOL)])
    assert (share[~on_interface] == 0).all() and (share[on_interface] > 0).all()
    ne = mesh.ne
    EI.refine_marked(mesh, EI.marked(eta), 2)
    assert mesh.ne > ne and mesh.GetCurveOrder() == 2


# ------------------------------------------------------------------ the refinement of a scene
def test_a_tolerance_beyond_order_four_is_met_on_refined_meshes_and_the_closed_form_agrees(tmp_path):
    tolerance = 1e-3
    path = tmp_path / "press_fit.toml"
    path.write_text(PRESS_FIT + f"tolerance = {tolerance}\n")
    out = D.run(loader.load(path), Clock())
    acc = out.results["accuracy"]
    ref = acc["refinement"]
    levels = ref["levels"]
    assert acc["met"] and ref["order"] == MR.MAX_REFINED_ORDER and ref["h_level"] >= 1
    assert [lv["order"] for lv in levels][:3] == [2, 3, 4] and {lv["order"] for lv in levels[3:]} == {4}
    assert [lv["h_level"] for lv in levels] == [0, 0, 0] + list(range(1, len(levels) - 2))
    assert all(a["elements"] < b["elements"] for a, b in zip(levels[2:], levels[3:]))
    assert [lv["met"] for lv in levels] == [False] * (len(levels) - 1) + [True]
    assert out.ndof == ref["ndof"] == levels[-1]["ndof"]
    assert "mesh refined" in accuracy_line(out.results)
    exact = _lame()
    for q in acc["quantities"]:
        true = abs(q["value"] - exact[q["name"]])
        assert q["relative_error"] <= tolerance and true <= tolerance * abs(exact[q["name"]]), q
        if true > 1e-8 * abs(exact[q["name"]]):            # the resultant balances the load to round-off
            assert 1.0 <= q["error"] / true <= 10.0, q


def test_a_corner_singularity_is_refined_towards_and_ends_the_run_with_its_figures(tmp_path):
    path = tmp_path / "block.toml"
    path.write_text(BLOCK)
    with pytest.raises(ConvergenceError) as info:
        D.run(loader.load(path), Clock())
    levels = info.value.history["refinement"]
    assert [lv["h_level"] for lv in levels if lv["order"] == MR.MAX_REFINED_ORDER][-1] >= 2
    refined = [lv for lv in levels if lv["h_level"] > 0]
    assert all(a["ndof"] < b["ndof"] for a, b in zip(levels, levels[1:]))
    peak = [lv["relative_errors"]["peak_pressure"] for lv in levels if lv["order"] == MR.MAX_REFINED_ORDER]
    assert peak[-1] < peak[0]                                 # the interface's estimate falls with the mesh
    assert refined and "grows with every mesh level" in str(info.value) and "mesh level" in str(info.value)


def two_scale_press_fit(tmp_path, monkeypatch, tolerance: float):
    """The press fit coupled with a spectral Westergaard cell (tests/drivers/test_study_kinds.py), its table cached
    in ``tmp_path``, with ``discretization.tolerance``."""
    from tests.drivers.test_study_kinds import two_scale_scene
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    path = two_scale_scene(tmp_path)
    path.write_text(path.read_text().replace("maxh = 0.3", f"maxh = 0.3\ntolerance = {tolerance}"))
    return loader.load(path)


def test_a_two_scale_scene_refines_its_mesh_by_the_loop_on_its_table(tmp_path, monkeypatch):
    """Past order 4 the two-scale press fit's mesh is refined: each level runs the loop again from the cell table
    (which covers the level's pressures: no cell solve), and the interface coefficients are the refined mesh's."""
    assert MR.h_refusal(SimpleNamespace(two_scale=object())) is None
    out = D.run(two_scale_press_fit(tmp_path, monkeypatch, 1e-3), Clock())
    res = out.results
    acc, ts = res["accuracy"], res["two_scale"]
    ref = acc["refinement"]
    assert ref["order"] == MR.MAX_REFINED_ORDER and ref["h_level"] >= 1 and out.ndof == ref["ndof"]
    assert len(ts["mesh_levels"]) == ref["h_level"]
    assert all(lv["cell_solves"] == 0 and lv["max_change"] == 0.0 for lv in ts["mesh_levels"]), ts["mesh_levels"]
    assert [lv["elements"] for lv in ts["mesh_levels"]] == [lv["elements"] for lv in ref["levels"][3:]]
    assert len(ts["interface_coefficients"]["contact_fraction"]) == len(res["interface"]["pressure"])
    q = {x["name"]: x for x in acc["quantities"]}
    assert all(x["met"] for name, x in q.items() if name != "cell_table_interpolation"), q
    # the tolerance refines the table too: its share of the macro quantities is judged, its own error
    # (two_scale.table_tol = 0.02) only said (tests/coupling/test_table_share.py)
    assert not q["cell_table_interpolation"]["counted"] and q["cell_table_share"]["met"] and acc["met"]


@pytest.mark.slow
def test_a_two_scale_scene_estimates_bound_its_error_against_one_refined_ten_times_further(tmp_path, monkeypatch):
    coarse = D.run(two_scale_press_fit(tmp_path, monkeypatch, 1e-3), Clock()).results["accuracy"]
    fine = D.run(two_scale_press_fit(tmp_path, monkeypatch, 1e-4), Clock()).results["accuracy"]
    assert fine["refinement"]["h_level"] > coarse["refinement"]["h_level"]
    ref = {x["name"]: x for x in fine["quantities"]}
    for q in coarse["quantities"]:
        r = ref.get(q["name"])
        if q["name"] in ("cell_table_interpolation", "two_scale_residual") or r is None:
            continue
        true = abs(q["value"] - r["value"])
        if true <= 1e-8 * abs(r["value"]):           # the resultant balances the load to round-off on both
            continue
        assert true + r["error"] <= q["error"] <= 10.0 * true, (q["name"], true, r["error"], q["error"])


@pytest.mark.parametrize("bound, said", [("MAX_MESH_LEVELS", "mesh level 2 is beyond the refinement's bound (1 levels)"),
                                         ("MAX_DOFS", "beyond the refinement's bound of 2000")])
def test_the_mesh_levels_end_at_their_bounds_with_the_figures(tmp_path, monkeypatch, bound, said):
    monkeypatch.setattr(MR, bound, 1 if bound == "MAX_MESH_LEVELS" else 2000)
    path = tmp_path / "press_fit.toml"
    path.write_text(PRESS_FIT + "tolerance = 1e-3\n")
    with pytest.raises(ConvergenceError) as info:
        D.run(loader.load(path), Clock())
    levels = info.value.history["refinement"]
    assert said in str(info.value) and "not met: at order 4" in str(info.value)
    assert [lv["h_level"] for lv in levels] == ([0, 0, 0, 1] if bound == "MAX_MESH_LEVELS" else [0, 0, 0])


SHAFT = PRESS_FIT.replace('setting = "plane_strain"', 'setting = "axisymmetric"').replace(
    "a = 0.5", "a = 0.0\nheight = 0.5").replace('boundary = "sym_x"', 'boundary = "axis"').replace(
    'components = ["x"]', 'components = ["r"]').replace('boundary = "sym_y"\ncomponents = ["y"]',
                                                      'boundary = "bottom"\ncomponents = ["z"]\n\n[[supports]]\n'
                                                      'boundary = "top"\ncomponents = ["z"]')


@pytest.mark.slow
def test_mesh_levels_of_a_shaft_on_its_axis_bound_the_closed_forms_error(tmp_path):
    """A solid shaft in its tube, axisymmetric with both ends held in z (Lame's plane strain fit with
    ``a = 0``): the mesh levels sample the shaft's stress next to the axis ``r = 0``, never on it."""
    from ngcontact.fem.materials import tresca, von_mises
    from ngcontact.verification.lame import lame_press_fit_pressure
    path = tmp_path / "shaft.toml"
    path.write_text(SHAFT + "tolerance = 2e-4\n")
    acc = D.run(loader.load(path), Clock()).results["accuracy"]
    assert acc["met"] and acc["refinement"]["h_level"] >= 1
    p = lame_press_fit_pressure(0.0, 1.0, 2.0, 200.0, 0.3, 70.0, 0.25, 1e-3, 300.0)
    shaft = np.diag([-p, -p, -0.6 * p])
    r1, r2 = 1.0, 2.0
    a, b = p * r1 ** 2 / (r2 ** 2 - r1 ** 2), p * r1 ** 2 * r2 ** 2 / (r2 ** 2 - r1 ** 2)
    tube = np.diag([a - b, a + b, 0.25 * 2 * a])
    exact = {"peak_pressure": p, "von_mises_inner": float(von_mises(shaft)), "tresca_inner": float(tresca(shaft)),
             "von_mises_outer": float(von_mises(tube)), "tresca_outer": float(tresca(tube))}
    for q in acc["quantities"]:
        if q["name"] in exact:
            true = abs(q["value"] - exact[q["name"]])
            assert q["error"] >= true and q["error"] <= 10.0 * max(true, 1e-7 * exact[q["name"]]), q
