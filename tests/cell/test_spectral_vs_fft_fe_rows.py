"""``scripts/spectral_vs_fft.py`` part 2: each FE row of the bisinusoid is the mesh its label names.

Without ``discretization.estimate = "estimate"`` the default tolerance refined every row within the 3D dof
budget, so the rows labelled ``interface_maxh 0.12`` and ``0.06`` both solved 38,826 dofs.  The row's dofs are
those of the scene's cell on the named interface mesh (:func:`ngcontact.drivers.build.cell_solver`, not solved),
and its estimate (one order more on that mesh) bounds its true error against the spectral reference, whose own
change from the grid of half its points is far below that error.
"""
import os
import sys
from dataclasses import replace

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import spectral_vs_fft as S  # noqa: E402


def test_an_fe_row_solves_its_named_mesh_and_its_estimate_bounds_its_error():
    from ngcontact.drivers.build import cell_solver
    from ngcontact.scene.loader import load
    spectral, fe = S.fe_against_spectral([0.12], quick=True)
    scene = load(os.path.join(S.ROOT, "geometries", "cells", "bisinusoid.toml"))
    named = replace(scene, discretization=replace(scene.discretization, interface_maxh=0.12))
    object.__setattr__(named, "base_dir", scene.base_dir)
    assert fe["grid_or_ndof"] == cell_solver(named).unknowns()
    assert "interface_maxh 0.12" in fe["setting"]
    assert fe["true_error"] == abs(fe["contact_fraction"] - spectral["contact_fraction"])
    assert spectral["estimate"] < 0.1 * fe["true_error"] <= 0.1 * fe["estimate"]
