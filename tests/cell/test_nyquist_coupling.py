"""The normal/tangential coupling of the layers' compliance is zeroed on the Nyquist mode only.

On an even grid of ``n`` points the mode ``n/2`` is its own mirror (``k`` and ``-k`` coincide), so the
odd (imaginary) coupling has no real counterpart there and is zeroed; an odd grid has no such mode and
keeps the coupling at every wave number, ``n // 2`` included.
"""
import numpy as np
import pytest

from ngcontact.cell.spectral.frictional_contact import _layers_compliance
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell


def _cell(dim: int, n: int) -> SpectralCell:
    shape = (n,) * (dim - 1)
    return SpectralCell(dim=dim, period=1.0, grid=n, rough=Layer(E=1.0, nu=0.3, h=0.5),
                        counter=Layer(E=3.0, nu=0.25, h=0.3), gap=np.zeros(shape), k_n=1.0)


@pytest.mark.parametrize("dim", [2, 3])
def test_the_coupling_is_zeroed_on_an_even_grids_nyquist_mode_only(dim):
    even, odd = _layers_compliance(_cell(dim, 16)), _layers_compliance(_cell(dim, 15))
    d = dim
    if dim == 2:
        assert even[8, 0, 1] == 0.0 and abs(even[7, 0, 1]) > 0.0
        assert abs(odd[7, 0, 1]) > 0.0
    else:
        assert np.all(even[8, :, :d - 1, d - 1] == 0.0) and np.all(even[:, 8, :d - 1, d - 1] == 0.0)
        assert np.abs(even[3, 7, :d - 1, d - 1]).max() > 0.0
        assert np.abs(odd[7, 3, :d - 1, d - 1]).max() > 0.0 and np.abs(odd[3, 7, :d - 1, d - 1]).max() > 0.0
