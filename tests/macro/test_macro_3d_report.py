"""A 3D macro scene reports its interface surface as a 2D scene reports its interface profile."""
import json

import numpy as np
import pytest

from ngcontact import cli
from press_fit_3d import press_fit_3d

SCENE = press_fit_3d()


@pytest.fixture(scope="module")
def run_3d(tmp_path_factory):
    """The scene's ``ngcontact run`` as a user runs it (its accuracy verdict included): its output directory
    and ``report.json``, shared by the tests of this module."""
    base = tmp_path_factory.mktemp("press_fit_3d")
    path = base / "s.toml"
    path.write_text(SCENE)
    out = base / "o"
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    return out, json.loads((out / "report.json").read_text())


def test_a_3d_macro_scene_reports_its_interface_surface(run_3d):
    out, rep = run_3d
    res = rep["results"]
    surf = res["interface"]
    assert {"x", "y", "z", "pressure", "shear", "shear_1", "shear_2", "jump_n", "jump_t1", "jump_t2",
            "status"} <= set(surf)
    r = np.hypot(surf["x"], surf["y"])
    assert np.allclose(r, 0.008, rtol=1e-3)                        # the samples lie on the interface r = b
    p = np.asarray(surf["pressure"])
    assert np.all(np.isfinite(p)) and p.max() > 0
    assert 0.0 < res["contact_area"] <= 1.0
    assert sum(res["status_counts"].values()) == len(p)
    assert res["maxima"]["pressure"]["pressure"] == pytest.approx(p.max())
    # the integrated area agrees with the share of samples in contact (the ends of the fit open)
    assert res["contact_area"] == pytest.approx(np.mean(p > 0), abs=0.05)
    for name in ("interface.csv", "interface.png", "interface_axial.png", "stress.png"):
        assert (out / name).stat().st_size > 0, name      # the profile against z and the y = 0 section too
    header = (out / "interface.csv").read_text().splitlines()[0]
    assert "pressure" in header and "shear_2" in header and "z" in header


def test_the_3d_interface_pressure_converges_to_the_axisymmetric_one(run_3d, tmp_path):
    # the same press fit in axisymmetry: the mean pressure over the middle of the fit (away from the ends,
    # where the pressure is singular) agrees within the discretization error, which falls under refinement.
    # The scene's mesh is the module's run; the axisymmetric and the refined scene are solved without the
    # run's accuracy verdict (only their interface samples are compared)
    axi = SCENE.replace('setting = "3d"', 'setting = "axisymmetric"').replace(
        '[[supports]]\nboundary = "sym_x"\ncomponents = ["x"]\n\n[[supports]]\nboundary = "sym_y"\n'
        'components = ["y"]\n\n', "")
    prof = _interface(tmp_path, "axi", axi)
    order = np.argsort(prof["z"])
    band = np.linspace(0.002, 0.008, 601)
    p_axi = np.interp(band, np.asarray(prof["z"])[order], np.asarray(prof["pressure"])[order]).mean()
    errors = []
    for s3 in (run_3d[1]["results"]["interface"],
               _interface(tmp_path, "h0.0028", SCENE.replace("maxh = 0.004", "maxh = 0.0028"))):
        z, p3 = np.asarray(s3["z"]), np.asarray(s3["pressure"])
        mid = (z > 0.002) & (z < 0.008)
        errors.append(abs(p3[mid].mean() / p_axi - 1))
    assert errors[1] < errors[0] and errors[1] < 0.04, errors


def _interface(tmp_path, name, text):
    """The interface samples ``results.interface`` a run of the scene ``text`` reports (its solve and its
    measures, :func:`ngcontact.drivers.run_macro.measured`), without the run's accuracy verdict."""
    from ngcontact.drivers.run_macro import build_geometry, measured, problem_of, solve_scene
    from ngcontact.scene import loader

    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    scene = loader.load(str(path))
    geo = build_geometry(scene)
    problem, law_info = problem_of(scene, geo)
    return measured(solve_scene(scene, problem), geo, law_info, scene.output).results["interface"]
