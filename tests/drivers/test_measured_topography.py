"""Cell scenes of measured topographies: the same answers as the same heights given as .npy, and a record.

Requirement (issue 37, "measured topographies"): ``profile = "height_map"`` with ``file = "scan.x3p"``
gives the same contact fractions as the same heights as ``.npy`` (to round-off); a non-periodic scan is
refused without ``periodize`` and accepted with one; missing units are refused naming the key; the report
records the topography (file, format, units, size, detrending, periodization, rms height and slope, PSD,
small-slope check) and plots its PSD; random surfaces with the measured spectrum form an ensemble.
"""
from pathlib import Path

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.errors import SceneError
from ngcontact.geometry import random_surface
from ngcontact.geometry.x3p import write_x3p
from ngcontact.runner import solve
from ngcontact.scene import loader


NEEDS = "reading measured topographies needs the optional extra ngcontact[topography] (SurfaceTopography)"
P, N = 1e-4, 32
SCENE = """kind = "cell"
[materials.solid]
E = 1.0e9
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "{profile}"
arrangement = "summit"
file = "{file}"
period = {period!r}
h_rough = 1.0e-4
h_counter = 1.0e-4
{extra}
[contact]
k_n = 1.0e15
enforcement = "exact"
[load]
pressure = [2.0e6, 1.0e7]
[discretization]
method = "spectral"
{ensemble}"""


@pytest.fixture
def scan(tmp_path):
    """A periodic surface (rms slope 0.05) as an X3P (metres, in the file), the .npy of the same heights and
    a plain-text matrix in micrometres with no units or size."""
    pytest.importorskip("SurfaceTopography", reason=NEEDS)
    z = random_surface.self_affine(grid=N, period=P, hurst=0.8, rms_slope=0.05, rolloff=P / 4, seed=1)
    write_x3p(tmp_path / "scan.x3p", z, (P / N, P / N))
    np.save(tmp_path / "scan.npy", random_surface.as_height_map(z))
    np.savetxt(tmp_path / "scan.txt", z * 1e6)
    return tmp_path


def scene(where, file, extra="", period=P, profile="height_map", ensemble=""):
    path = where / f"{Path(file).stem}_{abs(hash((extra, period, profile, ensemble)))}.toml"
    path.write_text(SCENE.format(file=file, extra=extra, period=period, profile=profile, ensemble=ensemble))
    return path


def answers(report):
    return [(e["contact_fraction"], e["mean_closure"]) for e in report["results"]["loads"]]


def test_x3p_gives_the_answers_of_the_same_heights_as_npy(scan):
    npy, _ = solve(str(scene(scan, "scan.npy")), workers=1)
    x3p, outcome = solve(str(scene(scan, "scan.x3p", "periodic = true")), workers=1)
    fractions = [a[0] for a in answers(npy)]
    assert 0.0 < fractions[0] < fractions[1] < 1.0
    for (f0, c0), (f1, c1) in zip(answers(npy), answers(x3p)):
        assert f1 == f0 and c1 == pytest.approx(c0, rel=1e-12)
    assert "topography" not in npy["results"] and "psd" in outcome.plots
    text, _ = solve(str(scene(scan, "scan.txt", 'periodic = true\nunits = "um"\nsize = [100.0, 100.0]')), workers=1)
    for (f0, c0), (f1, c1) in zip(answers(npy), answers(text)):
        assert f1 == pytest.approx(f0, abs=1e-9) and c1 == pytest.approx(c0, rel=1e-9)


def test_the_report_records_the_topography(scan, tmp_path):
    report, outcome = solve(str(scene(scan, "scan.x3p", 'periodic = true')), workers=1)
    t = report["results"]["topography"]
    assert (t["file"], t["format"], t["unit"], t["unit_from"]) == ("scan.x3p", "x3p", "m", "file")
    assert t["scan_size"] == pytest.approx([P, P]) and t["scan_grid"] == [N, N] and t["period"] == pytest.approx(P)
    assert (t["detrend"], t["periodic"], t["periodization"], t["source"]) == ("none", True, None, "measured")
    assert 0.04 < t["rms_slope"] < 0.06 and t["rms_height"] > 0
    assert len(t["psd"]["q"]) == len(t["psd"]["C"]) > 10
    s = t["small_slope"]
    assert s["name"] == "rms_slope" and s["limit"] == pytest.approx(0.1) and s["ok"]
    checks = {c["name"]: c for c in report["results"]["accuracy"]["checks"] if c["load"] is None}
    assert checks["rms_slope"]["value"] == s["value"]
    outcome.plots["psd"](str(tmp_path / "psd.png"))
    assert (tmp_path / "psd.png").stat().st_size > 1000


def test_a_nonperiodic_scan_is_refused_without_periodize_and_accepted_with_one(scan):
    with pytest.raises(SceneError, match=r"geometry.periodize = <missing>: the scan in scan.x3p is not periodic"):
        loader.load(scene(scan, "scan.x3p"))
    with pytest.raises(SceneError, match=r"geometry.period = 0.0001: must equal the period of the measured "
                                         r"topography 'scan.x3p': 0.0002"):
        loader.load(scene(scan, "scan.x3p", 'periodize = "mirror"'))
    report, _ = solve(str(scene(scan, "scan.x3p", 'periodize = "mirror"\ndetrend = "mean_plane"', period=2 * P)),
                      workers=1)
    t = report["results"]["topography"]
    assert t["periodization"] == {"method": "mirror"} and t["period"] == pytest.approx(2 * P)
    assert (t["detrend"], t["periodic"], t["periodic_from"]) == ("mean_plane", False, "file")
    assert 0.0 < report["results"]["loads"][0]["contact_fraction"] < 1.0
    windowed = scene(scan, "scan.x3p", 'periodize = "window"\nwindow_width = 0.125')
    assert loader.load(windowed).geometry.window_width == 0.125


def test_missing_units_are_refused_naming_the_key(scan):
    with pytest.raises(SceneError, match=r"geometry.units = <missing>: required: the file does not state its "
                                         r"length unit \(one of m, mm, um, nm\)"):
        loader.load(scene(scan, "scan.txt", "periodic = true"))
    with pytest.raises(SceneError, match=r"geometry.size = <missing>: required"):
        loader.load(scene(scan, "scan.txt", 'periodic = true\nunits = "um"'))


def test_measured_keys_on_a_npy_map_are_refused(tmp_path):
    np.save(tmp_path / "h.npy", np.zeros((5, 5)))
    with pytest.raises(SceneError, match=r"geometry.periodize = 'mirror': states what a measured topography file "
                                         r"does not"):
        loader.load(scene(tmp_path, "h.npy", 'periodize = "mirror"'))


def test_surfaces_like_this_one_form_an_ensemble(scan):
    report, outcome = solve(str(scene(scan, "scan.x3p", "periodic = true\nseed = 5", profile="measured_spectrum",
                                      ensemble="[ensemble]\nmembers = 2\n")), workers=1)
    r = report["results"]
    assert r["ensemble"]["seeds"] == [5, 6] and "psd" in outcome.plots
    t = r["topography"]
    assert t["source"] == "drawn with the measured spectrum, seed 5" and t["measured"]["rms_slope"] > 0
    members = [[e["contact_fraction"] for e in m] for m in r["members"]]
    assert members[0] != members[1] and all(0.0 < f < 1.0 for m in members for f in m)


def test_the_command_line_refuses_a_scan_in_one_line_with_exit_2(scan, capsys):
    path = scene(scan, "scan.x3p")
    assert cli.main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "geometry.periodize = <missing>: the scan in scan.x3p is not periodic" in err


def test_a_periodic_scan_is_not_detrended(scan):
    with pytest.raises(SceneError, match=r"geometry.detrend = 'curvature': the scan is periodic: removing a plane"):
        loader.load(scene(scan, "scan.x3p", 'periodic = true\ndetrend = "curvature"'))
