"""Measured topographies read as periodic height maps (ngcontact.geometry.topography).

Requirement: a scan in an instrument's format becomes the map of the package's layout in metres, with
what the file does not state taken from the scene (units, size) and refused when neither gives it; a
non-periodic scan is made periodic only by a stated method (mirror, window), and the spectrum of a map
feeds random surfaces like it.
"""
import sys

import numpy as np
import pytest

from ngcontact.errors import GeometryError
from ngcontact.geometry import random_surface, topography
from ngcontact.geometry.x3p import write_x3p
from ngcontact.geometry.topography import Reading, read_measured


NEEDS = "reading measured topographies needs the optional extra ngcontact[topography] (SurfaceTopography)"
P, N = 1e-4, 16


def _surface(n=N, seed=1):
    return random_surface.self_affine(grid=n, period=P, hurst=0.8, rms_slope=0.05, seed=seed)


@pytest.fixture
def st():
    return pytest.importorskip("SurfaceTopography", reason=NEEDS)


def test_a_periodic_x3p_gives_the_map_of_its_heights(tmp_path, st):
    z = _surface()
    write_x3p(tmp_path / "s.x3p", z, (P / N, P / N))
    m = read_measured(tmp_path / "s.x3p", Reading(periodic=True))
    assert m.period == pytest.approx(P, rel=1e-15)
    np.testing.assert_array_equal(m.heights, random_surface.as_height_map(z))
    r = m.record
    assert (r["format"], r["unit"], r["unit_from"], r["size_from"]) == ("x3p", "m", "file", "file")
    assert r["scan_grid"] == [N, N] and r["periodization"] is None and r["periodic_from"] == "scene"


def test_orientation_rows_are_y(tmp_path, st):
    """A map that varies along x only stays so: the file's x (CX, running fastest) is the layout's column."""
    x = np.arange(N) / N
    z = np.broadcast_to(1e-7 * np.sin(2 * np.pi * x), (N, N))
    write_x3p(tmp_path / "x.x3p", z, (P / N, P / N))
    H = read_measured(tmp_path / "x.x3p", Reading(periodic=True)).heights
    assert np.ptp(H[:, 3]) == 0.0 and np.ptp(H[3, :]) > 0.0


def test_a_nonperiodic_scan_is_refused_without_periodize(tmp_path, st):
    write_x3p(tmp_path / "s.x3p", _surface(), (P / N, P / N))
    with pytest.raises(GeometryError, match="geometry.periodize = <missing>: the scan in s.x3p is not periodic"):
        read_measured(tmp_path / "s.x3p", Reading())


def test_mirror_doubles_the_period_and_keeps_the_heights(tmp_path, st):
    z = _surface()
    write_x3p(tmp_path / "s.x3p", z, (P / N, P / N))
    m = read_measured(tmp_path / "s.x3p", Reading(periodize="mirror"))
    assert m.period == pytest.approx(2 * P) and m.heights.shape == (2 * N + 1, 2 * N + 1)
    np.testing.assert_array_equal(m.heights[:N, :N], z)
    np.testing.assert_array_equal(m.heights[:N, N:2 * N], z[:, ::-1])
    assert m.record["periodization"] == {"method": "mirror"}


def test_window_tapers_the_edges_to_the_mean_plane(tmp_path, st):
    z = _surface() + 3e-7
    write_x3p(tmp_path / "s.x3p", z, (P / N, P / N))
    with pytest.raises(GeometryError, match="geometry.window_width = <missing>: required for periodize = 'window'"):
        read_measured(tmp_path / "s.x3p", Reading(periodize="window"))
    m = read_measured(tmp_path / "s.x3p", Reading(periodize="window", window_width=0.25))
    w = topography.tukey(N, 0.25)
    np.testing.assert_allclose(m.heights[:N, :N], (z - z.mean()) * np.outer(w, w), rtol=1e-12, atol=1e-22)
    assert m.period == pytest.approx(P) and m.record["periodization"] == {"method": "window", "width": 0.25}
    assert w[N // 2] == 1.0 and w[0] < 0.05


def test_units_and_size_come_from_the_scene_where_the_file_has_none(tmp_path, st):
    z = _surface()
    np.savetxt(tmp_path / "s.txt", z * 1e6)                     # heights in micrometres, no size
    with pytest.raises(GeometryError, match="geometry.units = <missing>: required: the file does not state its "
                                            "length unit"):
        read_measured(tmp_path / "s.txt", Reading(periodic=True))
    with pytest.raises(GeometryError, match="geometry.size = <missing>: required"):
        read_measured(tmp_path / "s.txt", Reading(periodic=True, units="um"))
    m = read_measured(tmp_path / "s.txt", Reading(periodic=True, units="um", size=(P * 1e6, P * 1e6)))
    assert m.period == pytest.approx(P, rel=1e-12)
    np.testing.assert_allclose(m.heights, random_surface.as_height_map(z), rtol=1e-9, atol=1e-20)
    assert (m.record["unit_from"], m.record["size_from"]) == ("scene", "scene")


def test_a_unit_the_file_contradicts_is_refused(tmp_path, st):
    write_x3p(tmp_path / "s.x3p", _surface(), (P / N, P / N))
    with pytest.raises(GeometryError, match="geometry.units = 'µm': the file states 'm'"):
        read_measured(tmp_path / "s.x3p", Reading(periodic=True, units="um"))


def test_mean_plane_detrending_removes_a_tilt(tmp_path, st):
    x = P * np.arange(N) / N
    z = _surface()
    write_x3p(tmp_path / "t.x3p", z + 0.1 * x[None, :], (P / N, P / N))      # a tilt of 0.1: 10 um over the scan
    flat = read_measured(tmp_path / "t.x3p", Reading(periodize="mirror", detrend="mean_plane")).heights
    tilted = read_measured(tmp_path / "t.x3p", Reading(periodize="mirror")).heights
    assert np.ptp(flat) < 2 * np.ptp(z) and np.ptp(tilted) > 0.09 * P
    with pytest.raises(GeometryError, match="geometry.detrend = 'mean_plane': the scan is periodic"):
        read_measured(tmp_path / "t.x3p", Reading(periodic=True, detrend="mean_plane"))


def test_a_scan_that_is_not_square_is_refused(tmp_path, st):
    write_x3p(tmp_path / "r.x3p", _surface()[:8], (P / N, P / N))
    with pytest.raises(GeometryError, match="the cell is square"):
        read_measured(tmp_path / "r.x3p", Reading(periodic=True))


def test_without_the_package_the_error_names_the_extra(tmp_path, monkeypatch):
    (tmp_path / "s.x3p").write_bytes(b"PK")
    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)
    with pytest.raises(GeometryError, match=r"pip install 'ngcontact\[topography\]'"):
        read_measured(tmp_path / "s.x3p", Reading(periodic=True))


def test_surfaces_drawn_with_a_measured_spectrum_share_it():
    """Random surfaces from the radially averaged PSD of a map have, on average, its PSD and mean square."""
    z = _surface(32)
    q, C = random_surface.radial_psd(z, P)
    draws = [random_surface.from_psd(q, C, grid=32, period=P, seed=s) for s in range(64)]
    psds = np.array([random_surface.radial_psd(d, P)[1] for d in draws])
    band = slice(0, 8)                                           # the rings of the spectrum's power
    # each ring's C of one draw is a mean of 4 to 48 exponential variables: 64 draws average it within 30 %
    np.testing.assert_allclose(psds.mean(axis=0)[band], C[band], rtol=0.3)
    ms = np.mean([np.mean(d ** 2) for d in draws])
    assert ms == pytest.approx(np.mean(z ** 2), rel=0.3)
    assert not np.allclose(draws[0], draws[1])
    np.testing.assert_array_equal(draws[3], random_surface.from_psd(q, C, grid=32, period=P, seed=3))


def test_the_psd_sums_to_the_mean_square_height():
    z = _surface(32)
    zh = np.fft.fft2(z)
    C = P ** 2 * np.abs(zh) ** 2 / z.size ** 2
    assert np.sum(C) / P ** 2 == pytest.approx(np.mean(z ** 2), rel=1e-12)
    q, Cr = random_surface.radial_psd(z, P)
    assert np.rint(q[0] / (2 * np.pi / P)) == 1 and np.all(np.diff(q) > 0) and len(q) == len(Cr)
    assert random_surface.spectral_slope(z, P) == pytest.approx(0.05, rel=1e-12)


@pytest.mark.parametrize("name, content, expected", [
    pytest.param("empty.x3p", b"", "is empty; must be a topography file", id="empty"),
    pytest.param("junk.x3p", bytes(range(256)) * 2, "must be a topography file SurfaceTopography reads .*: "
                 "FileFormatMismatch: Stream is not a valid ZIP archive", id="x3p-not-zip"),
    pytest.param("words.txt", b"hello world\nfoo\n", "CorruptFile: Could not find any topography data", id="words"),
    pytest.param("noise.qqq", b"\x00\x01\x02", "no reader recognizes its format", id="unknown-suffix"),
])
def test_unreadable_files_are_refused_in_one_line(tmp_path, st, name, content, expected):
    (tmp_path / name).write_bytes(content)
    with pytest.raises(GeometryError, match=f"geometry.file = .*{expected}") as err:
        read_measured(tmp_path / name, Reading(periodic=True, units="um", size=(1.0, 1.0)))
    assert "\n" not in str(err.value)


def test_a_scan_of_one_point_is_refused(tmp_path, st):
    write_x3p(tmp_path / "one.x3p", np.ones((1, 1)), (1e-6, 1e-6))
    with pytest.raises(GeometryError, match="holds 1 x 1 points; a height map needs at least 2 per direction"):
        read_measured(tmp_path / "one.x3p", Reading(periodic=True))
