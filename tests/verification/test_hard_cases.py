"""Hard cases: each converges, stays finite and passes a physical check.

A tier of its own (marker ``hard``), kept out of the default tier (marker
``slow`` too, so ``pytest -m slow`` runs it).  References:

* the flat cell under a mean pressure ``p`` with periodic sides is in uniaxial
  strain, exactly for any ``nu`` and any order: the far-face jump is
  ``p (h_r / M_r + h_c / M_c + 1 / k_n)`` with the P-wave modulus
  ``M = E (1 - nu) / ((1 + nu)(1 - 2 nu))``, and the contact pressure is
  ``k_n`` times the penetration everywhere (patch test);
* Westergaard's sinusoid (:mod:`ngcontact.verification.westergaard`) for partial contact;
* the identity ``k_n0 + k_t0 = k_n |S_C| / |T|`` (trace of eq. 34) for the
  whole-surface coefficients of any profile.
"""
import math
import os

import ngsolve as ng
import numpy as np
import pytest

import ngcontact
from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
from ngcontact.laws.friction import Coulomb, Tresca
from ngcontact.geometry import profiles as pr
from ngcontact.geometry.cell2d import flat_cell
from ngcontact.cell.coefficients import coefficients
from ngcontact.fem.materials import isotropic
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

from height_map_cell import fe_height_map

pytestmark = [pytest.mark.slow, pytest.mark.hard]

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def p_wave(E, nu):
    return E * (1 - nu) / ((1 + nu) * (1 - 2 * nu))


def all_finite(sol):
    def walk(obj):
        if isinstance(obj, dict):
            return all(walk(v) for v in obj.values())
        if isinstance(obj, (list, tuple)):
            return all(walk(v) for v in obj)
        if isinstance(obj, (float, np.floating)):
            return math.isfinite(obj)
        if isinstance(obj, np.ndarray):
            return bool(np.all(np.isfinite(obj)))
        return True
    return walk(sol.results) and walk(sol.surface)


def test_penalty_sweep_on_a_flat_gap_cell():
    """k_n from 1e-2 to 1e6 E/h: penetration = p / k_n exactly; at most 5 Newton steps (observed <= 3)."""
    E, nu, h, p, g = 1.0, 0.3, 1.0, 0.01, 1e-3
    law = isotropic(E, nu)
    cell = flat_cell(h_rough=h, h_counter=h, maxh=0.25)
    kns, pens = [], []
    for c in 10.0 ** np.arange(-2, 7):
        kn = c * E / h
        P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=kn, order=2, gap=ng.CF(g)))
        sol = P.sweep([cell_load(2, pressure=p)])[0]
        assert all_finite(sol)
        assert sol.iterations <= 5, (c, sol.iterations)
        pen = sol.results["max_penetration"]
        assert kn * pen == pytest.approx(p, rel=1e-6), c
        assert sol.results["mean_closure"] - g == pytest.approx(p / kn, rel=1e-6), c
        jump = sol.results["far_face_jump"][1]
        assert jump == pytest.approx(g + p * (2 * h / p_wave(E, nu) + 1 / kn), rel=1e-9), c
        kns.append(kn)
        pens.append(pen)
    slope = np.polyfit(np.log(kns), np.log(pens), 1)[0]
    assert slope == pytest.approx(-1.0, abs=1e-6), f"penetration ~ k_n^{slope:.6f}"


def test_penalty_sweep_with_partial_contact_against_westergaard():
    """Sinusoidal gap, k_n = 1e2..1e4 E/h: contact fraction within 5 % of Westergaard,
    equilibrium kept, at most 20 Newton steps (observed 5-12 with interface_maxh = P/50).

    Above ~1e4 E/h the penalty, enforced at every quadrature point of the P2 jump,
    locks the contact edge on this mesh (fraction 0.48 instead of 0.55 at 1e6 E/h);
    that is the penalty model's own limit: exact enforcement has none
    (:func:`test_exact_contact_sweep_gives_one_contact_set_for_every_k_n`).
    """
    E, nu, h, p = 1.0, 0.3, 0.01, 0.01
    law = isotropic(E, nu)
    pstar = westergaard_p_star(e_star(E, nu, E, nu), h, 1.0)
    a_ref = westergaard_contact_fraction(p, pstar)
    cell = flat_cell(maxh=0.25, interface_maxh=0.02)
    gap = 2 * h * ng.sin(math.pi * ng.x) ** 2
    for c in (1e2, 1e3, 1e4):
        P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=c * E, order=2, gap=gap))
        sol = P.sweep([cell_load(2, pressure=p)])[0]
        assert all_finite(sol)
        assert sol.iterations <= 20, (c, sol.iterations)
        assert sol.results["mean_traction"][1] == pytest.approx(-p, rel=1e-9)
        assert sol.results["mean_pressure"] == pytest.approx(p, rel=1e-3), c
        assert sol.results["contact_fraction"] == pytest.approx(a_ref, rel=0.05), c


def test_exact_contact_sweep_gives_one_contact_set_for_every_k_n():
    """The cell above with exact enforcement, k_n (the augmentation) from 1e-2 to 1e8 E/h: one contact fraction to
    1e-8 (measured 1.3e-9), 0.66 % from Westergaard on this mesh, admissible and balanced.  The softest
    augmentations converge because Uzawa raises a slow one (18 passes at 1e-2 E/h, not converged in 500 without)."""
    E, nu, h, p, ih = 1.0, 0.3, 0.01, 0.01, 0.02
    law = isotropic(E, nu)
    pstar = westergaard_p_star(e_star(E, nu, E, nu), h, 1.0)
    cell = flat_cell(maxh=0.25, interface_maxh=ih)
    gap = 2 * h * ng.sin(math.pi * ng.x) ** 2
    fractions = []
    for c in (1e-2, 1.0, 1e2, 1e4, 1e6, 1e8):
        P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=c * E / ih, order=2, gap=gap,
                                        enforcement="exact"))
        sol = P.sweep([cell_load(2, pressure=p)])[0]
        assert all_finite(sol)
        r, uz = sol.results, sol.newton[-1]
        assert r["max_penetration"] <= 1e-10 * 2 * h, c
        # measured <= 5e-13 up to 1e2 E/h, 2e-11 at 1e4, 3e-9 to 2.7e-7 at 1e6 and 1e8 (the round-off of an
        # augmentation 1e8 times the bodies' stiffness, varying from run to run with the threads' summation order)
        balance = 1e-10 if c <= 1e4 else 1e-6
        assert r["equilibrium_error"] <= balance, c
        assert r["mean_pressure"] == pytest.approx(p, rel=balance), c
        assert uz["uzawa_iterations"] <= 30, (c, uz["uzawa_iterations"])
        assert bool(uz["uzawa_stiffened"]) == (c < 1e2), (c, uz["uzawa_stiffened"])
        fractions.append(r["contact_fraction"])
    assert max(fractions) - min(fractions) <= 1e-8 * fractions[0], fractions
    assert fractions[0] == pytest.approx(westergaard_contact_fraction(p, pstar), rel=0.01)


@pytest.mark.parametrize("E_rough, E_counter, nu, order", [(1.0, 1e4, 0.3, 2), (1e4, 1.0, 0.3, 2),
                                                           (1.0, 1.0, 0.4999, 4), (1.0, 1e4, 0.4999, 4)])
def test_stiffness_contrast_and_near_incompressibility_against_the_laminate(E_rough, E_counter, nu, order):
    """Contrast up to 1e4 and nu = 0.4999 at order 4: the uniaxial-strain laminate, to 1e-8."""
    p, kn = 0.01, 1e3
    rough, counter = isotropic(E_rough, nu), isotropic(E_counter, nu)
    cell = flat_cell(maxh=0.25)
    P = CellProblem(cell, CellModel(rough=rough, counter=counter, k_n=kn, order=order))
    sol = P.sweep([cell_load(2, pressure=p)])[0]
    assert all_finite(sol)
    assert sol.iterations <= 3
    exact = p * (1 / p_wave(E_rough, nu) + 1 / p_wave(E_counter, nu) + 1 / kn)
    assert sol.results["far_face_jump"][1] == pytest.approx(exact, rel=1e-8)
    assert sol.results["mean_pressure"] == pytest.approx(p, rel=1e-9)


@pytest.mark.parametrize("angles, width", [((85.0, 60.0), None), ((85.0, 85.0), 0.3)])
def test_sharp_valleys(angles, width):
    """Faces at 85 degrees: the trace identity of the coefficients, and a solve under
    pressure then shear that converges (at most 15 steps; observed 2-10) with equilibrium."""
    kn, p = 1e3, 0.01
    prof = pr.triangular_valley(*angles, width=width)
    lo, _ = prof.bounds
    cell = pr.profile_cell(prof, h_rough=-lo + 0.5, h_counter=0.5, maxh=0.15, interface_maxh=0.05, order=2)
    co = coefficients(cell, kn=kn)
    length = sum(math.dist(q.start, q.end) for q in prof.pieces)
    assert co.k_n + co.k_t == pytest.approx(kn * length / prof.period, rel=1e-10)
    assert co.contact_fraction == pytest.approx(length / prof.period, rel=1e-10)
    law = isotropic(1.0, 0.3)
    P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=kn, order=2))
    sols = P.sweep([cell_load(2, pressure=p, shear=(s,)) for s in (0.0, 0.002)])
    for sol, s in zip(sols, (0.0, 0.002)):
        assert all_finite(sol)
        assert sol.iterations <= 15
        assert sol.results["mean_traction"] == pytest.approx([s, -p], abs=1e-12)
        assert 0.0 < sol.results["contact_fraction"] <= length / prof.period + 1e-12


def test_tiny_and_huge_loads_scale_linearly():
    """p = 1e-9 E to 1e3 E on a flat cell without gap: the response is linear in p to 1e-9."""
    E, nu, kn = 1.0, 0.3, 1e3
    law = isotropic(E, nu)
    cell = flat_cell(maxh=0.25)
    compliance = 2 / p_wave(E, nu) + 1 / kn
    for p in (1e-9, 1e-3, 1.0, 1e3):
        P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=kn, order=2))
        sol = P.sweep([cell_load(2, pressure=p * E)])[0]
        assert all_finite(sol)
        assert sol.iterations <= 2, (p, sol.iterations)
        assert sol.results["far_face_jump"][1] == pytest.approx(p * compliance, rel=1e-9), p
        assert sol.results["max_penetration"] * kn == pytest.approx(p, rel=1e-9), p


def test_fully_open_and_fully_closed_interfaces():
    """A prescribed opening leaves the gap open (no pressure, no contact); a prescribed
    closure closes it everywhere with the laminate's pressure."""
    E, nu, kn, g = 1.0, 0.3, 1e3, 1e-3
    law = isotropic(E, nu)
    cell = flat_cell(maxh=0.25)
    P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=kn, order=2, gap=ng.CF(g)))
    opened, touching, closed = P.sweep([cell_load(2, normal_jump=-0.05), cell_load(2, normal_jump=g),
                                        cell_load(2, normal_jump=0.05)])
    for sol in (opened, touching, closed):
        assert all_finite(sol)
        assert sol.iterations <= 3
    assert opened.results["contact_fraction"] == 0.0 and opened.results["mean_pressure"] == 0.0
    # regression: the open interface made the effective stiffness a singular inverse (LinAlgError)
    assert opened.results["effective_stiffness"]["matrix"] == [[0.0]]
    assert opened.results["effective_stiffness"]["compliance"] is None
    # exactly the gap closed: touching with zero force
    assert abs(touching.results["mean_pressure"]) <= 1e-12
    assert closed.results["contact_fraction"] == pytest.approx(1.0, abs=1e-12)
    expected = (0.05 - g) / (2 / p_wave(E, nu) + 1 / kn)
    assert closed.results["mean_pressure"] == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("friction, shear", [(Tresca(w=1e-12, G=0.01), 0.005),
                                             (Coulomb(w=1e-12, mu=0.3), 0.0015)])
def test_huber_width_of_1e_12_sticks_with_slip_bounded_by_the_width(friction, shear):
    """T = G/2 < G (Tresca) and T = mu N / 2 (Coulomb) with w = 1e-12 P: stick, slip = w T / G.

    The stick stiffness G / w = 1e10 E/P puts the round-off floor of the residual at
    ~1e-8 (eps x G/w x |u|), far above rtol x the first residual; Newton stops there
    (regression: it wandered in the round-off until max_iter, already at w = 1e-9).
    """
    p = 0.01
    law = isotropic(1.0, 0.3)
    cell = flat_cell(maxh=0.25)
    P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=1e3, order=2, friction=friction))
    sol = P.sweep([cell_load(2, pressure=p, shear=(shear,))])[0]
    assert all_finite(sol)
    assert sol.iterations <= 10
    slip = np.asarray(sol.surface["slip"])
    G = friction.threshold(p)
    assert slip.max() <= friction.w
    assert slip.max() == pytest.approx(friction.w * shear / G, rel=1e-3)
    assert sol.results["mean_traction"] == pytest.approx([shear, -p], rel=1e-6)


def test_3d_cell_with_a_periodic_height_map(tmp_path):
    """The shipped height map (small-slope model) on the FE cell with the penalty, two pressures: at most 20
    Newton steps, finite, equilibrium, contact grows with the pressure."""
    path = tmp_path / "map.toml"
    path.write_text(fe_height_map(), encoding="utf-8")
    scene = ngcontact.load(str(path))
    from ngcontact.drivers.build import build_cell, model_of
    cell = build_cell(scene)
    P = CellProblem(cell, model_of(scene))
    sols = P.sweep([cell_load(3, pressure=q) for q in (0.002, 0.01)])
    for sol, q in zip(sols, (0.002, 0.01)):
        assert all_finite(sol)
        assert sol.iterations <= 20
        assert sol.results["mean_traction"][-1] == pytest.approx(-q, rel=1e-9)
        # the measured mean of k_n [J_n - g]_+ on a coarse 3D interface mesh: within 3 % (observed 1.6 %)
        assert sol.results["mean_pressure"] == pytest.approx(q, rel=0.03)
    assert 0.0 < sols[0].results["contact_fraction"] < sols[1].results["contact_fraction"] <= 1.0


@pytest.mark.parametrize("order", [1, 2, 3])
@pytest.mark.parametrize("law", ["linear", "bundle"])
def test_contact_across_the_symmetry_axis(order, law):
    """Axisymmetric: a cylinder pressed on a disc, the interface runs from r = 0 outwards.

    With ``u_r = 0`` on the sides the state is confined compression: the
    pressure ``P`` crosses the interface uniformly, right up to the axis, and
    the closure is ``P / k_n``.  Quadrature points on the axis (where ``u_r / r``
    is 0/0) must not spoil it at any order.
    """
    from ngcontact.laws import homogenized as il
    from ngcontact.macro import macro_problem as M
    from ngcontact.macro import macro_measures as MM
    from ngcontact.geometry import bodies as gm

    kn, P = 5e11, 2e6
    normal = (il.LinearLaw(kn=kn, kt=2e11) if law == "linear"
              else il.BundleLaw(weights=(kn,), directions=((1.0, 0.0),)))
    g = gm.block_on_plane(0.02, 0.03, 0.02, maxh=0.004)
    prob = M.MacroProblem(
        mesh=g.mesh, setting="axisymmetric", rough="block", counter="base",
        materials={"block": isotropic(100e9, 0.3), "base": isotropic(9e9, 0.27)},
        law=il.InterfaceLaw(normal=normal), order=order,
        supports=(M.Support(label="bottom", components=("z",)),
                  M.Support(label="block_sides", components=("r",)),
                  M.Support(label="base_sides", components=("r",))),
        loads=(M.Load(label="top", pressure=P),))
    sol = M.solve(prob)
    assert np.isfinite(sol.gfu.vec.FV().NumPy()).all()
    prof = MM.interface_profile(sol, points_per_element=4)
    assert min(prof["r"]) < 1e-3 * 0.02, "the profile must reach the axis"
    np.testing.assert_allclose(prof["pressure"], P, rtol=1e-9)
    np.testing.assert_allclose(prof["jump_n"], P / kn, rtol=1e-8)
    R = MM.resultant(sol)
    assert R["z"] == pytest.approx(-P * math.pi * 0.02 ** 2, rel=1e-9)
