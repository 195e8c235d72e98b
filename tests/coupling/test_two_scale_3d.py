"""The two-scale loop and the strength check on the 3D femur against the axisymmetric femur.

``geometries/femur_stem_3d_two_scale.toml`` (a quarter, order 2, 8 mm / 4 mm)
and ``geometries/femur_stem_two_scale.toml`` at the same sizes and order: the
same press fit, start law, loop and strength cell.  Both loops take their cell
responses from one groove cell, meshed at 4 um on the contact line (25
elements per period instead of 100, to keep the test short; the responses of
both tables come from the same cell, so the comparison is of the macro
problems and of the 3D sampling, frame and loads).

Tolerances, each a discretization error:

* the mean contact pressure on three bands of the interface away from the
  cone-cylinder corner and the ends (measured 0.2 %, 0.7 %, 0.5 %; allowed 2 %,
  as in ``tests/macro/test_femur_3d.py``);
* the loop: both converge after the same number of law updates and macro
  solves;
* the safety factor (eq. 78) is reached at the cone-cylinder corner, where the
  pressure is singular, in both settings: its 3D value must lie closer to the
  axisymmetric one than the axisymmetric one moves when its mesh is halved
  (measured: 3D 0.204, axisymmetric 0.219, halved 0.250);
* the mean over the seated cylinder of the cell's largest von Mises stress per
  macro point, away from the corner (measured 4 % lower in 3D for the stem,
  8 % for the bone; allowed 12 %).  The axisymmetric value moves by 1 % when
  its mesh is halved, so the difference is the 3D mesh's: of the order of the
  strain error of order 2 on a 4 mm 3D mesh (3-7 % on the coaxial fit of
  ``tests/coupling/test_interface_state_3d.py``); a refined 3D run to confirm
  it was too costly here.
"""
import os
from functools import partial

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.cell.fe.fe_cell import FECell
from ngcontact.coupling import pressure_table as PT
from ngcontact.coupling import two_scale as T
from ngcontact.drivers import run_macro as RM
from ngcontact.drivers.build import build_cell, model_of
from ngcontact.drivers.run_strength import evaluate
from ngcontact.laws import interface_energy as ie
from ngcontact.macro import macro_problem as M
from ngcontact.scene.loader import load

from fe_cells import fe_scene

pytestmark = pytest.mark.slow

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GEOMETRIES = os.path.join(ROOT, "geometries")
BANDS = {"cylinder": (0.14, 0.17), "upper cone": (0.11, 0.125), "lower cone": (0.095, 0.11)}
CORNER = 0.13     # z of the cone-cylinder corner of the stem


@pytest.fixture(scope="module")
def groove_response():
    cs = fe_scene("stem_grooves")         # the shipped cell is solved spectrally ("auto"); here its FE cell
    s = cs.solver
    cell = CellProblem(build_cell(cs, interface_maxh=4e-6), model_of(cs), rtol=s.rtol, atol=s.atol,
                       max_iter=s.max_iter)
    known: dict[float, PT.Response] = {}

    def response(p: float) -> PT.Response:
        if p not in known:
            known[p] = FECell.of(cell).response(p)
        return known[p]
    return response


def _run(name, response, **sizes):
    scene = load(os.path.join(GEOMETRIES, name))
    problem, _ = RM.problem_of(scene, RM.build_geometry(scene, **sizes), order=2)
    spec = scene.two_scale
    table = PT.CellTable(response, tol=spec.table_tol)
    with ng.TaskManager():
        out = T.couple(problem, table, tol=spec.tol, max_iter=spec.max_iter, table_min=spec.table_min,
                       solve=partial(RM.solve_scene, scene))
        strength = evaluate(scene, out.solution)
    sol = out.solution
    mesh, law = sol.problem.mesh, sol.problem.law
    p = ie.pressure(law.normal, sol.local_jump, M.gap_cf(sol.problem.gap))
    axial = ng.y if sol.problem.setting == "axisymmetric" else ng.z
    weight = 2 * np.pi * ng.x if sol.problem.setting == "axisymmetric" else ng.CF(1.0)
    header, rows = strength["table"]
    table_rows = np.array(rows, dtype=float)
    z = table_rows[:, header.index("z")]
    bands = {}
    for band, (lo, hi) in BANDS.items():
        inside = ng.IfPos(axial - lo, 1.0, 0.0) * ng.IfPos(hi - axial, 1.0, 0.0)
        force, area = (ng.Integrate(f * inside * weight, mesh, ng.BND, definedon=mesh.Boundaries("interface"),
                                    order=8) for f in (p, ng.CF(1.0)))
        sel = (z > lo) & (z < hi)
        bands[band] = {"pressure": force / area,
                       **{b: float(np.mean(table_rows[sel, header.index(f"sigma_eq_{b}")]))
                          for b in ("rough", "counter")}}
    return out, strength["results"], bands


def test_3d_two_scale_and_strength_match_the_axisymmetric_femur(groove_response):
    sizes = {"maxh": 0.008, "interface_maxh": 0.004}
    out3, st3, bands3 = _run("femur_stem_3d_two_scale.toml", groove_response)
    outa, sta, bandsa = _run("femur_stem_two_scale.toml", groove_response, **sizes)
    assert out3.solution.problem.setting == "3d" and outa.solution.problem.setting == "axisymmetric"
    # the loop: converged, with as many law updates and macro solves
    assert out3.converged and outa.converged
    assert len(out3.history) == len(outa.history) and out3.macro_solves == outa.macro_solves, \
        (out3.history, outa.history)
    for band in BANDS:
        a, b = bands3[band]["pressure"], bandsa[band]["pressure"]
        assert b > 0 and abs(a - b) <= 0.02 * b, (band, a, b)
    # strength: the critical point is the corner in both; the 3D safety factor within the axisymmetric
    # scene's own discretization error there
    for st in (st3, sta):
        assert abs(st["bodies"][st["critical_body"]]["macro_point"]["coordinates"][-1] - CORNER) < 1e-6
    assert st3["critical_body"] == sta["critical_body"]
    _, fine, _ = _run("femur_stem_two_scale.toml", groove_response, maxh=0.004, interface_maxh=0.002)
    error = abs(fine["safety_factor"] - sta["safety_factor"])
    assert abs(st3["safety_factor"] - sta["safety_factor"]) < error, (st3["safety_factor"], sta["safety_factor"],
                                                                       fine["safety_factor"])
    for body in ("rough", "counter"):
        a, b = bands3["cylinder"][body], bandsa["cylinder"][body]
        assert abs(a - b) <= 0.12 * b, (body, a, b)
