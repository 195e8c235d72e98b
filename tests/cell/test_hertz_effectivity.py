"""The graded FE cell's estimate against Hertz's cylinder (issue 35: effectivity on every oracle).

A cylinder gap ``(x - 1/2)^2 / (2R)`` in a periodic cell of period 1 pressed to Hertz half-width ``b = 0.02``
(:mod:`ngcontact.verification.hertz`).  The cell is periodic, so its exact answer is the row of cylinders
(:mod:`ngcontact.verification.periodic_hertz`), narrower than Hertz by ``(pi b)^2 / 12 = 3.3e-4`` relative: the
contact fraction ``0.0399868418``, to round-off.  Exact contact, so no penalty shifts the answer either, and
the true error is the discretization's alone; the penalty ``k_n = 1e6 E`` (slow tier) shifts it by less
than its discretization error at these tolerances.

The estimate is the larger of the orders' tail and the grading's
(:mod:`ngcontact.cell.fe.grading_estimate`).  Measured (NGCONTACT_THREADS=1): exact, tolerance 1e-2 (19 s),
error 4.6e-5, estimate 3.5e-4 (the orders' tail), effectivity 7.5; tolerance 1e-3 (28 s), 1.9e-6 against
1.4e-5, 7.4; penalty at 1e-2, 7.9e-5 against 6.2e-4 (the grading's tail at its observed ratio 0.2), 7.9.
"""
import math
from dataclasses import replace

import ngsolve as ng
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.fe.edge_grading import graded_flat_cell, solve_to_tolerance
from ngcontact.fem.materials import isotropic
from ngcontact.verification.hertz import hertz_half_width
from ngcontact.verification.moduli import e_star
from ngcontact.verification.periodic_hertz import periodic_hertz_half_width

NU, R, B = 0.3, 1.0, 0.02
LAW = isotropic(1.0, NU)
ES = e_star(1.0, NU, 1.0, NU)
P = math.pi * ES * B * B / (4 * R)            # Hertz's load of half-width B, per period


# 1e-3: two grading steps more, about 28 s on one thread (twice that under load), and the penalty: the slow tier
@pytest.mark.parametrize("tolerance, enforcement", [
    (1e-2, "exact"),
    pytest.param(1e-3, "exact", marks=pytest.mark.slow),
    pytest.param(1e-2, "penalty", marks=pytest.mark.slow),
])
def test_the_graded_estimate_bounds_its_error_within_ten_times_against_the_row_of_hertz_cylinders(tolerance,
                                                                                                     enforcement):
    assert hertz_half_width(P, R, ES) == pytest.approx(B, rel=1e-14)
    exact = 2 * periodic_hertz_half_width(P, R, ES, 1.0)
    model = CellModel(rough=LAW, counter=LAW, k_n=1e6 if enforcement == "penalty" else 1e3,
                      gap=(ng.x - 0.5) ** 2 / (2 * R), order=3, enforcement=enforcement)

    def make(vertices, order):
        cell = graded_flat_cell(1.0, 2.0, 2.0, maxh=0.3, interface_maxh=0.02, order=order, vertices=vertices)
        return CellProblem(cell, replace(model, order=order), max_iter=100)

    g = solve_to_tolerance(make, cell_load(2, pressure=P), tolerance, 0.02, 1.0, 3)
    error = abs(g.solution.results["contact_fraction"] - exact)
    estimate = g.estimate["contact_fraction"]
    assert error > 1e-9                        # the discretization's, far above the oracle's round-off
    assert estimate <= tolerance
    assert 1.0 <= estimate / error <= 10.0, (estimate, error, g.remark)
