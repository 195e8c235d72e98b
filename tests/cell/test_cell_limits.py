"""The cells at the edges of their inputs: full contact, no load, tiny heights, a subnormal pressure, large
strains, long solves (issue 36).

Each test is one defect of the issue's sweep: a well-posed trivial input that failed, hung or answered wrongly.
"""
import json
import logging
import math
import signal
from contextlib import contextmanager

import numpy as np
import pytest

from ngcontact import cli
from sinusoid_cell import sinusoid_cell
from ngcontact.cell import spectral_start
from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.predictor import _winkler_root, layer_stiffness, rigid_approach
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.fem.materials import isotropic
from ngcontact.geometry import profiles
from ngcontact.solvers import constrained_cg as ccg



def _run(tmp_path, text, name="s", quiet=True):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    out = tmp_path / name
    rc = cli.main(["run", str(path), "--out", str(out)] + (["--quiet"] if quiet else []))
    return rc, (json.loads((out / "report.json").read_text()) if rc == 0 else None)


@contextmanager
def deadline(seconds: int):
    """Fail instead of hanging: a ``TimeoutError`` after ``seconds``."""
    def expire(signum, frame):
        raise TimeoutError(f"still running after {seconds} s")
    previous = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _sinusoid_cell(N=256, enforcement="exact", k_n=1e3, h=0.01):
    x = np.arange(N) / N
    return SpectralCell(dim=2, period=1.0, grid=N, rough=Layer(1.0, 0.3, 1.0), counter=Layer(1.0, 0.3, 1.0),
                        gap=2 * h * np.sin(np.pi * x) ** 2, k_n=k_n, enforcement=enforcement, tol=1e-10,
                        max_iter=10000)


# ------------------------------------------------------------------ spectral cell: trivial limits
def test_full_contact_at_a_huge_pressure_is_answered_directly(tmp_path):
    """Was: exit 3 after 10000 CG steps (exact contact at pressure 1e6 on E = 1, which the scene now refuses as
    a strain beyond 1: ngcontact.scene.magnitudes).  At 0.5 (29 times Westergaard's full-contact pressure)."""
    rc, rep = _run(tmp_path, sinusoid_cell(k_n="1.0e3", enforcement="exact", pressure="0.5",
                                             discretization='method = "spectral"\ngrid = 256'))
    assert rc == 0
    load = rep["results"]["loads"][0]
    assert load["contact_fraction"] == 1.0 and load["iterations"] == 0
    assert load["mean_pressure"] == pytest.approx(0.5, rel=1e-14)


@pytest.mark.parametrize("enforcement, k_n", [("exact", 1e3), ("penalty", 1e3), ("penalty", 1e-2)])
def test_the_full_contact_solution_closes_every_gap_and_is_admissible(enforcement, k_n):
    cell = _sinusoid_cell(enforcement=enforcement, k_n=k_n)
    sol = cell.solve(cell_load(2, pressure=1e3))
    p = sol.fields["pressure"]
    assert sol.iterations == 0 and p.min() > 0 and p.mean() == pytest.approx(1e3, rel=1e-14)
    # closed everywhere: the gap g0 - J_n (+ p/k_n, the penalty layer's) vanishes to round-off at every point
    gap = cell.g0 - sol.fields["closure"] + (p / k_n if enforcement == "penalty" else 0.0)
    assert np.max(np.abs(gap)) <= 1e-12 * (0.02 + p.max() * cell.norm(uniform=False))


def test_a_prescribed_approach_that_opens_every_point_carries_nothing():
    cell = _sinusoid_cell()
    sol = cell.solve(cell_load(2, normal_jump=-0.5))
    assert sol.iterations == 0 and not sol.fields["pressure"].any()
    assert sol.results["contact_fraction"] == 0.0


def test_a_prescribed_approach_beyond_full_contact_is_answered_directly():
    cell = _sinusoid_cell()
    sol = cell.solve(cell_load(2, normal_jump=10.0))
    assert sol.iterations == 0 and sol.results["contact_fraction"] == 1.0
    assert sol.results["far_face_jump"][-1] == pytest.approx(10.0, rel=1e-12)


def test_constrained_cg_stops_at_the_round_off_of_its_operator():
    """At pressures far above the gap's scale the residual cannot fall below ``eps |A| |p|``."""
    cell = _sinusoid_cell(N=128)
    sym = float(np.max(cell.fluctuation))
    g0 = cell.g0.copy()
    g0[::2] += 1e-3        # a rough gap: not closed by a smooth pressure
    res = ccg.constrained_cg(cell.interface_compliance(uniform=False), g0, pbar=1e7, tol=1e-14, max_iter=2000,
                             gscale=float(np.ptp(g0)), norm=sym)
    assert res.p.min() >= 0 and res.p.mean() == pytest.approx(1e7, rel=1e-13)


def test_a_height_map_scaled_to_picometres_is_solved(tmp_path):
    """Was: exit 3 after 10000 CG steps (heights of 1e-12: full contact at any pressure)."""
    rng = np.random.default_rng(0)
    heights = 1e-12 * rng.random((17, 17))
    heights[-1, :], heights[:, -1] = heights[0, :], heights[:, 0]
    np.save(tmp_path / "tiny.npy", heights)
    text = sinusoid_cell(k_n="1.0e3", enforcement="exact", pressure="0.005", discretization='method = "spectral"')
    text = text.replace('profile = "flat"', 'profile = "height_map"\nfile = "tiny.npy"\narrangement = "summit"')
    text = text.replace('gap = { kind = "sinusoid", h = 0.01 }\n', "")
    rc, rep = _run(tmp_path, text)
    assert rc == 0 and rep["results"]["loads"][0]["contact_fraction"] == 1.0


def test_a_failed_twin_is_no_warning_to_the_user(caplog):
    """Was: 'spectral predictor: the twin failed' printed under --quiet; the FE cell falls back on its own."""
    cell = _sinusoid_cell(enforcement="penalty")
    cell.max_iter = 1
    cell.tol = 1e-300
    with caplog.at_level(logging.DEBUG, logger="ngcontact"):
        out = spectral_start.twin_solution(cell, cell_load(2, pressure=1e-3), "starting from the rigid predictor")
    assert isinstance(out, str)
    failed = [r for r in caplog.records if "the twin failed" in r.getMessage()]
    assert failed and all(r.levelno == logging.INFO for r in failed)


# ------------------------------------------------------------------ FE rigid predictor
def _sinusoid_problem():
    law = isotropic(1.0, 0.3)
    cell = profiles.profile_cell(profiles.sinusoid(0.05, 1.0), h_rough=1.0,
                                 h_counter=1.0, maxh=0.3, interface_maxh=0.1, order=1)
    return CellProblem(cell, CellModel(rough=law, counter=law, k_n=1e3, order=1))


@pytest.mark.parametrize("p", [5e-324, 1e-310, 0.0])
def test_the_rigid_predictor_brackets_a_subnormal_and_a_zero_load(p):
    """Was: a hang at pressure 5e-324 (the bracket stayed at 0)."""
    P = _sinusoid_problem()
    with deadline(60):
        d = _winkler_root(P, p, layer_stiffness(P, 1.0)) if p == 0.0 else rigid_approach(P, p)
    assert math.isfinite(d) and 0.0 <= d <= 1e-300


# ------------------------------------------------------------------ FE exact cell: the contact set
EXACT = sinusoid_cell(k_n="1.0e3", enforcement="exact", pressure="{pressure}",
                        discretization="order = 2\nmaxh = 0.25\ninterface_maxh = 0.05\nestimate = \"off\"")


def test_the_exact_cell_counts_no_touching_node_as_contact_at_zero_load(tmp_path):
    """Was: contact fraction 0.0101 at a prescribed approach of zero (the node touching at x = 0)."""
    text = EXACT.replace("pressure = [{pressure}]", "normal_jump = [0.0]")
    rc, rep = _run(tmp_path, text)
    assert rc == 0
    load = rep["results"]["loads"][0]
    assert load["mean_pressure"] == 0.0 and load["contact_fraction"] == 0.0


def test_the_exact_cell_contact_fraction_vanishes_with_the_load(tmp_path):
    """Was: 0.0169 at pressure 1e-12 (Westergaard: 4.9e-6): the touching node was counted with its element."""
    rc, rep = _run(tmp_path, EXACT.replace("{pressure}", "1e-12"))
    assert rc == 0
    assert rep["results"]["loads"][0]["contact_fraction"] <= 1e-3


# ------------------------------------------------------------------ small strain
@pytest.mark.parametrize("disc", ['method = "spectral"\ngrid = 64', "order = 1\nmaxh = 0.5\nestimate = \"off\""])
def test_a_far_face_jump_beyond_small_strain_is_warned_and_recorded(tmp_path, caplog, disc):
    """Was: a far-face jump of 14867 in a cell 2 high, without a word."""
    text = sinusoid_cell(k_n="1e-2", enforcement="penalty", pressure="1e-5, 0.2", discretization=disc)
    with caplog.at_level(logging.WARNING):
        rc, rep = _run(tmp_path, text)
    assert rc == 0
    small, large = rep["results"]["loads"]
    assert small["far_face_strain"] == pytest.approx(abs(small["far_face_jump"][-1]) / 2.0, rel=1e-12)
    assert small["far_face_strain"] < 0.05 < large["far_face_strain"]
    warned = [r.getMessage() for r in caplog.records if "small strain" in r.getMessage()]
    assert len(warned) == 1 and warned[0].startswith("load 1: ") and f"{large['far_face_strain']:.3g}" in warned[0]


# ------------------------------------------------------------------ progress of long spectral solves
REFINED = sinusoid_cell(k_n="1.0e3", enforcement="exact", pressure="0.003",
                          discretization='method = "spectral"\ngrid = 64\ntolerance = 1e-3')


def test_each_refinement_level_and_a_long_solve_print_a_progress_line(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(ccg, "PROGRESS_SECONDS", 0.0)       # every solve counts as long
    rc, rep = _run(tmp_path, REFINED, quiet=False)
    assert rc == 0
    err = capsys.readouterr().err
    levels = rep["results"]["method"]["refinement"]
    for level in levels:
        assert f"spectral grid {level['grid']}" in err
    assert "refinement may reach" in err and "constrained CG: step" in err
    assert all(line.startswith("[") for line in err.splitlines() if "spectral grid" in line)


def test_progress_lines_are_not_printed_with_quiet(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(ccg, "PROGRESS_SECONDS", 0.0)
    rc, _ = _run(tmp_path, REFINED, quiet=True)
    assert rc == 0 and capsys.readouterr().err == ""


def test_a_long_frictional_spectral_solve_prints_progress_lines(monkeypatch, caplog):
    from ngcontact.geometry.cell3d import bisinusoid_gap
    from ngcontact.laws.friction import Tresca
    monkeypatch.setattr(ccg, "PROGRESS_SECONDS", 0.0)       # every solve counts as long
    N = 32
    s = np.arange(N) / N
    cell = SpectralCell(dim=3, period=1.0, grid=N, rough=Layer(1, 0.3, 0.6), counter=Layer(2, 0.2, 0.6),
                        gap=bisinusoid_gap(0.005, 1.0, xy=(s[None, :], s[:, None])), k_n=1e3, enforcement="exact",
                        friction=Tresca(w=1e-5, G=0.004), tol=1e-10, max_iter=50000)
    with caplog.at_level(logging.INFO, logger="ngcontact.progress"):
        sol = cell.solve(cell_load(3, pressure=0.008, shear=(0.002, 0.0)))
    lines = [r.getMessage() for r in caplog.records if r.getMessage().startswith("accelerated proximal gradient: step")]
    assert sol.iterations > 10 and len(lines) == sol.iterations // 10 - 1
