"""The threads of the spectral cell's FFTs (:mod:`ngcontact.cell.spectral.fft_threads`): the run's, but at
most one per ``POINTS_PER_THREAD`` grid points, so that a small cell's transforms run on one thread."""
import numpy as np
import pytest
import scipy.fft as sfft

from ngcontact.cell.spectral import fft_threads
from ngcontact.cell.spectral.convolution import Convolution
from ngcontact.cell.spectral.fft_threads import POINTS_PER_THREAD, fft_workers


@pytest.mark.parametrize("threads, points, expected", [
    ("2", None, 2), ("2", 64 * 64, 1), ("2", POINTS_PER_THREAD, 1), ("2", 2 * POINTS_PER_THREAD, 2),
    ("2", 1024 * 1024, 2), ("4", 3 * POINTS_PER_THREAD - 1, 2), ("4", 1024 * 1024, 4), ("1", 1024 * 1024, 1)])
def test_a_transform_gets_the_runs_threads_where_each_has_enough_points(monkeypatch, threads, points, expected):
    monkeypatch.setenv(fft_threads.THREADS_ENV, threads)
    assert fft_workers(points) == expected


@pytest.mark.parametrize("n, expected", [(64, 1), (512, 2)])
def test_the_convolution_asks_for_the_threads_of_its_grid(monkeypatch, n, expected):
    """Both transforms of ``A x`` on a 64 x 64 grid run on one thread with two available, on 512 x 512 on
    both; the product is the same either way (the threads split independent lines of the transform)."""
    monkeypatch.setenv(fft_threads.THREADS_ENV, "2")
    seen = []
    for name in ("rfftn", "ifftn", "irfft"):
        real = getattr(sfft, name)
        monkeypatch.setattr(sfft, name, lambda *a, _real=real, **kw: seen.append(kw["workers"]) or _real(*a, **kw))
    rng = np.random.default_rng(5)
    A = Convolution(rng.random((n, n // 2 + 1)) + 0.1, (n, n))
    x = rng.standard_normal((n, n))
    Ax = A(x)
    assert seen and set(seen) == {expected}
    assert np.array_equal(Ax, sfft.irfftn(A.symbol * sfft.rfftn(x, workers=1), s=(n, n), workers=1))
