"""The tables of profiles and resolved shapes match the names the scene schema allows.

* ``geometry.profile`` of a cell scene: every admissible name has an entry
  in :data:`ngcontact.geometry.profile_registry.PROFILES` and every entry is
  an admissible name; the facts of each entry fit together (a 2D profile
  has a builder, only a 3D surface has heights, ...).
* ``geometry.shape`` of a direct scene: every admissible name has a class in
  :data:`ngcontact.geometry.resolved_shapes.RESOLVED_SHAPES`, boundary
  descriptions and study checks in the scene layer, and nothing more; the
  meshes of each shape carry exactly the boundary labels the scene validates
  supports and loads against.
"""
import dataclasses

import numpy as np
import pytest

from ngcontact.geometry import profiles as pr
from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.geometry.resolved_shapes import RESOLVED_SHAPES, resolved_shape
from ngcontact.scene import resolved_scene as rsc
from ngcontact.scene.cell_geometry import CellGeometry, SpectrumSpec


def _choices(cls, name):
    return {f.name: f for f in dataclasses.fields(cls)}[name].metadata["choices"]


def test_every_profile_name_has_one_entry_and_every_entry_a_name():
    names = _choices(CellGeometry, "profile")
    assert len(set(names)) == len(names)
    assert set(names) == set(PROFILES)
    assert all(name == kind.name for name, kind in PROFILES.items())


def test_the_facts_of_each_profile_fit_together():
    keys = {f.name for f in dataclasses.fields(CellGeometry)}
    for name, kind in PROFILES.items():
        assert kind.dim in (2, 3), name
        assert set(kind.keys) | set(kind.optional) <= keys, name
        assert kind.feature in keys, name
        assert (kind.profile is not None) == (kind.dim == 2), name       # every 2D profile has its builder
        if kind.dim == 2:
            assert kind.heights is None and kind.solid is None, name
        assert not (kind.flat and (kind.free_form or kind.solid is not None or kind.keys)), name
        assert kind.gap is None or kind.free_form, name                 # a gap formula of a surface only
        assert not kind.random or kind.own_grid, name                   # a drawn surface has its grid
        assert kind.free_form + (kind.solid is not None) + kind.flat <= 1, name
        if kind.dim == 3:
            assert kind.free_form or kind.solid is not None or kind.flat, name


SECTION = dict(period=1.0, h_rough=1.0, h_counter=1.0, width=0.4, depth=0.2, radius=0.3, angles=(30.0, 60.0),
               amplitude=0.05, arrangement="conforming",
               spectrum=SpectrumSpec(hurst=0.8, rms_height=0.01, grid=16))


@pytest.mark.parametrize("name", [n for n, k in PROFILES.items() if k.parametric])
def test_each_parametric_profile_builds_from_its_keys(name):
    g = CellGeometry(profile=name, **{k: SECTION[k] for k in PROFILES[name].keys + PROFILES[name].optional})
    g.check("geometry")
    builder = PROFILES[name].profile
    assert builder is not None
    prof = builder(g, None)
    assert isinstance(prof, pr.Profile) and prof.period == 1.0


@pytest.mark.parametrize("name", [n for n, k in PROFILES.items() if k.free_form and not k.reads_file])
def test_each_surface_without_a_file_gives_periodic_heights(name):
    g = CellGeometry(profile=name, **{k: SECTION[k] for k in PROFILES[name].keys})
    heights = PROFILES[name].heights
    assert heights is not None
    H = heights(g, None)
    assert H.ndim == 2 and np.allclose(H[0], H[-1]) and np.allclose(H[:, 0], H[:, -1])


def test_every_shape_name_has_one_class_and_every_class_a_name():
    names = _choices(rsc.DirectGeometry, "shape")
    assert len(set(names)) == len(names)
    assert set(names) == set(RESOLVED_SHAPES) == set(rsc.BOUNDARY_DOCS) == set(rsc.STUDY_CHECKS)
    assert all(name == cls.name for name, cls in RESOLVED_SHAPES.items())


def test_the_facts_of_each_shape_fit_the_scene():
    keys = {f.name for f in dataclasses.fields(rsc.DirectGeometry)}
    for name, cls in RESOLVED_SHAPES.items():
        assert set(cls.settings) <= set(rsc.COMPONENTS), name
        assert set(cls.required) <= set(cls.keys) <= keys, name
        assert set(cls.boundaries) == set(rsc.BOUNDARIES[name]), name
        assert set(cls.horizontal) <= set(cls.boundaries), name


#: a [geometry] section of each shape (a shape added to the table needs one here)
SHAPE_SECTIONS = {
    "blocks": rsc.DirectGeometry(cell="c.toml", periods=2, length=1.0, h_rough=0.5, h_counter=0.5),
    "femur_stem": rsc.DirectGeometry(cell="c.toml", periods=2, shape="femur_stem", setting="axisymmetric"),
}


@pytest.mark.parametrize("name", sorted(RESOLVED_SHAPES))
def test_the_meshes_of_each_shape_carry_the_labels_the_scene_knows(name):
    shape = resolved_shape(SHAPE_SECTIONS[name])
    assert isinstance(shape, RESOLVED_SHAPES[name])
    maxh = shape.extent()[1] / 2
    flat = shape.flat(maxh=maxh, interface_maxh=maxh, grading=0.3)
    assert set(flat.mesh.GetBoundaries()) == set(rsc.BOUNDARIES[name]) | {"interface"}
    resolved = shape.resolved(pr.rectangular_valley(0.5, 0.1), 4, maxh=maxh, interface_maxh=shape.eps(4) / 2,
                              order=1, grading=0.3)
    assert set(resolved.mesh.GetBoundaries()) == set(rsc.BOUNDARIES[name]) | {"contact"}
    assert set(resolved.mesh.GetMaterials()) == {"rough", "counter"}
    assert resolved.eps == pytest.approx(shape.interface_length() / 4, rel=1e-14)
