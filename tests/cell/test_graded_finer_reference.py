"""The graded FE cell's estimates against a finer solve of the same penalty model (issue 35: effectivity).

The shipped ``westergaard_graded.toml`` (penalty ``k_n = 1e6 E``) to its tolerance ``1e-4``; its penalty model has
no closed form, so the oracle is the finer solve of ``scripts/graded_effectivity.py``: graded 9 levels at order 7,
towards the answer's edges and then twice towards its own, its own error the largest of its changes from the
earlier passes and from order 6.  Where the true error exceeds that, the effectivity (estimate / error) is at
least 1, and for the quantities listed in :data:`WITHIN_TEN` at most 10 (measured: the fraction, k_n and g_n
8.5 and 6.0 at p/p* = 0.05 and 0.5; the closure 2.5 at 0.05; the stiffness 1.2 at 0.5, its orders' tail plus
its own grading's tail, the larger of the two alone 0.77 times its error).  The rest are bounded only: the
stiffness at 0.05 (42: its orders' errors +4.0e-5, +1.2e-6, -2.1e-8 change sign between the last two
orders, the last 36 times below the grading's tail of its change at order 3, an error the orders then removed;
the contact set's share it took before was 490 times its error) and the closure at 0.5 (14: its orders' errors
contract by 0.010 and then 0.0023, faster than the one observed ratio shows; both diagnosed on the recorded
levels in ``tests/cell/test_graded_recorded_levels.py``).  At p/p* = 0.8 the
finer solve's passes may swing between two edge positions 3.3e-7 apart, as far as the answer is from either:
no verdict there (seen at 0.2 too, once in three runs: :data:`SWING`).
"""
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import graded_effectivity  # noqa: E402

import ngcontact  # noqa: E402
from ngcontact.cell.cell_solution import headline, scale  # noqa: E402
from ngcontact.cell.fe.edge_grading import contact_edges  # noqa: E402
from ngcontact.drivers.build import cell_loads, fe_cell  # noqa: E402

RATE = ("contact_fraction", "coefficient_k_n", "coefficient_g_n")
#: per load (its index in the scene) the quantities whose effectivity must lie between 1 and 10
WITHIN_TEN = {0: RATE + ("mean_closure",), 2: RATE + ("normal_stiffness",)}
#: the finer solve's passes swung between two edge positions where its fraction moved by more than this (6e-7
#: where seen, at p/p* = 0.2 and 0.8; at 0.05 and 0.5 its passes agreed to 1e-8 in five runs): no verdict then
SWING = 1e-7


# about 70 s each on one thread: the load to 1e-4, then four solves of 30k dofs at order 7
@pytest.mark.slow
@pytest.mark.parametrize("k", sorted(WITHIN_TEN))
def test_the_graded_estimates_bound_their_error_within_ten_times_against_the_finer_solve(k):
    scene = ngcontact.load(graded_effectivity.SCENE)
    cell, load = fe_cell(scene), cell_loads(scene)[k]
    graded = cell.graded_solves(scene.discretization.tolerance, [load], True)[0]
    head, estimate = headline(graded.solutions[0].results), graded.estimates[0]
    assert max(estimate.values()) <= scene.discretization.tolerance
    reference, own = graded_effectivity.finer(scene, load, np.sort(contact_edges(cell.problem)))
    judged = set()
    for name, value in estimate.items():
        size = scale(name, head)
        error, resolution = abs(head[name] - reference[name]) / size, own[name] / size
        assert value >= error - resolution, (name, value, error, resolution)
        if error > resolution:
            judged.add(name)
            assert value >= error, (name, value, error)
            if name in WITHIN_TEN[k]:
                assert value <= 10.0 * error, (name, value, error)
    # the oracle resolves what is held to 10, unless its passes swung (the script's judged column says so too)
    assert set(WITHIN_TEN[k]) <= judged or own["contact_fraction"] > SWING, (judged, WITHIN_TEN[k], own)
