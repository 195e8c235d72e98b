"""Readers for tabulated roughness: a periodic profile (CSV) and a periodic height map (``.npy``).

Profile CSV: UTF-8 text (a byte-order mark is skipped), two columns ``x, y``
(an optional header line is skipped), one period from ``x = 0`` to ``x = P``
with ``y(0) = y(P)``; the profile is the polyline through the points
(:func:`ngcontact.geometry.profiles.tabulated`).

Height map ``.npy``: a 2D array ``H[i, j]`` of heights at ``x = j P / (n_x - 1)``,
``y = i P / (n_y - 1)`` over one period in each direction; the **last row and
column repeat the first** (``H[-1, :] = H[0, :]``, ``H[:, -1] = H[:, 0]``), which
makes the periodicity checkable.  Used as the initial gap of the small-slope
model (:func:`ngcontact.geometry.cell3d.height_map_gap`).

All checks raise :class:`~ngcontact.errors.GeometryError` naming the file, the
offending entry and what is allowed.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ngcontact.errors import GeometryError
from ngcontact.geometry.profiles import Profile, tabulated

PERIODIC_TOL = 1e-9
#: Largest span of a map's heights or a gap table's values: the upper end of the lengths a scene takes
#: (``LENGTH_RANGE`` of :mod:`ngcontact.scene.mesh_size`); beyond it the layers' energies overflow.
MAX_SPAN = 1e9

#: Largest data file read (a FIFO, a device or a huge file would hang or exhaust memory).
MAX_DATA_BYTES = 64 * 2 ** 20
#: Largest number of rows of a tabulated profile, whose every row becomes a segment of the mesh's
#: geometry (a gap table is interpolated, not meshed, and may be longer).
MAX_PROFILE_ROWS = 4096
#: Smallest step in ``x`` between a meshed profile's points, relative to the period: a closer pair is a
#: feature a million times smaller than the cell, which Netgen's mesher cannot resolve (it fails, or
#: where the feature lies against the cell's side, does not end).
MIN_PROFILE_STEP = 1e-6


def file_kind(mode: int) -> str | None:
    """What a path of ``os.stat`` mode ``mode`` is when it is not a regular file (``None`` when it is).

    A directory, FIFO or device named as an input is said to be one: reading
    it would fail, hang (a FIFO) or never end (``/dev/zero``).
    """
    import stat
    if stat.S_ISREG(mode):
        return None
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def check_data_file(file, where: str, what: str = "file") -> None:
    """A data file must be a regular file of at most :data:`MAX_DATA_BYTES` (checked before reading)."""
    import os
    try:
        st = os.stat(file)
    except OSError as err:
        raise GeometryError(where, str(file), f"must be a readable {what} ({err.strerror})") from None
    kind = file_kind(st.st_mode)
    if kind is not None:
        raise GeometryError(where, str(file), f"is {kind}; must be a regular file (a {what})")
    if st.st_size > MAX_DATA_BYTES:
        raise GeometryError(where, str(file), f"is {st.st_size} bytes; data files are limited to "
                            f"{MAX_DATA_BYTES // 2 ** 20} MiB")


def read_profile_csv(file, *, path: str | None = None, max_rows: int | None = MAX_PROFILE_ROWS,
                     min_step: float | None = MIN_PROFILE_STEP, value: str = "y",
                     what: str = "profile") -> Profile:
    """Read and validate a periodic profile from a CSV file with columns ``x, y``.

    Parameters
    ----------
    file
        Path of the CSV file.
    path
        Name used in error messages (default: the file name).
    max_rows
        Largest number of data rows (``None``: no limit but the file size).
    min_step
        Smallest step in ``x`` between consecutive rows, relative to the period (``None``: any increase;
        a gap table is interpolated, not meshed).
    value, what
        Name of the second column and of the tabulated function in messages.

    Messages name a row by its line in the file (the header is line 1) and
    never repeat the file's content.

    Returns
    -------
    Profile
    """
    file = Path(file)
    where = path or str(file)
    check_data_file(file, where, "CSV file")
    try:
        text = file.read_text(encoding="utf-8-sig")   # a byte-order mark is no part of the first row
    except OSError as err:
        raise GeometryError(where, str(file), f"must be a readable CSV file ({err.strerror})") from None
    except UnicodeDecodeError:
        raise GeometryError(where, str(file), f"must be a text (UTF-8) CSV file with columns x, {value}") from None
    numbered = [(k + 1, r) for k, r in enumerate(csv.reader(text.splitlines())) if r and any(c.strip() for c in r)]
    if numbered and not _numeric(numbered[0][1][0]):
        numbered = numbered[1:]                      # header
    if max_rows is not None and len(numbered) > max_rows:
        raise GeometryError(where, str(file), f"has {len(numbered)} rows; a tabulated {what} takes at most "
                            f"{max_rows} (each row is a segment of the mesh's geometry): resample it")
    xs, ys = [], []
    for line, row in numbered:
        if len(row) != 2:
            raise GeometryError(f"{where}[line {line}]", f"{len(row)} column{'' if len(row) == 1 else 's'}",
                                f"each row must have exactly two columns x, {value}")
        try:
            xs.append(float(row[0]))
            ys.append(float(row[1]))
        except ValueError:
            raise GeometryError(f"{where}[line {line}]", "not two numbers", f"x and {value} must be numbers") from None
    lines = [line for line, _ in numbered]
    profile = tabulated(xs, ys, path=where, lines=lines, value=value, what=what)
    if min_step is not None:
        step = min_step * xs[-1]
        for i in range(1, len(xs)):
            if xs[i] - xs[i - 1] < step:
                raise GeometryError(f"{where}[line {lines[i]}].x", xs[i],
                                    f"x must increase by at least {min_step:g} of the period ({step:.3g}; previous "
                                    f"x = {xs[i - 1]!r}): closer points make a feature the mesher cannot resolve")
    return profile


def read_height_map(file, *, path: str | None = None) -> np.ndarray:
    """Read and validate a periodic height map from a ``.npy`` file (see the module docstring).

    Returns
    -------
    numpy.ndarray
        The validated array, shape ``(n_y, n_x)`` with ``n_x, n_y >= 3``.
    """
    file = Path(file)
    where = path or str(file)
    check_data_file(file, where, ".npy array")
    try:
        H = np.load(file, allow_pickle=False)
    except (OSError, ValueError, EOFError) as err:
        raise GeometryError(where, str(file), f"must be a readable .npy array ({err or type(err).__name__})") from None
    if not isinstance(H, np.ndarray):  # an .npz archive
        H.close()
        raise GeometryError(where, str(file), "must be a single .npy array, not an .npz archive")
    return check_height_map(H, path=where)


def check_height_map(H, *, path: str = "height_map") -> np.ndarray:
    """Validate a height-map array: 2D, finite, periodic with repeated last row/column."""
    H = np.asarray(H)
    if H.ndim != 2 or min(H.shape) < 3:
        raise GeometryError(path, f"array of shape {H.shape}", "must be a 2D array with at least 3 "
                         "samples per direction (last row/column repeating the first)")
    if not np.issubdtype(H.dtype, np.number) or np.iscomplexobj(H):
        raise GeometryError(path, f"array of dtype {H.dtype}", "must hold real numbers")
    H = H.astype(float)
    bad = np.argwhere(~np.isfinite(H))
    if len(bad):
        i, j = bad[0]
        raise GeometryError(f"{path}[{i}, {j}]", float(H[i, j]), "heights must be finite")
    check_span(H, path)
    tol = PERIODIC_TOL * max(1.0, float(np.ptp(H)))
    for axis, name in ((0, "row"), (1, "column")):
        first, last = np.take(H, 0, axis=axis), np.take(H, -1, axis=axis)
        k = int(np.argmax(np.abs(first - last)))
        if abs(first[k] - last[k]) > tol:
            raise GeometryError(f"{path}[last {name}]", float(last[k]),
                             f"the map must be periodic: the last {name} must repeat the first "
                             f"(entry {k}: {float(first[k])!r}) within {tol:.3g}")
    return H


def _numeric(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_gap_csv(file, *, path: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Read a periodic initial gap ``g(x) >= 0`` from a CSV file with columns ``x, g``.

    The same layout and checks as :func:`read_profile_csv` (one period from
    ``x = 0``, strictly increasing, ``g(0) = g(P)``), and every ``g >= 0``.

    Returns
    -------
    (x, g)
        NumPy arrays of the samples.
    """
    where = path or str(file)
    prof = read_profile_csv(file, path=where, max_rows=None, min_step=None, value="g", what="gap")
    pts = [p.start for p in prof.pieces] + [prof.pieces[-1].end]
    x = np.array([p[0] for p in pts], dtype=float)
    g = np.array([p[1] for p in pts], dtype=float)
    _check_nonnegative(g, where)
    check_span(g, where)
    return x, g


def check_span(values: np.ndarray, where: str) -> None:
    """Refuse heights or gaps whose span (largest minus smallest) exceeds :data:`MAX_SPAN`."""
    with np.errstate(over="ignore"):
        span = float(np.max(values)) - float(np.min(values))
    if not span <= MAX_SPAN:
        raise GeometryError(where, f"heights spanning {span:.3g}", f"must span at most {MAX_SPAN:g}: choose a length "
                            "unit (e.g. mm or um) in which the geometry's sizes fall in [1e-09, 1e+09]")


def read_gap_map(file, *, path: str | None = None) -> np.ndarray:
    """Read a periodic initial-gap map ``g[i, j] >= 0`` from a ``.npy`` file (layout of :func:`read_height_map`)."""
    where = path or str(file)
    g = read_height_map(file, path=where)
    _check_nonnegative(g, where)
    return g


def _check_nonnegative(g: np.ndarray, where: str) -> None:
    bad = np.argwhere(np.asarray(g) < 0)
    if len(bad):
        idx = tuple(int(i) for i in bad[0])
        raise GeometryError(f"{where}[{', '.join(map(str, idx))}]", float(np.asarray(g)[idx]),
                         "a gap must be >= 0")
