"""A macro geometry from a CAD file: two solids read back, their interface found, faces listed and selected.

The STEP files are written here with Netgen's OCC kernel: a block (2 x 1 x 1
mm, named ``block``, its top face named ``top``) on a base below it
(``base``), touching on ``z = 0``.
"""
from __future__ import annotations

import json

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.errors import GeometryError
from ngcontact.geometry import cad_model as cad
from ngcontact.geometry import face_selectors as fs
from ngcontact.geometry.model_faces import body_index


def write_block_on_base(path) -> None:
    from netgen.occ import Box, Compound, Pnt, Z

    block = Box(Pnt(0, 0, 0), Pnt(2, 1, 1))
    base = Box(Pnt(0, 0, -1), Pnt(2, 1, 0))
    block.faces.Max(Z).name = "top"
    block.name, base.name = "block", "base"
    Compound([block, base]).WriteStep(str(path))


def write_block_on_base_meshes(folder) -> None:
    """The same block on its base as a Netgen mesh (``bb.vol``) and a Gmsh mesh (``bb.msh``), in metres.

    Netgen's Gmsh export writes no physical names, which Netgen's Gmsh reader
    requires: they are added here (the face names and the region names).
    """
    from netgen.occ import Box, Glue, OCCGeometry, Pnt, Z

    block = Box(Pnt(0, 0, 0), Pnt(2, 1, 1))
    base = Box(Pnt(0, 0, -1), Pnt(2, 1, 0))
    block.faces.Max(Z).name = "top"
    block.mat("block")
    base.mat("base")
    m = OCCGeometry(Glue([block, base])).GenerateMesh(maxh=0.5)
    m.Save(str(folder / "bb.vol"))
    m.Export(str(folder / "raw.msh"), "Gmsh2 Format")
    n = m.GetNFaceDescriptors()
    names = ["$PhysicalNames", str(n + 2)] + [f'2 {k} "{m.FaceDescriptor(k).bcname}"' for k in range(1, n + 1)] \
        + [f'3 {100000 + k} "{m.GetMaterial(k)}"' for k in (1, 2)] + ["$EndPhysicalNames", "$Nodes"]
    text = (folder / "raw.msh").read_text().replace("$Nodes", "\n".join(names), 1)
    (folder / "bb.msh").write_text(text)


SCENE = """\
kind = "macro"

[materials.steel]
E = 210e9
nu = 0.3

[bodies]
rough = "steel"
counter = "steel"

[geometry]
shape = "file"
setting = "3d"
file = "bb.step"
rough = {{ name = "block" }}
counter = {{ point = [1.0, 0.5, -0.5] }}

[geometry.boundaries.bottom]
plane = {{ point = [0.0, 0.0, -1.0], normal = [0.0, 0.0, 1.0] }}
{extra}
[interface]
law = "linear"
kn = 1e15
kt = 1e15

[[supports]]
boundary = "bottom"

[[loads]]
boundary = "{loaded}"
pressure = 1e6

[discretization]
order = 1
maxh = 0.001
"""


@pytest.fixture
def step(tmp_path):
    path = tmp_path / "bb.step"
    write_block_on_base(path)
    return path


def scene_file(tmp_path, extra="", loaded="top"):
    path = tmp_path / "s.toml"
    path.write_text(SCENE.format(extra=extra, loaded=loaded))
    return str(path)


@pytest.mark.parametrize("name", ["bb.step", "bb.brep"])
def test_a_cad_file_is_read_back_with_its_bodies_interface_and_faces(step, name):
    if name == "bb.brep":   # the same solids as BREP (no unit: read as written)
        from netgen.occ import OCCGeometry
        OCCGeometry(str(step)).shape.WriteBrep(str(step.parent / name))
    model = cad.read_cad(str(step.parent / name))
    assert model.solid_names == (["block", "base"] if name == "bb.step" else [None, None])
    assert model.volumes == pytest.approx([2.0, 2.0])
    assert len(model.faces) == 11                       # 6 + 6 faces, the shared one once
    (shared,) = model.interface_faces()
    assert set(shared.bodies) == {0, 1} and shared.area == pytest.approx(2.0)
    assert shared.form.kind == "plane" and np.allclose(shared.form.normal, (0, 0, 1))
    assert np.allclose(shared.centroid, (1.0, 0.5, 0.0))
    assert [f.label for f in model.faces].count("top") == (1 if name == "bb.step" else 0)
    assert all(f.form.kind == "plane" for f in model.faces)
    assert body_index(model, "k", point=(1.0, 0.5, 0.5)) == 0 and body_index(model, "k", index=1) == 1


def test_a_cylinder_is_recognised_by_its_axis_and_radius(tmp_path):
    from netgen.occ import Compound, Cylinder, Pnt, Z

    inner = Cylinder(Pnt(0, 0, 0), Z, r=1.0, h=2.0)
    outer = Cylinder(Pnt(0, 0, 0), Z, r=3.0, h=2.0) - Cylinder(Pnt(0, 0, 0), Z, r=1.0, h=2.0)
    Compound([inner, outer]).WriteStep(str(tmp_path / "c.step"))
    model = cad.read_cad(str(tmp_path / "c.step"))
    (shared,) = model.interface_faces()
    assert shared.form.kind == "cylinder" and shared.form.radius == pytest.approx(1.0, rel=1e-6)
    assert np.allclose(np.abs(shared.form.axis), (0, 0, 1), atol=1e-6)
    picked = fs.OnCylinder("k", (0, 0, 0), (0, 0, 1), 3.0).pick(model.faces, model.tolerance)
    assert [f.bodies for f in picked] == [(1,)] and picked[0].area == pytest.approx(2 * np.pi * 3 * 2)


def test_check_lists_every_face_with_its_body_area_centroid_and_form(tmp_path, step, capsys):
    assert cli.main(["check", scene_file(tmp_path)]) == 0
    out = capsys.readouterr().out
    for i in range(11):
        assert f"face {i}:" in out
    assert "'top', rough (body 0)" in out and "-> 'bottom'" in out and "-> 'interface'" in out
    assert "-> 'free'" in out and "-> 'top'" in out
    assert "rough (body 0) and counter (body 1), area 2, centroid (1, 0.5, 0), plane, normal (0, 0, 1)" in out


@pytest.mark.parametrize("name", ["bb.vol", "bb.msh"])
def test_a_mesh_file_is_read_with_its_regions_interface_and_boundary_regions(tmp_path, name):
    from ngcontact.geometry.mesh_model import read_mesh

    write_block_on_base_meshes(tmp_path)
    model = read_mesh(str(tmp_path / name))
    assert model.solid_names == ["block", "base"] and model.volumes == pytest.approx([2.0, 2.0])
    assert len(model.faces) == 11
    (shared,) = model.interface_faces()
    assert shared.bodies == (0, 1) and shared.area == pytest.approx(2.0)
    assert shared.form.kind == "plane" and np.allclose(shared.form.normal, (0, 0, 1))
    assert [f.label for f in model.faces].count("top") == 1
    assert body_index(model, "k", point=(1.0, 0.5, -0.5)) == 1 and body_index(model, "k", name="block") == 0


@pytest.mark.slow
@pytest.mark.parametrize("name,area", [("bb.step", 2e-6), ("bb.vol", 2.0), ("bb.msh", 2.0)])
def test_uniform_pressure_is_transmitted_through_the_interface(tmp_path, step, name, area):
    """The whole chain (read, select, mesh in metres, solve): the block's top load crosses S_0 unchanged."""
    write_block_on_base_meshes(tmp_path)
    out = tmp_path / "o"
    assert cli.main(["run", _with_file(tmp_path, name), "--out", str(out), "--quiet"]) == 0
    res = json.loads((out / "report.json").read_text())["results"]
    assert res["mean_pressure"] == pytest.approx(1e6, rel=1e-8)
    assert res["resultant"]["z"] == pytest.approx(-1e6 * area, rel=1e-8)   # pushed down
    assert res["dimensions"] == {"length_unit": 0.001 if name == "bb.step" else 1.0}


def _with_file(tmp_path, name) -> str:
    path = tmp_path / "m.toml"
    path.write_text(SCENE.format(extra="", loaded="top").replace('"bb.step"', f'"{name}"'))
    return str(path)


@pytest.mark.parametrize("extra,loaded,message", [
    ("[geometry.boundaries.nothing]\nplane = { point = [0.0, 0.0, 5.0], normal = [0.0, 0.0, 1.0] }\n", "top",
     "geometry.boundaries.nothing = 'nothing': matches no face of the model; the faces are"),
    ("[geometry.boundaries.middle]\nplane = { point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }\n", "top",
     "matches face 4, which both bodies share (the interface"),
    ("[geometry.boundaries.ends]\nbox = { low = [0.0, 0.0, -1.0], high = [0.0, 1.0, 1.0] }\n"
     "[geometry.boundaries.left]\nplane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }\n", "top",
     "geometry.boundaries.left = 'left': ambiguous: face"),
    ("[geometry.boundaries.corner]\nnearest = [-1.0, -1.0, 0.5]\n", "corner", "geometry.boundaries.corner = "
     "[-1.0, -1.0, 0.5]: ambiguous: faces"),
    ("", "flank", "loads[0].boundary = 'flank': no such boundary in the file's model; labels are bottom, free, "
     "interface, top"),
])
def test_a_bad_selection_is_refused_before_meshing_with_the_list_of_faces(tmp_path, step, capsys, extra, loaded,
                                                                          message):
    assert cli.main(["check", scene_file(tmp_path, extra, loaded)]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert "face 10:" in err or "ambiguous: faces" in err


def test_a_body_point_outside_both_solids_is_refused(tmp_path, step, capsys):
    text = SCENE.format(extra="", loaded="top").replace("point = [1.0, 0.5, -0.5]", "point = [9.0, 0.5, -0.5]")
    (tmp_path / "s.toml").write_text(text)
    assert cli.main(["check", str(tmp_path / "s.toml")]) == 2
    err = capsys.readouterr().err
    assert "geometry.counter = [9.0, 0.5, -0.5]: names no body of the model; the bodies are" in err
    assert "body 0: 'block', volume 2" in err


def test_the_nearest_face_and_the_face_index_select_one_face(step):
    model = cad.read_cad(str(step))
    top = next(f for f in model.faces if f.label == "top")
    assert fs.NearestTo("k", (1.0, 0.5, 1.2)).pick(model.faces, model.tolerance) == [top]
    assert fs.ByIndex("k", (top.index,)).pick(model.faces, model.tolerance) == [top]
    with pytest.raises(GeometryError, match="face 11 does not exist"):
        fs.ByIndex("k", (11,)).pick(model.faces, model.tolerance)


@pytest.mark.parametrize("geometry,message", [
    ('shape = "coaxial"\nsetting = "3d"\nfile = "bb.step"', "geometry.file = 'bb.step': only used with shape = "
     "'file'; remove it"),
    ('shape = "file"\nsetting = "3d"\nfile = "bb.stl"\nrough = { index = 0 }\ncounter = { index = 1 }',
     "geometry.file = 'bb.stl': must end in one of .step"),
    ('shape = "file"\nsetting = "3d"\nfile = "bb.step"\nlength_unit = 1.0\nrough = { index = 0 }\n'
     'counter = { index = 1 }', "geometry.length_unit = 1.0: a .step file is read in millimetres"),
    ('shape = "file"\nsetting = "3d"\nfile = "bb.step"\nrough = { index = 0, name = "block" }\n'
     'counter = { index = 1 }', "geometry.rough = {index, name}: give exactly one of name, index, point"),
    ('shape = "file"\nsetting = "3d"\nfile = "bb.step"\nrough = { index = 0 }',
     "geometry.counter = <missing>: required for shape = 'file'"),
    ('shape = "file"\nsetting = "plane_strain"\nfile = "bb.vol"\nrough = { index = 0 }\ncounter = { index = 1 }',
     "geometry.setting = 'plane_strain': a mesh file takes setting '3d'"),
    ('shape = "file"\nsetting = "plane_strain"\nfile = "bb.step"\nrough = { index = 0 }\ncounter = { index = 1 }',
     "geometry.file = 'bb.step': holds 2 solids and 12 faces; a 2D macro model needs exactly two planar faces"),
])
def test_file_geometry_keys_are_checked_when_the_scene_loads(tmp_path, step, capsys, geometry, message):
    write_block_on_base_meshes(tmp_path)
    start = SCENE.index("[geometry]\n")
    text = SCENE.format(extra="", loaded="top")
    text = text[:start] + "[geometry]\n" + geometry + "\n\n" + text[text.index("[geometry.boundaries.bottom]"):]
    (tmp_path / "s.toml").write_text(text)
    assert cli.main(["check", str(tmp_path / "s.toml")]) == 2
    assert message in capsys.readouterr().err
