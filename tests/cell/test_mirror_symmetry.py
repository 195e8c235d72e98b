"""The mirror-symmetric quarter of a 3D FE cell (``discretization.symmetry``).

A cell even about its mid-lines under a normal frictionless load is meshed as its quarter ``[0, P/2]^2``
with zero normal displacement on the mirror faces (:mod:`ngcontact.drivers.mirror_symmetry`,
:mod:`ngcontact.geometry.cell3d`): its means are the period's.  Anything that breaks the symmetry (a gap
that is not even, a tangential load, friction) keeps the whole period, and says why.
"""
import math

import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.contact_edge_mesh import edge_refined_cell, fold_quarter
from ngcontact.drivers.build import build_cell
from ngcontact.drivers.mirror_symmetry import even_gap, mirror_invariant, symmetry_choice
from ngcontact.errors import SceneError
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.cell3d import bisinusoid_gap, flat_cell3d
from ngcontact.output.report import method_line
from ngcontact.scene import loader

LAW = isotropic(2.0 * (1.0 - 0.3 ** 2), 0.3)        # E* = 1 for two equal bodies


def _solve(interface_maxh: float, symmetric: bool) -> tuple[int, dict]:
    """The bisinusoid (h = 0.005) under p = 0.02 pi E* h, exact contact, order 1, on the period or its quarter."""
    cell = flat_cell3d(1.0, 0.6, 0.6, maxh=0.3, interface_maxh=interface_maxh, symmetric=symmetric)
    model = CellModel(rough=LAW, counter=LAW, k_n=100.0 * LAW.lame[1] / interface_maxh, order=1,
                      gap=bisinusoid_gap(0.005, 1.0), enforcement="exact")
    P = CellProblem(cell, model)
    return P.ndof, P.solve(cell_load(3, pressure=0.02 * math.pi * 0.01), first=True).results


def test_the_quarter_holds_the_normal_displacement_on_its_mirror_faces():
    cell = flat_cell3d(1.0, 0.6, 0.6, maxh=0.3, interface_maxh=0.15, symmetric=True)
    assert cell.symmetric and cell.area == pytest.approx(0.25)
    assert {"symmetry_x", "symmetry_y", "contact", "top", "bottom"} == set(cell.mesh.GetBoundaries())
    xs = np.array([cell.mesh[v].point for v in cell.mesh.vertices])
    assert xs[:, 0].max() == pytest.approx(0.5) and xs[:, 1].max() == pytest.approx(0.5)


def test_points_of_the_period_fold_into_the_quarter():
    pts = np.array([[0.1, 0.2], [0.9, 0.2], [0.1, 0.8], [0.9, 0.8], [1.3, -0.4]])
    q = fold_quarter(pts, 1.0)
    assert q.ravel() == pytest.approx([0.1, 0.2, 0.3, 0.4])
    cell = edge_refined_cell(pts, edge_maxh=0.05, maxh=0.3, interface_maxh=0.15, symmetric=True)
    assert cell.symmetric and "symmetry_x" in set(cell.mesh.GetBoundaries())


def test_evenness_is_decided_on_the_samples():
    s = np.arange(32) / 32
    assert even_gap(bisinusoid_gap(0.005, 1.0, xy=(s[None, :], s[:, None])))
    shifted = 1.0 - np.cos(2 * np.pi * (s[None, :] - 0.1)) + 0.0 * s[:, None]
    assert not even_gap(shifted)
    assert not even_gap(np.random.default_rng(1).random((32, 32)))
    C = np.diag([3.0, 3.0, 3.0, 1.0, 1.0, 1.0])
    assert mirror_invariant(C)
    C[0, 5] = C[5, 0] = 0.2
    assert not mirror_invariant(C)


def _scene(tmp_path=None, *, gap=None, load=None, contact=None, symmetry=None):
    """A coarse 3D bisinusoid FE cell (or flat3d with a tabulated gap ``gap``: the array written to a file)."""
    geometry = {"profile": "bisinusoid", "arrangement": "summit", "amplitude": 0.005, "h_rough": 0.6,
                "h_counter": 0.6}
    c = {"enforcement": "exact", **(contact or {})}
    if gap is not None:
        np.save(tmp_path / "gap.npy", gap)
        geometry = {"profile": "flat3d", "h_rough": 0.6, "h_counter": 0.6}
        c["gap"] = {"kind": "tabulated", "file": "gap.npy"}
    d = {"method": "fe", "order": 1, "maxh": 0.3, "interface_maxh": 0.15, "estimate": "off"}
    if symmetry is not None:
        d["symmetry"] = symmetry
    data = {"kind": "cell", "materials": {"solid": {"E": 1.0, "nu": 0.3}},
            "bodies": {"rough": "solid", "counter": "solid"}, "geometry": geometry, "contact": c,
            "load": load or {"pressure": [0.008]}, "discretization": d}
    return loader.from_dict(data, base_dir=str(tmp_path or "."))


def test_a_symmetric_scene_is_meshed_as_its_quarter_and_says_so():
    scene = _scene()
    choice = symmetry_choice(scene)
    assert choice.used and choice.requested == "auto"
    assert build_cell(scene).symmetric
    line = method_line({"accuracy": {"symmetry": choice.as_dict()}})
    assert line is not None and line.startswith("meshed as its symmetric quarter: the gap is even")
    off = _scene(symmetry="off")
    assert not symmetry_choice(off).used and not build_cell(off).symmetric
    assert symmetry_choice(off).reason == "discretization.symmetry = 'off'"


def test_a_gap_that_is_not_even_keeps_the_period(tmp_path):
    t = np.linspace(0.0, 1.0, 17)
    X, Y = np.meshgrid(t, t)
    g = 0.005 * (1.0 + np.sin(2 * np.pi * X)) * (1.0 + 0.0 * Y)      # even about x = 1/4, not about x = 1/2
    choice = symmetry_choice(_scene(tmp_path, gap=g))
    assert not choice.used and choice.reason == "the initial gap is not even about the cell's mid-lines"
    assert not build_cell(_scene(tmp_path, gap=g)).symmetric
    even = 0.005 * (2.0 - np.cos(2 * np.pi * X) - np.cos(4 * np.pi * Y))
    assert symmetry_choice(_scene(tmp_path, gap=even)).used


def test_a_tangential_load_or_friction_keeps_the_period():
    sheared = _scene(load={"pressure": [0.008], "shear": [0.001, 0.0]},
                     contact={"friction": "coulomb", "mu": 0.3, "w": 1e-6})
    choice = symmetry_choice(sheared)
    assert not choice.used and choice.reason == "load.shear = [0.001, 0.0] is tangential"
    assert not build_cell(sheared).symmetric
    rubbing = _scene(contact={"friction": "coulomb", "mu": 0.3, "w": 1e-6})
    assert symmetry_choice(rubbing).reason == "contact.friction = 'coulomb' couples the tangential response"
    strained = _scene(load={"pressure": [0.008], "macro_strain": [0.0, 0.0, 1e-3]})
    assert symmetry_choice(strained).reason.startswith("load.macro_strain = [0.0, 0.0, 0.001] shears")
    assert symmetry_choice(_scene(load={"pressure": [0.008], "macro_strain": [1e-3, 0.0, 0.0]})).used


def test_a_bad_symmetry_names_the_key_and_the_values():
    with pytest.raises(SceneError, match=r"discretization.symmetry = 'quarter': must be one of 'auto', 'off'"):
        _scene(symmetry="quarter")
