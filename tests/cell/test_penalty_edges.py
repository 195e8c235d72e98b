"""A penalty's contact edges in the 2D spectral cell: the estimate of the quantities on them and the penalty's share.

Within the length ``lambda = E*/k_n`` of an edge the Winkler layer, not the bodies, carries the pressure; an edge
located on points farther away misses the part of the edge's move that lies within it
(:mod:`ngcontact.cell.spectral.contact_edges`, the penalty zone; :mod:`ngcontact.cell.penalty_share`).  Both are
held here against Westergaard's sinusoid with the same ``k_n`` on a grid whose step is well below ``lambda``.
"""
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.penalty_share import penalty_share
from ngcontact.cell.spectral.penalty_zone import PENALTY_ZONE, penalty_length
from ngcontact.cell.spectral.estimate_forms import RICHARDSON
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.refinement import sweep_to_tolerance
from ngcontact.cell.spectral.spectral_solver import SpectralCellSolver

NU, H = 0.3, 0.01
PRESSURES = (0.000863, 0.00345, 0.00863)


def _cell(n, k_n, enforcement="penalty"):
    gap = 2 * H * np.sin(np.pi * np.arange(n) / n) ** 2
    return SpectralCell(dim=2, period=1.0, grid=n, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                        gap=gap, k_n=k_n, enforcement=enforcement, tol=1e-12, max_iter=100000)


def test_the_penalty_length_is_the_bodies_plane_strain_modulus_over_k_n():
    assert penalty_length(_cell(64, 1e4)) == pytest.approx(1.0 / (1e4 * 2 * (1 - NU ** 2)))
    assert penalty_length(_cell(64, 1e4, "exact")) == 0.0


@pytest.mark.parametrize("k_n", [1e4, pytest.param(1e5, marks=pytest.mark.slow)])
def test_a_penalty_refined_to_a_tolerance_bounds_the_error_of_its_edges(k_n):
    """Refined to 1e-3, the quartic locates the edges on points farther than ``lambda`` from them: the contact
    fraction of every load is off by 0.7 ``lambda`` per edge at ``k_n = 1e4`` (8e-5) while the last differences
    show a tenth of that.  The penalty zone's floor bounds it, within ten times, and every other estimate bounds
    its error against the same cell on a grid 16 times finer (its step a fraction of ``lambda``)."""
    loads = [cell_load(2, pressure=p) for p in PRESSURES]
    refined = sweep_to_tolerance(lambda n: _cell(n, k_n), loads, 1e-3, 64, 2, 2 ** 22)
    grid = refined.history[-1]["grid"]
    reference = _cell(grid * 16, k_n).sweep(loads)
    for k, (sol, ref, est) in enumerate(zip(refined.solutions, reference, refined.estimates)):
        head, exact = headline(sol.results), headline(ref.results)
        for name in est:
            effectivity = est[name] / (abs(head[name] - exact[name]) / refined.scales[k][name])
            assert effectivity >= 1.0, (k, name, effectivity)
            if name == "contact_fraction":
                assert effectivity <= 10.0 and refined.forms[k][name] == PENALTY_ZONE, (k, effectivity)


def test_no_richardson_tail_before_the_grid_resolves_the_penalty_zone():
    """At ``k_n = 1e4`` refined to 1e-2 the heaviest load's mean closure contracts over five grids, then its
    differences turn as the step nears ``lambda``: a Richardson tail on 4096 points was 0.84 of its error against
    the same cell on 2^17 points.  On levels whose step exceeds ``lambda`` every estimate is the guarded bound,
    and bounds that error."""
    loads = [cell_load(2, pressure=PRESSURES[2])]
    refined = sweep_to_tolerance(lambda n: _cell(n, 1e4), loads, 1e-2, 64, 2, 2 ** 22)
    grid = refined.history[-1]["grid"]
    assert grid * penalty_length(_cell(grid, 1e4)) < 1.0           # the step exceeds lambda
    head, exact = headline(refined.solutions[0].results), headline(_cell(2 ** 17, 1e4).sweep(loads)[0].results)
    for name, estimate in refined.estimates[0].items():
        assert refined.forms[0][name] != RICHARDSON, name
        assert estimate >= abs(head[name] - exact[name]) / refined.scales[0][name], name


def _solver(grid, k_n, enforcement="penalty"):
    return SpectralCellSolver(_cell(grid, k_n, enforcement),
                              variant=lambda grid, k_n=k_n, enforcement=enforcement: _solver(grid, k_n, enforcement))


def test_the_penalty_share_of_the_contact_fraction_counts_the_move_within_its_length():
    """At ``k_n = 1e4`` on 16,384 points the penalized sweep minus the exact one is half the share (its edges read
    beyond ``lambda``); the share extrapolated from two softer penalties the grid resolves is that of the same
    model on 262,144 points, whose step is a fourteenth of ``lambda``, within 3 % at each load."""
    loads = [cell_load(2, pressure=p) for p in PRESSURES]
    solver = _solver(16384, 1e4)
    model = penalty_share(solver, loads, [s.results for s in solver.sweep(loads)])
    fine = [s.results["contact_fraction"] for s in _cell(2 ** 18, 1e4).sweep(loads)]
    exact = [s.results["contact_fraction"] for s in _cell(2 ** 16, 1e4, "exact").sweep(loads)]
    shares = {q["load"]: q["share"] for q in model["quantities"] if q["name"] == "contact_fraction"}
    assert "extrapolated as lambda (A ln(1/lambda) + B)" in model["how"]
    for k, share in shares.items():
        assert share == pytest.approx(fine[k] - exact[k], rel=0.03), k
