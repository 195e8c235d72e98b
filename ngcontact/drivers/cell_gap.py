"""The initial gap of a cell scene: the roughness a small-slope cell carries in its gap.

The gap ``g`` of paper eq. 65's penalty ``k_n [J.n - g]_+`` as the cell scene poses it: the height below the
highest summit of a 3D small-slope profile (a formula, a height map, a drawn random surface; a map's
surface is the bilinear interpolant of its samples) plus the scene's explicit ``contact.gap`` (a formula
or a table).  :func:`gap_cf` gives it as a CoefficientFunction for the FE cell, :func:`gap_samples` on the
uniform grid of the spectral cell.
"""
from __future__ import annotations

import math

import numpy as np
import ngsolve as ng

from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.scene.cell_geometry import small_slope
from ngcontact.scene.cell_scene import CellScene
from ngcontact.scene.sections import resolve
from ngcontact.fem.interpolants import periodic_table_1d


def gap_cf(scene):
    """The initial gap as a CoefficientFunction, or ``None`` when there is none.

    The sum of the explicit gap ``scene.contact.gap`` and, for the 3D
    small-slope profiles (bisinusoid, height map), the height below the
    highest summit.
    """
    terms = [t for t in (_profile_gap(scene), _explicit_gap(scene)) if t is not None]
    if not terms:
        return None
    return terms[0] if len(terms) == 1 else terms[0] + terms[1]


def map_heights(scene: CellScene) -> np.ndarray | None:
    """The height map of a small-slope cell whose gap comes from one (height map, self-affine surface), or
    ``None`` (a gap given by a formula)."""
    g = scene.geometry
    return height_map(scene) if small_slope(g) and PROFILES[g.profile].own_grid else None


def gap_samples(scene, grid: int, heights: np.ndarray | None = None) -> np.ndarray:
    """The initial gap of :func:`gap_cf` at the points of a uniform grid of ``grid`` points per period.

    ``heights``: the profile's height map when the caller has it already (:func:`height_map`).

    Shape ``(grid,)`` at ``x_j = j P / grid`` (2D) or ``(grid, grid)`` at
    ``(x_j, y_i)`` (3D); height maps and tabulated gaps are interpolated
    as the FE cell interpolates them (piecewise linear, bilinear).
    """
    from ngcontact.geometry import cell3d, tabulated
    g = scene.geometry
    P, dim = g.period, g.dim
    s = P * np.arange(grid) / grid
    xy = (s, np.zeros(1)) if dim == 2 else (s[None, :], s[:, None])
    shape = (grid,) * (dim - 1)
    out = np.zeros(shape)
    if small_slope(g):
        gap = PROFILES[g.profile].gap
        if gap is not None:
            out += gap(g, xy)
        else:
            H = height_map(scene) if heights is None else heights
            out += cell3d.bilinear_samples(H.max() - H, P, grid)
    gs = scene.contact.gap
    if gs.kind == "tabulated":
        if dim == 2:
            x, gv = tabulated.read_gap_csv(resolve(scene, gs.file), path="contact.gap.file")
            out += np.interp(s, x, gv)
        else:
            out += cell3d.bilinear_samples(tabulated.read_gap_map(resolve(scene, gs.file), path="contact.gap.file"),
                                           P, grid)
    elif gs.kind != "none":
        out += np.broadcast_to(_explicit_gap(scene, xy), shape)
    return out


def _profile_gap(scene):
    g = scene.geometry
    if not small_slope(g):
        return None
    from ngcontact.geometry import cell3d
    gap = PROFILES[g.profile].gap
    if gap is not None:
        return gap(g, None)
    return cell3d.height_map_gap(height_map(scene), g.period)


def height_map(scene) -> np.ndarray:
    """The heights of a ``height_map`` (read from its file) or ``self_affine`` (drawn from its spectrum) profile.

    In the file layout: the last row and column repeat the first.
    """
    g = scene.geometry
    kind = PROFILES[g.profile]
    if not kind.own_grid or kind.heights is None:
        raise ValueError(f"geometry.profile = {g.profile!r} has no height map")
    # the keys a profile uses are required by CellGeometry.check (check_selected)
    return kind.heights(g, resolve(scene, g.file) if kind.reads_file else None)


def _explicit_gap(scene, xy=None):
    """The ``[contact.gap]`` section's formula: a CoefficientFunction, or with ``xy = (x, y)`` its values."""
    gs, P = scene.contact.gap, scene.geometry.period
    x, y, m = (ng.x, ng.y, ng) if xy is None else (xy[0], xy[1], np)
    if gs.kind == "none":
        return None
    if gs.kind == "constant":
        return ng.CF(gs.value) if xy is None else gs.value + 0.0 * x
    if gs.kind == "sinusoid":
        return 2 * gs.h * m.sin(math.pi * x / P) ** 2
    if gs.kind == "bisinusoid":
        return gs.h * (2 - m.cos(2 * math.pi * x / P) - m.cos(2 * math.pi * y / P))
    from ngcontact.geometry import tabulated
    if scene.geometry.dim == 2:
        x, g = tabulated.read_gap_csv(resolve(scene, gs.file), path="contact.gap.file")
        return periodic_table_1d(x, g, P)
    g = tabulated.read_gap_map(resolve(scene, gs.file), path="contact.gap.file")
    return ng.VoxelCoefficient((0.0, 0.0), (P, P), np.ascontiguousarray(g), linear=True)


def topography(scene) -> dict | None:
    """The report's record of a cell's measured topography (``geometry.file`` in an instrument's format), or
    ``None``: what the file and the scene said (file, format, units, physical size, detrending,
    periodization: :func:`ngcontact.geometry.topography.read_measured`) and the rms height, rms slope and
    radially averaged PSD of the periodic map the cell uses (for ``measured_spectrum``, of the surface drawn
    with the measured spectrum; ``source`` says which)."""
    from ngcontact.geometry import topography as topo
    from ngcontact.geometry.profile_registry import reading
    g = scene.geometry
    if g.file is None or g.dim != 3 or not topo.is_measured(g.file):
        return None
    measured = topo.read_measured(resolve(scene, g.file), reading(g))
    record = dict(measured.record)
    scan = topo.statistics(measured.heights, measured.period)
    if PROFILES[g.profile].random:
        record["measured"] = {k: scan[k] for k in ("rms_height", "rms_slope")}
        record["source"] = f"drawn with the measured spectrum, seed {g.random_seed}"
        record.update(topo.statistics(height_map(scene), measured.period))
    else:
        record["source"] = "measured"
        record.update(scan)
    return record
