"""Interpolants of sampled data as NGSolve coefficient functions.

Tabulated gaps and profiles come as samples ``(x_i, g_i)``; the finite
element forms need them as functions of the mesh coordinates.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np


def periodic_table_1d(x, g, period: float, samples: int = 4096):
    """Piecewise-linear interpolant of the samples ``(x_i, g_i)`` as a function of ``x``.

    Resampled on a uniform grid of ``samples`` intervals (exact for the
    polyline up to the resampling of its kinks) and carried by a 2D voxel
    coefficient that is constant in ``y``.
    """
    xs = np.linspace(0.0, period, samples + 1)
    row = np.interp(xs, x, g)
    data = np.ascontiguousarray(np.vstack([row, row]))
    return ng.VoxelCoefficient((0.0, -1e3), (period, 1e3), data, linear=True)
