"""The mirror-symmetric quarter of a 3D FE cell (``discretization.symmetry``).

A cell even about its mid-lines under a normal frictionless load is meshed as its quarter ``[0, P/2]^2``
with zero normal displacement on the mirror faces (:mod:`ngcontact.drivers.mirror_symmetry`,
:mod:`ngcontact.geometry.cell3d`): its means are the period's.  Anything that breaks the symmetry (a gap
that is not even, a tangential load, friction) keeps the whole period, and says why.
"""
import math

import ngsolve as ng
import numpy as np
import pytest
from netgen.meshing import Element2D, Element3D, FaceDescriptor, IdentificationType, Mesh, MeshPoint, Pnt

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.contact_edge_mesh import edge_refined_cell, fold_quarter
from ngcontact.drivers import build as B, run_cell
from ngcontact.drivers.build import build_cell, cell_scene_of, with_symmetry
from ngcontact.drivers import mirror_symmetry as MS
from ngcontact.drivers.mirror_symmetry import even_gap, mirror_invariant, symmetry_choice
from ngcontact.errors import SceneError
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.cell2d import Cell
from ngcontact.geometry.cell3d import bisinusoid_gap, flat_cell3d
from ngcontact.output.report import Clock, method_line
from ngcontact.scene import loader

LAW = isotropic(2.0 * (1.0 - 0.3 ** 2), 0.3)        # E* = 1 for two equal bodies


def _solve(interface_maxh: float, symmetric: bool, cell=None) -> tuple[int, dict]:
    """The bisinusoid (h = 0.005) under p = 0.02 pi E* h, exact contact, order 1, on the period or its quarter
    (or on ``cell``)."""
    if cell is None:
        cell = flat_cell3d(1.0, 0.6, 0.6, maxh=0.3, interface_maxh=interface_maxh, symmetric=symmetric)
    model = CellModel(rough=LAW, counter=LAW, k_n=100.0 * LAW.lame[1] / interface_maxh, order=1,
                      gap=bisinusoid_gap(0.005, 1.0), enforcement="exact")
    P = CellProblem(cell, model)
    return P.ndof, P.solve(cell_load(3, pressure=0.02 * math.pi * 0.01), first=True).results


def mirrored_period(cell):
    """The period's periodic cell meshed as a symmetric quarter cell's mesh and its three mirror images
    (``x -> P - x``, ``y -> P - y``; elements of one reflection reoriented), the mirror planes inside the
    period dropped, the faces ``x = 0, P`` and ``y = 0, P`` identified periodically."""
    q, P = cell.mesh.ngmesh, cell.period[0]
    full = Mesh(dim=3)
    for i in (1, 2):
        full.SetMaterial(i, q.GetMaterial(i))
    fds = {}

    def face(name, domin, domout):
        if (name, domin, domout) not in fds:
            nr = len(fds) + 1
            full.Add(FaceDescriptor(surfnr=nr, domin=domin, domout=domout, bc=nr))
            full.SetBCName(nr - 1, name)
            fds[name, domin, domout] = nr
        return fds[name, domin, domout]
    index, qp = {}, q.Points()

    def point(x):
        key = tuple(int(round(c * 1e9)) for c in x)
        if key not in index:
            index[key] = full.Add(MeshPoint(Pnt(*x)))
        return index[key]
    for sx, sy in ((0, 0), (1, 0), (0, 1), (1, 1)):
        def image(v):
            x, y, z = qp[v]
            return (P - x if sx else x, P - y if sy else y, z)
        flip = (sx + sy) % 2 == 1
        for el in q.Elements3D():
            vs = [point(image(v)) for v in el.vertices]
            if flip:
                vs[0], vs[1] = vs[1], vs[0]
            full.Add(Element3D(el.index, vs))
        for el in q.Elements2D():
            fd = q.FaceDescriptor(el.index)
            xs = [image(v) for v in el.vertices]
            name = fd.bcname
            if name.startswith("symmetry"):
                axis = 0 if name == "symmetry_x" else 1
                if all(abs(x[axis] - 0.5 * P) < 1e-12 for x in xs):
                    continue        # the mirror plane inside the period
                name = "periodic"
            vs = [point(x) for x in xs]
            if flip:
                vs[1], vs[2] = vs[2], vs[1]
            full.Add(Element2D(face(name, fd.domin, fd.domout), vs))
    for axis, nr in ((0, 1), (1, 2)):
        for key, pid in index.items():
            if key[axis] == 0:
                other = list(key)
                other[axis] = int(round(P * 1e9))
                full.AddPointIdentification(pid, index[tuple(other)], identnr=nr, type=IdentificationType.PERIODIC)
    return Cell(mesh=ng.Mesh(full), dim=3, period=cell.period, h_rough=cell.h_rough, h_counter=cell.h_counter)


def test_the_quarter_cell_is_the_period_on_its_mirrored_mesh():
    """On the period meshed as the quarter and its mirror images the periodic cell's answers are the quarter's
    to round-off: contact fraction, mean closure, normal stiffness, the eq. 34 coefficients."""
    quarter_cell = flat_cell3d(1.0, 0.6, 0.6, maxh=0.3, interface_maxh=0.2, symmetric=True)
    period_cell = mirrored_period(quarter_cell)
    assert period_cell.mesh.ne == 4 * quarter_cell.mesh.ne and not period_cell.symmetric
    n_q, quarter = _solve(0.2, True, quarter_cell)
    n_f, full = _solve(0.2, False, period_cell)
    assert n_f > 2.5 * n_q
    assert quarter["contact_fraction"] > 0.03
    for key in ("contact_fraction", "mean_closure", "mean_pressure"):
        assert quarter[key] == pytest.approx(full[key], rel=1e-9), key
    assert quarter["effective_stiffness"]["matrix"][0][0] == pytest.approx(
        full["effective_stiffness"]["matrix"][0][0], rel=1e-8)
    for key in ("k_n", "g_n"):
        assert quarter["coefficients"][key] == pytest.approx(full["coefficients"][key], rel=1e-9), key


@pytest.mark.slow
def test_the_quarter_cell_agrees_with_a_period_meshed_on_its_own_within_their_discretization_difference():
    """Netgen's mesh of the whole period is not the quarter's mirrored: on the same sizes the two differ by
    no more than their own changes on halving the interface size."""
    out = {(h, sym): _solve(h, sym)[1] for h in (0.2, 0.1) for sym in (True, False)}
    for key in ("contact_fraction", "mean_closure"):
        q, f = out[0.2, True][key], out[0.2, False][key]
        own = abs(out[0.1, True][key] - q) + abs(out[0.1, False][key] - f)
        assert abs(q - f) <= own, key


def test_the_quarter_holds_the_normal_displacement_on_its_mirror_faces():
    cell = flat_cell3d(1.0, 0.6, 0.6, maxh=0.3, interface_maxh=0.25, symmetric=True)
    assert cell.symmetric and cell.area == pytest.approx(0.25)
    assert {"symmetry_x", "symmetry_y", "contact", "top", "bottom"} == set(cell.mesh.GetBoundaries())
    xs = np.array([cell.mesh[v].point for v in cell.mesh.vertices])
    assert xs[:, 0].max() == pytest.approx(0.5) and xs[:, 1].max() == pytest.approx(0.5)


def test_points_of_the_period_fold_into_the_quarter():
    pts = np.array([[0.1, 0.2], [0.9, 0.2], [0.1, 0.8], [0.9, 0.8], [1.3, -0.4]])
    q = fold_quarter(pts, 1.0)
    assert q.ravel() == pytest.approx([0.1, 0.2, 0.3, 0.4])
    cell = edge_refined_cell(pts, edge_maxh=0.1, maxh=0.3, interface_maxh=0.2, symmetric=True)
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


def _scene(tmp_path=None, *, gap=None, load=None, contact=None, symmetry="auto", taken_in=True):
    """A coarse 3D bisinusoid FE cell (or flat3d with a tabulated gap ``gap``: the array written to a file), as
    the drivers take it in (``taken_in``: its symmetry resolved by ``with_symmetry``) or as loaded."""
    geometry = {"profile": "bisinusoid", "arrangement": "summit", "amplitude": 0.005, "h_rough": 0.6,
                "h_counter": 0.6}
    c = {"enforcement": "exact", **(contact or {})}
    if gap is not None:
        np.save(tmp_path / "gap.npy", gap)
        geometry = {"profile": "flat3d", "h_rough": 0.6, "h_counter": 0.6}
        c["gap"] = {"kind": "tabulated", "file": "gap.npy"}
    d = {"method": "fe", "order": 1, "maxh": 0.3, "interface_maxh": 0.25, "estimate": "off"}
    if symmetry is not None:
        d["symmetry"] = symmetry
    data = {"kind": "cell", "materials": {"solid": {"E": 1.0, "nu": 0.3}},
            "bodies": {"rough": "solid", "counter": "solid"}, "geometry": geometry, "contact": c,
            "load": load or {"pressure": [0.008]}, "discretization": d}
    scene = loader.from_dict(data, base_dir=str(tmp_path or "."))
    return with_symmetry(scene) if taken_in else scene


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


def test_the_default_meshes_the_period_and_says_auto_would_mesh_the_quarter():
    """Without symmetry, a cell refined by its interface halving (here the penalty) meshes the period: the
    quarter is asked for there."""
    scene = _scene(symmetry=None, contact={"enforcement": "penalty", "k_n": 1000.0})
    choice = symmetry_choice(scene)
    assert scene.discretization.symmetry == "off" and not choice.used and not build_cell(scene).symmetric
    assert choice.reason == "discretization.symmetry = 'off' (the default; 'auto' meshes the quarter)"


def test_a_cell_refined_along_its_contact_edge_defaults_to_its_quarter():
    """Without symmetry, the exact frictionless cell (refined along its contact edge) is meshed as its
    quarter, stated as asked for by auto; set to off it keeps the period."""
    choice = symmetry_choice(_scene(symmetry=None))
    assert choice.used and choice.requested == "auto" and build_cell(_scene(symmetry=None)).symmetric
    assert not symmetry_choice(_scene(symmetry="off")).used


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


def test_the_choice_is_a_field_of_the_scene_decided_once_per_run(tmp_path, monkeypatch):
    """The loader leaves ``symmetry_choice`` unset (its rule reads the gap); ``with_symmetry`` sets it by
    ``dataclasses.replace`` (the folder kept), a resolved scene is returned as it is, a nested cell scene is
    resolved as it is loaded, and a run decides once: its mesh, refiner and report read the field."""
    raw = _scene(tmp_path, taken_in=False)
    assert raw.symmetry_choice is None
    scene = with_symmetry(raw)
    assert scene.symmetry_choice == symmetry_choice(raw) and scene.symmetry_choice.used
    assert scene.base_dir == str(tmp_path) and with_symmetry(scene) is scene
    path = tmp_path / "cell.toml"
    path.write_text('kind = "cell"\n[materials.solid]\nE = 1.0\nnu = 0.3\n[bodies]\nrough = "solid"\n'
                    'counter = "solid"\n[geometry]\nprofile = "bisinusoid"\narrangement = "summit"\n'
                    'amplitude = 0.005\nh_rough = 0.6\nh_counter = 0.6\n[contact]\nenforcement = "exact"\n'
                    '[load]\npressure = [0.008]\n[discretization]\nmethod = "fe"\nsymmetry = "auto"\n')
    assert cell_scene_of(str(path), key="cell").symmetry_choice.used
    calls = []
    counted = lambda sc: calls.append(sc) or symmetry_choice(sc)      # noqa: E731
    monkeypatch.setattr(B, "symmetry_choice", counted)
    monkeypatch.setattr(MS, "symmetry_choice", counted)                 # the mesh's own decision (quarter)
    out = run_cell.run(raw, Clock())
    assert len(calls) == 1 and out.results["accuracy"]["symmetry"] == scene.symmetry_choice.as_dict()


def test_a_scene_not_taken_in_by_a_driver_is_meshed_as_it_asked():
    """A scene handed to the mesh or the cell problem without ``with_symmetry`` (``symmetry_choice`` unset) is
    decided where it is meshed: "auto" of an even gap gives the quarter, as a driver's run would, "off" the
    period; the field, where set, is what the mesh reads."""
    raw = _scene(taken_in=False)
    assert raw.symmetry_choice is None and MS.quarter(raw) and build_cell(raw).symmetric
    off = _scene(symmetry="off", taken_in=False)
    assert not MS.quarter(off) and not build_cell(off).symmetric
    forced = B.scene_with(raw, symmetry_choice=MS.SymmetryChoice(False, "set by hand"))
    assert not MS.quarter(forced) and not build_cell(forced).symmetric


def test_the_recovery_cell_keeps_the_period_whatever_the_scene_asks(tmp_path):
    """The strength recovery's correctors and the shear response load the cell tangentially (macro shear
    strains, shear tractions), which the quarter's mirror faces would hold wrongly: a scene that would mesh
    its quarter for its own normal loads gives the recovery its period, and says why."""
    path = tmp_path / "cell.toml"
    path.write_text('kind = "cell"\n[materials.solid]\nE = 1.0\nnu = 0.3\n[bodies]\nrough = "solid"\n'
                    'counter = "solid"\n[geometry]\nprofile = "bisinusoid"\narrangement = "summit"\n'
                    'amplitude = 0.005\nh_rough = 0.6\nh_counter = 0.6\n[contact]\nenforcement = "exact"\n'
                    '[load]\npressure = [0.008]\n[discretization]\nmethod = "fe"\nsymmetry = "auto"\norder = 1\n'
                    'maxh = 0.3\ninterface_maxh = 0.25\n')
    assert cell_scene_of(str(path), key="strength.cell").symmetry_choice.used
    cs, P = B.recovery_cell_problem(str(path), key="strength.cell")
    assert not cs.symmetry_choice.used and cs.symmetry_choice.reason == B.RECOVERY_PERIOD
    assert not P.cell.symmetric
