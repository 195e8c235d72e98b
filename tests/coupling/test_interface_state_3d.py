"""The macro state that loads the cells, read from a 3D interface surface, against the axisymmetric one.

A press fit of two coaxial tubes (a quarter in 3D, and the same fit in
axisymmetry).  On the cylinder ``r = b`` the law's frame is ``t1 = -e_theta``,
``t2 = -e_z``, so the 3D state's ``e_11`` is the hoop strain and ``e_22`` the
axial strain of the axisymmetric state (``e_hoop``, ``e_t``); the hoop shear
and the in-plane shear strain vanish by symmetry.  Mean values over the
middle of the fit (away from the ends, where the stresses are singular) agree
within the discretization error of the coarse 3D mesh (order 3, h = 4 mm, 3.5k
dofs; the axisymmetric one at h = 1 mm): measured 1.3 % (hoop strain), 1.2 %
(axial strain), 3.2 % (pressure), 4.6 % (shear), allowed 3, 3, 6 and 8 %; at
order 2 the same mesh is off by 3.4, 6.7, 12 and 9 %, at h = 2 mm by 2.7,
0.8, 5.4 % (strains, pressure), so these are discretization errors.
"""
import numpy as np
import ngsolve as ng
import pytest

from ngcontact.coupling.interface_state import cell_loads, interface_states
from ngcontact.drivers import run_macro as RM
from ngcontact.errors import ModelError
from ngcontact.macro import macro_measures as MM
from ngcontact.scene.loader import from_dict

MAXH = 0.004
QUARTER = [{"boundary": "bottom"}, {"boundary": "sym_x", "components": ["x"]},
           {"boundary": "sym_y", "components": ["y"]}]


def _solve(setting):
    data = {"kind": "macro", "materials": {"steel": {"E": 210e9, "nu": 0.3}, "bone": {"E": 17e9, "nu": 0.3}},
            "bodies": {"rough": "steel", "counter": "bone"},
            "geometry": {"shape": "coaxial", "setting": setting,
                         "dimensions": {"a": 0.004, "b": 0.008, "c": 0.014, "height": 0.01}},
            "interface": {"law": "linear", "kn": 1e13, "kt": 1e12, "gap": -2e-6},
            "supports": QUARTER if setting == "3d" else [{"boundary": "bottom"}],
            "loads": [{"boundary": "top", "pressure": 5e6}],
            "discretization": {"order": 3, "maxh": MAXH if setting == "3d" else 0.001}}
    scene = from_dict(data)
    problem, _ = RM.problem_of(scene, RM.build_geometry(scene))
    with ng.TaskManager():
        return RM.solve_scene(scene, problem)


def _middle(states, key):
    z = np.asarray(states["z"])
    mid = (z > 0.003) & (z < 0.007)
    return float(np.mean(np.asarray(states[key])[mid]))


def test_3d_interface_state_matches_the_axisymmetric_one_in_the_law_frame():
    sol3 = _solve("3d")
    three = interface_states(sol3)
    axi = interface_states(_solve("axisymmetric"))
    # the frame: n0 radial, t2 = -e_z, t1 = -e_theta
    frame = MM.interface_surface_frame(sol3)
    radial = np.column_stack([three["x"], three["y"], np.zeros(len(three["x"]))])
    radial /= np.linalg.norm(radial, axis=1)[:, None]
    hoop = np.column_stack([-radial[:, 1], radial[:, 0], np.zeros(len(radial))])
    # (the mesh normals of the curved order-3 geometry tilt by up to 1e-4)
    assert np.allclose(np.einsum("ni,ni->n", frame[:, 0], radial), 1.0, atol=1e-3)   # rough -> counter
    assert np.allclose(np.einsum("ni,ni->n", frame[:, 1], hoop), -1.0, atol=1e-3)
    assert np.allclose(frame[:, 2, 2], -1.0, atol=1e-3)
    for key3, key_axi in (("e_11", "e_hoop"), ("e_22", "e_t"), ("pressure", "pressure")):
        a, b = _middle(three, key3), _middle(axi, key_axi)
        assert abs(a - b) <= (0.06 if key3 == "pressure" else 0.03) * abs(b), (key3, a, key_axi, b)
    # the shear along t2 = -e_z is the axisymmetric shear along t0 = -e_z, sign included
    a, b = _middle(three, "shear_2"), _middle(axi, "shear")
    assert abs(a - b) <= 0.08 * abs(b), (a, b)
    # no in-plane shear strain and no hoop shear by symmetry (measured 1.9 % and 0.16 %)
    z = np.asarray(three["z"])
    mid = (z > 0.003) & (z < 0.007)
    assert np.mean(np.abs(three["e_12"][mid])) < 0.05 * abs(_middle(axi, "e_hoop"))
    assert np.max(np.abs(three["shear_1"])) < 0.01 * np.max(three["pressure"])
    # the cell loads of a 3D cell in the order of strength.load_names(3); a 2D cell is refused
    loads = cell_loads(three, 3)
    expected = np.column_stack([-np.asarray(three["shear_1"]), -np.asarray(three["shear_2"]), three["pressure"],
                                three["e_11"], three["e_22"], three["e_12"]])
    assert np.array_equal(loads, expected)
    with pytest.raises(ModelError, match="2D cell takes one"):
        cell_loads(three, 2)
