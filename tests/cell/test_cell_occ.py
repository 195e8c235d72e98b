"""Free-form 3D cells with Netgen's OCC kernel (bisinusoid, height map).

The bisinusoid ``z = A (cos 2 pi x + cos 2 pi y - 2)`` in a unit cell has, in
full contact with ``k_n = 1`` (paper eq. 34), ``k_n0 = <1/w>``,
``k_t0 = <h_x^2 / w>`` and ``|S_C|/|T| = <w>`` with ``w = sqrt(1 + |grad h|^2)``
and ``<.>`` the cell average -- computed here by a fine midpoint rule of the
exact surface, independent of the mesh.
"""
import math

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.geometry.cell3d import bisinusoid_heights, surface_cell
from ngcontact.geometry.tabulated import read_height_map
from ngcontact.cell.coefficients import coefficients, contact_normal

A = 0.05


@pytest.fixture(scope="module")
def cell():
    return surface_cell(bisinusoid_heights(A, samples=33), h_rough=0.6, h_counter=0.6,
                        maxh=0.3, interface_maxh=0.12, order=2)


def exact_averages(n=1500):
    t = (np.arange(n) + 0.5) / n
    X, Y = np.meshgrid(t, t)
    k = 2 * math.pi
    hx, hy = -A * k * np.sin(k * X), -A * k * np.sin(k * Y)
    w = np.sqrt(1 + hx ** 2 + hy ** 2)
    return np.mean(1 / w), np.mean(hx ** 2 / w), np.mean(w)


def test_naming_contract(cell):
    assert set(cell.mesh.GetMaterials()) == {"rough", "counter"}
    assert set(cell.mesh.GetBoundaries()) == {"contact", "bottom", "top", "periodic"}


def test_full_contact_coefficients_match_the_exact_surface(cell):
    kn0, kt0, area = exact_averages()
    c = coefficients(cell, kn=1.0).as_dict()
    assert c["k_n"] == pytest.approx(kn0, rel=1e-4)
    assert c["k_t"][0] == pytest.approx(kt0, rel=2e-3)
    assert c["k_t"][1] == pytest.approx(kt0, rel=2e-3)
    assert c["contact_fraction"] == pytest.approx(area, rel=1e-4)
    assert abs(c["k_nt"][0]) < 1e-4 and abs(c["k_nt"][1]) < 1e-4   # symmetric valleys


def test_normal_points_into_counter_and_projects_to_the_cell(cell):
    n = contact_normal(cell)
    assert ng.Integrate(n[2] * ng.ds("contact"), cell.mesh) == pytest.approx(1.0, rel=1e-9)


def test_lateral_faces_identified_by_the_period(cell):
    ngm = cell.mesh.ngmesh
    pts = {i + 1: np.array(p.p) for i, p in enumerate(ngm.Points())}
    ids = ngm.GetIdentifications()
    assert len(ids) > 10
    for a, b, _ in ids:
        d = np.abs(pts[b] - pts[a])
        assert np.allclose(d, [1, 0, 0], atol=1e-9) or np.allclose(d, [0, 1, 0], atol=1e-9), d


def test_height_map_surface_builds_and_respects_the_cell_height(tmp_path):
    import os
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    H = read_height_map(os.path.join(here, "geometries", "cells", "data", "height_map_example.npy"))
    c = surface_cell(H, h_rough=0.6, h_counter=0.6, maxh=0.4, interface_maxh=0.2)
    assert "contact" in c.mesh.GetBoundaries()
    from ngcontact.errors import GeometryError
    with pytest.raises(GeometryError, match="^h_rough = "):
        surface_cell(H * 1e3, h_rough=0.6, h_counter=0.6, maxh=0.4)
