"""The 3D cell meshed along its spectral twin's contact edge (:mod:`ngcontact.cell.fe.contact_edge_mesh`)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.contact_edge_mesh import edge_points, edge_refined_cell
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.errors import GeometryError
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.cell3d import bisinusoid_gap

NU = 0.3
E = 2.0 * (1.0 - NU ** 2)          # E* = 1 for two equal bodies
H = 0.01                           # the bisinusoid's amplitude: p* = pi E* H / P


def spectral(grid: int, depth: float = 1.0) -> SpectralCell:
    s = np.arange(grid) / grid
    return SpectralCell(dim=3, period=1.0, grid=grid, rough=Layer(E, NU, depth), counter=Layer(E, NU, depth),
                        gap=bisinusoid_gap(H, 1.0, xy=(s[None, :], s[:, None])), k_n=1.0, enforcement="exact")


def test_edge_points_ring_a_disk():
    n = 64
    s = (np.arange(n) + 0.5) / n - 0.5
    p = np.where(np.hypot(s[None, :], s[:, None]) < 0.2, 1.0, 0.0)
    pts = edge_points(p, 2.0)
    r = np.hypot(pts[:, 0] - 1.0 + 1.0 / n, pts[:, 1] - 1.0 + 1.0 / n)
    assert pts.shape[1] == 2 and len(pts) > 40
    assert np.all(np.abs(r - 0.4) < 2.5 * 2.0 / n)
    assert edge_points(np.zeros((8, 8)), 1.0).shape == (0, 2)


def test_edge_maxh_beyond_the_interface_size_is_refused():
    with pytest.raises(GeometryError, match="edge_maxh"):
        edge_refined_cell(np.zeros((0, 2)), edge_maxh=0.3, maxh=0.4, interface_maxh=0.2)


def _interface_sizes(cell):
    """Centroid ``(x, y)`` and edge length of each triangle of ``S_C``."""
    mesh = cell.mesh
    out = []
    for el in mesh.Boundaries("contact").Elements():
        v = np.array([mesh[w].point for w in el.vertices])
        out.append((*v.mean(axis=0)[:2], max(np.linalg.norm(v[i] - v[i - 1]) for i in range(3))))
    return np.array(out)


def test_small_cell_against_the_spectral_cell():
    """p/p* = 0.2: the order-1 cell on the twin's edge mesh within 8 % of the spectral cell's contact fraction,
    its mesh fine at the edge and coarse away from it."""
    p = 0.2 * math.pi * H
    load = cell_load(3, pressure=p)
    twin = spectral(64).solve(load)
    pts = edge_points(twin.fields["pressure"], 1.0)
    cell = edge_refined_cell(pts, edge_maxh=0.04, maxh=0.4, interface_maxh=0.2)
    sizes = _interface_sizes(cell)
    wrap = np.minimum(sizes[:, :2], 1.0 - sizes[:, :2])
    radius = np.hypot(wrap[:, 0], wrap[:, 1])
    edge_radius = float(np.hypot(*np.minimum(pts, 1.0 - pts).T).mean())
    assert sizes[np.abs(radius - edge_radius) < 0.03, 2].max() < 0.08
    assert sizes[radius > edge_radius + 0.25, 2].min() > 0.08
    law = isotropic(E, NU)
    model = CellModel(rough=law, counter=law, k_n=100 * E / 0.04, gap=bisinusoid_gap(H, 1.0), order=1,
                      enforcement="exact")
    fe = CellProblem(cell, model).solve(load, first=True, measure=False).results["contact_fraction"]
    reference = spectral(512).solve(load).results["contact_fraction"]
    assert abs(fe / reference - 1.0) < 0.08
