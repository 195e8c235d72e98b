"""The split energy (bodies assembled once, interface each step) is the whole form to round-off."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.drivers.build import build_cell, model_of
from ngcontact.laws.friction import Tresca
from ngcontact.scene import loader
from ngcontact.solvers.split_energy import SplitEnergy, _positions

CELLS = Path(__file__).resolve().parents[2] / "geometries" / "cells"


def _values(mat) -> np.ndarray:
    return mat.AsVector().FV().NumPy().copy()


@pytest.mark.parametrize("friction", [None, Tresca(w=1e-4, G=2e-3)])
def test_split_energy_equals_the_whole_form(friction):
    """Residual, energy and tangent of the split agree with the whole form at a random state, with part
    of the interface open and part closed, before and after the load's parameters change, without
    and with (Tresca) friction."""
    scene = loader.load(CELLS / "sinusoid.toml")
    model = dataclasses.replace(model_of(scene), friction=friction)
    P = CellProblem(build_cell(scene, maxh=0.3, interface_maxh=0.1), model)
    P.sweep([cell_load(2, pressure=0.01, shear=(0.0 if friction is None else 1e-3,))])   # partly in contact
    rng = np.random.default_rng(3)
    vec = P.gfu.vec
    vec.FV().NumPy()[:] += 1e-3 * rng.standard_normal(len(vec)) * np.max(np.abs(vec.FV().NumPy()))
    split = P.energy()
    assert isinstance(split, SplitEnergy)
    split.AssembleLinearization(P.gfu.vec.CreateVector())   # (the whole form's at the first assembly only)
    whole = P.form
    a, b = vec.CreateVector(), vec.CreateVector()
    for traction in (-0.01, -0.03):
        P.traction[1].Set(traction)
        whole.Apply(vec, a)
        split.Apply(vec, b)
        scale = np.max(np.abs(a.FV().NumPy()))
        assert np.max(np.abs(a.FV().NumPy() - b.FV().NumPy())) <= 1e-12 * scale
        e_whole, e_split = whole.Energy(vec), split.Energy(vec)
        assert e_split == pytest.approx(e_whole, rel=1e-12, abs=1e-14 * scale)
        whole.AssembleLinearization(vec)
        K_whole = _values(whole.mat)
        split.AssembleLinearization(vec)
        assert not split.assembled_whole
        K_split = _values(split.mat)
        assert np.max(np.abs(K_whole - K_split)) <= 1e-12 * np.max(np.abs(K_whole))


def test_positions_refuse_an_entry_the_whole_matrix_does_not_store():
    """A part from another space (or storage) is an error, never a silent misplacement."""
    mesh = ng.Mesh(ng.unit_square.GenerateMesh(maxh=0.5))
    V1, V2 = ng.H1(mesh, order=1), ng.H1(mesh, order=2)
    forms = []
    for V in (V1, V2):
        u, v = V.TnT()
        f = ng.BilinearForm(ng.grad(u) * ng.grad(v) * ng.dx).Assemble()
        forms.append(f.mat)
    assert np.array_equal(_positions(forms[1], forms[1]), np.arange(forms[1].nze))
    with pytest.raises(ValueError, match="the whole form's matrix does not"):
        _positions(forms[0], forms[1])


@pytest.mark.parametrize("coupled", [False, True])
def test_macro_split_equals_the_whole_form(coupled):
    """The macro energy (Coulomb friction's frozen Tresca energy) and the coupled, non-symmetric
    Coulomb residual: the split gives the whole form's residual, energy and tangent at a random
    state, with loads that are plain numbers (no parameters: ``key`` constant)."""
    from ngcontact.fem import two_body
    from ngcontact.fem.materials import isotropic
    from ngcontact.geometry import bodies as gm
    from ngcontact.laws import homogenized as il
    from ngcontact.laws.local_frame import local_frame
    from ngcontact.macro import macro_energy as ME
    from ngcontact.macro import macro_problem as M
    g = gm.block_on_plane(0.1, 0.03, 0.02, maxh=0.012)
    law = il.InterfaceLaw(normal=il.BundleLaw(weights=(5e11,), directions=((1.0, 0.0),)),
                          friction=il.Friction(mu=0.3, width=1e-7))
    prob = M.MacroProblem(
        mesh=g.mesh, setting="plane_strain", rough="block", counter="base",
        materials={"block": isotropic(10e9, 0.3), "base": isotropic(70e9, 0.2)}, law=law, order=2,
        supports=(M.Support(label="bottom", components=("x", "y")),),
        loads=(M.Load(label="top", pressure=2e6, traction=(3e5, 0.0)),), gap=1e-6)
    fes = two_body.spaces(g.mesh, "plane_strain", ("block", "base"), prob.supports, 2)
    frame = local_frame(two_body.interface_normal(g.mesh, "block", "interface"), 2)
    gfu = ng.GridFunction(fes)
    rng = np.random.default_rng(5)
    gfu.vec.FV().NumPy()[:] = 2e-6 * rng.standard_normal(len(gfu.vec))   # part open, part closed, slipping
    whole = ME.macro_energy(prob, fes, frame, coupled=coupled, G=None if coupled else ng.CF(1e5))
    split = ME.macro_energy(prob, fes, frame, coupled=coupled, G=None if coupled else ng.CF(1e5), split=True)
    a, b = gfu.vec.CreateVector(), gfu.vec.CreateVector()
    whole.Apply(gfu.vec, a)
    split.Apply(gfu.vec, b)
    assert np.max(np.abs(a.FV().NumPy() - b.FV().NumPy())) <= 1e-12 * np.max(np.abs(a.FV().NumPy()))
    if not coupled:
        assert split.Energy(gfu.vec) == pytest.approx(whole.Energy(gfu.vec), rel=1e-12)
    whole.AssembleLinearization(gfu.vec)
    K_whole = _values(whole.mat)
    split.AssembleLinearization(gfu.vec.CreateVector())      # the first assembly, the whole form's, at 0
    split.AssembleLinearization(gfu.vec)
    assert not split.assembled_whole
    assert np.max(np.abs(K_whole - _values(split.mat))) <= 1e-12 * np.max(np.abs(K_whole))
