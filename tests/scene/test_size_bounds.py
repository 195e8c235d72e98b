"""Sizes bounded before any work (issue 36): ensemble members, spectral grids, refinement to a tolerance, and
the spectral cell's penalty.  Each case ends in exit 2, one line naming the key, the value and what is allowed,
and nothing written (``run_bad`` of :mod:`tests.scene.test_bad_input`)."""
import os

import pytest

from ngcontact.scene.cell_scene import MAX_MEMBERS
from ngcontact.scene.spectral_grid import MAX_SPECTRAL_POINTS, spectral_cost

from sinusoid_cell import sinusoid_cell
from test_bad_input import edit, run_bad

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CELLS = os.path.join(ROOT, "geometries", "cells")

SPECTRAL = sinusoid_cell()


def test_a_billion_ensemble_members_are_refused(tmp_path, capsys):
    """Was: accepted, then 'unexpected error (MemoryError)' after 45 s."""
    text = open(os.path.join(CELLS, "self_affine_ensemble.toml")).read()
    run_bad(tmp_path, capsys, edit(text, ("members = 32", "members = 1000000000")),
            f"ensemble.members = 1000000000: must lie in [2, {MAX_MEMBERS}]")


def test_the_schema_s_largest_grid_is_refused_with_its_cost(tmp_path, capsys):
    """Was: grid = 16777216 in 2D ran past 200 s."""
    memory, seconds = spectral_cost(2, 16777216)
    run_bad(tmp_path, capsys, edit(SPECTRAL, ("grid = 256", "grid = 16777216")),
            f"discretization.grid = 16777216: makes 16777216 grid points, more than {MAX_SPECTRAL_POINTS[2]}: "
            f"about {memory / 2 ** 30:.2g} GB of fields and of the order of {seconds:.2g} s per load", prefix=True)


def test_the_largest_grid_a_scene_may_use_is_within_minutes_per_load():
    for dim, grid in ((2, MAX_SPECTRAL_POINTS[2]), (3, round(MAX_SPECTRAL_POINTS[3] ** 0.5))):
        memory, seconds = spectral_cost(dim, grid)
        assert memory < 2 ** 30 and seconds < 1800


def test_a_refinement_tolerance_the_solver_cannot_resolve_is_refused_before_solving(tmp_path, capsys):
    """Was: the grid grew to 16.7M points, silent for 120 s, before 'not met'."""
    run_bad(tmp_path, capsys, edit(SPECTRAL, ("grid = 256", "grid = 256\ntolerance = 1e-12")),
            "discretization.tolerance = 1e-12: must be at least 10 x solver.rtol = 1e-09 (the grid's solutions are "
            "only that accurate, so no comparison of two grids can show less); loosen it or lower solver.rtol")


@pytest.mark.parametrize("k_n, grid, shown", [("1e-8", 256, "1e-08"), ("1e-300", 64, "1e-300")])
def test_a_spectral_penalty_so_soft_that_the_interface_holds_nothing(tmp_path, capsys, k_n, grid, shown):
    """Was: exit 3 after 10000 CG steps (k_n = 1e-8); the FE cell refused it with exit 2."""
    text = edit(SPECTRAL, ('enforcement = "exact"', 'enforcement = "penalty"'), ("k_n = 1.0e3", f"k_n = {k_n}"),
                ("grid = 256", f"grid = {grid}"))
    h = 1.0 / grid
    run_bad(tmp_path, capsys, text,
            f"contact.k_n = {shown}: k_n h / E = {float(k_n) * h:.3g} (h = {h:g} the grid step, E = 1 the softer "
            "body's modulus) must be at least 1e-08: the interface would hold nothing and the jump would dwarf "
            "the bodies; raise k_n")
