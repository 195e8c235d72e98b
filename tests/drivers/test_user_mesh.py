"""The package as a library on a mesh of the caller's: the scene's numbers, the caller's own forms, refusals.

``ngcontact.solve_mesh`` on the mesh a macro scene's shape builder makes
must give what ``ngcontact run`` gives for that scene (same mesh, same law,
same solver: round-off apart); ``ngcontact.interface_form`` in a form the
test writes itself must give the same displacement as ``solve_mesh``; bad
arguments end in an error naming the argument, its value and what is allowed.
"""
import json
import os

import ngsolve as ng
import pytest
from netgen.occ import Compound, OCCGeometry, WorkPlane, Y

import ngcontact
from ngcontact.errors import ModelError, SceneError
from ngcontact.geometry.bodies import block_on_plane, coaxial_3d, coaxial_axisymmetric
from ngcontact.laws.homogenized import BundleLaw, InterfaceLaw, LinearLaw
from ngcontact.scene.loader import from_dict

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE = os.path.join(ROOT, "geometries", "macro", "block_on_sawtooth.toml")
CELL = os.path.join(ROOT, "geometries", "macro", "sawtooth_cell.toml")
STEEL = {"E": 210e9, "nu": 0.3}
#: the scene's problem in the API's arguments (geometries/macro/block_on_sawtooth.toml)
BLOCK = dict(rough="block", counter="base", materials={"block": STEEL, "base": STEEL},
             supports=[{"boundary": "bottom"}], loads=[{"boundary": "top", "pressure": 10e6, "traction": [2e6, 0.0]}])
#: round-off: the same mesh, law and Newton; only the order of summation may differ
ROUND_OFF = 1e-8


@pytest.fixture(autouse=True)
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))


@pytest.fixture(scope="module")
def block_mesh():
    return block_on_plane(0.02, 0.005, 0.005, maxh=0.0025).mesh


def test_solve_mesh_gives_the_numbers_of_ngcontact_run(tmp_path, block_mesh):
    """The shipped block on a sawtooth: the scene as ``ngcontact run`` solves it (``runner.solve``), the same
    mesh and cell through the API, which writes the files the report lists."""
    scene, _ = ngcontact.solve(SCENE)                       # what `ngcontact run` computes (and then writes)
    law = ngcontact.cell_law(CELL, length_unit=1e-4)
    api, _ = ngcontact.solve_mesh(block_mesh, law, out=str(tmp_path / "api"), **BLOCK)
    with open(tmp_path / "api" / "report.json") as fh:
        assert json.load(fh)["results"]["resultant"] == api["results"]["resultant"]
    s, a = scene["results"], api["results"]
    scale = abs(s["resultant"]["y"])
    for c in ("x", "y"):
        assert a["resultant"][c] == pytest.approx(s["resultant"][c], rel=0, abs=ROUND_OFF * scale)
    assert a["maxima"]["pressure"]["pressure"] == pytest.approx(s["maxima"]["pressure"]["pressure"], rel=ROUND_OFF)
    assert a["interface"]["pressure"] == pytest.approx(s["interface"]["pressure"], rel=0,
                                                       abs=ROUND_OFF * s["maxima"]["pressure"]["pressure"])
    assert a["law"]["K0"] == s["law"]["K0"] and law.coefficients["K0"] == s["law"]["K0"]
    assert set(a) == set(s) and api["files"] == scene["files"]
    assert api["kind"] == "macro" and api["effects"] == scene["effects"]
    assert set(api["files"]) < set(os.listdir(tmp_path / "api"))


def test_solve_mesh_axisymmetric_with_interference_as_the_coaxial_scene():
    """The axisymmetric weight and a negative gap reach the API's problem as they reach a scene's."""
    a, b, c, height, maxh, delta = 0.01, 0.02, 0.04, 0.02, 0.005, 20e-6
    scene = from_dict({
        "kind": "macro", "materials": {"steel": STEEL, "bronze": {"E": 110e9, "nu": 0.34}},
        "bodies": {"rough": "steel", "counter": "bronze"},
        "geometry": {"shape": "coaxial", "setting": "axisymmetric",
                     "dimensions": {"a": a, "b": b, "c": c, "height": height}},
        "interface": {"law": "linear", "kn": 1e13, "gap": -delta},
        "supports": [{"boundary": "bottom", "components": ["z"]}], "discretization": {"maxh": maxh}})
    by_scene, _ = ngcontact.solve(scene)
    mesh = coaxial_axisymmetric(a, b, c, height, maxh=maxh).mesh
    by_api, _ = ngcontact.solve_mesh(mesh, LinearLaw(kn=1e13), rough="inner", counter="outer", setting="axisymmetric",
                                     materials={"inner": STEEL, "outer": {"E": 110e9, "nu": 0.34}}, gap=-delta,
                                     supports=[{"boundary": "bottom", "components": ["z"]}])
    peak = by_scene["results"]["maxima"]["pressure"]["pressure"]
    assert peak > 1e7                                      # the interference presses: tens of MPa
    assert by_api["results"]["maxima"]["pressure"]["pressure"] == pytest.approx(peak, rel=ROUND_OFF)
    assert by_api["effects"] == list(by_scene["effects"])


def test_interface_form_in_the_callers_own_forms_solves_as_solve_mesh(block_mesh):
    """The caller's own elastic energy, load and Newton, with the law's interface term, against ``solve_mesh``."""
    mesh = block_mesh
    law = ngcontact.cell_law(CELL, form="linear", length_unit=1e-4)
    fes = (ng.VectorH1(mesh, order=2, definedon=mesh.Materials("block"))
           * ng.VectorH1(mesh, order=2, definedon=mesh.Materials("base"), dirichlet="bottom"))
    ub, uc = fes.TrialFunction()
    E, nu = STEEL["E"], STEEL["nu"]
    mu, lam = E / (2 + 2 * nu), E * nu / ((1 + nu) * (1 - 2 * nu))

    def elastic(u):
        eps = ng.Sym(ng.Grad(u))
        return mu * ng.InnerProduct(eps, eps) + lam / 2 * ng.Trace(eps) ** 2

    a = ng.BilinearForm(fes, symmetric=True)
    a += ng.Variation(elastic(ub) * ng.dx("block") + elastic(uc) * ng.dx("base"))
    a += ng.Variation(-(2e6 * ub[0] - 10e6 * ub[1]) * ng.ds("top"))
    a += ngcontact.interface_form(law, mesh, ub, uc, rough="block", counter="base").variation
    gfu = ng.GridFunction(fes)
    ng.solvers.Newton(a, gfu, inverse="sparsecholesky", printing=False)
    _, outcome = ngcontact.solve_mesh(mesh, law, **BLOCK)
    fields = outcome.vtk["stress"].fields
    for own, api, region in ((gfu.components[0], fields["u_rough"], "block"),
                             (gfu.components[1], fields["u_counter"], "base")):
        diff = ng.Integrate(ng.InnerProduct(own - api, own - api), mesh, definedon=mesh.Materials(region))
        norm = ng.Integrate(ng.InnerProduct(api, api), mesh, definedon=mesh.Materials(region))
        assert diff <= ROUND_OFF ** 2 * norm
    form = ngcontact.interface_form(law, mesh, *gfu.components, rough="block", counter="base")
    assert -ng.Integrate(form.pressure * form.measure, mesh) == pytest.approx(-10e6 * 0.02, rel=ROUND_OFF)


# ----------------------------------------------------------------- refusals
def _refused(match, **changes):
    mesh = changes.pop("mesh", None) or block_on_plane(0.02, 0.005, 0.005, maxh=0.005).mesh
    law = changes.pop("law", InterfaceLaw(normal=LinearLaw(kn=1e12, kt=1e12)))
    with pytest.raises((ModelError, SceneError), match=match):
        ngcontact.solve_mesh(mesh, law, **{**BLOCK, **changes})


def test_a_region_the_mesh_lacks_is_named_with_the_regions_it_has():
    _refused(r"rough = 'stem': no such region in the mesh; its regions are 'base', 'block'", rough="stem")


def test_a_missing_interface_is_named_with_the_boundaries_the_mesh_has():
    _refused(r"interface = 'contact': no such boundary in the mesh; its boundaries are .*'interface'",
             interface="contact")


def test_an_outer_boundary_is_no_interface():
    _refused(r"interface = 'top': its element 0 borders one element only \(of 'block'\)", interface="top")


def test_a_law_of_the_wrong_type_is_refused():
    _refused(r"law = 'bundle': an InterfaceLaw \(ngcontact.cell_law", law="bundle")
    _refused(r"law = a dict: an InterfaceLaw", law={"kn": 1e12})


def test_bad_supports_materials_and_setting_name_their_argument():
    _refused(r"supports\[0\].boundary = 'floor': no such boundary in the mesh", supports=[{"boundary": "floor"}])
    _refused(r"supports\[0\].components = \['w'\]", supports=[{"boundary": "bottom", "components": ["w"]}])
    _refused(r"materials = \['block'\]: one material per body region: keys 'block' and 'base'",
             materials={"block": STEEL})
    _refused(r"materials\['base'\].nu = 0.7", materials={"block": STEEL, "base": {"E": 1e9, "nu": 0.7}})
    _refused(r"setting = '3d': the mesh is 2D", setting="3d")


def test_bodies_meshed_apart_are_refused_with_the_remedy():
    """Two faces meshed without gluing: the facing edges have doubled nodes, each borders one body only."""
    block = WorkPlane().MoveTo(0, 0).Rectangle(0.02, 0.005).Face()
    base = WorkPlane().MoveTo(0, -0.005).Rectangle(0.02, 0.005).Face()
    block.faces.name, base.faces.name = "block", "base"
    block.edges.Min(Y).name, base.edges.Max(Y).name = "interface", "interface_base"
    mesh = ng.Mesh(OCCGeometry(Compound([block, base]), dim=2).GenerateMesh(maxh=0.005))
    fes = ng.VectorH1(mesh, definedon=mesh.Materials("block")) * ng.VectorH1(mesh, definedon=mesh.Materials("base"))
    ub, uc = fes.TrialFunction()
    with pytest.raises(ModelError, match=r"separate \(doubled\) nodes.*netgen.occ.Glue"):
        ngcontact.interface_form(LinearLaw(kn=1e12), mesh, ub, uc, rough="block", counter="base")


def test_cell_law_refuses_what_is_no_cell():
    with pytest.raises(SceneError, match=r"cell = .*block_on_sawtooth.toml': names a 'macro' scene"):
        ngcontact.cell_law(SCENE)
    with pytest.raises(ModelError, match=r"cell = 42: a cell scene file or a scene of kind 'cell'"):
        ngcontact.cell_law(42)
    with pytest.raises(ModelError, match=r"form = 'cubic': one of bundle, linear"):
        ngcontact.cell_law(CELL, form="cubic")
    with pytest.raises(ModelError, match=r"friction = 'from_cell': the cell has no friction"):
        ngcontact.cell_law(CELL, friction="from_cell")


def test_cell_law_of_a_loaded_scene_is_the_law_of_its_file():
    by_file = ngcontact.cell_law(CELL, setting="axisymmetric", length_unit=1e-4)
    loaded = ngcontact.cell_law(ngcontact.load(CELL), setting="axisymmetric", length_unit=1e-4)
    assert loaded == by_file and isinstance(loaded, InterfaceLaw)
    assert loaded.coefficients == by_file.coefficients and len(by_file.coefficients["weights"]) == 2


def test_cell_law_with_friction_from_the_cell_is_the_macro_scenes():
    """Friction from a Coulomb cell (paper eqs. 42-43): in 2D ``mu0`` is the micro ``mu``, as a macro scene's
    ``interface.friction = "from_cell"`` has it."""
    from ngcontact.drivers.build import friction_from_cell
    path = os.path.join(ROOT, "geometries", "cells", "rectangular_coulomb.toml")
    law = ngcontact.cell_law(path, friction="from_cell")
    scene_friction, _ = friction_from_cell(path, width=law.friction.width)
    assert law.friction == scene_friction and law.friction.width == 1e-6
    assert law.coefficients["mu0"] == pytest.approx(0.3, rel=1e-12) and law.coefficients["G0"] == 0.0


@pytest.mark.slow  # a 3D quarter of two tubes solved twice: about 10 s on a loaded machine
def test_solve_mesh_in_3d_as_the_coaxial_scene():
    """The 3D frame (n0, t1, t2), a bundle law and an interference through both routes on the same mesh."""
    a, b, c, height, maxh, delta = 0.01, 0.02, 0.04, 0.01, 0.01, 20e-6
    supports = [{"boundary": "sym_x", "components": ["x"]}, {"boundary": "sym_y", "components": ["y"]},
                {"boundary": "bottom", "components": ["z"]}, {"boundary": "top", "components": ["z"]}]
    scene = from_dict({
        "kind": "macro", "materials": {"steel": STEEL}, "bodies": {"rough": "steel", "counter": "steel"},
        "geometry": {"shape": "coaxial", "setting": "3d", "dimensions": {"a": a, "b": b, "c": c, "height": height}},
        "interface": {"law": "bundle", "weights": [1e13], "directions": [[1.0, 0.0, 0.0]], "gap": -delta},
        "supports": supports, "discretization": {"maxh": maxh, "order": 2}})
    by_scene, _ = ngcontact.solve(scene)
    mesh = coaxial_3d(a, b, c, height, maxh=maxh, order=2).mesh
    by_api, _ = ngcontact.solve_mesh(mesh, BundleLaw(weights=(1e13,), directions=((1.0, 0.0, 0.0),)), rough="inner",
                                     counter="outer", materials={"inner": STEEL, "outer": STEEL}, gap=-delta,
                                     supports=supports)
    s, a_ = by_scene["results"], by_api["results"]
    assert a_["maxima"]["pressure"]["pressure"] == pytest.approx(s["maxima"]["pressure"]["pressure"], rel=ROUND_OFF)
    assert a_["contact_area"] == pytest.approx(s["contact_area"], rel=ROUND_OFF)
    for comp in ("x", "y"):
        assert a_["resultant"][comp] == pytest.approx(s["resultant"][comp], rel=ROUND_OFF)


def test_interface_form_friction_takes_the_threshold_given(block_mesh):
    """A uniform slip ``s`` of the block beyond the Huber width ``w``: the friction energy is ``G (s - w/2) L``
    (paper eqs. 38-44) with the threshold given, and zero at the law's own ``G0 = 0`` (Coulomb alone)."""
    from ngcontact.laws.homogenized import Friction
    mesh, s, w, G = block_mesh, 1e-4, 1e-6, 2e6
    law = InterfaceLaw(normal=LinearLaw(kn=1e12), friction=Friction(mu=0.3, threshold=0.0, width=w))
    fes = ng.VectorH1(mesh, definedon=mesh.Materials("block")) * ng.VectorH1(mesh, definedon=mesh.Materials("base"))
    gfu = ng.GridFunction(fes)
    gfu.components[0].Set(ng.CF((s, 0.0)))
    for threshold, expected in ((ng.CF(G), G * (s - w / 2) * 0.02), (None, 0.0)):
        form = ngcontact.interface_form(law, mesh, *gfu.components, rough="block", counter="base",
                                        threshold=threshold)
        assert ng.Integrate(form.energy, mesh) == pytest.approx(expected, rel=1e-12, abs=1e-12 * G * s * 0.02)
    assert ng.Integrate(form.traction[1] * form.measure, mesh) == pytest.approx(0.0, abs=1e-12 * G)
