"""The spectral small-slope cell: layer compliance, constrained CG, Westergaard, FE agreement, scenes."""
import json
import math
import os

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.spectral.layer_compliance import antiplane_compliance, layer_matrix, plane_compliances
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell, wave_numbers
from ngcontact.errors import ConvergenceError
from ngcontact.solvers.constrained_cg import constrained_cg, masked_cg
from ngcontact.verification.layer_fe import layer_fe_compliance
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import (westergaard_contact_fraction, westergaard_p_star,
                                                westergaard_pressure)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CELLS = os.path.join(ROOT, "geometries", "cells")


# ------------------------------------------------------------------ layer compliance
@pytest.mark.parametrize("k, h, E, nu", [(1.0, 1.0, 2.3, 0.27), (6.28, 0.3, 1.0, 0.3), (30.0, 1.0, 5.0, 0.45),
                                         (0.05, 1.0, 1.0, -0.2), (2 * math.pi, 0.6, 210e9, 0.3)])
def test_closed_form_compliance_equals_the_finite_elements_through_the_thickness(k, h, E, nu):
    nn, ll, ln = plane_compliances(k, E, nu, h)
    aa = antiplane_compliance(k, E, nu, h)
    fe = layer_fe_compliance(k, E, nu, h)
    for name, value in (("nn", nn), ("ll", ll), ("ln", ln), ("aa", aa)):
        assert abs(fe[name] - float(value)) <= 1e-10 * abs(float(value)), (name, fe[name], float(value))


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.49])
def test_thick_layer_is_the_half_space_and_thin_layer_the_uniaxial_strain_column(nu):
    E, k = 3.0, 2.0
    nn, ll, ln = plane_compliances(k, E, nu, 40.0 / k)
    mu = E / (2 * (1 + nu))
    assert float(nn) == pytest.approx(2 * (1 - nu ** 2) / (E * k), rel=1e-14)
    assert float(ll) == pytest.approx(2 * (1 - nu ** 2) / (E * k), rel=1e-14)
    assert float(ln) == pytest.approx(-(1 - 2 * nu) / (2 * mu * k), rel=1e-13, abs=1e-300)
    h = 1e-6          # k h = 2e-6: the O((k h)^2) correction, large near nu = 1/2, is below 1e-9
    M = 2 * mu * (1 - nu) / (1 - 2 * nu)
    nn0, ll0, _ = plane_compliances(k, E, nu, h)
    assert float(nn0) == pytest.approx(h / M, rel=1e-7)
    assert float(ll0) == pytest.approx(h / mu, rel=1e-7)
    assert plane_compliances(0.0, E, nu, h)[0] == pytest.approx(h / M, rel=1e-15)   # the zero mode


def test_layer_matrix_is_hermitian_positive_and_the_counter_mirrors_the_coupling():
    rng = np.random.default_rng(1)
    kv = rng.normal(size=(50, 2)) * 7
    C = layer_matrix(kv, 2.0, 0.3, 0.4)
    Cu = layer_matrix(kv, 2.0, 0.3, 0.4, above=True)
    assert np.allclose(C, np.conj(np.swapaxes(C, -1, -2)), rtol=0, atol=1e-14)
    assert np.all(np.linalg.eigvalsh(C) > 0)
    R = np.diag([1.0, 1.0, -1.0])
    assert np.allclose(Cu, R @ C @ R, rtol=0, atol=1e-15)
    # isotropy in the plane: rotating k rotates C
    c, s = math.cos(0.7), math.sin(0.7)
    Q = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
    Ck = layer_matrix(kv @ Q[:2, :2].T, 2.0, 0.3, 0.4)
    assert np.allclose(Ck, Q @ C @ Q.T, rtol=0, atol=1e-14)


# ------------------------------------------------------------------ constrained CG
def _operator(N, E=1.0, nu=0.3, h=1.0):
    cell = SpectralCell(dim=2, period=1.0, grid=N, rough=Layer(E, nu, h), counter=Layer(E, nu, h),
                        gap=np.zeros(N), k_n=1.0)
    return cell, cell.interface_compliance(uniform=True)


def test_the_operator_is_symmetric_positive_and_the_energy_gradient_is_its_residual():
    cell, A = _operator(64)
    rng = np.random.default_rng(3)
    x, y, b = rng.normal(size=(3, 64))
    assert np.dot(x, A(y)) == pytest.approx(np.dot(A(x), y), rel=1e-13)
    assert np.dot(x, A(x)) > 0

    def f(p):
        return 0.5 * np.dot(p, A(p)) + np.dot(p, b)
    grad = A(x) + b
    for i in (0, 17, 40):
        e = np.zeros(64)
        e[i] = 1e-4
        fd = (f(x + e) - f(x - e)) / 2e-4
        assert fd == pytest.approx(grad[i], rel=1e-7)


def test_constrained_cg_meets_the_contact_conditions_and_refuses_a_hopeless_budget():
    cell, A = _operator(256)
    x = np.arange(256) / 256
    g0 = 0.02 * np.sin(np.pi * x) ** 2
    res = constrained_cg(cell.interface_compliance(uniform=False), g0, pbar=5e-3, tol=1e-12, max_iter=1000,
                         gscale=0.02)
    assert res.p.min() >= 0 and res.p.mean() == pytest.approx(5e-3, rel=1e-14)
    on = res.p > 0
    assert np.max(np.abs(res.gap[on])) <= 1e-12 * 0.02 and res.gap[~on].min() >= -1e-12 * 0.02
    with pytest.raises(ConvergenceError, match="constrained CG"):
        constrained_cg(cell.interface_compliance(uniform=False), g0, pbar=5e-3, tol=1e-14, max_iter=3,
                       gscale=0.02)
    # the linearization at the contact set: C restricted to it is SPD, masked CG solves it
    sol, its = masked_cg(cell.interface_compliance(uniform=False), on, np.ones(256), rtol=1e-12)
    r = cell.interface_compliance(uniform=False)(sol)
    assert np.allclose(r[on], 1.0, atol=1e-10) and np.all(sol[~on] == 0) and its > 0


# ------------------------------------------------------------------ Westergaard
E_, NU, H = 1.0, 0.3, 0.01
P_STAR = westergaard_p_star(e_star(E_, NU) / 2, H, 1.0)
LOADS = (0.05, 0.2, 0.5, 0.8)


def _westergaard(N, thickness, enforcement="exact", k_n=1e3):
    x = np.arange(N) / N
    cell = SpectralCell(dim=2, period=1.0, grid=N, rough=Layer(E_, NU, thickness), counter=Layer(E_, NU, thickness),
                        gap=2 * H * np.sin(np.pi * x) ** 2, k_n=k_n, enforcement=enforcement)
    return cell, [cell.solve(cell_load(2, pressure=r * P_STAR)) for r in LOADS]


def _fraction_error(sols):
    return max(abs(s.results["contact_fraction"] - westergaard_contact_fraction(r * P_STAR, P_STAR))
               / westergaard_contact_fraction(r * P_STAR, P_STAR) for r, s in zip(LOADS, sols))


def test_westergaard_contact_fraction_converges_at_more_than_first_order_in_the_grid():
    errors = [_fraction_error(_westergaard(N, thickness=20.0)[1]) for N in (256, 1024, 4096)]
    rates = [math.log(errors[i] / errors[i + 1]) / math.log(4) for i in range(2)]
    assert errors[-1] <= 1e-5, errors
    assert min(rates) >= 1.2, (errors, rates)


def test_the_edge_fitted_far_from_the_contact_beats_the_line_through_the_first_open_points(monkeypatch):
    """The quartic over the far window places the edges ten times better than the two-point line."""
    from ngcontact.cell.spectral import grid_measures as spectral_measures
    cell, sols = _westergaard(4096, thickness=20.0)
    fitted = _fraction_error(sols)
    monkeypatch.setattr(spectral_measures, "EDGE_MIN_POINTS", 10 ** 9)       # the line only
    line = max(abs(spectral_measures.contact_fraction(cell, s.fields["pressure"], s.fields["gap"])
                   - westergaard_contact_fraction(r * P_STAR, P_STAR)) / westergaard_contact_fraction(r * P_STAR, P_STAR)
               for r, s in zip(LOADS, sols))
    assert fitted <= 0.2 * line, (fitted, line)


def test_westergaard_pressure_field_and_closure():
    cell, sols = _westergaard(4096, thickness=20.0)
    x = np.arange(4096) / 4096
    x = np.where(x > 0.5, x - 1, x)
    for r, s in zip(LOADS, sols):
        exact = westergaard_pressure(x, r * P_STAR, P_STAR, 1.0)
        assert np.linalg.norm(s.fields["pressure"] - exact) / np.linalg.norm(exact) <= 5e-4
        assert s.results["mean_pressure"] == pytest.approx(r * P_STAR, rel=1e-13)
        assert s.results["max_penetration"] <= 1e-9 * 2 * H


@pytest.mark.slow
def test_westergaard_on_a_fine_grid():
    assert _fraction_error(_westergaard(16384, thickness=20.0)[1]) <= 1e-6


def test_penalty_converges_to_exact_contact_like_one_over_k_n():
    _, exact = _westergaard(2048, thickness=1.0)
    errs = []
    for k_n in (1e2, 1e3, 1e4):
        _, pen = _westergaard(2048, thickness=1.0, enforcement="penalty", k_n=k_n)
        errs.append(max(abs(p.results["mean_closure"] - e.results["mean_closure"]) / e.results["mean_closure"]
                        for p, e in zip(pen, exact)))
    rates = [math.log10(errs[i] / errs[i + 1]) for i in range(2)]
    assert all(0.9 <= r <= 1.1 for r in rates), (errs, rates)


@pytest.mark.parametrize("ratio", [1.0, 10.0, 100.0])
def test_frictionless_answer_depends_on_the_materials_only_through_the_compliance(ratio):
    """Thick layers: dissimilar bodies E1, E2 = ratio E1 and identical bodies of the same E* agree."""
    N, nu = 1024, 0.3
    x = np.arange(N) / N
    g0 = 2 * H * np.sin(np.pi * x) ** 2
    E1, E2 = 1.0, ratio
    # identical bodies with 2 / E_eq = 1 / E1 + 1 / E2 (same nu): the same summed compliance
    E_eq = 2.0 / (1.0 / E1 + 1.0 / E2)
    load = cell_load(2, pressure=0.3 * westergaard_p_star(e_star(E1, nu) * e_star(E2, nu)
                                                          / (e_star(E1, nu) + e_star(E2, nu)), H, 1.0))
    a = SpectralCell(dim=2, period=1.0, grid=N, rough=Layer(E1, nu, 30.0), counter=Layer(E2, nu, 30.0),
                     gap=g0, k_n=1.0).solve(load)
    b = SpectralCell(dim=2, period=1.0, grid=N, rough=Layer(E_eq, nu, 30.0), counter=Layer(E_eq, nu, 30.0),
                     gap=g0, k_n=1.0).solve(load)
    assert a.results["contact_fraction"] == pytest.approx(b.results["contact_fraction"], rel=1e-10)
    assert np.allclose(a.fields["pressure"], b.fields["pressure"], rtol=0, atol=1e-10 * load.traction[-1] ** 2 + 1e-14)
    frac = westergaard_contact_fraction(0.3 * P_STAR, P_STAR)
    assert a.results["contact_fraction"] == pytest.approx(frac, rel=2e-3)


# ------------------------------------------------------------------ against the FE cell
def _run(tmp_path, scene_text, name):
    path = tmp_path / f"{name}.toml"
    path.write_text(scene_text)
    out = tmp_path / name
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    return json.loads((out / "report.json").read_text()), out


SCENE = """\
kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "flat"
h_rough = 1.0
h_counter = 1.0
[contact]
k_n = 1.0e3
gap = {{ kind = "sinusoid", h = 0.01 }}
[load]
pressure = [0.0034523, 0.00863075]
[discretization]
{disc}
"""


def test_a_small_fe_cell_and_the_spectral_cell_of_the_same_scene_agree(tmp_path):
    fe, _ = _run(tmp_path, SCENE.format(disc='order = 2\nmaxh = 0.25\ninterface_maxh = 0.005\nestimate = "off"'), "fe")
    # refined from 256 by doubling to the default tolerance, the 2D stiffness (of the located set) held to it
    # too: the four grids a stop needs, the last of 2048 points
    sp, out = _run(tmp_path, SCENE.format(disc='method = "spectral"\ngrid = 256'), "spectral")
    assert sp["results"]["method"]["name"] == "spectral" and sp["results"]["method"]["grid"] == 2048
    assert sp["results"]["accuracy"]["met"]
    for a, b in zip(fe["results"]["loads"], sp["results"]["loads"]):
        assert b["mean_closure"] == pytest.approx(a["mean_closure"], rel=2e-3)
        assert b["far_face_jump"][-1] == pytest.approx(a["far_face_jump"][-1], rel=2e-3)
        assert b["contact_fraction"] == pytest.approx(a["contact_fraction"], rel=1e-2)
        assert b["effective_stiffness"]["total"][0][0] == pytest.approx(a["effective_stiffness"]["total"][0][0],
                                                                         rel=5e-3)
        assert b["iterations"] > 0
    p = np.load(out / "pressure_load1.npy")
    assert p.shape == (2048,) and p.mean() == pytest.approx(0.00863075, rel=1e-12)
    assert {"surface.png", "contact_curve.png", "gap_load0.npy"} <= set(os.listdir(out))


def test_bisinusoid_spectral_cell_converges_in_the_grid_and_writes_a_pressure_map(tmp_path):
    text = open(os.path.join(CELLS, "bisinusoid.toml")).read()
    # the shipped scene's FE [discretization] (its last section) replaced by the spectral cell's
    # each grid alone, unrefined and unestimated
    text = text[:text.index("[discretization]")] + '[discretization]\nmethod = "spectral"\ngrid = {grid}\nestimate = "off"\n'
    closure, fraction = [], []
    for grid in (64, 128, 256):
        rep, out = _run(tmp_path, text.replace("{grid}", str(grid)), f"bis{grid}")
        load = rep["results"]["loads"][0]
        closure.append(load["mean_closure"])
        fraction.append(load["contact_fraction"])
    assert abs(closure[2] - closure[1]) <= 0.2 * abs(closure[1] - closure[0])    # faster than the grid step
    assert abs(fraction[2] - fraction[1]) <= 1.0 / 128                             # edges within a step: O(1/N)
    assert (out / "pressure_map.png").stat().st_size > 0
    assert np.load(out / "pressure_load0.npy").shape == (256, 256)


def _bisinusoid_fractions(grid: int) -> list[tuple[float, float]]:
    """(located, counted) contact fractions of ``h (2 - cos 2 pi x - cos 2 pi y)``, h = 0.01, at three loads."""
    s = np.arange(grid) / grid
    gap = 0.01 * (2 - np.cos(2 * np.pi * s[None, :]) - np.cos(2 * np.pi * s[:, None]))
    cell = SpectralCell(dim=3, period=1.0, grid=grid, rough=Layer(1.0, 0.3, 1.0), counter=Layer(1.0, 0.3, 1.0),
                        gap=gap, k_n=1e3, enforcement="exact")
    sols = [cell.solve(cell_load(3, pressure=p)) for p in (0.001, 0.004, 0.01)]
    return [(sol.results["contact_fraction"], sol.results["contact_fraction_grid"]) for sol in sols]


def test_3d_edges_located_along_rows_and_columns_beat_counting_the_points():
    """In 3D each row and column locates its contact edges by the line through the first two open points
    (:func:`~ngcontact.cell.spectral.grid_measures.row_weights`): on 64 and 128 points per direction the
    located contact fraction is at least three times closer to the 512 grid's than the count of points, the
    count erring at first order by a layer of points along the edges; the two agree on 512 points to a
    fraction of a grid step per edge."""
    reference = [located for located, _ in _bisinusoid_fractions(512)]
    counted_512 = [counted for _, counted in _bisinusoid_fractions(512)]
    for grid in (64, 128):
        for (located, counted), ref in zip(_bisinusoid_fractions(grid), reference):
            assert abs(located - ref) <= abs(counted - ref) / 3, (grid, located, counted, ref)
    # the two measures of one grid differ by less than a layer of points along the edges (perimeter < 4 periods)
    assert all(abs(c - ref) <= 4 / 512 * 0.5 for c, ref in zip(counted_512, reference))


def test_3d_located_fraction_is_the_same_for_the_transposed_map():
    """The rows' and the columns' located lengths are averaged: a map and its transpose give one fraction."""
    rng = np.random.default_rng(4)
    gap = np.abs(np.fft.irfft2(np.fft.rfft2(rng.standard_normal((64, 64))) * np.exp(
        -np.hypot(*np.meshgrid(np.fft.fftfreq(64) * 64, np.fft.rfftfreq(64) * 64, indexing="ij")) / 3)))
    gap = gap.max() - gap

    def fraction(g):
        cell = SpectralCell(dim=3, period=1.0, grid=64, rough=Layer(1.0, 0.3, 1.0), counter=Layer(1.0, 0.3, 1.0),
                            gap=g, k_n=1e3, enforcement="exact")
        return cell.solve(cell_load(3, pressure=0.05 * float(np.ptp(g)))).results["contact_fraction"]
    assert fraction(gap) == pytest.approx(fraction(np.ascontiguousarray(gap.T)), rel=1e-9)


# ------------------------------------------------------------------ scenes the spectral cell refuses
@pytest.mark.parametrize("edit, message", [
    (('profile = "flat"', 'profile = "sinusoid"\namplitude = 0.05'),
     "discretization.method = 'spectral': solves the small-slope cell"),
    (("grid = 2048", "grid = 2047"), "discretization.grid = 2047: must be even"),
])
def test_scenes_the_spectral_cell_refuses(tmp_path, capsys, edit, message):
    text = SCENE.format(disc='method = "spectral"\ngrid = 2048').replace(*edit)
    path = tmp_path / "s.toml"
    path.write_text(text)
    assert cli.main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_wave_numbers_cover_the_half_spectrum():
    k = wave_numbers(3, 8, 2.0)
    assert k.shape == (8, 5) and k[0, 0] == 0 and k[0, 1] == pytest.approx(math.pi)
    assert k[4, 4] == pytest.approx(math.hypot(4 * math.pi, 4 * math.pi))


# ------------------------------------------------------------------ the self-affine profile
SELF_AFFINE = os.path.join(CELLS, "self_affine_spectral.toml")


@pytest.mark.parametrize("edit, message", [
    (("rms_slope = 0.1,", "rms_slope = 0.1, rms_height = 0.01,"),
     "geometry.spectrum.rms_height = 0.01: give exactly one of rms_height and rms_slope"),
    (("grid = 256,", "grid = 255,"), "geometry.spectrum.grid = 255: must be even"),
    (("hurst = 0.8", "hurst = 1.2"), "geometry.spectrum.hurst = 1.2: must lie in (0, 1)"),
    (('profile = "self_affine"', 'profile = "flat3d"'),
     "geometry.spectrum = "),
])
def test_bad_spectra_are_refused_with_their_key(tmp_path, capsys, edit, message):
    text = open(SELF_AFFINE).read()
    assert edit[0] in text
    path = tmp_path / "s.toml"
    path.write_text(text.replace(*edit))
    assert cli.main(["check", str(path)]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.slow
def test_the_fe_cell_takes_the_same_self_affine_surface_as_its_gap(tmp_path):
    """A smooth self-affine surface (wavelengths 1/4 to 1/2) in an FE cell and in the spectral cell (penalty)."""
    text = open(SELF_AFFINE).read().replace('enforcement = "exact"', 'enforcement = "penalty"')
    text = text.replace("pressure = [0.001, 0.003, 0.01]", "pressure = [0.01]")
    text = text.replace("rolloff = 0.25, cutoff = 0.03125, grid = 256", "rolloff = 0.5, cutoff = 0.25, grid = 16")
    text = "\n".join(line for line in text.splitlines() if not line.startswith("grid = "))   # the first grid
    fe_text = text.replace('method = "spectral"', "order = 2\nmaxh = 0.5\ninterface_maxh = 0.1")
    fe, _ = _run(tmp_path, fe_text, "fe")
    # the spectral grid samples the map's bilinear interpolant, the gap the FE cell integrates
    sp, _ = _run(tmp_path, text.replace('method = "spectral"', 'method = "spectral"\ngrid = 256'), "sp")
    a, b = fe["results"]["loads"][0], sp["results"]["loads"][0]
    assert a["mean_closure"] == pytest.approx(b["mean_closure"], rel=1e-2)
    # the contact fraction of an FE mesh this coarse is far low (0.27 here, as on the bisinusoid, where it
    # climbs 0.61, 0.65, 0.66 under refinement towards the spectral 0.670); the spectral one is grid-converged
    fine, _ = _run(tmp_path, text.replace('method = "spectral"', 'method = "spectral"\ngrid = 512'), "fine")
    assert fine["results"]["loads"][0]["contact_fraction"] == pytest.approx(b["contact_fraction"], abs=5e-3)
    assert a["contact_fraction"] < b["contact_fraction"]


# ------------------------------------------------------------------ friction
FRICTION_SCENE = """\
kind = "cell"
[materials.soft]
E = 1.0
nu = 0.3
[materials.stiff]
E = 3.0
nu = 0.2
[bodies]
rough = "soft"
counter = "stiff"
[geometry]
profile = "flat"
h_rough = 1.0
h_counter = 0.5
[contact]
k_n = 1.0e3
gap = {{ kind = "sinusoid", h = 0.01 }}
{friction}
w = 1e-5
[load]
pressure = [0.008]
shear = [0.001]
[discretization]
{disc}
"""


@pytest.mark.parametrize("friction", ['friction = "tresca"\nG = 0.002',
                                      pytest.param('friction = "coulomb"\nmu = 0.3', marks=pytest.mark.slow)])
def test_frictional_spectral_cell_of_dissimilar_layers_equals_the_fe_cell(tmp_path, friction):
    """Normal-tangential coupling of dissimilar finite layers under shear: FE (fine) and spectral agree.  The FE
    cell's answer is its scene's discretization's, so it opts out of the default estimate (a second sweep)."""
    fe, _ = _run(tmp_path, FRICTION_SCENE.format(friction=friction, disc="order = 2\nmaxh = 0.08\n"
                                                 'interface_maxh = 0.005\nestimate = "off"'), "fe")
    sp, out = _run(tmp_path, FRICTION_SCENE.format(friction=friction, disc='method = "spectral"\ngrid = 512'), "sp")
    a, b = fe["results"]["loads"][0], sp["results"]["loads"][0]
    for key in ("far_face_jump", "mean_jump"):     # the tangential mean jump is small: to 2e-3 of the normal
        assert np.allclose(b[key], a[key], rtol=2e-3, atol=2e-3 * abs(a[key][-1])), (key, a[key], b[key])
    assert b["contact_fraction"] == pytest.approx(a["contact_fraction"], rel=5e-3)
    assert b["mean_traction"] == pytest.approx([0.001, -0.008], rel=1e-10)
    assert 0 < b["slip_fraction"] < 1
    assert np.load(out / "pressure_load0.npy").shape == (4096,)


def test_tresca_with_a_vanishing_threshold_is_the_frictionless_cell():
    N = 256
    x = np.arange(N) / N
    kw = dict(dim=2, period=1.0, grid=N, rough=Layer(1, 0.3, 1), counter=Layer(2, 0.25, 0.7),
              gap=0.02 * np.sin(np.pi * x) ** 2, k_n=1e3, enforcement="exact", tol=1e-10, max_iter=50000)
    from ngcontact.laws.friction import Tresca
    a = SpectralCell(**kw).solve(cell_load(2, pressure=0.008))
    b = SpectralCell(friction=Tresca(w=1e-5, G=1e-14), **kw).solve(cell_load(2, pressure=0.008, shear=(0.0,)))
    assert np.allclose(a.fields["pressure"], b.fields["pressure"], rtol=0, atol=1e-7 * 0.008)
    assert b.results["far_face_jump"][-1] == pytest.approx(a.results["far_face_jump"][-1], rel=1e-8)
    assert b.results["mean_closure"] == pytest.approx(a.results["mean_closure"], rel=1e-8)


def test_a_shear_beyond_the_friction_capacity_is_refused():
    from ngcontact.laws.friction import Tresca
    N = 128
    x = np.arange(N) / N
    cell = SpectralCell(dim=2, period=1.0, grid=N, rough=Layer(1, 0.3, 1), counter=Layer(1, 0.3, 1),
                        gap=0.02 * np.sin(np.pi * x) ** 2, k_n=1e3, friction=Tresca(w=1e-5, G=1e-3))
    with pytest.raises(ConvergenceError, match="cannot carry this load"):
        cell.solve(cell_load(2, pressure=0.008, shear=(2e-3,)))


def test_3d_shear_is_isotropic_on_the_bisinusoid():
    """Shear along x and along y on the symmetric bisinusoid (Tresca): the same answer, axes swapped."""
    from ngcontact.geometry.cell3d import bisinusoid_gap
    from ngcontact.laws.friction import Tresca
    N = 64
    s = np.arange(N) / N
    g0 = bisinusoid_gap(0.005, 1.0, xy=(s[None, :], s[:, None]))
    cell = SpectralCell(dim=3, period=1.0, grid=N, rough=Layer(1, 0.3, 0.6), counter=Layer(2, 0.2, 0.6), gap=g0,
                        k_n=1e3, enforcement="exact", friction=Tresca(w=1e-5, G=0.004), tol=1e-10,
                        max_iter=50000)
    a = cell.solve(cell_load(3, pressure=0.008, shear=(0.002, 0.0)))
    b = cell.solve(cell_load(3, pressure=0.008, shear=(0.0, 0.002)))
    ja, jb = a.results["far_face_jump"], b.results["far_face_jump"]
    assert ja[0] == pytest.approx(jb[1], rel=1e-6) and ja[2] == pytest.approx(jb[2], rel=1e-6)
    assert abs(ja[1]) <= 1e-7 * abs(ja[0]) and abs(jb[0]) <= 1e-7 * abs(jb[1])
    assert np.allclose(a.fields["pressure"], b.fields["pressure"].T, rtol=0, atol=1e-12 * 0.008)
    assert a.results["mean_traction"] == pytest.approx([0.002, 0.0, -0.008], abs=1e-15)


def test_full_traction_operator_is_symmetric_and_its_energy_gradient_consistent():
    N = 32
    cell = SpectralCell(dim=3, period=1.0, grid=N, rough=Layer(1, 0.3, 0.6), counter=Layer(4, 0.2, 0.3),
                        gap=np.zeros((N, N)), k_n=1.0)
    apply, L, K0 = cell.traction_operator((True, False, True))
    rng = np.random.default_rng(0)
    x, y = rng.normal(size=(2, 3, N, N))
    assert np.sum(x * apply(y)) == pytest.approx(np.sum(apply(x) * y), rel=1e-12)
    assert 0 < np.sum(x * apply(x)) <= L * np.sum(x * x) * (1 + 1e-12)
    b = rng.normal(size=(3, N, N))

    def energy(t):
        return 0.5 * np.sum(t * apply(t)) + np.sum(t * b)
    grad = apply(x) + b
    for idx in ((0, 3, 4), (1, 10, 2), (2, 31, 0)):
        e = np.zeros_like(x)
        e[idx] = 1e-5
        assert (energy(x + e) - energy(x - e)) / 2e-5 == pytest.approx(grad[idx], rel=1e-7)
    # the uniform modes: the layers' uniaxial-strain and shear compliances in series
    mu_r, mu_c = 1 / (2 * 1.3), 4 / (2 * 1.2)
    assert K0[0] == pytest.approx(0.6 / mu_r + 0.3 / mu_c, rel=1e-12)
    assert K0[2] == pytest.approx(0.6 / Layer(1, 0.3, 0.6).M + 0.3 / Layer(4, 0.2, 0.3).M, rel=1e-12)


def test_macro_strain_shifts_the_far_face_approach_as_in_the_fe_cell(tmp_path):
    def scene(disc):
        return SCENE.format(disc=disc).replace("pressure = [0.0034523, 0.00863075]",
                                               "pressure = [0.00863075]\nmacro_strain = [0.002]")
    fe, _ = _run(tmp_path, scene("order = 2\nmaxh = 0.25\ninterface_maxh = 0.01"), "fe")
    sp, _ = _run(tmp_path, scene('method = "spectral"\ngrid = 2048'), "sp")
    plain, _ = _run(tmp_path, SCENE.format(disc='method = "spectral"\ngrid = 2048'), "plain")
    a, b = fe["results"]["loads"][0], sp["results"]["loads"][0]
    assert b["far_face_jump"][-1] == pytest.approx(a["far_face_jump"][-1], rel=2e-3)
    # the contact problem itself does not see an in-plane strain of flat layers: same closure, shifted approach
    c = plain["results"]["loads"][1]
    assert b["mean_closure"] == pytest.approx(c["mean_closure"], rel=1e-12)
    assert b["far_face_jump"][-1] - c["far_face_jump"][-1] == pytest.approx(2 * 1.0 * (0.3 / 0.7) * 0.002, rel=1e-10)


def test_the_strength_recovery_refuses_a_spectral_cell():
    from ngcontact.drivers.build import recovery_cell_problem
    from ngcontact.errors import SceneError
    with pytest.raises(SceneError, match="needs the body stresses and the macro strain term of the FE cell"):
        recovery_cell_problem(os.path.join(CELLS, "self_affine_spectral.toml"), key="strength.cell")


def test_the_last_solution_from_no_start_is_returned_again_for_the_same_load():
    """A twin is asked for one load by the seed and every mesh of a graded solve: solved once."""
    n = 256
    x = np.arange(n) / n
    cell = SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, 0.3, 2.0), counter=Layer(1.0, 0.3, 2.0),
                        gap=0.02 * np.sin(np.pi * x) ** 2, k_n=1e6, enforcement="penalty", tol=1e-10)
    a, b = cell_load(2, pressure=0.002), cell_load(2, pressure=0.004)
    first = cell.solve(a)
    assert cell.solve(a) is first
    other = cell.solve(b)
    assert other is not first and other.results["contact_fraction"] > first.results["contact_fraction"]
    again = cell.solve(a)                                    # only the last load is kept: solved anew, same answer
    assert again is not first and again.results["contact_fraction"] == pytest.approx(
        first.results["contact_fraction"], rel=1e-12)
    warm = cell.solve(a, start=first.fields["pressure"])     # a start given: always solved
    assert warm is not again
