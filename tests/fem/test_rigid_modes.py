"""Rigid motions left free by supports and the interface tie (ngcontact.fem.rigid_modes)."""
import pytest

from ngcontact.fem.rigid_modes import free_rigid_modes
from ngcontact.fem.two_body import Support
from ngcontact.geometry import bodies as gm


@pytest.fixture(scope="module")
def block():
    return gm.block_on_plane(0.02, 0.005, 0.005, maxh=0.002).mesh


@pytest.mark.parametrize("supports, tangential, free", [
    ((Support(label="bottom"),), True, []),
    ((Support(label="bottom"),), False, ["body 'block': translation in x"]),
    ((Support(label="bottom", components=("y",)),), True, ["both bodies together: translation in x"]),
    ((Support(label="bottom", components=("x",)), Support(label="top", components=("y",))), False,
     ["body 'block': translation in x"]),
    ((Support(label="base_sides", components=("x",)), Support(label="top", components=("y",))), True, []),
])
def test_block_on_a_base(block, supports, tangential, free):
    assert free_rigid_modes(block, "plane_strain", ("block", "base"), supports, "interface", tangential) == free


def test_a_frictionless_ring_in_a_curved_bore_may_rotate_and_a_held_one_may_not():
    mesh = gm.coaxial_plane_strain(0.01, 0.02, 0.03, maxh=0.004, order=2).mesh
    held = (Support(label="mantle"),)
    assert free_rigid_modes(mesh, "plane_strain", ("inner", "outer"), held, "interface", False) == [
        "body 'inner': rotation in the x-y plane"]
    assert free_rigid_modes(mesh, "plane_strain", ("inner", "outer"), held, "interface", True) == []
    quarter = (Support(label="sym_x", components=("x",)), Support(label="sym_y", components=("y",)))
    assert free_rigid_modes(mesh, "plane_strain", ("inner", "outer"), quarter, "interface", False) == []


def test_three_dimensional_and_axisymmetric_modes():
    mesh = gm.coaxial_3d(0.01, 0.02, 0.03, 0.02, maxh=0.008, order=2).mesh
    quarter = (Support(label="sym_x", components=("x",)), Support(label="sym_y", components=("y",)))
    free = free_rigid_modes(mesh, "3d", ("inner", "outer"), quarter, "interface", True)
    assert free == ["both bodies together: translation in z"]
    assert free_rigid_modes(mesh, "3d", ("inner", "outer"), quarter + (Support(label="bottom", components=("z",)),),
                            "interface", True) == []
    axi = gm.coaxial_axisymmetric(0.01, 0.02, 0.03, 0.02, maxh=0.004).mesh
    assert free_rigid_modes(axi, "axisymmetric", ("inner", "outer"), (Support(label="bottom", components=("z",)),),
                            "interface", False) == []
    # a frictionless sleeve on a vertical interface: each body slides on its own
    assert free_rigid_modes(axi, "axisymmetric", ("inner", "outer"), (), "interface", False) == [
        "body 'inner': translation in z", "body 'outer': translation in z"]
