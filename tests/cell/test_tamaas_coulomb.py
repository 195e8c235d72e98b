"""Exact Coulomb friction of the spectral cell against Tamaas' ``PolonskyKeerTan`` (the ``bench`` extra).

The problem posed alike (``scripts/tamaas_coulomb.py``): an elastic half-space under a rigid rough surface,
Coulomb ``mu = 0.5``, a mean pressure and a mean shear along ``x``.  The oracles: (1) the cell's operator is
Tamaas' on every mode but the Nyquist ones, to round-off; (2) on Tamaas' own operator our active-set solver and
``PolonskyKeerTan``, each converged to the cell's stopping measure, give the same tractions (to 1e-9 of their norm)
and the same open, stick and slip sets.
"""
import importlib.util
import os

import numpy as np
import pytest

tm = pytest.importorskip("tamaas", reason="Tamaas is not installed (the 'bench' extra: pip install '.[bench]')")

from ngcontact.cell.cell_load import cell_load  # noqa: E402
from ngcontact.cell.spectral.traction_constraints import TractionConstraints  # noqa: E402
from ngcontact.geometry.random_surface import self_affine  # noqa: E402
from ngcontact.solvers.active_set_newton import coulomb_active_set  # noqa: E402

_SPEC = importlib.util.spec_from_file_location(
    "tamaas_coulomb", os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "tamaas_coulomb.py"))
assert _SPEC is not None and _SPEC.loader is not None
T = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(T)

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


def test_the_cell_operator_is_tamaas_off_the_nyquist_modes():
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
