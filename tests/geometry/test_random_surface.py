"""Random self-affine surfaces: spectrum, scale, seed, layout, bad arguments; the scene profile."""
import math

import numpy as np
import pytest

from ngcontact.errors import GeometryError
from ngcontact.geometry.random_surface import as_height_map, self_affine


@pytest.mark.parametrize("hurst", [0.3, 0.8])
def test_the_power_spectrum_falls_with_the_self_affine_exponent(hurst):
    z = self_affine(dim=3, grid=256, hurst=hurst, rms_height=1e-3, rolloff=0.25, cutoff=1 / 64, seed=2)
    C = np.abs(np.fft.fft2(z)) ** 2
    f = np.fft.fftfreq(256) * 256
    q = np.hypot(f[None, :], f[:, None])
    band = (q > 6) & (q < 28)        # between roll-off (q = 4) and cut-off (q = 64), away from both
    slope = np.polyfit(np.log(q[band]), np.log(C[band]), 1)[0]
    assert slope == pytest.approx(-2 * (1 + hurst), abs=0.15)
    assert np.all(C[q > 64.5] < 1e-20 * C.max())                       # nothing beyond the cut-off


def test_rms_height_and_slope_are_met_and_the_seed_repeats_the_surface():
    z = self_affine(dim=3, grid=128, hurst=0.7, rms_height=2e-3, seed=5)
    assert math.sqrt(np.mean(z ** 2)) == pytest.approx(2e-3, rel=1e-12) and abs(z.mean()) < 1e-15
    s = self_affine(dim=3, grid=128, hurst=0.7, rms_slope=0.05, cutoff=1 / 8, seed=5)
    # periodic central differences, 16 points per shortest wavelength: within 3 % of the spectral slope
    gx = (np.roll(s, -1, axis=1) - np.roll(s, 1, axis=1)) * 64
    gy = (np.roll(s, -1, axis=0) - np.roll(s, 1, axis=0)) * 64
    assert math.sqrt(np.mean(gx ** 2 + gy ** 2)) == pytest.approx(0.05, rel=0.03)
    assert np.array_equal(s, self_affine(dim=3, grid=128, hurst=0.7, rms_slope=0.05, cutoff=1 / 8, seed=5))
    assert not np.array_equal(s, self_affine(dim=3, grid=128, hurst=0.7, rms_slope=0.05, cutoff=1 / 8, seed=6))
    p = self_affine(dim=2, grid=512, hurst=0.5, rms_height=1.0, seed=1)
    assert p.shape == (512,) and math.sqrt(np.mean(p ** 2)) == pytest.approx(1.0, rel=1e-12)


def test_height_map_layout_repeats_the_first_row_and_column():
    z = self_affine(dim=3, grid=16, hurst=0.8, rms_height=1.0)
    m = as_height_map(z)
    assert m.shape == (17, 17) and np.array_equal(m[-1], m[0]) and np.array_equal(m[:, -1], m[:, 0])
    assert np.array_equal(m[:-1, :-1], z)
    assert as_height_map(np.arange(4.0)).tolist() == [0, 1, 2, 3, 0]


@pytest.mark.parametrize("kwargs, key", [
    (dict(hurst=1.0, rms_height=1.0), "hurst"),
    (dict(hurst=0.5), "rms_height"),
    (dict(hurst=0.5, rms_height=1.0, rms_slope=1.0), "rms_height"),
    (dict(hurst=0.5, rms_slope=-1.0), "rms_slope"),
    (dict(hurst=0.5, rms_height=1.0, cutoff=1 / 200), "cutoff"),
    (dict(hurst=0.5, rms_height=1.0, grid=15), "grid"),
])
def test_bad_arguments_are_named(kwargs, key):
    with pytest.raises(GeometryError) as err:
        self_affine(dim=3, **{"grid": 64, **kwargs})
    assert err.value.name == key
