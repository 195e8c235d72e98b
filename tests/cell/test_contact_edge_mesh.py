"""The 3D cell meshed along its spectral twin's contact edge (:mod:`ngcontact.cell.fe.contact_edge_mesh`)."""
from __future__ import annotations

import math

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.contact_edge_mesh import (LAYER_SPACING, PatchBody, edge_points, edge_refined_cell,
                                                 patch_body, patch_radius)
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


def test_the_grading_is_netgens_and_a_smaller_one_meshes_finer_away_from_the_edge():
    """``grading`` outside (0, 1] is refused by name; the default is Netgen's 0.3, and 0.15 grows the elements
    more slowly away from the same edge points: more of them, the size at the edge the same."""
    pts = np.array([[0.5, 0.5 + 0.1 * c] for c in (-1.0, 1.0)])
    for bad in (0.0, -0.1, 1.5, float("nan")):
        with pytest.raises(GeometryError, match="grading"):
            edge_refined_cell(pts, edge_maxh=0.02, maxh=0.4, interface_maxh=0.2, grading=bad)
    sizes = dict(edge_maxh=0.02, maxh=0.4, interface_maxh=0.2)
    default = edge_refined_cell(pts, **sizes).mesh.ne
    assert edge_refined_cell(pts, grading=0.3, **sizes).mesh.ne == default
    assert edge_refined_cell(pts, grading=0.15, **sizes).mesh.ne > 1.5 * default


def test_patch_body_on_the_contact_points_of_a_disk():
    """The points of a disk's grid, thinned to one per ``maxh``, inside the disk; the layers' heights 0 and
    +-k LAYER_SPACING maxh to the depth; the radius of one patch of the disk's area."""
    n = 64
    s = np.arange(n) / n
    p = np.where(np.hypot(s[None, :] - 0.5, s[:, None] - 0.5) < 0.2, 1.0, 0.0)
    body = patch_body(p, 1.0, maxh=0.05, depth=0.35)
    assert len(body.points) > 10
    assert np.all(np.hypot(body.points[:, 0] - 0.5, body.points[:, 1] - 0.5) < 0.2)
    assert len(body.points) < np.count_nonzero(p) / 4
    np.testing.assert_allclose(np.sort(body.heights()), LAYER_SPACING * 0.05 * np.array([-2, -1, 0, 1, 2]))
    assert abs(patch_radius(p, 1.0) - 0.2) < 0.01


def test_graded_patch_body_layers_spaced_by_their_size():
    """With ``growth`` the size at depth ``|z|`` is ``maxh + growth |z|`` and each layer lies LAYER_SPACING of
    the size of the one before it further out, to the depth, alike above and below."""
    body = PatchBody(points=np.zeros((1, 2)), maxh=0.01, depth=0.2, growth=0.3)
    z = np.sort(body.heights())
    np.testing.assert_allclose(z, -z[::-1])
    up = z[z >= 0.0]
    assert up[0] == 0.0 and abs(up[1] - LAYER_SPACING * 0.01) < 1e-12 and up[-1] <= 0.2
    np.testing.assert_allclose(np.diff(up)[1:], LAYER_SPACING * body.size(up[1:-1]))
    np.testing.assert_allclose(body.size(up), 0.01 + 0.3 * up)
    assert len(up) < len(np.sort(PatchBody(points=np.zeros((1, 2)), maxh=0.01, depth=0.2).heights())) / 2


def test_patch_body_of_no_size_is_refused():
    with pytest.raises(GeometryError, match="body maxh"):
        PatchBody(points=np.zeros((1, 2)), maxh=0.0, depth=0.1)
    with pytest.raises(GeometryError, match="body depth"):
        PatchBody(points=np.zeros((1, 2)), maxh=0.1, depth=-1.0)
    with pytest.raises(GeometryError, match="body growth"):
        PatchBody(points=np.zeros((1, 2)), maxh=0.1, depth=0.1, growth=-0.5)


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


def _model(order: int, edge: float, **kw) -> CellModel:
    law = isotropic(E, NU)
    return CellModel(rough=law, counter=law, k_n=100 * E / edge, gap=bisinusoid_gap(H, 1.0), order=order,
                     enforcement="exact", **kw)


def test_order_2_bodies_with_a_linear_trace_on_the_contact_surface():
    """Exact contact at order 2 in 3D on a linear trace (:mod:`ngcontact.cell.fe.linear_trace`): accepted, the
    multiplier of order 1, and any state's trace on S_C linear along each edge of S_C; without the linear
    trace order 2 is still refused."""
    from ngcontact.errors import ModelError
    cell = edge_refined_cell(np.zeros((0, 2)), edge_maxh=0.25, maxh=0.5, interface_maxh=0.25)
    with pytest.raises(ModelError, match="order = 2 with enforcement = 'exact' in a 3D cell"):
        CellProblem(cell, _model(2, 0.25))
    problem = CellProblem(cell, _model(2, 0.25, linear_trace=True))
    assert problem.multiplier.order == 1
    assert problem.ndof > CellProblem(cell, _model(1, 0.25)).ndof
    problem.gfu.vec.SetRandom()
    u = problem.gfu.components[0]
    # per triangle of S_C its vertices and edge midpoints (the trace, read on the boundary elements)
    rule = ng.IntegrationRule([(1, 0), (0, 1), (0, 0), (0.5, 0.5), (0, 0.5), (0.5, 0)], [1.0] * 6)
    vals = np.asarray(u(cell.mesh.MapToAllElements(rule, cell.mesh.Boundaries("contact")))).reshape(-1, 6, 3)
    mids = 0.5 * (vals[:, [0, 1, 0]] + vals[:, [1, 2, 2]])
    worst = float(np.abs(vals[:, 3:] - mids).max()) / float(np.abs(vals).max())
    assert worst < 1e-10


@pytest.mark.slow  # ~5 minutes under load: 28k and 48k dofs at order 2
def test_bisinusoid_extrapolated_in_the_edge_size_within_1_percent_of_the_converged_spectral_cell():
    """p/p* = 0.02, order 2 on a linear trace, edge sizes 0.02 and 0.01: each solve over the converged value
    (the node-to-node contact set's first-order error), their Richardson extrapolation
    (:mod:`ngcontact.cell.fe.edge_size_extrapolation`) within 1 % of it (issue 38's aim at this load) and
    within its estimate."""
    from ngcontact.cell.fe.edge_size_extrapolation import extrapolate
    load = cell_load(3, pressure=0.02 * math.pi * H)
    converged = 2.0 * spectral(1024).solve(load).results["contact_fraction"] \
        - spectral(512).solve(load).results["contact_fraction"]
    pts = edge_points(spectral(128).solve(load).fields["pressure"], 1.0)
    sizes, values = (0.02, 0.01), []
    for edge in sizes:
        cell = edge_refined_cell(pts, edge_maxh=edge, maxh=0.3, interface_maxh=0.1)
        sol = CellProblem(cell, _model(2, edge, linear_trace=True)).solve(load, first=True, measure=False)
        values.append(sol.results["contact_fraction"])
    assert values[0] > values[1] > converged
    ext = extrapolate(list(sizes), values)
    assert abs(ext.value / converged - 1.0) < 0.01
    assert abs(ext.value - converged) <= ext.estimate


def _patch_refined(load, twin_grid: int, n_edge: float, n_body: float, depth: float, **sizes):
    """The order-1 cell on the mesh refined along the twin's contact edge to ``a / n_edge`` and in the bodies
    below and above its patch to ``a / n_body`` down to ``depth a`` (``a`` the twin's patch radius)."""
    p = spectral(twin_grid).solve(load).fields["pressure"]
    a = patch_radius(p, 1.0)
    cell = edge_refined_cell(edge_points(p, 1.0), edge_maxh=a / n_edge,
                             body=patch_body(p, 1.0, maxh=a / n_body, depth=depth * a), **sizes)
    return CellProblem(cell, _model(1, a / n_edge)).solve(load, first=True, measure=False)


def test_patch_refined_coarse_cell_against_the_spectral_cell():
    """p/p* = 0.05, the edge at a/5, the bodies at a/4 to 0.75 a: within 6 % of the converged spectral cell's
    contact fraction (docs/benchmarks.md, section scaling_3d: about -5 % at these sizes)."""
    load = cell_load(3, pressure=0.05 * math.pi * H)
    fe = _patch_refined(load, 64, 5.0, 4.0, 0.75, maxh=0.4, interface_maxh=0.2).results["contact_fraction"]
    reference = spectral(512).solve(load).results["contact_fraction"]
    assert abs(fe / reference - 1.0) < 0.06


@pytest.mark.slow  # ~100k dofs at order 1: minutes under load
def test_patch_refined_cell_within_1_percent_of_the_converged_spectral_cell():
    """p/p* = 0.005, the edge at a/13, the bodies at a/10 to 1.8 a (scripts/bisinusoid_accuracy.py's
    ``ACC_PATCH``): within 1 % of the spectral cell's contact fraction extrapolated from 512^2 and 1024^2
    (issue 38's aim at this load)."""
    load = cell_load(3, pressure=0.005 * math.pi * H)
    converged = 2.0 * spectral(1024).solve(load).results["contact_fraction"] \
        - spectral(512).solve(load).results["contact_fraction"]
    fe = _patch_refined(load, 128, 13.0, 10.0, 1.8, maxh=0.15, interface_maxh=0.1).results["contact_fraction"]
    assert abs(fe / converged - 1.0) < 0.01
