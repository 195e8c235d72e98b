"""Random periodic self-affine surfaces from a power spectrum.

A self-affine rough surface of Hurst exponent ``H`` (0 < H < 1) has the
isotropic power spectral density

    C(q) = C0                      for q_l <= q < q_r   (roll-off),
    C(q) = C0 (q / q_r)^(-2(1+H))  for q_r <= q <= q_s,
    C(q) = 0                       otherwise,

(3D height maps; a 2D profile takes the exponent ``-(1+2H)``), with the
wave numbers ``q = 2 pi / wavelength``: ``q_l`` the longest wavelength kept
(the period by default), ``q_r`` the roll-off and ``q_s`` the shortest
(the small cut-off).  The generator draws each Fourier coefficient as a
complex Gaussian of variance ``C(|q|)`` (the surface of Persson et al.,
J. Phys.: Condens. Matter 17 (2005) R1, Sec. 4, filtered white noise), makes
the field real by an inverse real FFT, removes its mean, and scales it to
the requested root-mean-square height or slope (the slope as the RMS of the
spectral gradient, exact for the trigonometric interpolant).  A seed makes
it reproducible.

The result is periodic and sampled at ``x_j = j P / N``; :func:`as_height_map`
appends the repeated last row and column of the height-map file layout
(:func:`ngcontact.geometry.tabulated.read_height_map`).
"""
from __future__ import annotations

import math

import numpy as np

from ngcontact.errors import GeometryError
from ngcontact.geometry.tabulated import MAX_SPAN


def wave_vectors(dim: int, n: int, period: float):
    """Wave vectors of the half spectrum of ``scipy.fft.rfftn`` on ``n`` points per period.

    Returns ``(components, |k|)``: 2D ``((k_x,), |k_x|)``, shape ``(n//2+1,)``;
    3D ``((k_x, k_y), |k|)`` broadcasting to ``(n, n//2+1)`` (rows ``y``).
    """
    import scipy.fft as sfft  # on use: importing scipy.fft would slow the start of every process (and batch worker)
    k1 = 2 * math.pi * sfft.rfftfreq(n, d=period / n)
    if dim == 2:
        return (k1,), np.abs(k1)
    k0 = 2 * math.pi * sfft.fftfreq(n, d=period / n)
    kx, ky = k1[None, :], k0[:, None]
    return (kx, ky), np.sqrt(kx ** 2 + ky ** 2)


def self_affine(*, dim: int = 3, grid: int = 256, period: float = 1.0, hurst: float = 0.8,
                rms_height: float | None = None, rms_slope: float | None = None,
                rolloff: float | None = None, cutoff: float | None = None, longest: float | None = None,
                seed: int = 0) -> np.ndarray:
    """A random periodic self-affine surface (module docstring).

    Parameters
    ----------
    dim
        3: a height map of shape ``(grid, grid)`` indexed ``[y, x]``; 2: a
        profile of shape ``(grid,)``.
    grid, period
        Points per period and direction, and the period.
    hurst
        Hurst exponent, in (0, 1).
    rms_height, rms_slope
        Exactly one: the RMS height or the RMS slope of the result.
    rolloff, cutoff, longest
        Wavelengths ``2 pi / q_r``, ``2 pi / q_s`` and ``2 pi / q_l``
        (defaults: the period, four grid steps, the period).
    seed
        Seed of NumPy's default generator.
    """
    import scipy.fft as sfft  # on use: importing scipy.fft would slow the start of every process (and batch worker)
    if dim not in (2, 3):
        raise GeometryError("dim", dim, "must be 2 (profile) or 3 (height map)")
    if not (isinstance(grid, (int, np.integer)) and grid >= 8 and grid % 2 == 0):
        raise GeometryError("grid", grid, "must be an even integer >= 8")
    if not 0 < hurst < 1:
        raise GeometryError("hurst", hurst, "must lie in (0, 1)")
    if (rms_height is None) == (rms_slope is None):
        raise GeometryError("rms_height", rms_height, "give exactly one of rms_height and rms_slope")
    target = rms_height if rms_height is not None else rms_slope
    if not (target is not None and target > 0 and math.isfinite(target)):
        raise GeometryError("rms_height" if rms_height is not None else "rms_slope", target, "must be > 0")
    step = period / grid
    longest = period if longest is None else longest
    rolloff = longest if rolloff is None else rolloff
    cutoff = 4 * step if cutoff is None else cutoff
    order = [("cutoff", cutoff, 2 * step <= cutoff < rolloff), ("rolloff", rolloff, rolloff <= longest),
             ("longest", longest, longest <= period)]
    for name, value, ok in order:   # the first inequality that fails names its key
        if not ok:
            raise GeometryError(name, value, f"need 2 grid steps ({2 * step:g}) <= cutoff < rolloff ({rolloff:g}) "
                                f"<= longest ({longest:g}) <= period ({period:g})")
    q_l, q_r, q_s = (2 * math.pi / w for w in (longest, rolloff, cutoff))
    ks, q = wave_vectors(dim, grid, period)
    exponent = -2 * (1 + hurst) if dim == 3 else -(1 + 2 * hurst)
    eps = 1e-9 * q_s
    band = (q >= q_l - eps) & (q <= q_s + eps)
    psd = np.where(q < q_r, 1.0, (np.maximum(q, q_r) / q_r) ** exponent) * band
    rng = np.random.default_rng(seed)
    coeff = np.sqrt(psd) * (rng.standard_normal(q.shape) + 1j * rng.standard_normal(q.shape))
    shape = (grid,) * (dim - 1)
    coeff.flat[0] = 0.0
    z = sfft.irfftn(coeff, s=shape)
    if not np.any(z):
        raise GeometryError("cutoff", cutoff, "leaves no wave number between longest and cutoff on this grid")
    if rms_height is not None:
        scale = target / float(np.sqrt(np.mean(z ** 2)))
    else:
        zh = sfft.rfftn(z)
        grads = [sfft.irfftn(1j * k * zh, s=shape) for k in ks]
        scale = target / float(np.sqrt(np.mean(sum(g ** 2 for g in grads))))
    with np.errstate(over="ignore", invalid="ignore"):
        z = z * scale
        span = float(np.ptp(z))
    if not span <= MAX_SPAN:
        raise GeometryError("rms_height" if rms_height is not None else "rms_slope", target,
                            f"draws heights spanning {span:.3g}, more than {MAX_SPAN:g}: choose a length unit (e.g. mm "
                            "or um) in which the geometry's sizes fall in [1e-09, 1e+09]")
    return z


def as_height_map(z: np.ndarray) -> np.ndarray:
    """The periodic samples ``z`` with the first row and column repeated at the end (the file layout)."""
    z = np.asarray(z, dtype=float)
    if z.ndim == 1:
        return np.append(z, z[0])
    return np.pad(z, ((0, 1), (0, 1)), mode="wrap")


def _wave_numbers(shape: tuple[int, int], period: float) -> np.ndarray:
    """``|k|`` of the half spectrum of ``scipy.fft.rfft2`` of a ``[y, x]`` map of period ``period``."""
    import scipy.fft as sfft
    ny, nx = shape
    kx = 2 * math.pi * sfft.rfftfreq(nx, d=period / nx)
    ky = 2 * math.pi * sfft.fftfreq(ny, d=period / ny)
    return np.sqrt(kx[None, :] ** 2 + ky[:, None] ** 2)


def spectral_slope(z: np.ndarray, period: float) -> float:
    """The rms slope ``sqrt(<|grad z|^2>)`` of the trigonometric interpolant of periodic samples ``z[y, x]``."""
    import scipy.fft as sfft
    ny, nx = z.shape
    zh = sfft.fft2(z)
    kx = 2 * math.pi * sfft.fftfreq(nx, d=period / nx)[None, :]
    ky = 2 * math.pi * sfft.fftfreq(ny, d=period / ny)[:, None]
    return float(np.sqrt(np.sum((kx ** 2 + ky ** 2) * np.abs(zh) ** 2)) / z.size)


def radial_psd(z: np.ndarray, period: float) -> tuple[np.ndarray, np.ndarray]:
    """The radially averaged power spectral density of periodic samples ``z[y, x]`` (zero mean).

    ``C(k) = P^2 |c_k|^2`` with ``c_k = FFT(z)_k / N`` the Fourier coefficients (``N`` points), so that
    ``<z^2> = sum_k C(k) / P^2``; averaged over the wave vectors in rings ``|k| / (2 pi / P)`` rounded to
    ``m = 1, 2, ...``.  Returns the rings' mean ``|k|`` and mean ``C``.
    """
    import scipy.fft as sfft
    zh = sfft.fft2(z)
    ny, nx = z.shape
    kx = 2 * math.pi * sfft.fftfreq(nx, d=period / nx)[None, :]
    ky = 2 * math.pi * sfft.fftfreq(ny, d=period / ny)[:, None]
    k = np.sqrt(kx ** 2 + ky ** 2).ravel()
    C = (period ** 2 * np.abs(zh) ** 2 / z.size ** 2).ravel()
    ring = np.rint(k / (2 * math.pi / period)).astype(int)
    count = np.bincount(ring)
    keep = np.nonzero(count)[0]
    keep = keep[keep > 0]
    return (np.bincount(ring, weights=k)[keep] / count[keep], np.bincount(ring, weights=C)[keep] / count[keep])


def from_psd(q: np.ndarray, C: np.ndarray, *, grid: int, period: float, seed: int = 0) -> np.ndarray:
    """A random periodic surface ``[y, x]`` on ``grid x grid`` points with the isotropic spectrum ``C(q)``.

    ``C`` in the normalization of :func:`radial_psd`, given on its rings ``m = rint(q / (2 pi / P))``: each
    wave vector takes its ring's ``C`` (zero at ``k = 0``, in rings not given and beyond the last).  Each
    Fourier coefficient ``Z_k`` of the forward FFT is a complex Gaussian of variance ``N^2 C / P^2`` (``N``
    points; the filtered white noise of :func:`self_affine` with a tabulated spectrum), so that the expected
    spectrum of the surface is ``C`` and its expected mean square height ``sum_k C / P^2``, that of the
    surface whose spectrum ``C`` is.  The surface is not scaled to one rms height: for a spectrum whose few
    longest waves carry most of the power, scaling every draw to one rms would bias the expected spectrum
    of the others.  A seed makes it reproducible.
    """
    import scipy.fft as sfft
    q, C = np.asarray(q, float), np.asarray(C, float)
    ok = (q > 0) & (C > 0)
    if not ok.any():
        raise GeometryError("psd", "...", "a spectrum needs a ring of positive power")
    rings = np.rint(q[ok] / (2 * math.pi / period)).astype(int)
    table = np.zeros(rings.max() + 2)
    table[rings] = C[ok]
    m = np.minimum(np.rint(_wave_numbers((grid, grid), period) / (2 * math.pi / period)).astype(int),
                   len(table) - 1)
    variance = table[m] * (grid ** 2 / period) ** 2
    variance.flat[0] = 0.0
    # the columns k_x = 0 and Nyquist hold a wave vector and its conjugate twin: irfft2 keeps their mean
    # (half the variance), so they are drawn with twice it
    variance[:, 0] *= 2.0
    if grid % 2 == 0:
        variance[:, -1] *= 2.0
    rng = np.random.default_rng(seed)
    coeff = np.sqrt(variance / 2) * (rng.standard_normal(m.shape) + 1j * rng.standard_normal(m.shape))
    return sfft.irfft2(coeff, s=(grid, grid))
