"""The shipped press fit from a STEP file against Lame, against another STEP of the same part, and against the
built-in coaxial shape with the same data (``geometries/macro/press_fit_step.toml``).

Both ends held in ``z`` make the quarter plane strain, so its mean interface
pressure is Lame's with the interface compliance ``1/kn`` in series
(:func:`ngcontact.verification.lame.lame_press_fit_pressure`).
"""
from __future__ import annotations

import os
import shutil

import pytest

from ngcontact.drivers import run_macro as RM
from ngcontact.macro import macro_measures as MM
from ngcontact.scene import loader
from ngcontact.verification.lame import lame_press_fit_pressure

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "geometries", "macro", "press_fit_step.toml")
A, B, C = 0.005, 0.03, 0.075          # bore, interface, outer radius [m]
LAME = lame_press_fit_pressure(A, B, C, 210e9, 0.3, 110e9, 0.34, interference=2e-5, k_n=5e12)


def mean_pressure(scene) -> float:
    problem, _ = RM.problem_of(scene, RM.build_geometry(scene))
    return MM.mean_pressure(RM.solve_scene(scene, problem))


def write_revolved(path) -> None:
    """The same part made otherwise: hub first, each ring a rectangle in ``y = 0`` revolved by 90 degrees
    about ``z`` (another face order and orientation than the shipped file's boolean cuts)."""
    from netgen.occ import Axes, Axis, Compound, WorkPlane, X, Y, Z

    def ring(r0, r1):
        section = WorkPlane(Axes((0, 0, 0), n=-Y, h=X)).MoveTo(r0, 0).Rectangle(r1 - r0, 20.0).Face()
        return section.Revolve(Axis((0, 0, 0), Z), 90)

    Compound([ring(30.0, 75.0), ring(5.0, 30.0)]).WriteStep(str(path))


@pytest.mark.slow
def test_press_fit_from_step_matches_lame_another_step_and_the_builtin_shape(tmp_path):
    shipped = mean_pressure(loader.load(SCENE))
    assert abs(shipped / LAME - 1) < 5e-3, (shipped, LAME)

    os.makedirs(tmp_path / "data")
    write_revolved(tmp_path / "data" / "press_fit_quarter.step")
    shutil.copy(SCENE, tmp_path / "scene.toml")
    other = mean_pressure(loader.load(tmp_path / "scene.toml"))
    assert abs(other / LAME - 1) < 5e-3 and abs(other / shipped - 1) < 1e-3, (other, shipped)

    with open(SCENE, "rb") as fh:
        import tomllib
        data = tomllib.load(fh)
    data["geometry"] = {"shape": "coaxial", "setting": "3d",
                        "dimensions": {"a": A, "b": B, "c": C, "height": 0.02}}
    builtin = mean_pressure(loader.from_dict(data, base_dir=os.path.dirname(SCENE)))
    assert abs(builtin / shipped - 1) < 1e-4, (builtin, shipped)


PLANAR = """\
kind = "macro"

[materials.steel]
E = 210e9
nu = 0.3

[materials.bronze]
E = 110e9
nu = 0.34

[bodies]
rough = "steel"
counter = "bronze"

[geometry]
shape = "file"
setting = "{setting}"
file = "planar.step"
rough = {{ point = [15.0, 1.0, 0.0] }}
counter = {{ point = [50.0, 1.0, 0.0] }}
{boundaries}
[interface]
law = "linear"
kn = 5e12
gap = -2e-5
{supports}
[discretization]
order = 3
maxh = 0.006
"""
ENDS = """
[geometry.boundaries.bottom]
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }

[geometry.boundaries.top]
plane = { point = [0.0, 20.0, 0.0], normal = [0.0, 1.0, 0.0] }
"""
QUARTER = """
[geometry.boundaries.sym_x]
plane = { point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }

[geometry.boundaries.sym_y]
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }

[geometry.boundaries.mantle]
cylinder = { point = [0.0, 0.0, 0.0], axis = [0.0, 0.0, 1.0], radius = 75.0 }
"""


def write_planar(path, setting: str) -> None:
    """Two faces in ``z = 0``, in mm: the ``(r, z)`` rectangles of tube and hub (axisymmetric), or their quarter
    annuli (plane strain)."""
    from netgen.occ import Compound, WorkPlane

    if setting == "axisymmetric":
        tube = WorkPlane().MoveTo(5.0, 0.0).Rectangle(25.0, 20.0).Face()
        hub = WorkPlane().MoveTo(30.0, 0.0).Rectangle(45.0, 20.0).Face()
    else:
        quarter = WorkPlane().Rectangle(100.0, 100.0).Face()

        def disk(r):
            return WorkPlane().Circle(r).Face()

        tube, hub = (disk(30.0) - disk(5.0)) * quarter, (disk(75.0) - disk(30.0)) * quarter
    Compound([hub, tube]).WriteStep(str(path))


@pytest.mark.parametrize("setting", ["axisymmetric", "plane_strain"])
def test_a_planar_step_model_gives_lames_pressure(tmp_path, setting):
    """Two faces of a STEP file as a plane-strain quarter or an axisymmetric section (ends held in z)."""
    from ngcontact.runner import check

    write_planar(tmp_path / "planar.step", setting)
    if setting == "axisymmetric":
        boundaries, supports = ENDS, [("bottom", "z"), ("top", "z")]
    else:
        boundaries, supports = QUARTER, [("sym_x", "x"), ("sym_y", "y")]
    text = PLANAR.format(setting=setting, boundaries=boundaries, supports="".join(
        f'\n[[supports]]\nboundary = "{b}"\ncomponents = ["{c}"]\n' for b, c in supports))
    (tmp_path / "s.toml").write_text(text)
    scene = loader.load(tmp_path / "s.toml")
    listing = "\n".join(check(scene))
    assert "-> 'interface'" in listing and "length" in listing
    if setting == "plane_strain":
        assert "circular arc, centre (0, 0, 0), radius 30 -> 'interface'" in listing
        assert "radius 75 -> 'mantle'" in listing
    p = mean_pressure(scene)
    assert abs(p / LAME - 1) < 1e-3, (p, LAME)


@pytest.mark.slow
def test_the_femur_posed_from_a_step_section_gives_the_built_in_peak_pressure(tmp_path, monkeypatch):
    """geometries/macro/femur_stem_step.toml: the femur scene's section as two unnamed faces of a STEP file,
    its supports and load chosen by where they lie; its peak interface pressure is the built-in shape's."""
    import ngcontact

    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path))
    peaks = []
    for path in (("femur_stem.toml",), ("macro", "femur_stem_step.toml")):
        report, _ = ngcontact.solve(os.path.join(ROOT, "geometries", *path))
        quantities = {q["name"]: q for q in report["results"]["accuracy"]["quantities"]}
        peaks.append(quantities["peak_pressure"]["value"])
    assert abs(peaks[1] / peaks[0] - 1) < 1e-3, peaks
