"""Netgen's mesher with the task manager's workers asleep (:mod:`ngcontact.geometry.mesher`): the same mesh,
and the task manager works in parallel again afterwards."""
import numpy as np
import pytest
import ngsolve as ng

from ngcontact.geometry import cell3d, mesher


def _points(ngmesh) -> np.ndarray:
    return np.array([p.p for p in ngmesh.Points()])


def test_the_mesh_is_the_same_with_the_workers_asleep():
    geo = cell3d.square_hills_cell  # the strength check's cell, meshed through mesher.generate
    ng.SetNumThreads(2)
    with ng.TaskManager():
        inside = geo(0.4, 0.2, h_rough=0.6, h_counter=0.6, maxh=0.4, interface_maxh=0.2).mesh
        area = ng.Integrate(ng.CF(1.0), inside, definedon=inside.Boundaries("contact"))
    outside = geo(0.4, 0.2, h_rough=0.6, h_counter=0.6, maxh=0.4, interface_maxh=0.2).mesh
    assert np.array_equal(_points(inside.ngmesh), _points(outside.ngmesh))
    assert inside.ne == outside.ne
    assert area == pytest.approx(0.4 ** 2, rel=1e-12)     # the summit, integrated in parallel


def test_generate_runs_the_geometry_s_own_mesher():
    from netgen.csg import unit_cube
    ng.SetNumThreads(2)
    with ng.TaskManager():
        m = mesher.generate(unit_cube, maxh=0.5)
    assert np.array_equal(_points(m), _points(unit_cube.GenerateMesh(maxh=0.5)))
