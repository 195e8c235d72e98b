"""Exact Coulomb friction of the spectral cell against Tamaas' ``PolonskyKeerTan`` (the ``bench`` extra).

The problem posed alike (``scripts/tamaas_coulomb.py``): an elastic half-space under a rigid rough surface,
Coulomb ``mu = 0.5``, a mean pressure and a mean shear along ``x``.  The oracles: (1) the cell's operator is
Tamaas' on every mode but the Nyquist ones, to round-off; (2) on Tamaas' own operator our active-set solver and
``PolonskyKeerTan``, each converged to the cell's stopping measure, give the same tractions (to 1e-9 of their norm)
and the same open, stick and slip sets; (3) the schedule of a Tamaas solver's runs meets the tolerance of a
geometric residual in one extrapolated run and stops a stalling one.  Without Tamaas the tests that run it skip.
"""
import csv
import importlib.util
import os

import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.spectral.traction_constraints import TractionConstraints
from ngcontact.geometry.random_surface import self_affine
from ngcontact.solvers.active_set_newton import coulomb_active_set

SCRIPTS = os.path.join(os.path.dirname(__file__), "..", "..", "scripts")
NO_TAMAAS = "Tamaas is not installed (the 'bench' extra: pip install '.[bench]')"



def _script(name: str):
    spec = importlib.util.spec_from_file_location(name, os.path.join(SCRIPTS, f"{name}.py"))
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


T = _script("tamaas_coulomb")

E, NU, MU = 1.0, 0.3, 0.5
P = 0.05 * E / (2 * (1 - NU ** 2)) * 0.1
S = 0.2 * P
N = 32
TOL = 1e-11


def surface() -> np.ndarray:
    return self_affine(dim=3, grid=N, hurst=0.8, rms_slope=0.1, rolloff=0.25, cutoff=1 / 16, seed=7)


def without_nyquist(t: np.ndarray) -> np.ndarray:
    spectrum = np.fft.rfftn(t, axes=(1, 2))
    spectrum[:, N // 2, :] = 0.0
    spectrum[:, :, N // 2] = 0.0
    return np.fft.irfftn(spectrum, s=(N, N), axes=(1, 2))


def test_the_schedule_extrapolates_a_geometric_residual_and_stops_a_stalling_one():
    residual = lambda k: 10.0 ** (-k / 35)          # noqa: E731  (one digit per 35 steps: 1e-10 at 350)
    runs = [(k, residual(k)) for k in (100, 200)]
    assert T.next_steps([], 1e-10, 100) == 100 and T.next_steps(runs[:1], 1e-10, 100) == 200
    k = T.next_steps(runs, 1e-10, 100)
    assert k is not None and residual(k) <= 1e-10 and k <= 1.1 * 350 + 1     # one run, 10 % beyond the need
    assert T.next_steps(runs + [(k, residual(k))], 1e-10, 100) is None
    assert T.next_steps([(100, 1e-3), (200, 0.6e-3)], 1e-10, 100) is None      # doubling did not halve it
    assert T.next_steps([(100, 1e-3), (200, 1e-5), (400, 2e-5)], 1e-10, 100) is None   # a run that did not lower it


def test_the_cell_operator_is_tamaas_off_the_nyquist_modes():
    pytest.importorskip("tamaas", reason=NO_TAMAAS)
    cell = T.halfspace_cell(surface(), E, NU, MU, TOL)
    ours = cell.traction_operator((False, False, False))[0]
    theirs = T.tamaas_operator(N, E, NU)
    t = np.random.default_rng(1).normal(size=(3, N, N))
    t -= t.mean(axis=(1, 2), keepdims=True)
    smooth = without_nyquist(t)
    assert T.traction_difference(ours(smooth), theirs(smooth)) < 1e-10
    # the Nyquist modes are where the two discretizations differ (the module docstring of the script)
    assert T.traction_difference(ours(t), theirs(t)) > 1e-4


def test_exact_coulomb_agrees_with_polonsky_keer_tan_on_its_operator():
    pytest.importorskip("tamaas", reason=NO_TAMAAS)
    z = surface()
    cell = T.halfspace_cell(z, E, NU, MU, TOL)
    apply = T.tamaas_operator(N, E, NU)
    L = cell.traction_operator((False, False, False))[1]
    b = np.zeros((3, N, N))
    b[2] = cell.g0
    h = TractionConstraints(cell.shape, lambda p: MU * p, L, None, None, P, np.array([-S, 0.0]), slope=MU)
    t0 = np.zeros((3, N, N))
    t0[0] = -S
    t0[2] = cell.solve_normal(cell_load(3, pressure=P), None)["p"]
    ours = coulomb_active_set(lambda t: apply(t) + b, apply, b, h, cell.traction_preconditioner(0.0), t0, L,
                              tol=TOL, scale=cell.gscale, max_iter=20000)
    theirs, grad, _ = T.run_tamaas("PolonskyKeerTan", z, E, NU, MU, P, S, steps=3000)
    assert T.fixed_point_residual(ours.t, apply(ours.t) + b, L, cell.gscale, MU, P, S) <= TOL
    assert T.fixed_point_residual(theirs, grad, L, cell.gscale, MU, P, S) <= TOL
    assert T.traction_difference(ours.t, theirs) < 1e-9
    contact, stick = T.fractions(ours.t, MU)
    assert 0 < stick < contact < 1
    assert (contact, stick) == T.fractions(theirs, MU)


@pytest.mark.slow
def test_the_speed_script_runs_the_halfspace_rows(tmp_path):
    """A 32^2 run of ``scripts/spectral_friction_speed.py --cases halfspace`` (half a minute: ten child processes):
    ours and ``PolonskyKeerTan`` meet the tolerance and agree to the discretizations' difference; a solver that
    does not reach it says so."""
    pytest.importorskip("tamaas", reason=NO_TAMAAS)
    speed = _script("spectral_friction_speed")
    assert speed.main([str(tmp_path), "--grids", "32", "--cases", "halfspace", "--tamaas-first", "1000",
                       "--tamaas-budget", "30"]) == 0
    with open(tmp_path / "spectral_friction_speed.csv") as fh:
        rows = {r["solver"]: r for r in csv.DictReader(fh)}
    assert set(rows) == {"current", "current 1 thread"} | {f"tamaas {name}" for name in T.SOLVERS}
    for solver in ("current", "current 1 thread", "tamaas PolonskyKeerTan"):
        assert float(rows[solver]["residual"]) <= speed.TOL
    peer = rows["tamaas PolonskyKeerTan"]
    assert 1e-4 < float(peer["traction_difference"]) < 2e-2
    assert peer["attempts"].startswith("1000:") and int(peer["steps"]) >= 1000
    assert float(rows["tamaas BeckTeboulle"]["residual"]) > speed.TOL
