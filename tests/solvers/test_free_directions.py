"""The projector onto the free directions of an active-set step, on the grid and on its support.

:class:`ngcontact.solvers.free_directions.FreeDirections` against the projector written out on whole grid
fields (the pressure where pressed, the shear where sticking, the tangent of the disc where turning, the sums
of the prescribed means zero), and the Coulomb lift's form on the support against its grid form.
"""
import numpy as np
import pytest

from ngcontact.cell.spectral.traction_constraints import TractionConstraints
from ngcontact.solvers.free_directions import FreeDirections


def _grid_projector(x, pressed, stick, rim, t_hat, constrained):
    """The projector of the module docstring on whole grid fields, entry by entry."""
    d = x.shape[0]
    y = np.zeros_like(x)
    y[d - 1] = np.where(pressed, x[d - 1], 0.0)
    if constrained[d - 1] and pressed.any():
        y[d - 1] = np.where(pressed, y[d - 1] - y[d - 1].sum() / pressed.sum(), 0.0)
    shear = np.where(stick, x[:d - 1], 0.0)
    basis = []                               # the free shear directions, one grid field each
    for i in zip(*np.nonzero(stick)):
        for a in range(d - 1):
            e = np.zeros_like(x[:d - 1])
            e[(a,) + i] = 1.0
            basis.append(e)
    if d == 3:
        for i in zip(*np.nonzero(rim)):
            q = t_hat[:2][(slice(None),) + i]
            e = np.zeros_like(x[:2])
            e[(slice(None),) + i] = np.array([-q[1], q[0]]) / np.hypot(*q)
            shear += e * float(np.sum(e * x[:2]))
            basis.append(e)
    if constrained[0]:
        B = np.array([b.ravel() for b in basis]).T               # orthonormal columns
        sums = np.array([b.reshape(d - 1, -1).sum(axis=1) for b in basis]).T     # (d - 1, m)
        c = B.T @ shear.ravel()
        # the projection onto {c : sums c = 0} in the coordinates of the orthonormal basis
        c -= sums.T @ np.linalg.lstsq(sums @ sums.T, sums @ c, rcond=None)[0]
        shear = (B @ c).reshape(shear.shape)
    y[:d - 1] = shear
    return y


def _state(d, seed):
    rng = np.random.default_rng(seed)
    shape = (6, 5) if d == 3 else (17,)
    t_hat = rng.normal(size=(d,) + shape)
    kind = rng.integers(0, 3, size=shape)          # 0 open, 1 stick, 2 rim
    pressed = kind > 0
    return t_hat, pressed, kind == 1, kind == 2, rng


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("constrained", [(False,) * 3, (True,) * 3, (True, True, False)])
def test_the_projector_on_the_support_is_the_grid_projector(d, constrained):
    constrained = constrained[-d:]
    t_hat, pressed, stick, rim, rng = _state(d, 3)
    free = FreeDirections(pressed, stick, rim, t_hat, constrained)
    x = rng.normal(size=t_hat.shape)
    y = free(x)
    assert np.allclose(y, _grid_projector(x, pressed, stick, rim, t_hat, constrained), rtol=0, atol=1e-12)
    assert np.allclose(free(y), y, rtol=0, atol=1e-12)
    assert np.array_equal(free.scatter(free.gather(y)), y)          # the range lies on the support
    c = free.gather(x)
    assert np.allclose(free.reduced(c), free.gather(y), rtol=0, atol=1e-14)


@pytest.mark.parametrize("d", [2, 3])
def test_the_coulomb_lift_on_the_support_is_its_grid_form(d):
    t_hat, pressed, stick, rim, rng = _state(d, 5)
    shape = t_hat.shape[1:]
    t_hat[d - 1] = np.abs(t_hat[d - 1]) * pressed
    G = 0.5 * t_hat[d - 1]
    # sticking shear inside the disc, slipping shear on its rim
    norm = np.sqrt(np.sum(t_hat[:d - 1] ** 2, axis=0))
    t_hat[:d - 1] *= np.where(stick, 0.5 * G / norm, np.where(rim, G / norm, 0.0))
    h = TractionConstraints(shape, lambda p: 0.5 * p, 1.0, None, None, 1.0, np.zeros(d - 1), slope=0.5)
    free, D, lift = h.linearize(t_hat, t_hat, (0.0, np.zeros(d - 1)))
    c = free.reduced(free.gather(rng.normal(size=t_hat.shape)))
    full = lift(free.scatter(c))
    assert np.array_equal(free.scatter(free.gather(full)), full)   # the lift stays on the support
    assert np.allclose(lift.reduced(c), free.gather(full), rtol=0, atol=1e-14)
