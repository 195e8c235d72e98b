"""Interpolants of sampled data as NGSolve coefficient functions.

Tabulated gaps and profiles come as samples ``(x_i, g_i)``; the finite
element forms need them as functions of the mesh coordinates.  A periodic
table (:func:`periodic_table_1d`, the cell's gap and profile) is resampled
on a voxel grid; periodic samples on a uniform grid (:func:`periodic_grid`,
a spectral cell's fields) are carried by one as they are; an open one (:func:`piecewise_linear`, the macro gap table
and the two-scale coefficient fields) is written exactly as a sum of ramps.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.errors import ModelError


def periodic_table_1d(x, g, period: float, samples: int = 4096):
    """Piecewise-linear interpolant of the samples ``(x_i, g_i)`` as a function of ``x``.

    Resampled on a uniform grid of ``samples`` intervals (exact for the
    polyline up to the resampling of its kinks) and carried by a 2D voxel
    coefficient that is constant in ``y``.
    """
    xs = np.linspace(0.0, period, samples + 1)
    return _voxels(np.interp(xs, x, g), period)


def periodic_grid(values, period: float):
    """The periodic (bi)linear interpolant of samples at ``x_j = j P / N`` (2D arrays indexed ``[y, x]``,
    ``y_i = i P / N``): of ``x`` (constant in ``y``) for a 1D array, of ``(x, y)`` (constant in ``z``) for a
    2D one; the period's far end repeats the first samples."""
    closed = np.pad(np.asarray(values, dtype=float), [(0, 1)] * np.ndim(values), mode="wrap")
    return _voxels(closed, period)


def _voxels(closed: np.ndarray, period: float):
    """A voxel coefficient over ``[0, P]`` (or ``[0, P]^2``) from samples that include both ends."""
    if closed.ndim == 1:
        return ng.VoxelCoefficient((0.0, -1e3), (period, 1e3), np.ascontiguousarray(np.vstack([closed, closed])),
                                   linear=True)
    return ng.VoxelCoefficient((0.0, 0.0), (period, period), np.ascontiguousarray(closed), linear=True)


def piecewise_linear(coordinate, points):
    """CoefficientFunction interpolating ``points = [(x_i, y_i)]`` linearly in ``coordinate``.

    Constant ``y_0`` before ``x_0`` and ``y_last`` after the last point;
    written as ``y_0 + sum_i d_i [x - x_i]_+`` with the slope increments ``d_i``.
    """
    xs = np.array([q[0] for q in points], float)
    ys = np.array([q[1] for q in points], float)
    if len(xs) == 1:
        return ng.CF(float(ys[0]))
    if np.any(np.diff(xs) <= 0):
        raise ModelError("the abscissae of a piecewise linear table must increase strictly")
    slopes = np.diff(ys) / np.diff(xs)
    incr = np.diff(np.concatenate([[0.0], slopes, [0.0]]))
    f = ng.CF(float(ys[0]))
    for xi, d in zip(xs, incr):
        if d != 0:
            f = f + float(d) * ng.IfPos(coordinate - float(xi), coordinate - float(xi), 0.0)
    return f
