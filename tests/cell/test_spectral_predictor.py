"""The spectral predictor (:mod:`ngcontact.cell.spectral_start`): a small-slope FE cell's first load starts
on its spectral twin's contact set and reaches the rigid start's solution."""
import os
from dataclasses import replace

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.cell.fe.measures import sample_surface
from ngcontact.cell.fe.predictor import set_start
from ngcontact.cell.spectral_start import spectral_start
from ngcontact.fem.interpolants import periodic_grid
from ngcontact.drivers.build import TWIN_GRID, build_cell, cell_loads, cell_problem, model_of, predictor_twin
from ngcontact.scene.loader import load

from fe_cells import FE, fe_scene
from height_map_cell import fe_height_map

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _scene(name):
    if name == "height_map":          # the shipped map is solved by the spectral cell; here its FE cell
        import tomllib
        from ngcontact.scene.loader import from_dict
        return from_dict(tomllib.loads(fe_height_map()))
    if name in FE:                    # shipped for the spectral cell (method = "auto"); here its FE cell
        return fe_scene(name)
    return load(os.path.join(ROOT, "geometries", "cells", f"{name}.toml"))


BISINUSOID = _scene("bisinusoid")


def _period(scene):
    """``scene`` meshed over its whole period (``discretization.symmetry = "off"``)."""
    return replace(scene, discretization=replace(scene.discretization, symmetry="off"))


def _problem(scene, start, interface_maxh=None):
    return CellProblem(build_cell(scene, interface_maxh=interface_maxh), model_of(scene), start=start,
                       predictor=predictor_twin(scene, interface_maxh))


def test_the_start_has_the_twin_s_contact_set():
    """After the spectral start, the penetration on S_C is the twin's interpolated one: the same sign wherever
    the twin's penetration is not within 5 % of its range of zero, and close to it everywhere."""
    P = _problem(BISINUSOID, "predictor", 0.12)
    twin = P.predictor.twin
    load_ = cell_loads(BISINUSOID)[0]
    P._apply_load(load_)
    set_start(P, load_)                           # the rigid predictor's state
    record = spectral_start(P, load_, twin)
    assert record["kind"] == "spectral" and record["grid"] == twin.grid == 64
    s = sample_surface(P, {"s": P.penetration, "x": ng.x, "y": ng.y})
    target = twin.solve(load_).fields["closure"] - twin.g0
    # the twin's penetration, bilinear between its grid points, at the sampled points
    N, period = twin.grid, twin.period
    u, v = s["x"] / period * N, s["y"] / period * N
    i0, j0 = np.floor(u).astype(int), np.floor(v).astype(int)
    fu, fv = u - i0, v - j0

    def at(i, j):
        return target[j % N, i % N]
    expected = ((1 - fu) * (1 - fv) * at(i0, j0) + fu * (1 - fv) * at(i0 + 1, j0)
                + (1 - fu) * fv * at(i0, j0 + 1) + fu * fv * at(i0 + 1, j0 + 1))
    opened = -expected.min()                   # the largest elastic gap
    inside, outside, clear = expected > 0, expected < 0, expected < -0.05 * opened

    def agreement(pen):
        return np.mean(pen[inside] > 0), np.mean(pen[outside] < 0), np.mean(pen[clear] < 0)
    closed_share, open_share, clear_share = agreement(s["s"])
    assert closed_share >= 0.8 and open_share >= 0.95 and clear_share == 1.0
    assert np.max(np.abs(s["s"] - expected)) <= 0.05 * opened
    # the rigid start's penetration is a level set of the gap: further from the twin's contact set
    R = _problem(BISINUSOID, "rigid", 0.12)
    R._apply_load(load_)
    set_start(R, load_)
    rigid = agreement(sample_surface(R, {"s": R.penetration})["s"])
    assert rigid[0] + rigid[1] < closed_share + open_share


@pytest.mark.parametrize("name, interface_maxh", [("bisinusoid", 0.12), ("height_map", None), ("westergaard", None),
                                                  ("tabulated_gap", None)])
def test_the_spectral_start_reaches_the_rigid_start_s_solution(name, interface_maxh):
    """Every load of a sweep solved afresh from either start: the same contact fraction, pressure and far-face
    jump to the Newton tolerance; the spectral start records itself in the history and takes no more
    Newton steps than the rigid start (3D and 2D cells; the height map is not symmetric in x and y, so a
    twin read transposed would start Newton on another contact set)."""
    scene = _scene(name)
    rigid, spectral = _problem(scene, "rigid", interface_maxh), _problem(scene, "predictor", interface_maxh)
    assert spectral.start == "predictor"
    for load_ in cell_loads(scene):
        a = rigid.solve(load_, first=True, measure=False)
        b = spectral.solve(load_, first=True, measure=False)
        assert b.results["contact_fraction"] == pytest.approx(a.results["contact_fraction"], rel=1e-9)
        assert b.results["mean_pressure"] == pytest.approx(a.results["mean_pressure"], rel=1e-8)
        ua, ub = (np.array([P.gfu.vec[i] for i in P.u_dofs]) for P in (rigid, spectral))
        assert np.allclose(ub, ua, rtol=1e-8, atol=1e-12 * np.max(np.abs(ua)))
        assert b.newton[0]["start"]["kind"] == "spectral" and "start" not in a.newton[0]
        assert sum(h["iterations"] for h in b.newton) <= sum(h["iterations"] for h in a.newton)


def test_periodic_grid_is_the_periodic_bilinear_interpolant():
    """At the grid points (the period's far end included, wrapped) the values, between them the mean of
    the two neighbours, on a 3D cell's S_C (the whole period's: not its symmetric quarter)."""
    mesh = build_cell(_period(BISINUSOID), interface_maxh=0.12).mesh
    rng = np.random.default_rng(3)
    N = 8
    values = rng.standard_normal((N, N))
    cf = periodic_grid(values, 1.0)
    for j, i in ((0, 0), (3, 5), (7, 7), (N, 2), (4, N)):
        assert cf(mesh(i / N, j / N, 0.0)) == pytest.approx(values[j % N, i % N], abs=1e-12)
    assert cf(mesh(2.5 / N, 1.0 / N, 0.0)) == pytest.approx(0.5 * (values[1, 2] + values[1, 3]), abs=1e-12)
    assert cf(mesh(1.0 / N, 7.5 / N, 0.0)) == pytest.approx(0.5 * (values[7, 1] + values[0, 1]), abs=1e-12)


def test_a_twin_only_where_the_spectral_cell_solves_the_same_problem():
    """The penalty on a small-slope cell has a twin, its grid four points per interface element size (a
    power of two, within the bounds); exact enforcement, a resolved rough surface and a scene asking for
    another start (``solver.start``) have none; a spectral start without a twin is refused."""
    assert predictor_twin(BISINUSOID, 0.12).twin.grid == 64
    assert predictor_twin(BISINUSOID, 0.021).twin.grid == 256
    assert predictor_twin(BISINUSOID, 1e-4).twin.grid == TWIN_GRID[3][1]
    assert predictor_twin(BISINUSOID, 0.12).twin.friction is None
    assert predictor_twin(_scene("westergaard_exact")) is None
    assert predictor_twin(_scene("sinusoid")) is None
    assert predictor_twin(_scene("bisinusoid_surface")) is None
    for start in ("rigid", "closed"):        # the scene asks for another start
        assert predictor_twin(replace(BISINUSOID, solver=replace(BISINUSOID.solver, start=start))) is None
    with pytest.raises(ValueError, match="needs a predictor"):
        CellProblem(build_cell(BISINUSOID, interface_maxh=0.12), model_of(BISINUSOID), start="predictor")


def test_the_scene_s_start_reaches_the_cell_problem():
    """``solver.start`` through :func:`~ngcontact.drivers.build.cell_problem`: auto is the spectral start
    where the cell has a twin; rigid and closed build no twin."""
    cell = build_cell(BISINUSOID, interface_maxh=0.12)
    for start, expected in (("auto", "predictor"), ("spectral", "predictor"), ("rigid", "rigid"),
                            ("closed", "closed")):
        P = cell_problem(replace(BISINUSOID, solver=replace(BISINUSOID.solver, start=start)), cell)
        assert P.start == expected and (P.predictor is not None) == (expected == "predictor")


def test_a_failing_twin_leaves_the_rigid_start():
    """A twin whose solver stops unconverged: the load is solved from the rigid predictor (the same solution),
    and the history says why."""
    twin = predictor_twin(BISINUSOID, 0.12)
    twin.twin.max_iter = 2
    cell = build_cell(BISINUSOID, interface_maxh=0.12)
    load_ = cell_loads(BISINUSOID)[0]
    failed = CellProblem(cell, model_of(BISINUSOID), predictor=twin).solve(load_, first=True, measure=False)
    rigid = CellProblem(cell, model_of(BISINUSOID), start="rigid").solve(load_, first=True, measure=False)
    start = failed.newton[0]["start"]
    assert start["kind"] == "rigid" and "above the tolerance" in start["twin_failed"]
    assert failed.results["contact_fraction"] == rigid.results["contact_fraction"]
    assert failed.iterations == rigid.iterations


def test_a_twin_is_refused_for_a_curved_interface():
    """A twin solves the small-slope cell: a cell whose S_C is a resolved rough surface refuses one."""
    surface = _scene("bisinusoid_surface")
    with pytest.raises(ValueError, match="not flat"):
        CellProblem(build_cell(surface), model_of(surface), predictor=predictor_twin(BISINUSOID, 0.12))


def test_a_twin_contact_set_between_the_mesh_points_leaves_the_rigid_start():
    """A pressure so light that the twin touches at a point or two of its grid: no point of the FE cell's S_C
    would penetrate and the start would float; the rigid start is kept, and the load is solved as from it."""
    from ngcontact.cell.cell_load import cell_load
    scene = _scene("stem_grooves")
    P = cell_problem(scene)
    sol = P.solve(cell_load(2, pressure=5.0), first=True, measure=False)
    assert sol.newton[0]["start"]["kind"] == "rigid" and "misses every point" in sol.newton[0]["start"]["twin_failed"]
    rigid = cell_problem(replace(scene, solver=replace(scene.solver, start="rigid")), P.cell)
    again = rigid.solve(cell_load(2, pressure=5.0), first=True, measure=False)
    assert sol.iterations == again.iterations
    for key in ("contact_fraction", "mean_pressure"):
        assert sol.results[key] == pytest.approx(again.results[key], rel=1e-12)


def test_a_frictionless_sweep_starts_every_pressure_from_the_twin():
    """A frictionless sweep with a twin solves each pressure afresh from the twin (one minimizer, so the
    previous state need not be kept): the same contact fractions and pressures as the rigid start's
    continuation, and every load's history records the spectral start."""
    scene = _scene("westergaard")
    loads = cell_loads(scene)
    twin_sweep = cell_problem(scene).sweep(loads)
    continued = cell_problem(replace(scene, solver=replace(scene.solver, start="rigid"))).sweep(loads)
    for a, b in zip(continued, twin_sweep):
        assert b.newton[0]["start"]["kind"] == "spectral"
        for key in ("contact_fraction", "mean_pressure", "mean_closure"):
            assert b.results[key] == pytest.approx(a.results[key], rel=1e-9, abs=1e-15)
    assert sum(s.iterations for s in twin_sweep) < sum(s.iterations for s in continued)
