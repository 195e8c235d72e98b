"""``discretization.refinements``: the macro mesh made with ``maxh``, split uniformly and curved after.

One process refines the whole mesh (the MPI tier checks that ranks refining
their parts give the same report): every tetrahedron becomes 8, the new
boundary points lie on the geometry (the quarter tubes' volume nears its
exact value), the mesh is curved to the order; bad values and refined sizes
beyond ``max_elements`` are refused naming the key.
"""
from __future__ import annotations

import math

import pytest
from press_fit_3d import press_fit_3d

from ngcontact.drivers.macro_geometry import build_geometry
from ngcontact.errors import SceneError
from ngcontact.scene import loader


def _scene(tmp_path, extra: str, maxh: float = 0.01):
    text = press_fit_3d(maxh=maxh).replace(f"maxh = {maxh}\n", f"maxh = {maxh}\n{extra}")
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return loader.load(path)


def test_one_refinement_splits_every_tetrahedron_into_eight_on_the_geometry(tmp_path):
    import ngsolve as ng

    scene = _scene(tmp_path, "refinements = 1\n")
    fine, coarse = build_geometry(scene), build_geometry(scene, refinements=0)
    assert fine.mesh.ne == 8 * coarse.mesh.ne
    assert fine.mesh.GetCurveOrder() == scene.discretization.order == 2
    exact = math.pi / 4 * (0.014 ** 2 - 0.004 ** 2) * 0.01          # a quarter of the tubes a < r < c
    straight = build_geometry(scene, order=1)
    assert straight.mesh.GetCurveOrder() <= 1
    assert abs(ng.Integrate(1.0, straight.mesh) - exact) < abs(ng.Integrate(1.0, build_geometry(
        scene, order=1, refinements=0).mesh) - exact)               # new boundary points on the cylinders
    assert set(fine.mesh.GetBoundaries()) == set(coarse.mesh.GetBoundaries())


@pytest.mark.parametrize("value", [-1, 5])
def test_refinements_outside_their_range_are_refused_naming_the_key(tmp_path, value):
    with pytest.raises(SceneError, match="discretization.refinements"):
        _scene(tmp_path, f"refinements = {value}\n")


def test_refined_counts_beyond_max_elements_are_refused_naming_the_refinements(tmp_path):
    with pytest.raises(SceneError, match="fewer discretization.refinements"):
        _scene(tmp_path, "refinements = 4\nmax_elements = 100000\n", maxh=0.002)
