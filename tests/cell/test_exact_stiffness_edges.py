"""Exact contact's normal stiffness on the graded 2D cell is taken at the contact edges, not at the closed nodes.

Westergaard's sinusoid ``g0 = 2h sin^2(pi x)`` (period 1) between two layers twice the period deep, exact
contact, ``p/p* = 0.8``: the stiffness is the periodic flat punch's of the contact's half-width ``a``, ``pi E* /
(2 ln(1 / sin(pi a)))`` (the spectral cell meets it to 1e-7, ``tests/cell/test_graded_headline_estimates.py``).
The tangent holds the closed nodes closed, a set that ends a node spacing short of each edge; at this load
``d ln K / da = 14``, and the closed nodes alone took ``K`` 1.4e-4 low, 2.5 times its estimate
(:func:`ngcontact.cell.fe.stiffness.edge_interpolation`).
"""
import math
from dataclasses import replace

import ngsolve as ng
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.edge_grading import graded_flat_cell, solve_to_tolerance
from ngcontact.fem.materials import isotropic
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

H, NU, RATIO = 0.01, 0.3, 0.8
E_S = e_star(1.0, NU, 1.0, NU)
PSTAR = westergaard_p_star(E_S, H, 1.0)
LAW = isotropic(1.0, NU)
MODEL = CellModel(rough=LAW, counter=LAW, k_n=1e3, gap=2 * H * ng.sin(math.pi * ng.x) ** 2, order=3,
                  enforcement="exact")


def _make(vertices, order):
    cell = graded_flat_cell(1.0, 2.0, 2.0, maxh=0.3, interface_maxh=0.02, order=order, vertices=vertices)
    return CellProblem(cell, replace(MODEL, order=order), max_iter=100)


@pytest.mark.slow
def test_the_exact_stiffness_at_its_edges_is_within_its_estimate_of_the_flat_punch():
    graded = solve_to_tolerance(_make, cell_load(2, pressure=RATIO * PSTAR), 1e-4, 0.02, 1.0, 3)
    a = 0.5 * westergaard_contact_fraction(RATIO * PSTAR, PSTAR)
    punch = math.pi * E_S / (2 * math.log(1 / math.sin(math.pi * a)))
    error = abs(headline(graded.solution.results)["normal_stiffness"] / punch - 1)
    estimate = graded.estimate["normal_stiffness"]
    assert error > 1e-6                          # above the punch's own error against the cell (1e-7)
    assert 1.0 <= estimate / error <= 10.0, (estimate, error, graded.remark)
    assert graded.solution.results["effective_stiffness"]["edges"]["slope"] > 0   # the edges' record is kept
