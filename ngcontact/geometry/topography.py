"""Measured topographies: a profilometer's or an AFM's scan as the periodic height map of a cell.

The instrument formats (X3P, DATX, OPD, SUR, PLU, IBW, DI, ... and plain-text matrices) are read by the
optional SurfaceTopography package (``pip install 'ngcontact[topography]'``), with the units and physical
size the file carries; a file's suffix chooses the reader where one reader owns it (``.x3p`` is read as X3P
or refused), else the content does.  The scene states what the file does not (:class:`Reading`): the length unit and
the scan's physical size, the detrending and whether the scan is periodic.  The result is a height map in
the package's layout (:func:`ngcontact.geometry.tabulated.read_height_map`: ``H[i, j]`` at
``y_i = i P / n_y``, ``x_j = j P / n_x``, the last row and column repeating the first) in metres, the
initial gap of the small-slope model (the height below the highest summit, paper eq. 65's ``g``).

Steps, in this order:

1. heights ``h(x, y)`` of the scan's ``n_x x n_y`` points, spacing ``L_x / n_x`` and ``L_y / n_y``
   (``L`` the physical size), converted to metres;
2. detrending: ``none``; ``mean_plane``, the least-squares plane ``a + b x + c y`` removed (tilt);
   ``curvature``, the least-squares quadratic removed (tilt and form); a periodic scan is not detrended
   (neither a plane nor a quadratic is periodic: removing one would put a step at the cell's boundary);
3. periodicity: a scan that is periodic (``periodic = true``, or the file says so) is used as it is, of
   period ``L``.  One that is not would put a step at the cell's boundary, a cliff that the periodic cell
   would press on; it is made periodic by a stated method (:data:`PERIODIZE`):

   * ``mirror``: the scan and its reflections in ``x``, in ``y`` and in both,
     ``[[h, h(L - x, .)], [h(., L - y), h(L - x, L - y)]]``, a continuous periodic surface of period ``2 L``
     with the scan's heights and slopes (a kink, no step, on the seams);
   * ``window``: ``(h - mean) w(x) w(y)`` with the cosine-tapered (Tukey) window of width ``a``,
     ``w(t) = (1 - cos(pi t / a)) / 2`` for ``t < a``, ``1`` in the middle and symmetric at the far end,
     ``t = (j + 1/2) / n`` the point's position over the scan: the heights fall to the mean plane within
     ``a`` of each edge; period ``L``, and the rms height and slope of the edges are lost.

The cell is square: the scan (after mirroring, its double) must be square in physical size (the grids
may differ).  :func:`statistics` gives the rms height, the rms slope and the radially averaged power
spectral density of the periodic map (:func:`ngcontact.geometry.random_surface.radial_psd`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ngcontact.errors import MISSING, GeometryError
from ngcontact.geometry import x3p

#: the optional dependency's name in ``pyproject.toml``
EXTRA = "topography"
#: the package's own height-map layout, read without SurfaceTopography
NATIVE_SUFFIXES = (".npy",)
#: length units a scene may state for a file that has none, in metres
UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "nm": 1e-9}
#: ``detrend`` -> SurfaceTopography's detrend mode (``None``: the heights as measured)
DETREND = {"none": None, "mean_plane": "height", "curvature": "curvature"}
#: how a non-periodic scan is made periodic (module docstring)
PERIODIZE = ("mirror", "window")
#: relative tolerance of a square scan's two physical sizes
SQUARE_TOL = 1e-6


def is_measured(file) -> bool:
    """A file in an instrument's format, read through SurfaceTopography: one whose name ends in a suffix
    other than the package's ``.npy`` (a name without one is read as ``.npy``, as it always was)."""
    suffix = Path(file).suffix.lower()
    return bool(suffix) and suffix not in NATIVE_SUFFIXES


@dataclass(frozen=True, kw_only=True)
class Reading:
    """What the scene states of a measured file (``None``: what the file says, or the default)."""

    units: str | None = None
    size: tuple[float, float] | None = None
    detrend: str | None = None
    periodic: bool | None = None
    periodize: str | None = None
    window_width: float | None = None


@dataclass(frozen=True, kw_only=True)
class MeasuredMap:
    """A measured scan made a periodic height map (module docstring), with what was done to it."""

    heights: np.ndarray          # the package's layout, metres
    period: float                # metres
    record: dict[str, Any]       # file, format, units, size, detrending, periodization


def _reader(file, where: str):
    """SurfaceTopography's reader of ``file`` and what its default channel states: ``(reader, channel, facts)``
    with ``facts`` its ``dim``, ``unit``, ``physical_sizes`` (``None`` where the file states none) and
    ``periodic``."""
    try:
        import SurfaceTopography as st
    except ImportError:
        raise GeometryError(where, str(file), "is a measured topography (not a .npy height map); reading it "
                            "needs the optional SurfaceTopography package: pip install "
                            f"'ngcontact[{EXTRA}]'") from None
    try:
        r = st.open_topography(str(file), format=_format_of(Path(file).suffix))
        ch = r.default_channel
        sizes = ch.physical_sizes
        facts = {"dim": ch.dim, "unit": ch.unit, "periodic": bool(ch.is_periodic),
                 "physical_sizes": None if sizes is None or None in tuple(sizes) else tuple(sizes)}
    except Exception as err:  # the package raises its own classes per format
        raise GeometryError(where, str(file), "must be a topography file SurfaceTopography reads (X3P, DATX, OPD, "
                            f"SUR, PLU, IBW, DI, plain-text matrix, ...): {_one_line(err)}") from None
    return r, ch, facts


def _format_of(suffix: str) -> str | None:
    """The one reader's format whose file extension ``suffix`` is (a ``.x3p`` is read as X3P only), or ``None``
    (unknown or shared, as ``.dat``): detected from the content."""
    from SurfaceTopography.IO import readers
    ext = suffix.lower().lstrip(".")
    owners = [r.format() for r in readers if ext in (getattr(r, "_file_extensions", None) or ())]
    return owners[0] if len(owners) == 1 else None


def _one_line(err: Exception, limit: int = 200) -> str:
    """A reader's error in one line: its class and the first line of its text, cut at ``limit`` characters."""
    if type(err).__name__ == "CannotDetectFileFormat":
        return "no reader recognizes its format"
    lines = [line.strip() for line in str(err).splitlines() if line.strip()]
    text = f"{type(err).__name__}: {lines[0]}" if lines else type(err).__name__
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _stated(file_value, scene_value, key: str, same, what: str) -> tuple[Any, str]:
    """The file's value, else the scene's; both given and different is refused."""
    if file_value is None:
        if scene_value is None:
            raise GeometryError(key, MISSING, f"required: the file does not state {what}")
        return scene_value, "scene"
    if scene_value is not None and not same(file_value, scene_value):
        raise GeometryError(key, scene_value, f"the file states {file_value!r}; remove the key or give the same")
    return file_value, "file"


def _metres(unit: str) -> float:
    from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor
    return float(get_unit_conversion_factor(unit, "m"))


def read_scan(file, reading: Reading, where: str = "geometry.file") -> tuple[np.ndarray, dict[str, Any]]:
    """The scan's detrended heights ``[y, x]`` in metres and its record: what the file and the scene said,
    its physical size ``scan_size`` in metres (steps 1 and 2 of the module docstring)."""
    from ngcontact.geometry.tabulated import check_data_file
    check_data_file(file, where, "topography file")
    if Path(file).stat().st_size == 0:
        raise GeometryError(where, str(file), "is empty; must be a topography file")
    x3p.check_checksums(file, where)       # an X3P container's MD5s: a corrupted file is refused
    r, ch, facts = _reader(file, where)
    if facts["dim"] != 2:
        raise GeometryError(where, str(file), f"holds a {facts['dim']}D scan; a cell's height map is a 2D scan")
    scene_unit = None if reading.units is None else {"um": "µm"}.get(reading.units, reading.units)
    unit, unit_from = _stated(facts["unit"], scene_unit, "geometry.units",
                              lambda a, b: math.isclose(_metres(a), _metres(b)),
                              f"its length unit (one of {', '.join(UNITS)})")
    scale = _metres(unit)
    size, size_from = _stated(facts["physical_sizes"], reading.size, "geometry.size",
                              lambda a, b: np.allclose(np.asarray(a, float), np.asarray(b, float), rtol=1e-9),
                              "the scan's physical size: give [x, y] in geometry.units")
    try:
        topo = r.topography(channel_index=ch.index, physical_sizes=None if size_from == "file" else tuple(size),
                            unit=None if unit_from == "file" else unit)
    except Exception as err:  # a file whose header reads and whose data does not
        raise GeometryError(where, str(file), f"has data SurfaceTopography cannot read: {_one_line(err)}") from None
    if not topo.is_uniform:
        raise GeometryError(where, str(file), "holds a nonuniform scan; a height map needs a uniform grid")
    if topo.has_undefined_data:
        raise GeometryError(where, str(file), "has undefined (missing) points; fill them before use")
    mode = DETREND[reading.detrend or "none"]
    if mode is not None:
        topo = topo.detrend(detrend_mode=mode)
    h = np.asarray(topo.heights(), float).T * scale
    if min(h.shape) < 2:
        raise GeometryError(where, str(file), f"holds {h.shape[1]} x {h.shape[0]} points; a height map needs at "
                            "least 2 per direction")
    record = {"file": Path(file).name, "format": r.format(), "format_name": r.name(), "unit": unit,
              "unit_from": unit_from, "scan_size": [float(s) * scale for s in size], "size_from": size_from,
              "scan_grid": [int(n) for n in topo.nb_grid_pts], "detrend": reading.detrend or "none",
              "periodic": reading.periodic if reading.periodic is not None else facts["periodic"],
              "periodic_from": "scene" if reading.periodic is not None else "file"}
    return h, record


def read_measured(file, reading: Reading, where: str = "geometry.file") -> MeasuredMap:
    """Read a measured topography and make it the periodic height map of a cell (module docstring)."""
    h, record = read_scan(file, reading, where)
    Lx, Ly = record["scan_size"]
    if record["periodic"]:
        if record["detrend"] != "none":
            raise GeometryError("geometry.detrend", reading.detrend, "the scan is periodic: removing a plane or a "
                                "quadratic would break its periodicity (a step at the cell's boundary); use 'none', "
                                "or periodize a scan that is not periodic")
        if reading.periodize is not None:
            raise GeometryError("geometry.periodize", reading.periodize, "the scan is periodic (geometry.periodic); "
                                "it needs no periodization: remove the key")
        record["periodization"] = None
    elif reading.periodize is None:
        raise GeometryError("geometry.periodize", MISSING, f"the scan in {record['file']} is not periodic: state "
                            "periodize = 'mirror' (reflected into a period twice its size) or 'window' (with "
                            "window_width, tapered to the mean plane at its edges), or periodic = true if it is")
    elif reading.periodize == "mirror":
        h = np.block([[h, h[:, ::-1]], [h[::-1, :], h[::-1, ::-1]]])
        Lx, Ly = 2 * Lx, 2 * Ly
        record["periodization"] = {"method": "mirror"}
    else:
        a = reading.window_width
        if a is None:
            raise GeometryError("geometry.window_width", MISSING, "required for periodize = 'window': the fraction "
                                "of the scan at each edge tapered to the mean plane, in (0, 0.5]")
        h = (h - h.mean()) * np.outer(tukey(h.shape[0], a), tukey(h.shape[1], a))
        record["periodization"] = {"method": "window", "width": a}
    if not math.isclose(Lx, Ly, rel_tol=SQUARE_TOL):
        raise GeometryError(where, str(record["file"]), f"is a scan of {Lx:.6g} m x {Ly:.6g} m (periodized); the "
                            "cell is square: crop it to a square")
    from ngcontact.geometry.random_surface import as_height_map
    from ngcontact.geometry.tabulated import check_height_map
    record["period"] = Lx
    return MeasuredMap(heights=check_height_map(as_height_map(h), path=where), period=Lx, record=record)


def tukey(n: int, width: float) -> np.ndarray:
    """The cosine-tapered window of ``n`` points (module docstring), ``width`` the tapered fraction per edge."""
    t = (np.arange(n) + 0.5) / n
    edge = np.minimum(t, 1.0 - t)
    return np.where(edge < width, 0.5 * (1.0 - np.cos(np.pi * np.minimum(edge / width, 1.0))), 1.0)


def statistics(heights: np.ndarray, period: float) -> dict[str, Any]:
    """The rms height, the rms slope (spectral gradient of the trigonometric interpolant) and the radially
    averaged PSD ``C(q)`` of a periodic map in the package's layout."""
    from ngcontact.geometry.random_surface import radial_psd, spectral_slope
    z = np.asarray(heights, float)[:-1, :-1]
    z = z - z.mean()
    q, C = radial_psd(z, period)
    return {"rms_height": float(np.sqrt(np.mean(z ** 2))), "rms_slope": spectral_slope(z, period),
            "psd": {"q": q.tolist(), "C": C.tolist(),
                    "definition": "C(q) = (P^2 / N^2) |FFT(h)|^2 (N points) averaged over the wave vectors in rings "
                                  "of width 2 pi / P: the sum of C / P^2 over the wave vectors is the mean "
                                  "square height"}}
