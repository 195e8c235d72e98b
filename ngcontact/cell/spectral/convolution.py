"""A periodic convolution on the grid, applied by real FFTs, with its view from Fourier space.

The spectral cell's operators (:mod:`ngcontact.cell.spectral.layered_cell`) are convolutions with a real,
even symbol ``a(k)`` on the half spectrum of ``scipy.fft.rfftn``, plus a multiple ``w`` of the identity (the
penalty layer's ``p / k_n``):

    A x = IFFT(a FFT(x)) + w x.

Besides ``x -> A x`` (one forward and one inverse transform), :class:`Convolution` answers the questions of a
conjugate-gradient step from the forward transform ``X = FFT(x)`` alone (the seam
:class:`ngcontact.solvers.constrained_cg.DirectionOperator`):

* the energy ``<x, A x> = (1/n) sum_k m_k a_k |X_k|^2 + w <x, x>`` by Parseval's identity, ``n`` the grid's
  points and ``m_k`` the multiplicity of a wave vector of the half spectrum (2 where its conjugate is not
  stored, 1 on the planes ``k_last = 0`` and, for an even grid, ``k_last = N/2``);
* ``c A x = IFFT(c a X) + c w x`` by the inverse transform alone.

So a step whose displacement is a multiple of its direction costs one forward and one inverse transform, and
its step length costs none.  The inverse transform is made in its two passes, complex-to-complex over the
leading axes and complex-to-real along the last, each in place: the same transform as ``scipy.fft.irfftn``,
with no copy of the spectrum.
"""
from __future__ import annotations

import numpy as np

from ngcontact.cell.spectral.fft_threads import fft_workers


def multiplicity(shape: tuple[int, ...]) -> np.ndarray:
    """``m_k`` of the half spectrum of ``rfftn`` on a grid of ``shape`` (module docstring), broadcastable."""
    n = shape[-1]
    m = np.full(n // 2 + 1, 2.0)
    m[0] = 1.0
    if n % 2 == 0:
        m[-1] = 1.0
    return m


class Convolution:
    """``x -> IFFT(symbol FFT(x)) + diagonal x`` on a grid of ``shape`` (module docstring).

    ``symbol``: real, on the half spectrum of ``rfftn`` for ``shape``; ``diagonal``: the multiple ``w`` of
    the identity (0: none).  Counts its transforms in ``forward`` and ``inverse`` (the solvers' cost).
    """

    def __init__(self, symbol: np.ndarray, shape: tuple[int, ...], diagonal: float = 0.0):
        self.symbol, self.shape, self.diagonal = symbol, tuple(shape), float(diagonal)
        self.points = int(np.prod(self.shape))
        self._weights = symbol * multiplicity(self.shape) / self.points
        self.forward = self.inverse = 0

    def transform(self, x: np.ndarray) -> np.ndarray:
        """``X = FFT(x)`` on the half spectrum (a new array)."""
        import scipy.fft as sfft  # on use: importing scipy.fft would slow the start of every process
        self.forward += 1
        return sfft.rfftn(x, workers=fft_workers(x.size))

    def from_transform(self, X: np.ndarray, x: np.ndarray, factor: float = 1.0) -> np.ndarray:
        """``factor A x`` from ``X = FFT(x)`` and ``x`` (a new array; ``X`` is overwritten)."""
        import scipy.fft as sfft
        self.inverse += 1
        X *= self.symbol
        if factor != 1.0:
            X *= factor
        workers = fft_workers(x.size)
        if len(self.shape) > 1:
            X = sfft.ifftn(X, axes=tuple(range(len(self.shape) - 1)), workers=workers, overwrite_x=True)
        out = sfft.irfft(X, n=self.shape[-1], axis=-1, workers=workers, overwrite_x=True)
        if self.diagonal:
            out += (factor * self.diagonal) * x
        return out

    def energy(self, X: np.ndarray, x: np.ndarray) -> float:
        """``<x, A x>`` from ``X = FFT(x)`` and ``x`` by Parseval's identity (module docstring)."""
        e = float(np.sum(self._weights * (X.real * X.real + X.imag * X.imag)))
        if self.diagonal:
            e += self.diagonal * float(np.multiply(x, x).sum())
        return e

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """``A x`` (a new array)."""
        return self.from_transform(self.transform(x), x)
