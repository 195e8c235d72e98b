"""Consistency of the interface energies: energy -> residual -> tangent.

Central differences of the total cell energy (elasticity plus the contact
terms of :mod:`ngcontact.laws.penalty`) along a random direction must match the
residual NGSolve derives, and central differences of the residual must match
the tangent, at states away from the kinks of ``[.]_+`` and of the Huber
function.
"""
import ngsolve as ng
import numpy as np
import pytest

from ngcontact.laws import penalty as contact
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.laws.friction import Coulomb, Tresca
from ngcontact.cell.fe.measures import sample_surface
from ngcontact.geometry.cell2d import flat_cell
from ngcontact.fem.materials import isotropic

LAW = isotropic(1.0, 0.3)
W = 1e-3


def _problem(friction):
    cell = flat_cell(maxh=0.35, order=1)
    model = CellModel(rough=LAW, counter=LAW, k_n=50.0, order=2, friction=friction)
    return CellProblem(cell, model)


def _set_state(P, slip, rng):
    """Every point closed (J_n ~ 0.02 > 0) and |J_t| near ``slip``, plus noise."""
    vec = P.gfu.vec.FV().NumPy()
    free = np.array([P.X.FreeDofs()[i] for i in range(P.X.ndof)])
    vec[:] = 0.0
    vec[free] = 1e-4 * rng.standard_normal(free.sum())
    vec[P.u_dofs[1]] = -0.02      # counter pushed down: closure 0.02
    vec[P.u_dofs[0]] = -slip      # rigid tangential shift: J_t ~ slip
    return free


def _check(P, rng, slip):
    free = _set_state(P, slip, rng)
    u = P.gfu.vec
    v = u.CreateVector()
    v.FV().NumPy()[:] = 0.0
    v.FV().NumPy()[free] = rng.standard_normal(free.sum())
    v.FV().NumPy()[P.u_dofs[1]] = 1.0
    h = 1e-6 * max(slip, 1e-3)
    up, um = u.CreateVector(), u.CreateVector()
    up.data = u + h * v
    um.data = u - h * v
    r, rp, rm, Kv = (u.CreateVector() for _ in range(4))
    P.form.Apply(u, r)
    dE = (P.form.Energy(up) - P.form.Energy(um)) / (2 * h)
    rv = ng.InnerProduct(r, v)
    assert abs(dE - rv) <= 1e-7 * abs(rv), f"energy vs residual: {dE} vs {rv}"
    P.form.Apply(up, rp)
    P.form.Apply(um, rm)
    P.form.AssembleLinearization(u)
    Kv.data = P.form.mat * v
    fd = (rp.FV().NumPy() - rm.FV().NumPy()) / (2 * h)
    kv = Kv.FV().NumPy()
    err = np.linalg.norm(fd - kv) / np.linalg.norm(kv)
    assert err <= 1e-7, f"residual vs tangent: relative error {err:.2e}"


def test_normal_penalty_consistency():
    _check(_problem(None), np.random.default_rng(1), slip=0.0)


@pytest.mark.parametrize("slip", [0.3 * W, 5 * W], ids=["stick", "slip"])
def test_tresca_consistency(slip):
    _check(_problem(Tresca(w=W, G=0.01)), np.random.default_rng(2), slip=slip)


@pytest.mark.parametrize("slip", [0.3 * W, 5 * W], ids=["stick", "slip"])
def test_coulomb_consistency(slip):
    P = _problem(Coulomb(w=W, mu=0.3))
    rng = np.random.default_rng(3)
    _set_state(P, slip, rng)
    P.coulomb_previous.vec.data = P.gfu.vec   # frozen pressure of the previous iterate: positive
    p_prev = sample_surface(P, {"p": P.pressure})["p"]
    assert p_prev.min() > 0
    _check(P, rng, slip)


def test_huber_values_and_slope():
    w = 0.2
    s = np.array([0.0, 0.1, 0.2, 0.5, 2.0])
    mesh = flat_cell(maxh=0.5).mesh
    got = [contact.huber(ng.CF(v), w)(mesh(0.5, 0.5)) for v in s]
    want = np.where(s <= w, s ** 2 / (2 * w), s - w / 2)
    assert np.allclose(got, want, rtol=1e-14, atol=1e-16)


def test_no_friction_term_when_frictionless():
    J = ng.CF((0.3, 0.1))
    n = ng.CF((0.0, 1.0))
    mesh = flat_cell(maxh=0.5).mesh
    e = contact.interface_energy(J, n, k_n=2.0)
    assert e(mesh(0.5, 0.5)) == pytest.approx(0.5 * 2.0 * 0.1 ** 2, rel=1e-15)
    with pytest.raises(ValueError):
        contact.interface_energy(J, n, k_n=2.0, friction=Tresca(w=W, G=0.01))    # no threshold


@pytest.mark.parametrize("case", ["normal", "augmented", "tresca-stick", "tresca-slip", "augmented-tresca-slip"])
def test_interface_stiffness_is_the_linearization_of_the_interface_energy(case):
    """The written-out second variation (a bilinear form of the state, assembled by ``Assemble``) equals
    NGSolve's linearization of the energy's ``Variation`` entry by entry, in stick and slip, with and
    without a multiplier (the augmented energy), at a state where some points are open and some closed."""
    friction = Tresca(w=W, G=0.01) if "tresca" in case else None
    P = _problem(friction)
    slip = 5 * W if "slip" in case else 0.3 * W
    _set_state(P, slip, np.random.default_rng(4))
    counter = ng.GridFunction(P.X.components[1])       # lifted along half of the period: open points
    counter.Set(ng.CF((0.0, 0.05 * ng.sin(2 * np.pi * ng.x))))
    P.gfu.components[1].vec.data += counter.vec
    keywords = dict(k_n=50.0, friction=friction,
                    threshold=None if friction is None else friction.threshold(None),
                    multiplier=ng.CF(0.2) if "augmented" in case else None)
    trial, test = P.X.TnT()
    s = P.gfu.components

    def jump(u):
        return u[0] - u[1] - ng.CF(tuple(u[2:]))
    ds = ng.ds("contact", bonus_intorder=4)
    automatic = ng.BilinearForm(P.X, symmetric=True)
    automatic += ng.Variation(contact.interface_energy(jump(trial), P.n, **keywords) * ds)
    automatic.AssembleLinearization(P.gfu.vec)
    written = ng.BilinearForm(P.X, symmetric=True)
    written += contact.interface_stiffness(jump(s), P.n, jump(trial), jump(test), **keywords) * ds
    written.Assemble()
    a, b = automatic.mat.AsVector().FV().NumPy(), written.mat.AsVector().FV().NumPy()
    assert np.max(np.abs(a)) > 1.0 and np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a))
    # both regimes of the case are present: closed and open points (and slipping ones in slip)
    at = sample_surface(P, {"s": contact.penetration(jump(s), P.n), "t": contact.slip_magnitude(jump(s), P.n)})
    assert at["s"].min() < 0 < at["s"].max()
    assert (at["t"].min() > W) if "slip" in case else (at["t"].max() < W)
