"""Bad input: every case ends with exit status 2, one line on stderr, nothing written.

Each case is a small scene written into ``tmp_path`` (derived from a flat
cell, a macro block or a shipped scene) and run through the real command
line, ``ngcontact run SCENE --out DIR`` (and ``check`` where the case is
about the scene alone).  The message is checked exactly, or by an exact
prefix where its tail lists many keys; it always has the form
``path = value: what is allowed``.
"""
import os

import numpy as np
import pytest

from ngcontact import cli

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CELLS = os.path.join(ROOT, "geometries", "cells")

CELL = """\
kind = "cell"

[materials.solid]
E = 1.0
nu = 0.3

[bodies]
rough = "solid"
counter = "solid"

[geometry]
profile = "flat"

[contact]
k_n = 1.0e3
{contact}

[load]
pressure = [0.01]

[discretization]
order = 1
maxh = 0.5

[solver]
rtol = 1e-10
"""

MACRO = """\
kind = "macro"

[materials.steel]
E = 210e9
nu = 0.3

[bodies]
rough = "steel"
counter = "steel"

[geometry]
shape = "block"
setting = "plane_strain"

[geometry.dimensions]
length = 0.02
h_block = 0.005
h_base = 0.005

[interface]
law = "linear"
kn = 1e12
kt = 1e11

[[supports]]
boundary = "bottom"

[[loads]]
boundary = "top"
pressure = 10e6

[discretization]
order = 1
maxh = 0.01
"""


def edit(text: str, *pairs) -> str:
    """``text`` with each ``(old, new)`` substituted once; ``old`` must occur."""
    for old, new in pairs:
        assert old in text, old
        text = text.replace(old, new, 1)
    return text


def run_bad(tmp_path, capsys, text, expected, *, prefix=False, commands=("run", "check"), files=None):
    """Write ``text`` as a scene, run it, and check exit 2, the one-line message and no output."""
    work = tmp_path / "work"
    work.mkdir(exist_ok=True)
    for name, content in (files or {}).items():
        target = work / name
        if isinstance(content, np.ndarray):
            np.save(target, content)
        else:
            target.write_text(content)
    scene = work / "scene.toml"
    scene.write_text(text)
    before = sorted(os.listdir(tmp_path)), sorted(os.listdir(work))
    out = tmp_path / "out"
    for command in commands:
        argv = ["run", str(scene), "--out", str(out), "--quiet"] if command == "run" else ["check", str(scene)]
        assert cli.main(argv) == 2, command
        captured = capsys.readouterr()
        err = captured.err
        assert err.endswith("\n") and err.count("\n") == 1, err
        message = err.rstrip("\n")
        want = f"ngcontact: error: {scene}: {expected}"
        if prefix:
            assert message.startswith(want), message
        else:
            assert message == want, message
        assert not out.exists()
        assert (sorted(os.listdir(tmp_path)), sorted(os.listdir(work))) == before


# ------------------------------------------------------------- materials
@pytest.mark.parametrize("E, shown", [("0.0", "0.0"), ("-2.0e9", "-2000000000.0")])
def test_young_modulus_must_be_positive(tmp_path, capsys, E, shown):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("E = 1.0", f"E = {E}")),
            f"materials.solid.E = {shown}: must be > 0")


@pytest.mark.parametrize("nu", ["0.5", "-1.0", "0.7"])
def test_poisson_ratio_must_lie_in_the_open_interval(tmp_path, capsys, nu):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("nu = 0.3", f"nu = {nu}")),
            f"materials.solid.nu = {float(nu)!r}: must lie in (-1, 0.5)")


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_non_finite_material_constant(tmp_path, capsys, value):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("E = 1.0", f"E = {value}")),
            f"materials.solid.E = {float(value)!r}: must be a finite number")


def test_non_finite_entry_of_a_load_sweep_names_its_index(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("pressure = [0.01]", "pressure = [0.01, nan]")),
            "load.pressure[1] = nan: must be a finite number")


def test_non_finite_macro_traction(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(MACRO, ("pressure = 10e6", "pressure = 10e6\ntraction = [inf, 0.0]")),
            "loads[0].traction[0] = inf: must be a finite number")


def test_a_string_where_a_number_is_asked(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("E = 1.0", 'E = "stiff"')),
            "materials.solid.E = 'stiff': must be a number")


def test_a_body_names_an_undefined_material(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ('counter = "solid"', 'counter = "steel"')),
            "bodies.counter = 'steel': must name a material defined under [materials]: solid")


# --------------------------------------------------------- contact laws
def test_negative_penalty(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("k_n = 1.0e3", "k_n = -1.0e3")),
            "contact.k_n = -1000.0: must be > 0")


def test_negative_coulomb_coefficient(tmp_path, capsys):
    text = CELL.format(contact='friction = "coulomb"\nmu = -0.2\nw = 1e-6')
    run_bad(tmp_path, capsys, text, "contact.mu = -0.2: must be >= 0")


def test_negative_tresca_threshold(tmp_path, capsys):
    text = CELL.format(contact='friction = "tresca"\nG = -1.0\nw = 1e-6')
    run_bad(tmp_path, capsys, text, "contact.G = -1.0: must be >= 0")


@pytest.mark.parametrize("w", ["0.0", "-1e-6"])
def test_regularization_width_must_be_positive(tmp_path, capsys, w):
    text = CELL.format(contact=f'friction = "tresca"\nG = 1.0\nw = {w}')
    run_bad(tmp_path, capsys, text, f"contact.w = {float(w)!r}: must be > 0")


def test_negative_macro_threshold_and_huber_width(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(MACRO, ("kt = 1e11", "kt = 1e11\nthreshold = -1e6")),
            "interface.threshold = -1000000.0: must be >= 0")
    run_bad(tmp_path, capsys, edit(MACRO, ("kt = 1e11", "kt = 1e11\nhuber_width = 0.0")),
            "interface.huber_width = 0.0: must be > 0")


def test_coefficient_not_used_by_tresca(tmp_path, capsys):
    text = CELL.format(contact='friction = "tresca"\nG = 1.0\nmu = 0.3\nw = 1e-6')
    run_bad(tmp_path, capsys, text, "contact.mu = 0.3: not used by friction = 'tresca'; remove it")


def test_threshold_not_used_by_coulomb(tmp_path, capsys):
    text = CELL.format(contact='friction = "coulomb"\nG = 1.0\nmu = 0.3\nw = 1e-6')
    run_bad(tmp_path, capsys, text, "contact.G = 1.0: not used by friction = 'coulomb'; remove it")


def test_width_without_friction(tmp_path, capsys):
    run_bad(tmp_path, capsys, CELL.format(contact="w = 1e-6"),
            "contact.w = 1e-06: not used by friction = 'none'; remove it")


def test_macro_law_parameter_not_used(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(MACRO, ("kt = 1e11", "kt = 1e11\nweights = [1e12]")),
            "interface.weights = [1000000000000.0]: not used by law = 'linear'; remove it")


# -------------------------------------------------------------- profiles
def test_profile_key_the_profile_does_not_use(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ('profile = "flat"', 'profile = "sinusoid"\namplitude = 0.05\nradius = 0.1'))
    run_bad(tmp_path, capsys, text, "geometry.radius = 0.1: not used by profile = 'sinusoid'; remove it")


def test_profile_key_missing(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ('profile = "flat"', 'profile = "semicircular"'))
    run_bad(tmp_path, capsys, text, "geometry.radius = <missing>: required for profile = 'semicircular'")


def test_sinusoid_amplitude_reaching_the_cell_height(tmp_path, capsys):
    # valley depth 2 A = 0.6 = h_rough: the roughness would cut the rough body through
    text = edit(CELL.format(contact=""),
                ('profile = "flat"', 'profile = "sinusoid"\namplitude = 0.3\nh_rough = 0.6'))
    run_bad(tmp_path, capsys, text,
            "geometry.h_rough = 0.6: must exceed the profile depth 0.6 (the roughness must lie inside "
            "the rough body)")


def test_rectangular_valley_as_wide_as_the_period(tmp_path, capsys):
    text = edit(CELL.format(contact=""),
                ('profile = "flat"', 'profile = "rectangular"\nwidth = 1.0\ndepth = 0.2'))
    run_bad(tmp_path, capsys, text, "geometry.width = 1.0: must be < period = 1.0 (plateaus must remain)")


def test_triangular_face_angle_of_90_degrees(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ('profile = "flat"', 'profile = "triangular"\nangles = [30.0, 90.0]'))
    run_bad(tmp_path, capsys, text, "geometry.angles = [30.0, 90.0]: must lie in (0, 90)", prefix=True)


TAB = edit(CELL.format(contact=""), ('profile = "flat"', 'profile = "tabulated"\nfile = "p.csv"\nh_rough = 0.6'))


def test_tabulated_profile_that_is_not_periodic(tmp_path, capsys):
    run_bad(tmp_path, capsys, TAB,
            "geometry.file (p.csv)[line 4].y = -0.02: the profile must be periodic: the last row is x = period "
            "and repeats the first, y(period) = y(0) = 0.0 within 1e-09",
            files={"p.csv": "x,y\n0,0\n0.5,-0.1\n1.0,-0.02\n"})


def test_tabulated_profile_with_a_non_finite_value(tmp_path, capsys):
    run_bad(tmp_path, capsys, TAB, "geometry.file (p.csv)[line 3] = [0.5, nan]: x and y must be finite numbers",
            files={"p.csv": "x,y\n0,0\n0.5,nan\n1.0,0\n"})


def test_tabulated_profile_with_three_columns(tmp_path, capsys):
    run_bad(tmp_path, capsys, TAB,
            "geometry.file (p.csv)[line 3] = '3 columns': each row must have exactly two columns x, y",
            files={"p.csv": "x,y\n0,0\n0.5,-0.1,7\n1.0,0\n"})


def test_tabulated_profile_deeper_than_the_rough_body(tmp_path, capsys):
    run_bad(tmp_path, capsys, TAB,
            "geometry.file = 'p.csv': the profile height 0.7 must stay below h_rough and h_counter",
            files={"p.csv": "x,y\n0,0\n0.5,-0.7\n1.0,0\n"})


def test_missing_profile_file(tmp_path, capsys):
    where = tmp_path / "work" / "p.csv"
    run_bad(tmp_path, capsys, TAB,
            f"geometry.file (p.csv) = '{where}': must be a readable CSV file (No such file or directory)")


HMAP = edit(CELL.format(contact=""),
            ('profile = "flat"', 'profile = "height_map"\nfile = "h.npy"\narrangement = "summit"'),
            ("maxh = 0.5", "maxh = 0.5\ninterface_maxh = 0.25"))


def test_height_map_of_the_wrong_shape(tmp_path, capsys):
    run_bad(tmp_path, capsys, HMAP,
            "geometry.file (h.npy) = 'array of shape (5,)': must be a 2D array with at least 3 samples per "
            "direction (last row/column repeating the first)", files={"h.npy": np.zeros(5)})


def test_height_map_with_a_non_finite_value(tmp_path, capsys):
    H = np.zeros((4, 4))
    H[1, 2] = np.inf
    run_bad(tmp_path, capsys, HMAP, "geometry.file (h.npy)[1, 2] = inf: heights must be finite",
            files={"h.npy": H})


def test_height_map_that_is_not_periodic(tmp_path, capsys):
    H = np.zeros((4, 4))
    H[-1, 1] = 0.01
    run_bad(tmp_path, capsys, HMAP,
            "geometry.file (h.npy)[last row] = 0.01: the map must be periodic: the last row must repeat "
            "the first (entry 1: 0.0) within 1e-09", files={"h.npy": H})


# ------------------------------------------------------------------ keys
def test_unknown_top_level_section(tmp_path, capsys):
    text = CELL.format(contact="").replace("[solver]", "[solvr]")
    run_bad(tmp_path, capsys, text, "solvr = {rtol}: unknown key; allowed keys here are bodies, compute, contact, "
            "discretization, ensemble, geometry, kind, load, materials, solver, title")


def test_misspelled_key_in_a_section(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ("rtol = 1e-10", "r_tol = 1e-10"))
    run_bad(tmp_path, capsys, text, "solver.r_tol = 1e-10: unknown key; allowed keys here are atol, cg_max_iter, "
            "coulomb, coulomb_max_iter, coulomb_rtol, inverse, iterative_from, linear, max_iter, rtol, start")


def test_misspelled_material_constant(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ("nu = 0.3", "Nu = 0.3"))
    run_bad(tmp_path, capsys, text, "materials.solid.Nu = 0.3: unknown key; allowed keys here are C, E, nu, sigma_u")


def test_misspelled_key_of_an_array_of_tables(tmp_path, capsys):
    text = edit(MACRO, ('boundary = "bottom"', 'boundry = "bottom"'))
    run_bad(tmp_path, capsys, text,
            "supports[0].boundry = 'bottom': unknown key; allowed keys here are G, boundary, components, "
            "displacement, slope, symmetry, u0")


def test_unknown_kind(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ('kind = "cell"', 'kind = "cells"')),
            "kind = 'cells': must be one of 'cell', 'direct', 'macro', 'manufactured'")


def test_scene_that_is_not_toml(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("E = 1.0", "E = 1.0 GPa")),
            f"<scene file> = '{tmp_path / 'work' / 'scene.toml'}': not valid TOML", prefix=True)


def test_missing_scene_file(tmp_path, capsys):
    missing = tmp_path / "nowhere.toml"
    for argv in (["run", str(missing), "--out", str(tmp_path / "out")], ["check", str(missing)]):
        assert cli.main(argv) == 2
        assert capsys.readouterr().err == (f"ngcontact: error: {missing}: <scene file> = '{missing}': "
                                           "no such file\n")
    assert os.listdir(tmp_path) == []


# ------------------------------------------------------- labels and files
def test_macro_support_on_a_boundary_that_does_not_exist(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(MACRO, ('boundary = "bottom"', 'boundary = "floor"')),
            "supports[0].boundary = 'floor': no such boundary in 'block' (plane_strain); labels are "
            "base_sides, block_sides, bottom, interface, top")


def test_macro_load_on_a_boundary_that_does_not_exist(tmp_path, capsys):
    text = MACRO.replace('shape = "block"\nsetting = "plane_strain"', 'shape = "coaxial"\nsetting = "plane_strain"')
    text = edit(text, ("length = 0.02\nh_block = 0.005\nh_base = 0.005", "a = 0.01\nb = 0.02\nc = 0.03"),
                ('boundary = "bottom"', 'boundary = "sym_x"\ncomponents = ["x"]'),
                ('boundary = "top"', 'boundary = "top"'))
    run_bad(tmp_path, capsys, text, "loads[0].boundary = 'top': no such boundary in 'coaxial' (plane_strain); "
            "labels are bore, interface, mantle, sym_x, sym_y")


def test_missing_cell_scene_of_a_macro_scene(tmp_path, capsys):
    text = edit(MACRO, ('law = "linear"\nkn = 1e12\nkt = 1e11', 'cell = "no_cell.toml"'))
    run_bad(tmp_path, capsys, text, "interface.cell = 'no_cell.toml': no such cell scene file")


def test_macro_scene_whose_cell_scene_is_invalid(tmp_path, capsys):
    bad_cell = open(os.path.join(ROOT, "geometries", "macro", "sawtooth_cell.toml")).read()
    bad_cell = edit(bad_cell, ("nu = 0.3", "nu = 0.6"))
    text = edit(MACRO, ('law = "linear"\nkn = 1e12\nkt = 1e11', 'cell = "cell.toml"'))
    run_bad(tmp_path, capsys, text,
            "interface.cell = 'cell.toml': invalid cell scene: materials.steel.nu = 0.6: must lie in (-1, 0.5)",
            files={"cell.toml": bad_cell})


def test_two_scale_cell_of_another_kind(tmp_path, capsys):
    text = MACRO + '\n[two_scale]\ncell = "other.toml"\ntol = 1e3\n'
    run_bad(tmp_path, capsys, text, "two_scale.cell = 'other.toml': invalid cell scene: must be of kind 'cell', "
            "not 'macro'", files={"other.toml": MACRO})


def test_unwritable_output_directory(tmp_path, capsys):
    scene = tmp_path / "scene.toml"
    scene.write_text(CELL.format(contact=""))
    blocker = tmp_path / "plain_file"
    blocker.write_text("keep me")
    for out in (blocker, blocker / "below"):
        assert cli.main(["run", str(scene), "--out", str(out), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1
        if out == blocker:
            assert err == f"ngcontact: error: --out {out}: exists and is not a directory\n"
        else:
            assert err == f"ngcontact: error: --out {out}: cannot write in {blocker}\n"
    assert sorted(os.listdir(tmp_path)) == ["plain_file", "scene.toml"]
    assert blocker.read_text() == "keep me"


# --------------------------------------------------- numerics settings
def test_polynomial_order_below_one(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("order = 1", "order = 0")),
            "discretization.order = 0: must lie in [1, 10]")


def test_boolean_is_not_an_order(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("order = 1", "order = true")),
            "discretization.order = True: must be an integer")


@pytest.mark.parametrize("key, value, allowed", [("rtol", "0.0", "must be > 0"), ("rtol", "-1e-8", "must be > 0"),
                                                ("max_iter", "0", "must be >= 1"), ("atol", "-1.0", "must be >= 0")])
def test_solver_tolerances_and_limits(tmp_path, capsys, key, value, allowed):
    text = edit(CELL.format(contact=""), ("rtol = 1e-10", f"{key} = {value}"))
    shown = value if key == "max_iter" else repr(float(value))
    run_bad(tmp_path, capsys, text, f"solver.{key} = {shown}: {allowed}")


def test_non_positive_mesh_size(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("maxh = 0.5", "maxh = 0.0")),
            "discretization.maxh = 0.0: must be > 0")


def test_two_scale_tolerance_and_iteration_limit(tmp_path, capsys):
    cell_text = open(os.path.join(ROOT, "geometries", "macro", "sawtooth_cell.toml")).read()
    base = MACRO + '\n[two_scale]\ncell = "cell.toml"\ntol = 1e3\n'
    run_bad(tmp_path, capsys, edit(base, ("tol = 1e3", "tol = 0.0")), "two_scale.tol = 0.0: must be > 0",
            files={"cell.toml": cell_text})
    run_bad(tmp_path, capsys, edit(base, ("tol = 1e3", "tol = 1e3\nmax_iter = 0")),
            "two_scale.max_iter = 0: must be >= 1", files={"cell.toml": cell_text})
    run_bad(tmp_path, capsys, edit(base, ("tol = 1e3", "tol = 1e3\nmax_cell_solves = 0")),
            "two_scale.max_cell_solves = 0: must be >= 1", files={"cell.toml": cell_text})


def test_strength_check_without_ultimate_stress(tmp_path, capsys):
    cell_text = open(os.path.join(ROOT, "geometries", "macro", "sawtooth_cell.toml")).read()
    text = MACRO + '\n[strength]\ncell = "cell.toml"\n'
    run_bad(tmp_path, capsys, text,
            "materials.steel.sigma_u = <missing>: the ultimate stress of the rough body is required by "
            "[strength]; a number > 0 [Pa]", files={"cell.toml": cell_text})


def test_load_sweeps_of_unequal_length(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ("pressure = [0.01]", "pressure = [0.01, 0.02]\nshear = [0.0, 0.1, 0.2]"))
    run_bad(tmp_path, capsys, text,
            "load.shear = [0.0, 0.1, 0.2]: makes 3 loads but load.pressure has 2; sweeps need equal lengths "
            "or length 1")


def test_both_pressure_and_normal_jump(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ("pressure = [0.01]", "pressure = [0.01]\nnormal_jump = [0.001]"))
    run_bad(tmp_path, capsys, text, "load.pressure = [0.01]: give exactly one of pressure and normal_jump")


def test_boundary_table_matches_the_meshed_geometries():
    """The labels checked without meshing are exactly those the meshers create."""
    from ngcontact.geometry import bodies as gm
    from ngcontact.geometry.femur import FemurStemDims, femur_stem
    from ngcontact.scene.macro_shapes import BOUNDARIES
    from ngcontact.macro.macro_problem import boundary_labels
    from ngcontact.geometry.femur3d import femur_stem_3d
    built = {("femur_stem", "axisymmetric"): femur_stem(FemurStemDims(), maxh=0.02),
             ("femur_stem", "3d"): femur_stem_3d(FemurStemDims(), maxh=0.03, order=1),
             ("coaxial", "plane_strain"): gm.coaxial_plane_strain(1.0, 2.0, 3.0, maxh=1.0),
             ("coaxial", "axisymmetric"): gm.coaxial_axisymmetric(1.0, 2.0, 3.0, 1.0, maxh=1.0),
             ("coaxial", "3d"): gm.coaxial_3d(1.0, 2.0, 3.0, 1.0, maxh=1.0),
             ("block", "plane_strain"): gm.block_on_plane(2.0, 1.0, 1.0, maxh=1.0)}
    assert set(built) == set(BOUNDARIES)
    for key, geometry in built.items():
        assert tuple(sorted(boundary_labels(geometry.mesh))) == BOUNDARIES[key], key


@pytest.mark.parametrize("key", ["shear", "tangential_jump"])
def test_shear_on_a_frictionless_flat_interface(tmp_path, capsys, key):
    """Found here: this was a ValueError from the solver (exit 3) after meshing."""
    text = edit(CELL.format(contact=""), ("pressure = [0.01]", f"pressure = [0.01]\n{key} = [0.0, 0.001]"))
    run_bad(tmp_path, capsys, text, f"load.{key} = [0.0, 0.001]: a frictionless flat contact surface carries "
            "no shear and fixes no tangential jump: give 0 or set contact.friction")


# ------------------------------------------------------------- hostile data files
def test_a_fifo_as_profile_file_is_refused_without_reading_it(tmp_path, capsys):
    """Was: a FIFO as profile or height map hung 'run' and 'check' alike."""
    work = tmp_path / "work"
    work.mkdir()
    os.mkfifo(work / "p.csv")
    run_bad(tmp_path, capsys, TAB, f"geometry.file (p.csv) = '{work / 'p.csv'}': is a FIFO; must be a regular file "
            "(a CSV file)")


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_a_device_as_height_map_is_refused_without_reading_it(tmp_path, capsys, device):
    """Was: /dev/zero or /dev/urandom as a data file was read until memory ran out."""
    run_bad(tmp_path, capsys, HMAP.replace('file = "h.npy"', f'file = "{device}"'),
            f"geometry.file ({device}) = '{device}': is a character device; must be a regular file (a .npy array)")


def test_a_profile_of_a_hundred_thousand_rows_is_refused_before_meshing(tmp_path, capsys):
    """Was: a 1e5-row CSV profile hung the mesher."""
    rows = "".join(f"{i / 100000!r},0.0\n" for i in range(100001))
    run_bad(tmp_path, capsys, TAB, "geometry.file (p.csv) = '{}': has 100001 rows; a tabulated profile takes at "
            "most 4096 (each row is a segment of the mesh's geometry): resample it".format(tmp_path / "work" / "p.csv"),
            files={"p.csv": "x,y\n" + rows})


def test_a_utf16_profile_is_bad_input_not_a_solver_failure(tmp_path, capsys):
    """Was: exit 3 for a UTF-16 (or binary) CSV."""
    work = tmp_path / "work"
    work.mkdir()
    (work / "p.csv").write_bytes("x,y\n0,0\n0.5,-0.1\n1,0\n".encode("utf-16"))
    run_bad(tmp_path, capsys, TAB, f"geometry.file (p.csv) = '{work / 'p.csv'}': must be a text (UTF-8) CSV "
            "file with columns x, y")


def test_an_empty_npy_and_an_npz_archive_are_bad_input(tmp_path, capsys):
    """Was: exit 3 for an empty .npy."""
    work = tmp_path / "work"
    work.mkdir()
    (work / "h.npy").write_bytes(b"")
    run_bad(tmp_path, capsys, HMAP, f"geometry.file (h.npy) = '{work / 'h.npy'}': must be a readable .npy array "
            "(No data left in file)")
    np.savez(work / "a.npz", h=np.zeros((3, 3)))
    os.replace(work / "a.npz", work / "h.npy")
    run_bad(tmp_path, capsys, HMAP, f"geometry.file (h.npy) = '{work / 'h.npy'}': must be a single .npy array, "
            "not an .npz archive")


# ------------------------------------------------------------- values beyond what can run
def test_kind_that_is_not_a_string(tmp_path, capsys):
    """Was: exit 3 with 'unhashable type: list'."""
    run_bad(tmp_path, capsys, CELL.format(contact="").replace('kind = "cell"', 'kind = ["cell"]'),
            "kind = ['cell']: must be one of 'cell', 'direct', 'macro', 'manufactured'")


def test_a_scene_nested_too_deeply(tmp_path, capsys):
    """Was: RecursionError (exit 3)."""
    scene = tmp_path / "work" / "scene.toml"
    run_bad(tmp_path, capsys, 'kind = "cell"\nx = ' + "[" * 2000 + "]" * 2000 + "\n",
            f"<scene file> = '{scene}': nests arrays or tables too deeply to be a scene")


def test_a_utf16_scene(tmp_path, capsys):
    """Was: exit 3 for a UTF-16 scene file."""
    work = tmp_path / "work"
    work.mkdir()
    scene = work / "scene.toml"
    scene.write_bytes(CELL.format(contact="").encode("utf-16"))
    out = tmp_path / "out"
    for argv in (["check", str(scene)], ["run", str(scene), "--out", str(out), "--quiet"]):
        assert cli.main(argv) == 2
        assert capsys.readouterr().err == (f"ngcontact: error: {scene}: <scene file> = '{scene}': "
                                           "must be UTF-8 text (TOML)\n")
    assert not out.exists()


@pytest.mark.parametrize("order", ["100", "2147483648"])
def test_an_order_beyond_what_can_be_assembled(tmp_path, capsys, order):
    """Was: std::bad_alloc (order 100) and four pybind11 lines (order 2147483648), exit 3."""
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("order = 1", f"order = {order}")),
            f"discretization.order = {order}: must lie in [1, 10]")


def test_a_penalty_that_double_precision_cannot_resolve(tmp_path, capsys):
    """Was: numpy overflow warnings, then a solver failure (k_n = 1e308)."""
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("k_n = 1.0e3", "k_n = 1e308")),
            "contact.k_n = 1e+308: k_n h / E = 5e+307 (h = 0.5 the interface mesh size, E = 1 the softer "
            "body's modulus) must stay below 1e+10: the penalty would outweigh the bodies beyond what double "
            "precision resolves; lower k_n")


# ------------------------------------------------------------- sizes that would hang the mesher
def test_a_period_of_a_tenth_of_a_millimetre_in_a_cell_of_default_height(tmp_path, capsys):
    """Was: the likeliest real case (0.1 mm grooves, heights left at 1) hung the mesher."""
    text = edit(CELL.format(contact=""), ('profile = "flat"', 'profile = "flat"\nperiod = 1e-4'))
    run_bad(tmp_path, capsys, text, "geometry.period = 0.0001: the mesh would have about 4.1e+05 elements, more "
            "than discretization.max_elements = 300000; coarsen it (the bodies are 1e+04 periods high; the cell's "
            "boundary layer decays within a few periods, so h_rough and h_counter of 0.5 to 5 periods suffice), "
            "or raise discretization.max_elements if the machine can take it")


def test_a_tiny_mesh_size(tmp_path, capsys):
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("maxh = 0.5", "maxh = 0.001")),
            "discretization.maxh = 0.001: the mesh would have about 4.6e+06 elements, more than "
            "discretization.max_elements = 300000; coarsen it, or raise discretization.max_elements if the "
            "machine can take it")


def test_twenty_verification_levels(tmp_path, capsys):
    """Was: 20 levels of uniform refinement hung (now at most 8, and the finest mesh is estimated)."""
    text = open(os.path.join(ROOT, "geometries", "verify_3d.toml")).read()
    run_bad(tmp_path, capsys, edit(text, ("levels = 3", "levels = 20")),
            "manufactured.levels = 20: must lie in [3, 8]")
    run_bad(tmp_path, capsys, edit(text, ("levels = 3", "levels = 6")),
            "manufactured.levels = 6: the mesh would have about", prefix=True)


def test_the_element_estimate_follows_the_shipped_meshes():
    """The guard's estimate stays within a factor of three of the real element count of every shipped cell (the
    estimate is the period's: a symmetric quarter cell counts four times its elements)."""
    import glob

    import ngcontact
    from ngcontact.drivers.build import build_cell
    from ngcontact.scene import mesh_size

    for path in sorted(glob.glob(os.path.join(CELLS, "*.toml"))):
        sc = ngcontact.load(path)
        g, d = sc.geometry, sc.discretization
        P = g.period
        n = mesh_size.estimate(g.dim, P ** (g.dim - 1) * (g.h_rough + g.h_counter), d.maxh,
                               width=min(P, g.h_rough, g.h_counter), interface=P ** (g.dim - 1),
                               h_interface=d.interface_maxh)
        cell = build_cell(sc)
        actual = cell.mesh.ne * (4 if cell.symmetric else 1)
        assert actual / 3 <= n <= 3 * actual, (os.path.basename(path), n, actual)


def test_a_semicircle_that_leaves_no_plateau_or_no_arc(tmp_path, capsys):
    """Was: 'NgException: meshing failed' (exit 3) for radius 0.4999999 or 1e-9."""
    text = open(os.path.join(CELLS, "ex27_semicircular.toml")).read()
    run_bad(tmp_path, capsys, edit(text, ("radius = 0.3", "radius = 0.4999999")),
            "geometry.radius = 0.4999999: leaves a piece of the profile 1e-07 long, below 0.0001 of the period 1, "
            "which the mesher cannot resolve")
    run_bad(tmp_path, capsys, edit(text, ("radius = 0.3", "radius = 1e-9")),
            "geometry.radius = 1e-09: leaves a piece of the profile 1.41e-09 long, below 0.0001 of the period 1, "
            "which the mesher cannot resolve")


def test_a_tabulated_profile_above_the_counter_body_is_refused_by_check_too(tmp_path, capsys):
    """Was: 'check' accepted a tabulated profile above h_counter that 'run' then refused."""
    run_bad(tmp_path, capsys, TAB, "geometry.h_counter = 1.0: must exceed the profile height 1.2",
            files={"p.csv": "x,y\n0,1.0\n0.5,1.2\n1.0,1.0\n"})


@pytest.mark.parametrize("periods", [["3", "3", "3"], ["8", "4", "16"], ["4", "8"]])
def test_epsilon_study_levels_that_give_no_rate(tmp_path, capsys, periods):
    """Was: --periods 3 3 3 ran and reported meaningless rates."""
    scene = os.path.join(ROOT, "geometries", "direct", "block_rect_valleys.toml")
    assert cli.main(["study", "epsilon", scene, "--periods", *periods, "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert capsys.readouterr().err == (f"ngcontact: error: --periods {' '.join(periods)}: at least 3 increasing "
                                       "numbers N >= 1 (a rate needs three distinct levels)\n")
    assert not (tmp_path / "o").exists()


def test_a_support_that_contradicts_another_on_the_same_boundary(tmp_path, capsys):
    """Was: the second [[supports]] entry of a boundary was silently ignored."""
    text = edit(MACRO, ('[[supports]]\nboundary = "bottom"\n',
                        '[[supports]]\nboundary = "bottom"\n\n[[supports]]\nboundary = "bottom"\n'
                        'components = ["y"]\ndisplacement = [1e-5]\n'))
    run_bad(tmp_path, capsys, text, "supports[1] = 'bottom': fixes component 'y' of boundary 'bottom', which "
            "supports[0] fixes already; give each component of a boundary once")


def test_a_two_scale_table_minimum_outside_its_range_names_the_key(tmp_path, capsys):
    """Was: 'inadmissible model input: table range [2.6e13, 3.25e7]' without the key."""
    text = open(os.path.join(ROOT, "geometries", "femur_stem_two_scale.toml")).read()
    work = tmp_path / "work"
    work.mkdir()
    os.symlink(os.path.join(ROOT, "geometries", "cells"), work / "cells")
    run_bad(tmp_path, capsys, edit(text, ("table_min = 1e-3", "table_min = 1e6")),
            "two_scale.table_min = 1000000.0: must lie in (0, 1)")


COAXIAL = edit(MACRO, ('shape = "block"', 'shape = "coaxial"'),
               ("length = 0.02\nh_block = 0.005\nh_base = 0.005", "a = 0.01\nb = 0.02\nc = 0.03"),
               ("kt = 1e11", "gap = -1e-5"),
               ('[[supports]]\nboundary = "bottom"\n', '[[supports]]\nboundary = "sym_x"\ncomponents = ["x"]\n\n'
                '[[supports]]\nboundary = "sym_y"\ncomponents = ["y"]\n'),
               ('[[loads]]\nboundary = "top"\npressure = 10e6\n', ""),
               ("maxh = 0.01", "maxh = 0.004"))


def test_swapped_symmetry_supports_are_refused(tmp_path, capsys):
    """Was: sym_x fixed in y and sym_y in x ran and gave a mean pressure 10 % off, varying 4.4x around the ring."""
    text = edit(COAXIAL, ('boundary = "sym_x"\ncomponents = ["x"]', 'boundary = "sym_x"\ncomponents = ["y"]'),
                ('boundary = "sym_y"\ncomponents = ["y"]', 'boundary = "sym_y"\ncomponents = ["x"]'))
    run_bad(tmp_path, capsys, text, "supports[0].components = ['y']: 'sym_x' is the symmetry plane x = 0: fix only "
            "its normal component ['x'] there")


def test_a_translation_that_no_support_fixes(tmp_path, capsys):
    """Was: a base held only in x solved a singular system and reported 15 MPa under 10 MPa, 'converged'."""
    text = edit(MACRO, ('[[supports]]\nboundary = "bottom"\n', '[[supports]]\nboundary = "bottom"\ncomponents = ["x"]\n'))
    run_bad(tmp_path, capsys, text, "supports = ['bottom']: no support fixes component 'y': the bodies could "
            "translate freely in y (a singular system); fix y on some boundary")


def test_the_coaxial_quarter_with_its_symmetry_supports_runs(tmp_path, capsys):
    """The documented labels and components are accepted (the negative cases above are not vacuous)."""
    scene = tmp_path / "coaxial.toml"
    scene.write_text(COAXIAL)
    assert cli.main(["check", str(scene)]) == 0
    capsys.readouterr()


GAPTAB = CELL.format(contact='gap = { kind = "tabulated", file = "g.csv" }')


def test_a_gap_table_that_does_not_close_the_period_speaks_of_the_gap(tmp_path, capsys):
    """Was: a gap file's message spoke of 'y' and 'profile', and the closing row was documented nowhere."""
    run_bad(tmp_path, capsys, GAPTAB,
            "contact.gap.file (g.csv)[line 4].g = 0.002: the gap must be periodic: the last row is x = period "
            "and repeats the first, g(period) = g(0) = 0.001 within 1e-09",
            files={"g.csv": "x,g\n0,0.001\n0.5,0.0\n1.0,0.002\n"})


def test_messages_name_lines_and_never_repeat_a_file_s_content(tmp_path, capsys):
    """Was: a message echoed a line of an arbitrary file (a root-only one, run as root) and counted rows
    from 0 after the header."""
    run_bad(tmp_path, capsys, TAB, "geometry.file (p.csv)[line 3] = 'not two numbers': x and y must be numbers",
            files={"p.csv": "x,y\n0,0\nroot,secret-hash\n1,0\n"})
    run_bad(tmp_path, capsys, TAB, "geometry.file (p.csv)[line 3] = '1 column': each row must have exactly two "
            "columns x, y", files={"p.csv": "x,y\n0,0\nroot:x:0:0:root:/root:/bin/bash\n1,0\n"})


def test_a_gap_table_that_stops_short_of_the_interface(tmp_path, capsys):
    """Was: outside its rows the gap was silently held at the end values."""
    text = open(os.path.join(ROOT, "geometries", "femur_stem.toml")).read()
    work = tmp_path / "work"
    work.mkdir()
    os.symlink(os.path.join(ROOT, "geometries", "cells"), work / "cells")
    old = "gap_table = [[0.05, 20e-6], [0.09, 0.0], [0.13, -50e-6], [0.18, -50e-6]]"
    run_bad(tmp_path, capsys, edit(text, (old, "gap_table = [[0.07, 20e-6], [0.09, 0.0], [0.13, -50e-6]]")),
            "interface.gap_table = [[0.07, 2e-05], [0.09, 0.0], [0.13, -5e-05]]: covers z in [0.07, 0.13], but the "
            "interface spans [0.05, 0.18]; give rows that cover it (outside them the gap would be held at the end "
            "values)", commands=("run",))


@pytest.mark.parametrize("length", ["1e-15", "1e100"])
def test_a_cell_scaled_beyond_the_mesher_s_lengths(tmp_path, capsys, length):
    """Was: a segmentation fault (exit -11, no message) for a cell scaled to 1e-15, a hang or a crash at 1e100."""
    text = edit(CELL.format(contact=""), ('profile = "flat"', f'profile = "flat"\nperiod = {length}\nh_rough = {length}\n'
                                          f'h_counter = {length}'), ("maxh = 0.5", f"maxh = {length}"))
    run_bad(tmp_path, capsys, text, f"geometry.period = {float(length)!r}: must lie in [1e-09, 1e+09]: choose a "
            "length unit (e.g. mm or um) in which the geometry's sizes fall in that range")


def test_a_penalty_so_soft_that_the_interface_holds_nothing(tmp_path, capsys):
    """Was: k_n = 1e-300 on a flat cell 'converged' to a far-face jump of 1e298."""
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ("k_n = 1.0e3", "k_n = 1e-300")),
            "contact.k_n = 1e-300: k_n h / E = 5e-301 (h = 0.5 the interface mesh size, E = 1 the softer body's "
            "modulus) must be at least 1e-08: the interface would hold nothing and the jump would dwarf the "
            "bodies; raise k_n")


def test_a_rotation_that_no_support_removes_is_named(tmp_path, capsys):
    """A frictionless ring held only by its mantle (every translation fixed) could still rotate in its bore."""
    text = edit(COAXIAL, ('[[supports]]\nboundary = "sym_x"\ncomponents = ["x"]\n\n'
                          '[[supports]]\nboundary = "sym_y"\ncomponents = ["y"]\n',
                          '[[supports]]\nboundary = "mantle"\n'), ("order = 1", "order = 2"))
    run_bad(tmp_path, capsys, text, "inadmissible model input: the supports (mantle ['x', 'y']) leave a "
            "rigid-body motion free: body 'inner': rotation in the x-y plane; the system would be singular: "
            "fix more components or boundaries")


def test_the_same_ring_with_a_tangential_stiffness_is_held(tmp_path, capsys):
    """The negative case above is not vacuous: k_t0 > 0 ties the ring to the mantle."""
    text = edit(COAXIAL, ('[[supports]]\nboundary = "sym_x"\ncomponents = ["x"]\n\n'
                          '[[supports]]\nboundary = "sym_y"\ncomponents = ["y"]\n',
                          '[[supports]]\nboundary = "mantle"\n'), ("gap = -1e-5", "gap = -1e-5\nkt = 1e11"),
                ("order = 1", "order = 2"))
    scene = tmp_path / "ring.toml"
    scene.write_text(text)
    assert cli.main(["check", str(scene)]) == 0, capsys.readouterr().err


def test_a_tolerance_out_of_its_interval_is_refused(tmp_path, capsys):
    text = CELL.format(contact='gap = { kind = "sinusoid", h = 0.01 }')
    run_bad(tmp_path, capsys, edit(text, ("maxh = 0.5", "maxh = 0.5\ntolerance = 2.0")),
            "discretization.tolerance = 2.0: must lie in (0, 1)")


@pytest.mark.parametrize("edits", [
    (('profile = "flat"', 'profile = "sinusoid"\namplitude = 0.1'),),
    (("k_n = 1.0e3", 'k_n = 1.0e3\nfriction = "tresca"\nG = 0.001\nw = 1e-4'),),
])
def test_a_tolerance_where_edge_grading_does_not_apply_is_accepted(tmp_path, capsys, edits):
    """A curved or frictional FE cell refines by a sequence of interface meshes (issue 35): its tolerance is
    no longer refused."""
    text = CELL.format(contact='gap = { kind = "sinusoid", h = 0.01 }').replace("maxh = 0.5",
                                                                                 "maxh = 0.5\ntolerance = 1e-4")
    scene = tmp_path / "cell.toml"
    scene.write_text(edit(text, *edits))
    assert cli.main(["check", str(scene)]) == 0, capsys.readouterr().err


def _two_scale_scene(tmp_path, *pairs) -> str:
    text = open(os.path.join(ROOT, "geometries", "femur_stem_two_scale.toml")).read()
    work = tmp_path / "work"
    work.mkdir(exist_ok=True)
    if not (work / "cells").exists():
        os.symlink(os.path.join(ROOT, "geometries", "cells"), work / "cells")
    return edit(text, *pairs)


def test_a_two_scale_cell_method_the_cell_cannot_take(tmp_path, capsys):
    """The spectral cell needs a small-slope cell; the loop's shear table needs the FE cell."""
    run_bad(tmp_path, capsys, _two_scale_scene(tmp_path, ('cell_method = "spectral"', 'cell_method = "bem"')),
            "two_scale.cell_method = 'bem': must be one of 'fe', 'spectral'")
    run_bad(tmp_path, capsys, _two_scale_scene(tmp_path, ('cell = "cells/stem_grooves.toml"',
                                                          'cell = "cells/sinusoid.toml"')),
            "two_scale.cell_method = 'spectral': the cell 'cells/sinusoid.toml' cannot be solved by this method: "
            "discretization.method = 'spectral': solves the small-slope cell", prefix=True)
    run_bad(tmp_path, capsys, _two_scale_scene(tmp_path, ("mu = 0.3            #", 'friction = "from_cell"\n'
                                                          'cell_friction = "coulomb"\ncell_mu = 0.3\ncell_w = 1e-9\n#')),
            "two_scale.cell_method = 'spectral': the loop solves a spectral cell for its pressure table only; the "
            "shear table of interface.friction = 'from_cell' with a frictional cell needs the FE cell: use "
            "two_scale.cell_method = 'fe', or interface.friction = 'given'")


def test_a_spectral_start_without_a_spectral_twin(tmp_path, capsys):
    """The spectral predictor needs the penalty on a flat interface: a sinusoid profile has none."""
    text = edit(CELL.format(contact=""), ('profile = "flat"', 'profile = "sinusoid"\namplitude = 0.05'),
                ("rtol = 1e-10", 'rtol = 1e-10\nstart = "spectral"'))
    run_bad(tmp_path, capsys, text,
            "solver.start = 'spectral': starts from the spectral cell of the same small-slope cell: it needs "
            "contact.enforcement = 'penalty' and a flat interface", prefix=True)


def test_an_unknown_start(tmp_path, capsys):
    text = edit(CELL.format(contact=""), ("rtol = 1e-10", 'rtol = 1e-10\nstart = "spectal"'))
    run_bad(tmp_path, capsys, text, "solver.start = 'spectal': must be one of 'auto', 'spectral', 'rigid', 'closed'")


def test_a_spectral_start_with_exact_enforcement(tmp_path, capsys):
    """The spectral predictor moves the penalty's contact set: exact enforcement has no twin."""
    text = edit(CELL.format(contact='enforcement = "exact"'), ("rtol = 1e-10", 'rtol = 1e-10\nstart = "spectral"'))
    run_bad(tmp_path, capsys, text, "solver.start = 'spectral': starts from the spectral cell of the same "
            "small-slope cell: it needs contact.enforcement = 'penalty'", prefix=True)


# ------------------------------------------------------------- round three: inputs and messages


def test_a_scene_with_a_utf8_byte_order_mark_is_read(tmp_path, capsys):
    """Was: 'not valid TOML (line 1, column 1)' for a scene saved by an editor that writes a BOM."""
    scene = tmp_path / "scene.toml"
    scene.write_bytes(b"\xef\xbb\xbf" + CELL.format(contact="").encode())
    assert cli.main(["check", str(scene)]) == 0, capsys.readouterr().err
    capsys.readouterr()


def test_a_profile_csv_with_a_byte_order_mark_and_no_header_keeps_its_first_row(tmp_path, capsys):
    """Was: the BOM made the first row 'not numeric', so it was skipped as a header: the profile then
    started at x = 0.5 and was refused."""
    work = tmp_path / "work"
    work.mkdir()
    (work / "p.csv").write_bytes(b"\xef\xbb\xbf0,0\n0.5,-0.1\n1.0,0\n")
    scene = work / "scene.toml"
    scene.write_text(TAB)
    assert cli.main(["check", str(scene)]) == 0, capsys.readouterr().err
    capsys.readouterr()


def test_a_scene_path_that_is_a_directory_or_a_device_says_what_it_is(tmp_path, capsys):
    """Was: 'no such file' for a directory and for /dev/null."""
    folder = tmp_path / "scene.toml"
    folder.mkdir()
    for path, kind in ((str(folder), "a directory"), ("/dev/null", "a character device")):
        assert cli.main(["check", path]) == 2
        assert capsys.readouterr().err == (f"ngcontact: error: {path}: <scene file> = '{path}': is {kind}; "
                                           "must be a regular file (a scene file)\n")


def test_a_cell_link_that_is_a_directory_says_what_it_is(tmp_path, capsys):
    """Was: 'no such cell scene file' for a directory."""
    (tmp_path / "work").mkdir()
    (tmp_path / "work" / "cells").mkdir()
    text = edit(MACRO, ('law = "linear"\nkn = 1e12\nkt = 1e11', 'cell = "cells"'))
    run_bad(tmp_path, capsys, text, "interface.cell = 'cells': is a directory; must be a regular file (a cell scene)")


def test_a_law_file_that_is_a_directory_says_what_it_is(tmp_path, capsys):
    """Was: 'no such law file' for a directory."""
    (tmp_path / "work").mkdir()
    (tmp_path / "work" / "law.json").mkdir()
    text = edit(MACRO, ('law = "linear"\nkn = 1e12\nkt = 1e11', 'law = "file"\nlaw_file = "law.json"'))
    run_bad(tmp_path, capsys, text, f"interface.law_file = '{tmp_path / 'work' / 'law.json'}': is a directory; "
            "must be a regular file (a JSON law file)")


def test_a_data_file_that_is_a_directory_says_what_it_is(tmp_path, capsys):
    (tmp_path / "work").mkdir()
    (tmp_path / "work" / "p.csv").mkdir()
    run_bad(tmp_path, capsys, TAB, f"geometry.file (p.csv) = '{tmp_path / 'work' / 'p.csv'}': is a directory; "
            "must be a regular file (a CSV file)")


def test_a_title_beyond_the_string_limit_is_refused_and_not_echoed(tmp_path, capsys):
    """Was: a 50 MB title was accepted and copied into a 100 MB report.json."""
    from ngcontact.scene.schema import MAX_STRING
    title = "x" * (MAX_STRING + 1)
    run_bad(tmp_path, capsys, edit(CELL.format(contact=""), ('kind = "cell"', f'kind = "cell"\ntitle = "{title}"')),
            f"title = 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...' ({MAX_STRING + 1} characters): must be at most "
            f"{MAX_STRING} characters")


def test_a_scene_file_beyond_the_size_limit_is_refused_before_parsing(tmp_path, capsys):
    from ngcontact.scene.schema import MAX_SCENE_BYTES
    text = CELL.format(contact="") + "# padding\n" * (MAX_SCENE_BYTES // 10 + 1)
    scene = tmp_path / "work" / "scene.toml"
    size = len(text.encode())
    run_bad(tmp_path, capsys, text, f"<scene file> = '{scene}': is {size} bytes; a scene file is limited to "
            f"{MAX_SCENE_BYTES // 2 ** 20} MiB")


def test_a_component_given_twice_is_refused(tmp_path, capsys):
    """Was: components = ["x", "x", "y"] was accepted and one x value dropped."""
    text = edit(MACRO, ('[[supports]]\nboundary = "bottom"\n',
                        '[[supports]]\nboundary = "bottom"\ncomponents = ["x", "x", "y"]\n'
                        'displacement = [0.0, 1e-6, 0.0]\n'))
    run_bad(tmp_path, capsys, text, "supports[0].components = ['x', 'x', 'y']: must not repeat an entry")


def test_the_bore_label_states_the_rule_the_dimensions_enforce(tmp_path, capsys):
    """Was: 'a > 0: the inner body is a tube', as if a = 0 (a solid rod) were allowed, and a = 0 was refused.

    Now a = 0 is a solid shaft (no bore) and the label says so; a < 0 is refused with the rule.
    """
    from ngcontact.scene.macro_shapes import BOUNDARY_DOCS
    for setting in ("plane_strain", "axisymmetric", "3d"):
        assert "with a = 0 it is a solid shaft and has no bore" in BOUNDARY_DOCS["coaxial", setting]["bore"]
    run_bad(tmp_path, capsys, edit(COAXIAL, ("a = 0.01", "a = -0.01")),
            "geometry.dimensions.a = -0.01: must be >= 0 (a > 0: the inner body is a tube; a = 0: a solid shaft)",
            prefix=True)
    scene = tmp_path / "shaft.toml"
    scene.write_text(edit(COAXIAL, ("a = 0.01", "a = 0.0")))
    assert cli.main(["check", str(scene)]) == 0
    capsys.readouterr()


def test_a_mesher_failure_of_a_plain_cell_names_the_size_ratio(tmp_path, capsys):
    """Was: 'a feature is too small or too thin' for a rectangular cell of height 1 at interface_maxh 0.002,
    whose features are 0.3 and 0.4 long: Netgen's 2D mesher fails on size ratios near 100."""
    text = open(os.path.join(CELLS, "ex27_rectangular.toml")).read()
    run_bad(tmp_path, capsys, edit(text, ("interface_maxh = 0.05", "interface_maxh = 0.002")),
            "inadmissible model input: discretization.interface_maxh = 0.002: Netgen's mesher failed (meshing "
            "failed) on the cell meshed at maxh = 0.2 with the interface at 0.002: sizes 100 times apart, which its "
            "grading does not bridge reliably (failures seen from about 90); keep maxh / interface_maxh below 50: "
            "raise discretization.interface_maxh or lower discretization.maxh", commands=("run",))


def test_the_macro_friction_coefficient_documents_the_default_coupled_newton():
    """Was: interface.mu read 'fixed point on the pressure' while solver.coulomb defaults to the coupled Newton."""
    import dataclasses
    from ngcontact.scene.macro_scene import InterfaceSpec
    from ngcontact.scene.sections import SolverSpec
    doc = next(f for f in dataclasses.fields(InterfaceSpec) if f.name == "mu").metadata["doc"]
    assert SolverSpec().coulomb == "newton" and "solver.coulomb" in doc and "Newton" in doc


def test_order_2_of_an_exact_3d_fe_cell_is_accepted_on_a_linear_trace(tmp_path, capsys):
    """Was refused ('must be 1 with contact.enforcement = exact in a 3D FE cell'); the scene now takes the
    linear trace on S_C (ngcontact.cell.fe.linear_trace), the 2D cell and the penalty keep the full trace."""
    from ngcontact.drivers.build import model_of
    from ngcontact.scene.loader import load
    text = edit(CELL.format(contact='enforcement = "exact"'), ('profile = "flat"', 'profile = "flat3d"'),
                ("order = 1", "order = 2"))
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    assert cli.main(["check", str(scene)]) == 0, capsys.readouterr().err
    assert model_of(load(scene)).linear_trace
    scene.write_text(edit(CELL.format(contact='enforcement = "exact"'), ("order = 1", "order = 2")))
    assert not model_of(load(scene)).linear_trace
    scene.write_text(edit(text, ('enforcement = "exact"', 'enforcement = "penalty"')))
    assert not model_of(load(scene)).linear_trace


def test_a_removed_key_names_its_successor(tmp_path, capsys):
    """Was: output.coulomb_tol (removed) gave 'unknown key' with no pointer to solver.coulomb_rtol."""
    run_bad(tmp_path, capsys, MACRO + "\n[output]\ncoulomb_tol = 1e-6\n",
            "output.coulomb_tol = 1e-06: removed; use solver.coulomb_rtol (the Coulomb fixed point stops when "
            "max |p_k - p_k-1| <= coulomb_rtol x max p_k)")


def test_exact_coulomb_friction_of_the_spectral_cell_needs_no_huber_width(tmp_path, capsys):
    """Was: 'contact.w = <missing>: required for friction = 'coulomb'' with exact friction, which has no width."""
    text = edit(CELL.format(contact='enforcement = "exact"\nfriction = "coulomb"\nmu = 0.3\n'
                            'gap = { kind = "sinusoid", h = 0.01 }'),
                ("order = 1", 'method = "spectral"\ngrid = 64\norder = 1'))
    scene = tmp_path / "spectral.toml"
    scene.write_text(text)
    assert cli.main(["check", str(scene)]) == 0, capsys.readouterr().err
    assert cli.main(["run", str(scene), "--out", str(tmp_path / "spectral"), "--quiet"]) == 0, capsys.readouterr().err
    capsys.readouterr()
    # the FE cell regularizes friction with w under exact enforcement too: there it stays required
    run_bad(tmp_path, capsys, text.replace('method = "spectral"\ngrid = 64\n', ""),
            "contact.w = <missing>: required for friction = 'coulomb' in an FE cell, which regularizes friction "
            "with the Huber width w under exact enforcement too (the spectral cell's exact friction needs none)")
