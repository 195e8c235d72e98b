"""The resolved rough interface in axisymmetry and the femur with resolved stem grooves.

* Geometry: the grooves follow the cone and the cylinder of the stem in whole
  periods, the resolved surface has the length of its faces, the micro
  normal points out of the stem into the bone, and the mesh grows like N.
* Axisymmetric periodic strip (ring grooves on the face of an annular disk
  at radius R, far from the axis) against the same strip in plane strain:
  the difference is the curvature effect, of order (strip width) / R, so it
  must shrink about tenfold when R grows tenfold.
* ``femur_stem_grooves.toml`` validates, rejects inconsistent keys, runs,
  and satisfies global equilibrium (support reaction = interface force =
  load, per revolution).
* Epsilon study on the femur: the bundle law's errors fall at a rate of
  about eps, the whole-surface linear law stalls far above them.
"""
import math
import os

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.resolved import resolved_problem as D
from ngcontact.fem import materials as mat
from ngcontact.scene import loader as scene_mod
from ngcontact.drivers import run_resolved as drv
from ngcontact.coupling.homogenization_error import CONSTANTS
from ngcontact.drivers.study_epsilon import run_study
from ngcontact.errors import SceneError
from ngcontact.geometry import profiles as pr
from ngcontact.geometry.femur import FemurStemDims, femur_stem, split_periods
from ngcontact.geometry.resolved_bodies import resolved_blocks
from ngcontact.output.report import Clock, accuracy_line
from ngcontact.fem.reaction import boundary_reaction
from ngcontact.fem.sampling import probe

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FEMUR = os.path.join(ROOT, "geometries", "direct", "femur_stem_grooves.toml")
REGIONS = ("rough", "counter")  # the direct kind's region names
DIMS = FemurStemDims(r_stem=0.011, r_tip=0.005, r_bone=0.016, z_tip=0.05, z_corner=0.13, z_bone_top=0.18,
                     z_stem_top=0.20)
GROOVE = pr.rectangular_valley(0.5, 0.1, 1.0)
MATS = {"rough": mat.isotropic(100e9, 0.3), "counter": mat.isotropic(9e9, 0.27)}
CYL, CONE = 0.05, math.hypot(0.006, 0.08)


# ---------------------------------------------------------------- geometry
def test_split_periods_gives_whole_periods_close_to_eps():
    for N in (4, 8, 16, 32, 64):
        split = split_periods([CYL, CONE], N)
        eps = (CYL + CONE) / N
        assert sum(n for n, _ in split) == N, split
        for (n, e), L in zip(split, (CYL, CONE)):
            assert n * e == pytest.approx(L, rel=1e-14)
            assert 2 / 3 * eps <= e <= 2 * eps, (N, split)


def test_femur_grooves_follow_the_interface():
    N = 8
    g = femur_stem(DIMS, GROOVE, N, maxh=0.004, interface_maxh=(CYL + CONE) / N / 8, order=2, regions=REGIONS)
    mesh = g.mesh
    assert set(mesh.GetBoundaries()) == {"contact", "axis", "stem_top", "stem_side", "stem_tip", "bone_top",
                                         "bone_outer", "canal", "base"}
    # every period adds two walls of depth eps_i / 10 to the macro length
    length = ng.Integrate(ng.CF(1.0), mesh, ng.BND, definedon=mesh.Boundaries("contact"))
    walls = sum(n * 2 * 0.1 * e for n, e in g.segments)
    assert length == pytest.approx(CYL + CONE + walls, rel=1e-10)
    # the stem keeps its volume minus the grooves: the flat geometry has the macro volume
    flat = femur_stem(DIMS, None, 0, maxh=0.004, interface_maxh=0.002, regions=REGIONS)
    vol_flat = ng.Integrate(2 * math.pi * ng.x, flat.mesh, definedon=flat.mesh.Materials("rough"))
    cone = math.pi / 3 * 0.08 * (0.005 ** 2 + 0.005 * 0.011 + 0.011 ** 2)
    assert vol_flat == pytest.approx(cone + math.pi * 0.011 ** 2 * 0.07, rel=1e-10)
    vol = ng.Integrate(2 * math.pi * ng.x, mesh, definedon=mesh.Materials("rough"))
    assert vol < vol_flat
    # micro normal from the stem into the bone: +r on the cylinder's plateaus, -z / +z on the walls
    n = D.interface_normal(mesh, "rough", "contact")
    n_cyl, e_cyl = g.segments[0]
    z0 = DIMS.z_bone_top - e_cyl * 0.125        # a plateau (the profile starts with one, from the top down)
    zw = DIMS.z_bone_top - e_cyl * 0.25         # first wall, crossed going down: faces -z (into the bone)
    checks = ((DIMS.r_stem, z0, (1.0, 0.0)), (DIMS.r_stem - 0.05 * e_cyl, zw, (0.0, -1.0)),
              (DIMS.r_stem - 0.05 * e_cyl, zw - 0.5 * e_cyl, (0.0, 1.0)))
    for r, z, expect in checks:
        mip = mesh(r, z, VOL_or_BND=ng.BND)
        assert np.asarray(n(mip)).ravel() == pytest.approx(expect, abs=1e-10), (r, z)


def test_femur_mesh_grows_like_the_number_of_grooves():
    ne = [femur_stem(DIMS, GROOVE, N, maxh=0.004, interface_maxh=(CYL + CONE) / N / 8, regions=REGIONS).mesh.ne
          for N in (16, 32, 64)]
    assert ne[1] / ne[0] < 2.6 and ne[2] / ne[1] < 2.6, ne


def test_grooves_reaching_the_axis_are_rejected():
    with pytest.raises(ValueError, match="axis"):
        femur_stem(DIMS, pr.rectangular_valley(0.5, 0.45, 1.0), 2, maxh=0.004, interface_maxh=0.004, regions=REGIONS)


# ----------------------------------------------- axisymmetric periodic strip
def _strip(setting, x0, N=2):
    """Periodic strip of N grooves of period 1 in [x0, x0 + N]; bottom clamped, top moved by (-dt, -dn)."""
    g = resolved_blocks(GROOVE, N, float(N), 1.0, 1.0, maxh=0.25, interface_maxh=0.0625, order=2,
                        periodic=True, x0=x0)
    dn, dt = 1e-5, 4e-6
    prob = D.DirectProblem(mesh=g.mesh, materials=MATS, k_n=1e10, setting=setting, periodic=True,
                           supports=(D.Support(label="bottom"), D.Support(label="top", value=(-dt, -dn))))
    sol = D.solve(prob)
    assert sol.history["converged"]
    R = boundary_reaction(g.mesh, setting, MATS["counter"], sol.u_counter, "counter", "top", 2)
    area = N if setting == "plane_strain" else math.pi * ((x0 + N) ** 2 - x0 ** 2)
    traction = R["y" if setting == "plane_strain" else "z"] / area
    pts = [(x0 + 0.5, 0.5), (x0 + 1.3, -0.5), (x0 + 0.8, 0.2)]
    u = np.array([probe(g.mesh, sol.u_counter if y > 0 else sol.u_rough, [(x, y)])[0] for x, y in pts])
    force = D.contact_force(sol)
    return traction, u, force, R


def test_axisymmetric_strip_far_from_the_axis_tends_to_plane_strain():
    t_ps, u_ps, _, _ = _strip("plane_strain", 0.0)
    diffs = []
    for R in (20.0, 200.0):
        t_ax, u_ax, force, react = _strip("axisymmetric", R)
        # equilibrium per revolution: the interface passes to the counter what the top support takes
        assert force[1] == pytest.approx(react["z"], rel=1e-6)
        shifted = _strip("plane_strain", R)[1]  # plane strain is translation invariant
        assert shifted == pytest.approx(u_ps, rel=1e-8, abs=1e-14)
        diffs.append((abs(t_ax / t_ps - 1), float(np.max(np.abs(u_ax - u_ps)) / np.max(np.abs(u_ps)))))
    (dt1, du1), (dt2, du2) = diffs
    # curvature effect ~ (strip width) / R: tenfold smaller radius ratio, about tenfold smaller difference
    assert dt2 < 0.2 * dt1 and du2 < 0.2 * du1, diffs
    assert dt2 < 5e-3 and du2 < 5e-3, diffs
    assert dt1 > 1e-4, diffs   # the axisymmetric path is not the plane-strain path in disguise


# ------------------------------------------------------------------ scene
def test_femur_grooves_scene_validates_and_rejects_bad_keys(tmp_path):
    sc = scene_mod.load(FEMUR)
    assert sc.geometry.shape == "femur_stem" and sc.geometry.setting == "axisymmetric"
    assert sc.cell_scene.geometry.profile == "rectangular"
    text = open(FEMUR).read().replace('cell = "stem_grooves_cell.toml"',
                                      f'cell = "{os.path.join(ROOT, "geometries", "direct", "stem_grooves_cell.toml")}"')
    cases = {"geometry.setting": ('setting = "axisymmetric"', 'setting = "plane_strain"'),
             "supports[0].boundary": ('boundary = "base"', 'boundary = "bottom"'),
             "supports[1].components": ('components = ["r"]', 'components = ["x"]'),
             "study.probes[0]": ("probes = [[0.002, 0.199]", "probes = [[0.0105, 0.15]"),
             "geometry.dimensions": ("r_tip = 0.005 ", "r_tip = 0.012 ")}
    for path, (old, new) in cases.items():
        assert old in text, old
        bad = tmp_path / "bad.toml"
        bad.write_text(text.replace(old, new, 1))
        with pytest.raises(SceneError) as info:
            scene_mod.load(bad)
        assert info.value.path.startswith(path), (path, info.value.path)


def test_femur_grooves_scene_runs_in_equilibrium():
    sc = scene_mod.load(FEMUR)
    out = drv.run(sc, Clock(None))
    res = out.results
    load = 1e6 * math.pi * 0.011 ** 2                     # 1 MPa on the stem top, per revolution
    assert res["segments"] == [[3, pytest.approx(CYL / 3)], [5, pytest.approx(CONE / 5)]]
    assert set(res["reactions"]) == {"base"}               # the axis support fixes r only: no axial reaction
    assert res["reactions"]["base"]["z"] == pytest.approx(-load, rel=1e-6)
    assert res["contact_force"][1] == pytest.approx(-load, rel=1e-6)
    # the stem sinks; the walls on one side of each groove open, so less than the whole surface is closed
    assert res["probes"][0][1] < 0
    assert 0.5 < res["contact_fraction"] < 1.2
    # the headline quantities with their discretization errors, from the mesh refined uniformly once
    acc = res["accuracy"]
    q = {x["name"]: x for x in acc["quantities"]}
    assert set(q) == {"contact_fraction", "contact_force"} and acc["tolerance_from"] == "default"
    assert q["contact_fraction"]["value"] == res["contact_fraction"] and q["contact_fraction"]["orders"] == [2, 2, 2]
    assert all("refined uniformly once" in x["how"] for x in q.values())
    assert q["contact_fraction"]["controlled"] == "absolute" and q["contact_force"]["controlled"] == "relative"
    assert q["contact_force"]["value"] == pytest.approx(math.hypot(*res["contact_force"]), rel=1e-12)
    for x in q.values():
        assert x["error"] is not None and 0 < x["error"] < 0.1 * abs(x["value"]), x
    assert accuracy_line(res).startswith("accuracy ")


# ---------------------------------------------------------- epsilon study
def test_femur_bundle_error_falls_with_eps():
    res = run_study(scene_mod.load(FEMUR), (4, 8, 16), laws=("bundle", "linear")).results
    rows, rates = res["rows"], res["rates"]
    for key in ("field", "probe"):
        assert rates["bundle"][key] >= 0.8, (key, rates["bundle"], [r[f"bundle_{key}"] for r in rows])
        # the linear law glues both walls of every groove: its error does not go away
        assert rates["linear"][key] < 0.3, (key, rates["linear"])
        assert rows[-1][f"bundle_{key}"] < 0.2 * rows[-1][f"linear_{key}"], (key, rows[-1])
    assert rows[-1]["bundle_interface"] < rows[-1]["linear_interface"], rows[-1]
    assert "moment" not in rates["bundle"]       # axisymmetric reactions carry no moment
    # the rates rest on levels whose meshes are a small share of the error (the separation of the two errors)
    assert res["rate_levels"]["bundle"]["field"] == [4, 8, 16]
    assert all(r["bundle_field_discretization"] <= 0.1 * r["bundle_field"] for r in rows), rows
    # the constant of the macro reports' modelling-error estimate E <= C eps / L bounds what the study measures
    constant = CONSTANTS["bundle"][0]
    for r in rows:
        for key in ("field", "probe"):
            assert r[f"bundle_{key}"] * r["N"] <= constant, (key, r["N"], r[f"bundle_{key}"] * r["N"], constant)
    # the base carries the whole load: its reaction error is round-off, and no rate is made of it
    assert rates["bundle"]["reaction"] is None
    assert res["refused"]["bundle"]["reaction"].startswith("the error is at round-off")


@pytest.mark.slow
def test_femur_bundle_and_effective_laws_converge_on_finer_levels():
    res = run_study(scene_mod.load(FEMUR), (8, 16, 32, 64)).results
    rows, rates = res["rows"], res["rates"]
    for law in ("bundle", "effective"):
        for key in ("field", "probe"):
            assert rates[law][key] >= 0.8, (law, key, rates[law])
    assert rows[-1]["bundle_field"] < 0.01, rows[-1]
    assert res["below_1_percent"]["bundle"]["field"] is not None


# -------------------------------------------------------------- command line
@pytest.mark.slow
def test_cli_study_epsilon_writes_the_study_and_uses_the_exit_codes(tmp_path, capsys):
    import json

    from ngcontact.cli import EXIT_OK, EXIT_SCENE, main
    out = tmp_path / "eps"
    assert main(["study", "epsilon", FEMUR, "--periods", "4", "8", "16", "--out", str(out), "--quiet"]) == EXIT_OK
    rep = json.loads((out / "report.json").read_text())
    assert rep["kind"] == "direct-epsilon-study"
    assert [r["N"] for r in rep["results"]["rows"]] == [4, 8, 16]
    assert set(rep["results"]["rates"]) == {"bundle", "linear", "effective"}
    assert (out / "epsilon.csv").exists() and (out / "epsilon.png").stat().st_size > 0
    # not a direct scene: exit 2, nothing written
    cell = os.path.join(ROOT, "geometries", "direct", "stem_grooves_cell.toml")
    assert main(["study", "epsilon", cell, "--out", str(tmp_path / "no"), "--quiet"]) == EXIT_SCENE
    assert not (tmp_path / "no").exists()
    # output path is a file: exit 2
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["study", "epsilon", FEMUR, "--out", str(blocker), "--quiet"]) == EXIT_SCENE
    assert "error" in capsys.readouterr().err
