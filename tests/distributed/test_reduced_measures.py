"""The reduced measures on one rank are the whole mesh's: sums, extrema, the interface samples in order.

:class:`ngcontact.distributed.reduced_measures.Reduced` combines the ranks'
parts with the MPI collectives; on one rank (a communicator whose
collectives return this rank's own part) it must give the report of one
process exactly, which checks its ordering of the interface samples by the
elements' numbers in the whole mesh (found by their mid-points) and its extrema and sums without ``mpiexec`` (the
``mpi`` tier checks two and three ranks).
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np
import pytest
from press_fit_3d import press_fit_3d
from test_mpi_macro import BLOCK

from ngcontact.distributed.boundary_numbers import Coarse, midpoints, numbered
from ngcontact.distributed.reduced_measures import Reduced
from ngcontact.distributed.world import World
from ngcontact.drivers import run_macro as R
from ngcontact.scene import loader


class OneRank:
    """The collectives of a communicator of one rank."""

    rank, size = 0, 1

    def allreduce(self, value):
        return value

    def allgather(self, value):
        return [value]

    def gather(self, value, root=0):
        return [value]

    def bcast(self, value, root=0):
        return value

    def scatter(self, values, root=0):
        return values[0]


def _solved(tmp_path, text: str):
    path = tmp_path / "scene.toml"
    path.write_text(text)
    scene = loader.load(path)
    geo = R.build_geometry(scene)
    problem, info = R.problem_of(scene, geo)
    return scene, geo, info, R.solve_scene(scene, problem)


def _same(a, b, path=""):
    if isinstance(a, dict):
        assert set(a) == set(b), path
        for k in a:
            _same(a[k], b[k], f"{path}/{k}")
    elif isinstance(a, (list, tuple)) and not isinstance(a, np.ndarray):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{path}[{i}]")
    elif isinstance(a, np.ndarray):
        np.testing.assert_array_equal(a, b, err_msg=path)
    else:
        assert a == b, path


@pytest.mark.parametrize("text", [BLOCK, press_fit_3d(maxh=0.006)], ids=["2d block, friction", "3d press fit"])
def test_one_rank_reduces_to_the_report_of_one_process(tmp_path, text):
    scene, geo, info, sol = _solved(tmp_path, text)
    whole = R.measured(sol, geo, info, scene.output)
    world = World(comm=OneRank(), rank=0, size=1)
    numbers = numbered(world, geo.mesh, Coarse.of(geo.mesh))
    assert np.array_equal(numbers.serial, np.arange(geo.mesh.GetNE(ng.BND)))
    reduced = R.measured(sol, geo, info, scene.output, Reduced(world, numbers))
    _same(whole.results, reduced.results)
    assert whole.ndof == reduced.ndof


def test_the_keys_of_the_interface_elements_are_their_vertices_mid_points():
    from ngcontact.geometry import bodies as gm

    mesh = gm.block_on_plane(1.0, 1.0, 1.0, maxh=0.5).mesh
    mine = np.array([el.mat == "interface" for el in mesh.Elements(ng.BND)])
    keys = midpoints(mesh)[mine]
    assert len(keys) == sum(1 for el in mesh.Elements(ng.BND) if el.mat == "interface")
    assert np.allclose(keys[:, 1], keys[0, 1]) and len(np.unique(np.round(keys[:, 0], 12))) == len(keys)
