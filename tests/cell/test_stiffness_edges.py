"""The 2D penalty cell's effective stiffness takes its tangent exactly up to the contact edges
(ngcontact.cell.fe.stiffness.edge_correction): it is the derivative of the solution, not of where the
energy's rule puts the edges."""
import os
from dataclasses import replace

import pytest

from ngcontact.cell.cell_solution import headline
from ngcontact.cell.fe.fe_cell import FECell
from ngcontact.drivers.build import cell_loads, cell_problem, model_of
from ngcontact.scene.loader import load_with_contact

from fe_cells import CELLS


def _stiffness(scene, load, bonus: int) -> tuple[float, float]:
    problem = cell_problem(scene, model=replace(model_of(scene), contact_bonus_order=bonus))
    (solution,) = FECell.of(problem).sweep([load])
    head = headline(solution.results)
    return head["normal_stiffness"], head["contact_fraction"]


def test_the_stiffness_does_not_depend_on_the_rule_at_the_contact_edge():
    """Westergaard at order 2, interface_maxh 0.01, p/p* = 0.2: the contact_bonus_order of the penalty's rule
    (12, the default, against 40) moves the contact fraction by 3e-5 and, with the edge correction, the
    effective stiffness by 1.5e-4 relative; at the energy's rule alone it moved by 3.4e-3 (more than its
    error against the spectral twin, 5e-4)."""
    scene = load_with_contact(os.path.join(CELLS, "westergaard.toml"), None, "fe",
                              {"order": 2, "interface_maxh": 0.01})
    load = cell_loads(scene)[1]
    (s12, f12), (s40, f40) = (_stiffness(scene, load, b) for b in (12, 40))
    assert f40 == pytest.approx(f12, abs=1e-4)
    assert s40 == pytest.approx(s12, rel=5e-4)
