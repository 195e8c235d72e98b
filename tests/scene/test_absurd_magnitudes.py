"""Moduli, loads and interface stiffnesses beyond what the model or double precision can take (issue 35's audit):
each is refused before anything is solved or written, naming the key, the value and the bound of
:mod:`ngcontact.scene.magnitudes` (exit 2), where it used to end in a solver failure (exit 3) naming no input.
``run_bad`` (:mod:`tests.scene.test_bad_input`) runs ``ngcontact run --out D`` and ``ngcontact check`` and asserts
the one-line message, exit 2 and that neither ``D`` nor any other file appeared."""
import os

import pytest

from ngcontact.scene import magnitudes

from sinusoid_cell import sinusoid_cell
from test_bad_input import MACRO, edit, run_bad

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CELLS = {"spectral": sinusoid_cell(discretization='method = "spectral"\ngrid = 64'),
         "fe": sinusoid_cell(enforcement="penalty", discretization="order = 1\nmaxh = 0.5")}
MODULUS = "must lie in [1e-20, 1e+20]: choose a stress unit (e.g. Pa, MPa or GPa) in which the bodies' moduli fall " \
          "in that range"


def strained(E: str, strain: str) -> str:
    return (f"strains the softer body (materials.solid, E = {E}) by {strain}; a load must stay below a strain of 1, "
            f"i.e. at most {E} in magnitude (a body compressed by its own size; linear elasticity holds to about "
            "0.05): check the load and the units")


def read(*parts: str) -> str:
    with open(os.path.join(ROOT, *parts)) as f:
        return f.read()


@pytest.mark.parametrize("E", ["1e-308", "1e300"])
@pytest.mark.parametrize("method", ["spectral", "fe"])
def test_a_cell_modulus_beyond_any_stress_unit(tmp_path, capsys, E, method):
    """Was: spectral, exit 3 ('non-finite number inf at report.results.loads[0].far_face_jump[1]'; 1e300:
    'constrained CG: the complementarity residual nan'); FE, exit 2 blaming contact.k_n ('k_n h / E = inf')
    or exit 3 ('the tangent solve gave non-finite values')."""
    run_bad(tmp_path, capsys, edit(CELLS[method], ("E = 1.0", f"E = {E}")), f"materials.solid.E = {float(E)!r}: {MODULUS}")


@pytest.mark.parametrize("method", ["spectral", "fe"])
def test_a_cell_pressure_beyond_the_modulus(tmp_path, capsys, method):
    """Was: spectral, exit 0 with a far-face strain of 1e300 (warned); the bound is the strain that compresses
    the body by its own size."""
    run_bad(tmp_path, capsys, edit(CELLS[method], ("pressure = [0.005]", "pressure = [0.005, 1e300]")),
            f"load.pressure[1] = 1e+300: {strained('1', '1e+300')}")


def test_a_cell_shear_beyond_the_modulus(tmp_path, capsys):
    text = edit(sinusoid_cell(friction="coulomb", discretization='method = "spectral"\ngrid = 64'),
                ('friction = "coulomb"', 'friction = "coulomb"\nmu = 0.3'),
                ("pressure = [0.005]", "pressure = [0.005]\nshear = [-3.0]"))
    run_bad(tmp_path, capsys, text, f"load.shear[0] = -3.0: {strained('1', '3')}")


@pytest.mark.parametrize("method", ["spectral", "fe"])
def test_a_prescribed_jump_beyond_the_cell_height(tmp_path, capsys, method):
    run_bad(tmp_path, capsys, edit(CELLS[method], ("pressure = [0.005]", "normal_jump = [0.01, 2.5]")),
            "load.normal_jump[1] = 2.5: over the cell's height h_rough + h_counter = 2 is a mean strain of 1.25; a "
            "prescribed jump must stay below a strain of 1, i.e. at most 2 in magnitude (the bodies compressed by "
            "their own height)")


def test_a_macro_strain_of_a_cell_beyond_one(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELLS["spectral"], ("pressure = [0.005]", "pressure = [0.005]\nmacro_strain = "
                                                                             "[-1.5]")),
            "load.macro_strain[0] = -1.5: a strain must stay below 1 in magnitude (a body stretched or compressed "
            "by its own size)")


@pytest.mark.parametrize("method", ["spectral", "fe"])
def test_moduli_of_the_two_bodies_beyond_double_precision(tmp_path, capsys, method):
    text = edit(CELLS[method], ("E = 1.0\nnu = 0.3\n", "E = 1.0\nnu = 0.3\n[materials.hard]\nE = 1e11\nnu = 0.3\n"),
                ('counter = "solid"', 'counter = "hard"'))
    run_bad(tmp_path, capsys, text, "materials.hard = 'E = 1e+11': 1e+11 times the modulus of materials.solid (1); "
            "the bodies' moduli may differ by at most a factor 1e+10, beyond which the softer body's response is "
            "lost in the round-off of the stiffer one's (double precision); model the stiffer body as rigid (a "
            "support) or bring the moduli closer")


STEEL = strained("2.1e+11", "{}").replace("materials.solid", "materials.steel")


@pytest.mark.parametrize("line, key, shown, strain", [
    ("pressure = 1e300", "loads[0].pressure", "1e+300", "4.76e+288"),
    ("pressure = -3e11", "loads[0].pressure", "-300000000000.0", "1.43"),
    ("pressure = 0.0\ntraction = [3e11, -3e11]", "loads[0].traction", "[300000000000.0, -300000000000.0]", "2.02")])
def test_a_macro_load_beyond_the_modulus(tmp_path, capsys, line, key, shown, strain):
    """Was: exit 3, 'solver failed: the start value gives a non-finite energy or residual' (1e300 Pa)."""
    run_bad(tmp_path, capsys, edit(MACRO, ("pressure = 10e6", line)), f"{key} = {shown}: {STEEL.format(strain)}")


def test_a_macro_body_force_beyond_the_modulus(tmp_path, capsys):
    """A force density over the bodies' smallest width (5 mm here) is the stress held against the modulus."""
    run_bad(tmp_path, capsys, edit(MACRO, ("[discretization]", "[body_forces]\nrough = [0.0, -1e14]\n\n"
                                                               "[discretization]")),
            "body_forces.rough = [0.0, -100000000000000.0]: strains the softer body (materials.steel, E = 2.1e+11) by 2.38; a "
            "load must stay below a strain of 1, i.e. at most E / 0.005 = 4.2e+13 (over the bodies' smallest width) "
            "in magnitude (a body compressed by its own size; linear elasticity holds to about 0.05): check the load "
            "and the units")


def test_a_refused_scene_leaves_an_earlier_output_directory_as_it_was(tmp_path, capsys):
    """``ngcontact run bad.toml --out D`` with D holding an earlier run's output: exit 2, D byte for byte as it was."""
    from ngcontact import cli
    good, scene, out = tmp_path / "good.toml", tmp_path / "bad.toml", tmp_path / "D"
    good.write_text(MACRO)
    assert cli.main(["run", str(good), "--out", str(out), "--quiet"]) == 0
    scene.write_text(edit(MACRO, ("pressure = 10e6", "pressure = 1e300")))
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert "report.json" in before
    assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 2
    assert "loads[0].pressure = 1e+300: strains the softer body" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_a_macro_modulus_beyond_any_stress_unit(tmp_path, capsys):
    """Was: exit 3, 'the linear solve gave non-finite values: the system is singular'."""
    run_bad(tmp_path, capsys, edit(MACRO, ("E = 210e9", "E = 1e-308")), f"materials.steel.E = 1e-308: {MODULUS}")


def test_an_anisotropic_modulus_beyond_any_stress_unit(tmp_path, capsys):
    C = [[0.0] * 6 for _ in range(6)]
    for i in range(3):
        C[i][i] = 3e300
    for i in range(3, 6):
        C[i][i] = 1e300
    text = edit(MACRO, ("E = 210e9\nnu = 0.3", f"C = {C}".replace("e+300", "e300")))
    run_bad(tmp_path, capsys, text, "materials.steel.C = [[3e+300, 0.0, 0.0, 0.0, 0.0, 0.0], ", prefix=True)
    assert magnitudes.young_moduli(type("M", (), {"C": C, "E": None})()) == pytest.approx((3e300, 3e300))


@pytest.mark.parametrize("line, key, shown, ratio", [
    ("kn = 1e300", "interface.kn", "1e+300", "4.76e+286"),
    ("kn = 1e-300", "interface.kn", "1e-300", "4.76e-314")])
def test_a_macro_penalty_beyond_double_precision(tmp_path, capsys, line, key, shown, ratio):
    """Was: exit 3, 'the start value gives a non-finite energy or residual' (kn = 1e300)."""
    text = edit(MACRO, ("kn = 1e12", line))
    bound = ("must stay below 1e+10: the penalty would outweigh the bodies beyond what double precision resolves; "
             "lower kn") if "e300" in line else ("must be at least 1e-08: the interface would hold nothing and the "
                                                 "jump would dwarf the bodies; raise kn")
    run_bad(tmp_path, capsys, text, f"{key} = {shown}: kn h / E = {ratio} (h = 0.01 the interface mesh size, "
            f"E = 2.1e+11 the softer body's modulus) {bound}")


def test_a_bundle_or_table_stiffer_than_double_precision(tmp_path, capsys):
    bundle = edit(MACRO, ('law = "linear"\nkn = 1e12\nkt = 1e11', 'law = "bundle"\nweights = [1e300, 1e300]\n'
                                                                  'directions = [[1.0, 0.0], [0.0, 1.0]]'))
    run_bad(tmp_path, capsys, bundle, "interface.weights = [1e+300, 1e+300]: sum(weights) = 2e+300, sum(weights) h / "
            "E = 9.52e+286 (h = 0.01 ", prefix=True)
    table = edit(MACRO, ('law = "linear"\nkn = 1e12\nkt = 1e11', 'law = "tabulated"\nclosure = [0.0, 1e-6, 2e-6]\n'
                                                                 'pressure = [0.0, 1e6, 1e300]'))
    run_bad(tmp_path, capsys, table, "interface.pressure = [0.0, 1000000.0, 1e+300]: dp/dc = 1e+306, dp/dc h / E = ",
            prefix=True)


CELL_LAW = edit(read("geometries", "macro", "block_on_sawtooth.toml"), ("pressure = 10e6", "pressure = 1e6"))


def test_a_law_from_a_cell_whose_penalty_is_beyond_double_precision(tmp_path, capsys):
    """The bundle's weights are the cell's k_n (times the surface's share): an override of 1e300 in the macro
    scene, or the cell's own k_n, is named where it was written."""
    cell = read("geometries", "macro", "sawtooth_cell.toml")
    files = {"sawtooth_cell.toml": cell}
    run_bad(tmp_path, capsys, edit(CELL_LAW, ("cell_length_unit = 1e-4", "cell_length_unit = 1e-4\ncell_k_n = 1e300")),
            "interface.cell_k_n = 1e+300: the cell's k_n h / E = 1.19e+286 (h = 0.0025 the interface mesh size, "
            "E = 2.1e+11 the softer body's modulus) must stay below 1e+10: the penalty would outweigh the bodies "
            "beyond what double precision resolves; lower the cell's k_n", files=files)
    run_bad(tmp_path, capsys, CELL_LAW, "interface.cell = 'sawtooth_cell.toml': the cell's k_n = 1e+300, ", prefix=True,
            files={"sawtooth_cell.toml": edit(cell, ("k_n = 1e12", "k_n = 1e300"))})


TWO_SCALE = read("geometries", "femur_stem_two_scale.toml").replace('cell = "cells/', 'cell = "')
TWO_SCALE_FILES = {"stem_grooves.toml": read("geometries", "cells", "stem_grooves.toml"),
                   "hip_hills.toml": read("geometries", "cells", "hip_hills.toml")}


def test_a_two_scale_scene_with_a_load_beyond_the_modulus(tmp_path, capsys):
    text = edit(TWO_SCALE, ("pressure = 1e6 ", "pressure = 1e300 "))
    run_bad(tmp_path, capsys, text, "loads[0].pressure = 1e+300: strains the softer body (materials.bone, E = 9e+09) "
            "by 1.11e+290; ", prefix=True, files=TWO_SCALE_FILES)


def test_a_two_scale_cell_modulus_beyond_any_stress_unit(tmp_path, capsys):
    files = dict(TWO_SCALE_FILES, **{"stem_grooves.toml": edit(TWO_SCALE_FILES["stem_grooves.toml"],
                                                               ("E = 9e9 ", "E = 1e-308 "))})
    run_bad(tmp_path, capsys, TWO_SCALE, f"two_scale.cell = 'stem_grooves.toml': invalid cell scene: "
            f"materials.bone.E = 1e-308: {MODULUS}", files=files)


RESOLVED = read("geometries", "direct", "femur_stem_grooves.toml")
RESOLVED_FILES = {"stem_grooves_cell.toml": read("geometries", "direct", "stem_grooves_cell.toml")}


def test_a_resolved_scene_with_a_load_or_penalty_beyond_its_bounds(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(RESOLVED, ("pressure = 1e6 ", "pressure = 1e300 ")),
            "loads[0].pressure = 1e+300: strains the softer body (materials.bone, E = 9e+09) by 1.11e+290; ",
            prefix=True, files=RESOLVED_FILES)
    cell = edit(RESOLVED_FILES["stem_grooves_cell.toml"], ("k_n = 32e9", "k_n = 1e300"))
    run_bad(tmp_path, capsys, RESOLVED, "geometry.cell = 'stem_grooves_cell.toml': the cell's k_n = 1e+300, the "
            "cell's k_n h / E = ", prefix=True, files={"stem_grooves_cell.toml": cell})


def test_every_shipped_scene_is_within_the_bounds():
    """The bounds refuse no shipped scene (geometries/, with the cells they name)."""
    import glob

    import ngcontact
    scenes = glob.glob(os.path.join(ROOT, "geometries", "*.toml")) + glob.glob(os.path.join(ROOT, "geometries",
                                                                                           "*", "*.toml"))
    assert len(scenes) > 30
    for path in scenes:
        ngcontact.load(path)
