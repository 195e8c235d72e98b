"""Macro supports as the resolved kind has them: affine displacements, symmetry planes, body forces;
the solid coaxial shaft against Lame; bad input."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import ngsolve as ng
import pytest
from netgen.geom2d import SplineGeometry

from ngcontact import cli
from ngcontact.drivers import run_macro as RM
from ngcontact.drivers import run_resolved as drv
from ngcontact.drivers.mesh_supports import supports_on
from ngcontact.fem import two_body
from ngcontact.fem.materials import isotropic
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.scene.loader import load
from ngcontact.scene.supports import SupportSpec
from ngcontact.verification.lame import lame_press_fit_pressure

ROOT = Path(__file__).resolve().parents[2]
STEEL = isotropic(210e9, 0.3)


def scene_file(tmp_path, text: str, name: str = "scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return load(path)


def dirichlet_vector(mesh, setting, supports, order=2) -> np.ndarray:
    fes = two_body.spaces(mesh, setting, ("rough", "counter"), supports, order)
    gfu = ng.GridFunction(fes)
    two_body.set_dirichlet(mesh, setting, supports, gfu)
    return gfu.vec.FV().NumPy().copy()


# ------------------------------------------------------------------ affine
def test_the_affine_support_is_the_resolved_kinds_tilt_on_the_same_mesh():
    """The direct scene's tilted top, read by the resolved kind (its shape's horizontal boundaries), by the
    macro kind (read off the mesh) and written as u0 + G x (in the direct scene), prescribes the same values,
    and the homogenized fields agree to round-off."""
    scene = load(ROOT / "geometries" / "direct" / "block_rect_valleys.toml")
    flat = drv.build_flat(scene, 0.1)
    mesh, setting = flat.mesh, scene.geometry.setting
    resolved = drv.supports_of(scene, mesh)
    macro = supports_on(scene.supports, mesh, setting)
    # u_y = -1e-4 - 1.5e-4 (x - 1/2) = -0.25e-4 - 1.5e-4 x, u_x = 1e-4
    affine = drv.supports_of(replace(scene, supports=(scene.supports[0], SupportSpec(
        boundary="top", u0=(1e-4, -0.25e-4), G=((0.0, 0.0), (-1.5e-4, 0.0))))), mesh)
    ref = dirichlet_vector(mesh, setting, resolved)
    assert np.abs(ref).max() > 1e-4
    for other in (macro, affine):
        assert np.abs(dirichlet_vector(mesh, setting, other) - ref).max() <= 1e-12 * np.abs(ref).max()
    law = il.InterfaceLaw(normal=il.LinearLaw(kn=1e11, kt=1e10))
    fields = []
    for supports in (resolved, affine):
        problem = M.MacroProblem(mesh=mesh, setting=setting, rough="rough", counter="counter",
                                 materials={"rough": STEEL, "counter": isotropic(70e9, 0.33)}, law=law,
                                 supports=supports, order=2)
        fields.append(M.solve(problem).gfu.vec.FV().NumPy().copy())
    assert np.abs(fields[1] - fields[0]).max() <= 1e-12 * np.abs(fields[0]).max()


def test_an_affine_support_in_3d_and_axisymmetry_prescribes_u0_plus_G_x():
    """Every dof of the top face carries u0 + G x (the field is affine, so order 2 holds it exactly)."""
    from ngcontact.geometry import bodies as gm
    for geo, setting, u0, G in (
            (gm.coaxial_3d(0.0, 1.0, 2.0, 1.0, maxh=0.6), "3d", (1e-4, -2e-4, 3e-4),
             ((1e-4, 2e-4, 0.0), (0.0, -1e-4, 5e-5), (3e-4, 0.0, -2e-4))),
            (gm.coaxial_axisymmetric(0.0, 1.0, 2.0, 1.0, maxh=0.3), "axisymmetric", (0.0, -1e-4),
             ((0.0, 0.0), (2e-4, 0.0)))):
        mesh = geo.mesh
        support = supports_on((SupportSpec(boundary="top", u0=u0, G=G),), mesh, setting)
        fes = two_body.spaces(mesh, setting, ("inner", "outer"), support, 2)
        gfu = ng.GridFunction(fes)
        two_body.set_dirichlet(mesh, setting, support, gfu)
        pts = {v for el in mesh.Elements(ng.BND) if el.mat == "top" for v in el.vertices}
        for v in pts:
            x = np.array(mesh[v].point)
            r = np.hypot(x[0], x[1] if setting == "3d" else 0.0)
            if abs(r - 1.0) < 1e-9:
                continue                  # on the interface: a point of both bodies
            u = gfu.components[0 if r < 1.0 else 1]
            got = np.array(u(mesh(*x)))
            assert np.allclose(got, np.array(u0) + np.array(G) @ x, rtol=0, atol=1e-15), (x, got)


# ---------------------------------------------------------------- symmetry
def _blocks(x0: float, x1: float, left: str, maxh: float) -> ng.Mesh:
    """Block [x0, x1] x [0, 1] (rough) on a base [x0, x1] x [-1, 0]; the left faces labelled ``left``."""
    geo = SplineGeometry()
    P = [geo.AppendPoint(x, y) for x, y in ((x0, -1), (x1, -1), (x1, 0), (x1, 1), (x0, 1), (x0, 0))]
    for i, j, dom, bc in ((0, 1, 2, "bottom"), (1, 2, 2, "right"), (2, 3, 1, "right"), (3, 4, 1, "top"),
                          (4, 5, 1, left), (5, 0, 2, left)):
        geo.Append(["line", P[i], P[j]], leftdomain=dom, rightdomain=0, bc=bc)
    geo.Append(["line", P[5], P[2]], leftdomain=1, rightdomain=2, bc="interface")
    geo.SetMaterial(1, "rough")
    geo.SetMaterial(2, "counter")
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def _top_force(mesh, extra=()) -> float:
    specs = (SupportSpec(boundary="bottom"), SupportSpec(boundary="top", displacement=(0.0, -1e-4))) + extra
    problem = M.MacroProblem(mesh=mesh, setting="plane_strain", rough="rough", counter="counter",
                             materials={"rough": STEEL, "counter": isotropic(70e9, 0.33)},
                             law=il.InterfaceLaw(normal=il.LinearLaw(kn=1e11, kt=1e10)),
                             supports=supports_on(specs, mesh, "plane_strain"), order=2)
    sol = M.solve(problem)
    return RM.reactions(sol)["top"]["y"]


def test_a_half_with_its_symmetry_plane_carries_half_the_whole():
    """Blocks on [-1, 1] pressed down against the half [0, 1] with symmetry = true on x = 0."""
    whole = _top_force(_blocks(-1.0, 1.0, "right", 0.1))
    half = _top_force(_blocks(0.0, 1.0, "mid", 0.1), (SupportSpec(boundary="mid", symmetry=True),))
    free = _top_force(_blocks(0.0, 1.0, "mid", 0.1))
    assert whole > 0                                     # the blocks push the top support up
    assert abs(2 * half - whole) <= 2e-4 * abs(whole)
    assert abs(2 * free - whole) > 1e-2 * abs(whole)     # without the plane the half is another problem


# -------------------------------------------------------------- body force
GRAVITY = """\
kind = "macro"

[materials.steel]
E = 210e9
nu = 0.3

[materials.aluminium]
E = 70e9
nu = 0.33

[bodies]
rough = "steel"
counter = "aluminium"

[geometry]
shape = "block"
setting = "plane_strain"

[geometry.dimensions]
length = 0.5
h_block = 2.0
h_base = 1.0

[interface]
law = "linear"
kn = 1e9

[[supports]]
boundary = "block_sides"
symmetry = true

[[supports]]
boundary = "base_sides"
symmetry = true

[[supports]]
boundary = "bottom"
symmetry = true

[body_forces]
rough = [0.0, -7.7e4]
counter = [0.0, -2.7e4]

[discretization]
order = 2
maxh = 0.25
"""


def test_a_column_under_its_weight_is_the_closed_form():
    """Uniaxial strain (sides on rollers, a roller base): sigma_yy is linear in y and u_y quadratic, so the
    order-2 solution is exact: the interface pressure is the block's weight per area, and u_y at the top is
    the sum of both bodies' shortening and the interface's closure p / k_n."""
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        scene = scene_file(Path(tmp), GRAVITY)
    geo = RM.build_geometry(scene)
    problem, _ = RM.problem_of(scene, geo)
    sol = RM.solve_scene(scene, problem)
    RM.checked_equilibrium(sol)
    gb, gB, hb, hB, kn = 7.7e4, 2.7e4, 2.0, 1.0, 1e9

    def modulus(E, nu):
        return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))

    Mb, MB = modulus(210e9, 0.3), modulus(70e9, 0.33)
    p = gb * hb

    def u_base(y):      # sigma_yy = -p + gB y, zero displacement at y = -hB
        return (-p * (y + hB) + gB * (y * y - hB * hB) / 2) / MB

    u_top = u_base(0.0) - p / kn - gb * hb ** 2 / (2 * Mb)
    mesh = geo.mesh
    assert sol.u_rough(mesh(0.2, hb))[1] == pytest.approx(u_top, rel=1e-9)
    assert sol.u_counter(mesh(0.3, -0.4))[1] == pytest.approx(u_base(-0.4), rel=1e-9)
    assert RM.reactions(sol)["bottom"]["y"] == pytest.approx(-(p + gB * hB) * 0.5, rel=1e-9)


# ---------------------------------------------------------- solid shaft
SHAFT = """\
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
shape = "coaxial"
setting = "{setting}"

[geometry.dimensions]
a = 0.0
b = 0.01
c = 0.025
height = 0.01

[interface]
law = "linear"
kn = 1e13
gap = -1e-5

{supports}
[discretization]
order = 2
maxh = {maxh}
"""
ENDS = '[[supports]]\nboundary = "bottom"\nsymmetry = true\n\n[[supports]]\nboundary = "top"\nsymmetry = true\n\n'
QUARTER = '[[supports]]\nboundary = "sym_x"\nsymmetry = true\n\n[[supports]]\nboundary = "sym_y"\nsymmetry = true\n\n'
AXIS = '[[supports]]\nboundary = "axis"\ncomponents = ["r"]\n\n'


@pytest.mark.parametrize("setting, supports", [("axisymmetric", "AXIS"), ("3d", "QUARTER")])
def test_the_base_of_a_shaft_in_its_tube_carries_their_weight(tmp_path, setting, supports):
    """Axisymmetric and 3D: the bottom's reaction is the body forces times the meshed volumes (per
    revolution in axisymmetry), the interface's tangential stiffness holding the shaft."""
    text = SHAFT.format(setting=setting, supports={"AXIS": AXIS, "QUARTER": QUARTER}[supports]
                        + '[[supports]]\nboundary = "bottom"\nsymmetry = true\n\n', maxh=0.004)
    text = text.replace("gap = -1e-5", "kt = 1e12").replace("[discretization]", "[body_forces]\nrough = {f_in}\n"
                                                            "counter = {f_out}\n\n[discretization]")
    down = (0.0, -7.7e4) if setting == "axisymmetric" else (0.0, 0.0, -7.7e4)
    scene = scene_file(tmp_path, text.format(f_in=list(down), f_out=[2 * c for c in down]))
    geo = RM.build_geometry(scene)
    problem, _ = RM.problem_of(scene, geo)
    sol = RM.solve_scene(scene, problem)
    RM.checked_equilibrium(sol)
    mesh = geo.mesh
    w = 2 * np.pi * ng.x if setting == "axisymmetric" else ng.CF(1.0)
    volume = {r: ng.Integrate(w, mesh, definedon=mesh.Materials(r)) for r in ("inner", "outer")}
    weight = -7.7e4 * (volume["inner"] + 2 * volume["outer"])
    # 3D: the curved elements' quadrature of the reaction is not the assembly's
    assert RM.reactions(sol)["bottom"]["z"] == pytest.approx(weight, rel=1e-9 if setting == "axisymmetric" else 2e-6)


def _mean_pressure(scene) -> float:
    geo = RM.build_geometry(scene)
    problem, _ = RM.problem_of(scene, geo)
    sol = RM.solve_scene(scene, problem)
    RM.checked_equilibrium(sol)
    mesh = geo.mesh
    w = ng.x if mesh.dim == 2 else ng.CF(1.0)       # axisymmetric: the 2 pi cancels
    on = mesh.Boundaries("interface")
    from ngcontact.macro import macro_measures as MM
    p = MM.interface_tractions(sol)[0]
    return ng.Integrate(p * w, mesh, ng.BND, definedon=on) / ng.Integrate(w, mesh, ng.BND, definedon=on)


LAME = lame_press_fit_pressure(0.0, 0.01, 0.025, 210e9, 0.3, 110e9, 0.34, 1e-5, k_n=1e13)


def test_a_solid_shaft_in_axisymmetry_is_lames_press_fit_with_the_layer_in_series(tmp_path):
    """Ends on rollers (u_z = 0): the plane-strain Lame press fit of a solid shaft in a tube, the interface
    compliance 1/k_n in series; the axis r = 0 fixed in r."""
    scene = scene_file(tmp_path, SHAFT.format(setting="axisymmetric", supports=AXIS + ENDS, maxh=0.001))
    assert _mean_pressure(scene) == pytest.approx(LAME, rel=2e-6)


def test_a_solid_shaft_in_3d_is_lames_press_fit(tmp_path):
    """The 3D quarter of the same shaft: symmetry planes x = 0, y = 0, ends on rollers."""
    scene = scene_file(tmp_path, SHAFT.format(setting="3d", supports=QUARTER + ENDS, maxh=0.004))
    assert _mean_pressure(scene) == pytest.approx(LAME, rel=2e-3)


# ---------------------------------------------------------------- bad input
BLOCK = GRAVITY.replace('[[supports]]\nboundary = "block_sides"\nsymmetry = true\n\n', "")


@pytest.mark.parametrize("old, new, message", [
    ('boundary = "bottom"\nsymmetry = true', 'boundary = "bottom"\nu0 = [0.0]',
     "supports[1].u0 = [0.0]: one value per component (2: x, y)"),
    ('boundary = "bottom"\nsymmetry = true', 'boundary = "bottom"\nG = [[0.0, 1e-3]]',
     "supports[1].G = [[0.0, 0.001]]: one row per prescribed component (2: x, y), each with 2 numbers "
     "(the derivatives along x, y)"),
    ('boundary = "bottom"\nsymmetry = true', 'boundary = "bottom"\ncomponents = ["y"]\nG = [[0.0, 1e-3, 0.0]]',
     "supports[1].G = [[0.0, 0.001, 0.0]]: one row per prescribed component (1: y), each with 2 numbers "
     "(the derivatives along x, y)"),
    ('boundary = "bottom"\nsymmetry = true', 'boundary = "bottom"\ndisplacement = [0.0, 0.0]\nu0 = [0.0, 1e-4]',
     "supports[1].displacement = [0.0, 0.0]: give either displacement and slope (values at the boundary's "
     "mid-point) or u0 and G (u = u0 + G x), not both"),
    ('boundary = "bottom"\nsymmetry = true', 'boundary = "bottom"\nsymmetry = true\ncomponents = ["y"]',
     "supports[1].components = ['y']: not used with symmetry = true (the plane fixes its normal component at "
     "zero); remove it"),
    ("rough = [0.0, -7.7e4]", "rough = [0.0, -7.7e4, 0.0]",
     "body_forces.rough = [0.0, -77000.0, 0.0]: one number per component (x, y)"),
])
def test_bad_supports_and_body_forces_name_the_key(tmp_path, capsys, old, new, message):
    assert old in BLOCK
    path = tmp_path / "scene.toml"
    path.write_text(BLOCK.replace(old, new, 1))
    assert cli.main(["check", str(path)]) == 2
    assert capsys.readouterr().err.rstrip("\n") == f"ngcontact: error: {path}: {message}"


def test_a_slope_in_3d_and_a_shaft_without_its_axis_are_refused(tmp_path, capsys):
    path = tmp_path / "scene.toml"
    path.write_text(SHAFT.format(setting="3d", supports=QUARTER + ENDS.replace(
        'boundary = "top"\nsymmetry = true', 'boundary = "top"\ncomponents = ["z"]\nslope = [1e-3]'), maxh=0.004))
    assert cli.main(["check", str(path)]) == 2
    assert capsys.readouterr().err.rstrip("\n").endswith(
        "supports[3].slope = [0.001]: a face in 3D has two directions: give the tilt as u0 and G (u = u0 + G x)")
    path.write_text(SHAFT.format(setting="axisymmetric", supports=ENDS, maxh=0.002))
    assert cli.main(["check", str(path)]) == 2
    assert capsys.readouterr().err.rstrip("\n").endswith(
        "a solid shaft (coaxial with a = 0) in axisymmetry needs u_r = 0 on its axis: add [[supports]] "
        "boundary = \"axis\", components = [\"r\"]")
    path.write_text(SHAFT.format(setting="axisymmetric", supports=AXIS.replace("axis", "bore") + ENDS, maxh=0.002))
    assert cli.main(["check", str(path)]) == 2
    assert capsys.readouterr().err.rstrip("\n").endswith(
        "supports[0].boundary = 'bore': no such boundary in 'coaxial' (axisymmetric); labels are axis, bottom, "
        "interface, mantle, top")


def test_a_symmetry_plane_on_a_curved_boundary_and_a_slope_on_a_slanted_one_are_refused(tmp_path):
    from ngcontact.errors import SceneError
    scene = scene_file(tmp_path, SHAFT.format(setting="axisymmetric", supports=AXIS + ENDS, maxh=0.002))
    geo = RM.build_geometry(scene)
    bad = replace(scene, supports=scene.supports + (SupportSpec(boundary="mantle", symmetry=True),))
    RM.supports_of(bad, geo.mesh)          # r = c is a line normal to r in (r, z): u_r = 0 there, accepted
    q = scene_file(tmp_path, SHAFT.format(setting="plane_strain", supports=QUARTER, maxh=0.004), "q.toml")
    mesh = RM.build_geometry(q).mesh
    with pytest.raises(SceneError, match=r"supports\[2\]\.symmetry = True: boundary 'mantle' is not a plane"):
        RM.supports_of(replace(q, supports=q.supports + (SupportSpec(boundary="mantle", symmetry=True),)), mesh)
    with pytest.raises(SceneError, match=r"supports\[2\]\.slope = \[0\.001\]: boundary 'mantle' is neither"):
        RM.supports_of(replace(q, supports=q.supports + (SupportSpec(boundary="mantle", components=("x",),
                                                                     slope=(1e-3,)),)), mesh)
