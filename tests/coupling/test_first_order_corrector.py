"""The first-order corrector (:mod:`ngcontact.coupling.first_order_corrector`) and its cell boundary layer
(:mod:`ngcontact.coupling.cell_boundary_layer`) on cases with a closed-form ``u^1``."""
from __future__ import annotations

import math

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.coupling.cell_boundary_layer import CellBoundaryLayer, StationCell
from ngcontact.coupling.first_order_corrector import FirstOrderCorrector, extension
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.profiles import flat, profile_cell
from ngcontact.geometry.resolved_bodies import flat_blocks
from ngcontact.laws import homogenized as il
from ngcontact.macro import macro_problem as M
from ngcontact.verification.laminate import laminate_stiffness

E_R, NU_R, E_C, NU_C = 3.0, 0.3, 1.0, 0.25
K_N = 20.0


def macro_solution(law) -> M.MacroSolution:
    """Two blocks on a flat ``S_0`` (``y = 0``): bottom clamped, top pressed and sheared."""
    geo = flat_blocks(1.0, 0.5, 0.5, maxh=0.1)
    mats = {"rough": isotropic(E_R, NU_R), "counter": isotropic(E_C, NU_C)}
    supports = (M.Support(label="bottom"),)
    loads = (M.Load(label="top", traction=(0.01, -0.02)),)
    problem = M.MacroProblem(mesh=geo.mesh, setting="plane_strain", rough="rough", counter="counter",
                             materials=mats, law=il.InterfaceLaw(normal=law), supports=supports, loads=loads,
                             order=2, interface=geo.interface)
    return M.solve(problem)


@pytest.fixture(scope="module")
def linear_solution():
    return macro_solution(il.LinearLaw(kn=K_N, kt=K_N, knt=0.0))


def test_a_flat_interface_with_a_linear_law_needs_no_corrector(linear_solution):
    # the resolved bodies are the flat ones: no point lies across S_0, u^1 = 0 and u^c = u^0 exactly
    rng = np.random.default_rng(3)
    pts = np.column_stack([rng.uniform(0.05, 0.95, 40), rng.uniform(-0.3, 0.3, 40)])
    body = (pts[:, 1] > 0).astype(int)
    corrector = FirstOrderCorrector(linear_solution, eps=0.1, width=0.2)
    assert np.array_equal(corrector.at(pts, body), corrector.homogenized(pts))


def test_the_extension_across_the_interface_is_the_normal_taylor_polynomial(linear_solution):
    sol = linear_solution
    mesh = sol.problem.mesh
    # an affine field is its own extension; u^0 of the counter extended by its trace and normal derivative
    affine = ng.GridFunction(sol.u_counter.space)
    affine.Set(ng.CF((0.1 + 0.2 * ng.x - 0.3 * ng.y, -0.4 + 0.5 * ng.y)), definedon=mesh.Materials("counter"))
    below = np.array([[0.3, -0.05], [0.7, -0.02]])
    exact = np.column_stack([0.1 + 0.2 * below[:, 0] - 0.3 * below[:, 1], -0.4 + 0.5 * below[:, 1]])
    assert extension(affine, mesh, below, side=1.0, offset=1e-6) == pytest.approx(exact, rel=1e-9, abs=1e-12)


def flat_station(pressure: float, eps: float = 0.2):
    """The flat cell of period ``eps`` (two layers, an interface spring ``k_n``) under a pressure."""
    h = eps
    cell = profile_cell(flat(eps), h_rough=h, h_counter=h, maxh=eps / 4, order=2)
    model = CellModel(rough=isotropic(E_R, NU_R), counter=isotropic(E_C, NU_C), k_n=K_N, order=2)
    prob = CellProblem(cell, model)
    prob.sweep([cell_load(2, pressure=pressure)])
    comps = prob.gfu.components
    U = tuple(float(c.vec[0]) for c in comps[2:])
    return StationCell(x=0.5 * eps, mesh=cell.mesh, u_rough=comps[0], u_counter=comps[1] + ng.CF(U), period=eps,
                       h_rough=h, h_counter=h), U


def test_the_flat_laminate_cell_has_the_closed_form_far_field_and_no_boundary_layer():
    p, eps = 0.02, 0.2
    station, U = flat_station(p, eps)
    (r0, g_r), (c0, g_c) = station.far_field()
    M_r = E_R * (1 - NU_R) / ((1 + NU_R) * (1 - 2 * NU_R))
    M_c = E_C * (1 - NU_C) / ((1 + NU_C) * (1 - 2 * NU_C))
    # uniaxial strain in each layer: d_y u_y = -p / M (1e-7: the counter is read 1e-9 h inside its far face)
    assert g_r == pytest.approx([0.0, -p / M_r], rel=1e-7, abs=1e-9 * p / M_c)
    assert g_c == pytest.approx([0.0, -p / M_c], rel=1e-7, abs=1e-9 * p / M_c)
    # the far faces close by p / K_n of the laminate in series with the spring
    K = laminate_stiffness(eps, E_R, NU_R, eps, E_C, NU_C, k_n=K_N, k_t=math.inf)
    assert -c0[1] == pytest.approx(p / K[0, 0], rel=1e-8)
    # the cell's field is its far field: u^1 vanishes in both bodies
    xi = np.column_stack([np.linspace(0.01, 0.19, 7), np.linspace(-0.15, 0.15, 7)])
    body = (xi[:, 1] > 0).astype(int)
    layer = CellBoundaryLayer((station,), eps)
    assert np.max(np.abs(layer.at(xi + [[3 * eps, 0.0]], body))) < 1e-8 * p / M_c * eps


def test_a_boundary_layer_needs_stations_of_its_period():
    station, _ = flat_station(0.02, eps=0.2)
    with pytest.raises(ValueError, match="periods differ"):
        CellBoundaryLayer((station,), eps=0.1)
    with pytest.raises(ValueError, match="at least one station"):
        CellBoundaryLayer((), eps=0.2)


def test_beyond_the_cells_far_faces_the_boundary_layer_is_zero():
    station, _ = flat_station(0.02, eps=0.2)
    far = np.array([[0.05, -0.3], [0.1, 0.25]])
    assert np.array_equal(station.oscillation(far, np.array([0, 1])), np.zeros((2, 2)))
