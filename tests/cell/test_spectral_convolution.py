"""The spectral cell's convolution (:mod:`ngcontact.cell.spectral.convolution`) and the transforms a step of the
constrained CG costs (:mod:`ngcontact.solvers.constrained_cg`, its cost of a step).

Per step: one forward and one inverse transform of the preconditioner, one forward transform of the direction
(its step length by Parseval's identity), one inverse transform for the gap where the step clips no point,
else one application to the pressure (a forward and an inverse transform).  So the inverse transforms are
exactly two per step (one without the preconditioner), besides the start and the confirmation of the answer.
"""
import numpy as np
import pytest
import scipy.fft as sfft

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.spectral.convolution import Convolution
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.geometry.random_surface import self_affine
from ngcontact.solvers.constrained_cg import constrained_cg

P = 0.0027


def _cell(dim: int, n: int, enforcement: str = "exact") -> SpectralCell:
    z = self_affine(dim=dim, grid=n, hurst=0.8, rms_slope=0.1, rolloff=0.25, cutoff=1 / 16, seed=7)
    return SpectralCell(dim=dim, period=1.0, grid=n, rough=Layer(1.0, 0.3, 0.5), counter=Layer(3.0, 0.25, 0.3),
                        gap=z.max() - z, k_n=30.0, enforcement=enforcement, tol=1e-10, max_iter=100000)


@pytest.mark.parametrize("shape", [(64,), (63,), (16, 16), (15, 15)])
def test_the_convolution_answers_from_one_forward_transform(shape):
    """``<x, A x>`` by Parseval and ``c A x`` from the transform agree with ``A x`` itself, odd and even
    grids, with a multiple of the identity."""
    rng = np.random.default_rng(3)
    half = shape[:-1] + (shape[-1] // 2 + 1,)
    A = Convolution(rng.random(half) + 0.1, shape, diagonal=0.3)
    x = rng.standard_normal(shape)
    Ax = A(x)
    X = A.transform(x)
    assert A.energy(X, x) == pytest.approx(float(np.sum(x * Ax)), rel=1e-12)
    assert np.allclose(A.from_transform(X, x, -2.5), -2.5 * Ax, rtol=0, atol=1e-12 * np.max(np.abs(Ax)))
    assert A.forward == 2 and A.inverse == 2


@pytest.fixture
def transforms(monkeypatch):
    """The forward and inverse real FFTs called, counted (an inverse transform ends in ``irfft``, or is
    ``irfftn``)."""
    counts = {"forward": 0, "inverse": 0}

    def counted(fn, key):
        def wrapped(*args, **kwargs):
            counts[key] += 1
            return fn(*args, **kwargs)
        return wrapped
    monkeypatch.setattr(sfft, "rfftn", counted(sfft.rfftn, "forward"))
    monkeypatch.setattr(sfft, "irfftn", counted(sfft.irfftn, "inverse"))
    monkeypatch.setattr(sfft, "irfft", counted(sfft.irfft, "inverse"))
    return counts


@pytest.mark.parametrize("dim, n, enforcement", [(3, 64, "exact"), (2, 512, "penalty")])
@pytest.mark.parametrize("preconditioned", [True, False])
def test_a_constrained_cg_step_costs_one_transform_pair_of_the_operator(transforms, dim, n, enforcement,
                                                                        preconditioned):
    cell = _cell(dim, n, enforcement)
    transforms.update(forward=0, inverse=0)        # not those of the map
    res = constrained_cg(cell.interface_compliance(uniform=False), cell.g0, pbar=P, tol=1e-10, max_iter=10000,
                         gscale=cell.gscale, precondition=cell.inverse_compliance() if preconditioned else None)
    steps, per_step = res.iterations, 2 if preconditioned else 1
    assert steps > 5 and res.p.min() >= 0
    # the start's A p, then per step; one more A p confirms an answer reached on an updated gap
    assert per_step * steps + 1 <= transforms["inverse"] <= per_step * steps + 2, (steps, transforms)
    # one more forward transform on a step that clips points or refreshes the gap
    assert transforms["forward"] <= (per_step + 1) * steps + 2, (steps, transforms)


def test_a_prescribed_approach_costs_the_same_transforms(transforms):
    cell = _cell(3, 64)
    approach = cell.solve(cell_load(3, pressure=P)).results["far_face_jump"][-1]
    transforms.update(forward=0, inverse=0)
    b = cell.g0 - approach
    res = constrained_cg(cell.interface_compliance(uniform=True), b, pbar=None, tol=1e-10, max_iter=10000,
                         gscale=cell.gscale, precondition=cell.inverse_compliance())
    # and one application for the start (the operator's diagonal)
    assert 2 * res.iterations + 2 <= transforms["inverse"] <= 2 * res.iterations + 3, (res.iterations, transforms)
