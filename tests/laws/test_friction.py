"""A friction law is one class: the cell problems and the macro reduction take any law of the registry.

The laws defined here live outside the package: a constant threshold (Tresca
under another name) must give the FE cell, the spectral cell and the
homogenized friction of eqs. 42-43 exactly Tresca's numbers, and a threshold
``c + mu p`` coupled to the pressure must make the cell run its coupled solve
and slide at ``c + mu p``.  Entering a law in the registry is all a scene
needs to build it (:func:`ngcontact.drivers.build.micro_friction`).
"""
from dataclasses import dataclass
from types import SimpleNamespace
from typing import ClassVar

import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.coupling import cell_law
from ngcontact.drivers.build import micro_friction
from ngcontact.errors import ModelError
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.cell2d import flat_cell
from ngcontact.laws import friction as F
from ngcontact.scene.cell_scene import FRICTION

LAW = isotropic(1.0, 0.3)
P, W = 0.01, 1e-3


@dataclass(frozen=True, kw_only=True)
class Constant(F.FrictionLaw):
    """A constant threshold ``G``: Tresca's law under another name."""

    G: float
    name: ClassVar[str] = "constant"
    parameters: ClassVar[tuple[str, ...]] = ("G", "w")

    def threshold(self, p=None):
        return self.G


@dataclass(frozen=True, kw_only=True)
class Cohesive(F.FrictionLaw):
    """Coulomb with a cohesion: ``G = c + mu p``."""

    c: float
    mu: float
    name: ClassVar[str] = "cohesive"
    parameters: ClassVar[tuple[str, ...]] = ("c", "mu", "w")
    couples_to_pressure: ClassVar[bool] = True

    def threshold(self, p):
        return self.c + self.mu * p


@pytest.fixture(scope="module")
def cell():
    return flat_cell(maxh=0.3, order=1)


def _solve(cell, friction, **load):
    problem = CellProblem(cell, CellModel(rough=LAW, counter=LAW, k_n=1e3, order=2, friction=friction))
    (sol,) = problem.sweep([cell_load(2, pressure=P, **load)])
    return sol


def test_the_registry_names_the_laws_and_the_scene_choices():
    assert FRICTION == ("none", *F.FRICTION_LAWS)
    for name, law in F.FRICTION_LAWS.items():
        assert law.name == name
        assert set(law.parameters) <= set(law.__dataclass_fields__)
    assert not F.Tresca.couples_to_pressure and F.Coulomb.couples_to_pressure
    assert F.Tresca(G=2.0, w=W).affine_parts() == (2.0, 0.0)
    assert F.Coulomb(mu=0.3, w=W).affine_parts() == (0.0, 0.3)
    with pytest.raises(ModelError, match="width"):
        F.Tresca(G=2.0, w=0.0)
    with pytest.raises(ModelError, match="Coulomb"):
        F.Coulomb(mu=-0.1, w=W)


def test_a_law_entered_in_the_registry_is_built_from_a_scene_section(monkeypatch):
    monkeypatch.setitem(F.FRICTION_LAWS, Cohesive.name, Cohesive)
    contact = SimpleNamespace(friction="cohesive", c=0.001, mu=0.2, w=W, G=None)
    assert micro_friction(contact) == Cohesive(c=0.001, mu=0.2, w=W)
    assert micro_friction(SimpleNamespace(friction="tresca", G=0.5, w=W, mu=None)) == F.Tresca(G=0.5, w=W)
    assert micro_friction(SimpleNamespace(friction="none")) is None


@pytest.mark.parametrize("load", [{"shear": (0.5 * 0.3 * P,)}, {"tangential_jump": (-20 * W,)}],
                         ids=["stick", "slide"])
def test_a_constant_threshold_law_gives_the_fe_cell_tresca_numbers(cell, load):
    """The same numbers to round-off: two FE solves of one problem can differ in their last bits from run to
    run, so the comparison allows 1e-12 of each quantity's size."""
    a = _solve(cell, F.Tresca(G=0.3 * P, w=W), **load)
    b = _solve(cell, Constant(G=0.3 * P, w=W), **load)
    for key in ("mean_traction", "far_face_jump"):
        assert np.allclose(b.results[key], a.results[key], rtol=1e-12, atol=1e-12 * np.max(np.abs(a.results[key])))
    slip = a.surface["slip"]
    assert np.allclose(b.surface["slip"], slip, rtol=1e-12, atol=1e-12 * np.max(np.abs(slip)))


def test_a_law_coupled_to_the_pressure_runs_the_coupled_solve_and_slides_at_its_threshold(cell):
    c, mu = 0.001, 0.2
    sol = _solve(cell, Cohesive(c=c, mu=mu, w=W), tangential_jump=(-20 * W,))
    assert sol.surface["slip"].min() > W
    assert abs(sol.results["mean_traction"][0]) == pytest.approx(c + mu * P, rel=1e-8)
    # without the cohesion it is Coulomb's law
    a = _solve(cell, F.Coulomb(mu=mu, w=W), tangential_jump=(-20 * W,))
    b = _solve(cell, Cohesive(c=0.0, mu=mu, w=W), tangential_jump=(-20 * W,))
    assert b.results["mean_traction"] == pytest.approx(a.results["mean_traction"], rel=1e-12)


def test_a_constant_threshold_law_gives_the_spectral_cell_tresca_numbers():
    N = 128
    x = np.arange(N) / N
    kw = dict(dim=2, period=1.0, grid=N, rough=Layer(1, 0.3, 1), counter=Layer(2, 0.25, 0.7),
              gap=0.02 * np.sin(np.pi * x) ** 2, k_n=1e3, enforcement="penalty", tol=1e-10, max_iter=50000)
    load = cell_load(2, pressure=0.008, shear=(0.001,))
    a = SpectralCell(friction=F.Tresca(G=0.002, w=1e-5), **kw).solve(load)
    b = SpectralCell(friction=Constant(G=0.002, w=1e-5), **kw).solve(load)
    assert b.results["far_face_jump"] == a.results["far_face_jump"]
    assert np.array_equal(b.fields["pressure"], a.fields["pressure"])


def test_the_homogenized_friction_of_a_new_law_takes_its_affine_parts():
    k_n = 5.0
    ang = np.radians([0.0, 30.0, -60.0])
    ds = np.array([0.2, 0.3, 0.5])
    arrays = {"w": k_n * ds / np.cos(ang), "n": np.column_stack([np.cos(ang), np.sin(ang)])}
    tresca = cell_law.friction_from_bundle(arrays, k_n=k_n, friction=F.Tresca(G=7.0, w=W))
    assert cell_law.friction_from_bundle(arrays, k_n=k_n, friction=Constant(G=7.0, w=W)) == tresca
    coulomb = cell_law.friction_from_bundle(arrays, k_n=k_n, friction=F.Coulomb(mu=0.4, w=W))
    both = cell_law.friction_from_bundle(arrays, k_n=k_n, friction=Cohesive(c=7.0, mu=0.4, w=W))
    assert both == pytest.approx({"mu0": coulomb["mu0"], "G0": tresca["G0"]}, rel=1e-12)
