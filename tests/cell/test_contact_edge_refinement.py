"""The second discretization of a flat 3D cell with exact contact along its contact edge
(ngcontact.cell.fe.contact_edge_refinement, wired by ngcontact.drivers.contact_edge_refiner)."""
from __future__ import annotations


import numpy as np
import pytest

from ngcontact.cell.fe.contact_edge_refinement import ContactEdgeRefinement
from ngcontact.cell.fe.second_discretization import HALVING_RATE, InterfaceHalving
from ngcontact.drivers.build import fe_cell
from ngcontact.scene.loader import load
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

from sinusoid_cell import sinusoid_cell

PSTAR = westergaard_p_star(e_star(1.0, 0.3, 1.0, 0.3), 0.01, 1.0)
PRESSURE = 0.5 * PSTAR

SCENE = sinusoid_cell(k_n="1.0e4", pressure=repr(PRESSURE), profile="flat3d", friction="none",
                      discretization="order = 2\nmaxh = 0.4\ninterface_maxh = 0.1")


def _interface_sizes(mesh) -> np.ndarray:
    """``x`` of the centroid and the longest edge of each triangle of ``S_C``."""
    out = []
    for el in mesh.Boundaries("contact").Elements():
        v = np.array([mesh[w].point for w in el.vertices])
        out.append((v[:, 0].mean(), max(np.linalg.norm(v[i] - v[i - 1]) for i in range(3))))
    return np.array(out)


@pytest.mark.slow  # ~17 s under load: the twin at 256^2 and the refined cell's mesh and space
def test_an_exact_flat_3d_cell_refines_along_its_twins_contact_edge(tmp_path):
    """Level 1 of the scene's refiner: the mesh finer (edge_maxh below interface_maxh) at Westergaard's edges x = 1/2 +- a
    (waves along x) than away from them, S_C with more triangles than the scene's; the penalty cell keeps
    the halving."""
    path = tmp_path / "s.toml"
    path.write_text(SCENE)
    cell = fe_cell(load(path))
    refiner = cell.refiner()
    assert isinstance(refiner, ContactEdgeRefinement) and refiner.rule is HALVING_RATE
    h1 = refiner.edge_maxh(1)        # the strips' width 2a over EDGE_CELLS, within interface_maxh
    assert h1 < 0.1 and refiner.level(0) is cell and refiner.describe(2).startswith(f"edge_maxh {h1 / 2:g}")
    a = westergaard_contact_fraction(0.5, 1.0) / 2      # half the contact width (period 1)
    pts = refiner.points()
    assert len(pts) > 0 and np.all(np.abs(np.abs(pts[:, 0] - 0.5) - a) < 2.0 / 256)
    sizes = _interface_sizes(refiner.level(1).problem.mesh)
    near = np.abs(np.abs(sizes[:, 0] - 0.5) - a) < 0.02
    far = np.abs(np.abs(sizes[:, 0] - 0.5) - a) > 0.2
    # measured: mean longest edge 0.085 within 0.02 of the edges, 0.107 beyond 0.2 from them
    assert sizes[near, 1].mean() < 0.85 * sizes[far, 1].mean()
    assert len(sizes) > len(_interface_sizes(cell.problem.mesh))
    path.write_text(SCENE.replace('enforcement = "exact"', 'enforcement = "penalty"'))
    assert isinstance(fe_cell(load(path)).refiner(), InterfaceHalving)


def _disk(grid: int, radius: float) -> np.ndarray:
    """A pressure grid carrying pressure on the disk of ``radius`` about the period's corner (periodically)."""
    s = np.arange(grid) / grid
    d = np.minimum(s, 1.0 - s)
    return np.where(d[None, :] ** 2 + d[:, None] ** 2 < radius ** 2, 1.0, 0.0)


def test_the_patch_width_is_the_radius_of_a_disk_and_the_width_of_a_strip():
    from ngcontact.cell.fe.contact_edge_mesh import patch_length
    assert patch_length(_disk(512, 0.1), 1.0) == pytest.approx(0.1, rel=0.03)
    assert patch_length(_disk(512, 0.05), 1.0) == pytest.approx(0.05, rel=0.03)
    strip = np.zeros((256, 256))
    strip[:, :64] = 1.0                                  # a band a quarter of the period wide
    assert patch_length(strip, 1.0) == pytest.approx(0.25, rel=0.3)   # straight edges: within (4/pi - 1)
    assert patch_length(np.zeros((64, 64)), 1.0) is None


def test_the_edge_sizes_scale_with_the_narrowest_patch_and_the_twin_resolves_them():
    """Level 1 at the narrowest load's patch width over EDGE_CELLS, halved per level; the edge points of a
    level from a twin whose grid step is at most its edge size; halving interface_maxh without an edge."""
    from ngcontact.cell.fe.contact_edge_refinement import EDGE_CELLS, twin_grid
    asked = []

    def pressures(grid):
        asked.append(grid)
        return [_disk(grid, 0.08), _disk(grid, 0.15)]

    ladder = ContactEdgeRefinement(None, pressures, lambda points, h, grading: (points, h), interface_maxh=0.1,
                                   period=1.0)
    assert ladder.edge_maxh(1) == pytest.approx(0.08 / EDGE_CELLS, rel=0.03)
    assert ladder.edge_maxh(3) == pytest.approx(ladder.edge_maxh(1) / 4)
    points, h = ladder.level(3)
    assert h == ladder.edge_maxh(3) and 1.0 / twin_grid(h, 1.0) <= h and asked == [256, twin_grid(h, 1.0)]
    assert len(points) > len(ladder.points(1))
    assert twin_grid(0.0025, 1.0) == 512 and twin_grid(0.1, 1.0) == 256 and twin_grid(1e-4, 1.0) == 1024
    wide = ContactEdgeRefinement(None, lambda grid: [_disk(grid, 0.4)], lambda p, h, grading: h, 0.05, 1.0)
    assert [wide.edge_maxh(k) for k in (1, 2)] == [0.025, 0.0125]     # the halving's sizes where l/10 is coarser
    flat = ContactEdgeRefinement(None, lambda grid: [np.zeros((grid, grid))], lambda p, h, grading: h, 0.1, 1.0)
    graded = ContactEdgeRefinement(None, lambda grid: [np.zeros((grid, grid))], lambda p, h, g: g, 0.1, 1.0,
                                   grading=0.2)
    assert graded.level(1) == graded.level(3) == 0.2 and flat.grading == 0.3      # every level's, Netgen's
    assert flat.edge_maxh(2) == pytest.approx(0.025) and not flat.ready(3) and flat.ready(4)
