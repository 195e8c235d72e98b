"""The spectral cell's fast solvers against the former ones: same answers to the tolerance, fewer steps.

Frictionless: the constrained CG preconditioned by the inverse compliance on the contact set
(:mod:`ngcontact.solvers.constrained_cg`) against the plain one.  Friction: the active-set method
(:mod:`ngcontact.solvers.active_set_newton`) against accelerated proximal gradients
(:mod:`ngcontact.solvers.projected_gradient`), exact and regularized, Tresca and Coulomb, dissimilar layers, 2D
and 3D, under a prescribed mean or a prescribed jump.  Exact Coulomb friction against the Huber-regularized law
as its width ``w`` goes to zero (paper eqs. 16-17, :mod:`ngcontact.laws.friction`).
"""
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.geometry.random_surface import self_affine
from ngcontact.laws.friction import Coulomb, Tresca

P = 0.0027              # about 8 % contact on the maps below


def _gap(dim: int, n: int) -> np.ndarray:
    z = self_affine(dim=dim, grid=n, hurst=0.8, rms_slope=0.1, rolloff=0.25, cutoff=1 / 16, seed=7)
    return z.max() - z


def _cell(dim, n, *, friction=None, enforcement="exact", **old):
    cell = SpectralCell(dim=dim, period=1.0, grid=n, rough=Layer(1.0, 0.3, 0.5), counter=Layer(3.0, 0.25, 0.3),
                        gap=_gap(dim, n), k_n=1.0 if enforcement == "exact" else 30.0, enforcement=enforcement,
                        tol=1e-10, max_iter=100000, friction=friction)
    for key, value in old.items():
        setattr(cell, key, value)
    return cell


def _solve_both(dim, n, load, **kw):
    new = _cell(dim, n, **kw).solve(load)
    old_kw = dict(preconditioned=False, friction_method="proximal")
    old = _cell(dim, n, **kw, **old_kw).solve(load)
    return new, old


def _agree(new, old, scale):
    assert np.allclose(new.fields["pressure"], old.fields["pressure"], rtol=0, atol=2e-6 * scale)
    for key in ("shear", "slip", "closure"):
        if key in old.fields:
            ref = max(float(np.max(np.abs(old.fields[key]))), 1e-300)
            assert np.allclose(new.fields[key], old.fields[key], rtol=0, atol=1e-5 * ref), key
    assert np.allclose(new.results["far_face_jump"], old.results["far_face_jump"], rtol=1e-7, atol=1e-12)
    assert new.results["contact_fraction"] == pytest.approx(old.results["contact_fraction"], rel=1e-6)


@pytest.mark.parametrize("pressure", [P / 4, P, 4 * P])
def test_preconditioned_constrained_cg_gives_the_plain_answer_in_fewer_steps(pressure):
    new, old = _solve_both(3, 64, cell_load(3, pressure=pressure))
    _agree(new, old, pressure)
    assert new.iterations < old.iterations
    # the stiffness of the contact set: the masked CG, preconditioned or not
    assert new.results["effective_stiffness"]["total"][0][0] == pytest.approx(
        old.results["effective_stiffness"]["total"][0][0], rel=1e-8)


def test_preconditioned_constrained_cg_under_a_prescribed_approach():
    cell = _cell(3, 64)
    approach = cell.solve(cell_load(3, pressure=P)).results["far_face_jump"][-1]
    new, old = _solve_both(3, 64, cell_load(3, normal_jump=approach))
    _agree(new, old, P)


def test_preconditioned_constrained_cg_needs_few_steps_on_a_random_map():
    """The step count on a 128^2 random map stays small at three loads (the plain CG takes 40 to 90)."""
    cell = _cell(3, 128)
    steps = [cell.solve(cell_load(3, pressure=p)).iterations for p in (P / 4, P, 4 * P)]
    assert max(steps) <= 40, steps


CASES = [
    (2, 256, Tresca(w=None, G=0.3 * P), "exact", (0.2 * P,)),
    (2, 256, Coulomb(w=None, mu=0.5), "exact", (0.2 * P,)),
    (2, 256, Coulomb(w=1e-4, mu=0.5), "penalty", (0.2 * P,)),
    (2, 256, Tresca(w=1e-4, G=0.3 * P), "penalty", (0.2 * P,)),
    (3, 32, Coulomb(w=None, mu=0.5), "exact", (0.2 * P, 0.05 * P)),
    (3, 32, Tresca(w=None, G=0.3 * P), "exact", (0.1 * P, -0.1 * P)),
    (3, 32, Coulomb(w=1e-4, mu=0.5), "penalty", (0.2 * P, 0.0)),
]


@pytest.mark.parametrize("dim, n, law, enforcement, shear", CASES)
def test_active_set_friction_gives_the_proximal_answer(dim, n, law, enforcement, shear):
    new, old = _solve_both(dim, n, cell_load(dim, pressure=P, shear=shear), friction=law, enforcement=enforcement)
    _agree(new, old, P)
    assert new.results["slip_fraction"] == pytest.approx(old.results["slip_fraction"], abs=2.0 / n ** (dim - 1))


def test_active_set_friction_under_a_prescribed_tangential_jump():
    law = Coulomb(w=None, mu=0.5)
    sheared = _cell(2, 256, friction=law).solve(cell_load(2, pressure=P, shear=(0.2 * P,)))
    jump = sheared.results["far_face_jump"][0]
    new, old = _solve_both(2, 256, cell_load(2, pressure=P, tangential_jump=(jump,)), friction=law)
    _agree(new, old, P)
    assert new.results["mean_traction"][0] == pytest.approx(0.2 * P, rel=1e-6)


def test_active_set_friction_needs_few_steps():
    """Exact Coulomb friction, 2D, 1024 points: a bound on the operator applications (the proximal method: 600)."""
    sol = _cell(2, 1024, friction=Coulomb(w=None, mu=0.5)).solve(cell_load(2, pressure=P, shear=(0.2 * P,)))
    assert sol.iterations <= 150, sol.iterations


def _halfspace_coulomb_steps(n: int) -> int:
    """Operator applications of exact Coulomb (``mu = 0.5``) on an elastic half-space (a layer four periods thick)
    under a rigid surface (``E = 1e12``), the map of ``scripts/spectral_friction_speed.py`` (drawn on 1024^2,
    sampled on ``n``^2), its mean pressure and a mean shear of 0.2 times it: the halfspace case of that script."""
    z = self_affine(dim=3, grid=1024, hurst=0.8, rms_slope=0.1, rolloff=0.25, cutoff=1 / 64, seed=7)[::1024 // n,
                                                                                                        ::1024 // n]
    p0 = 0.05 / (2 * (1 - 0.3 ** 2)) * 0.1
    cell = SpectralCell(dim=3, period=1.0, grid=n, rough=Layer(1.0, 0.3, 4.0), counter=Layer(1e12, 0.3, 4.0),
                        gap=z.max() - z, k_n=1.0, enforcement="exact", tol=1e-10, max_iter=100000,
                        friction=Coulomb(w=None, mu=0.5))
    sol = cell.solve(cell_load(3, pressure=p0, shear=(0.2 * p0, 0.0)))
    assert sol.residuals[-1] <= 1e-10
    return sol.iterations


def test_coulomb_steps_on_the_halfspace_grow_slowly_with_the_grid():
    """At 256^2 the coupled Newton steps raised the residual step after step while the stick and slip sets swapped
    points, until the solve gave up on them for the fixed point of Tresca problems: 363 operator applications
    against 62 at 128^2 and 177 at 512^2.  A step that raises the residual (its root mean square) is shortened
    (:func:`ngcontact.solvers.active_set_newton.active_set_newton`): at most twice the steps of 128^2."""
    coarse, fine = _halfspace_coulomb_steps(128), _halfspace_coulomb_steps(256)
    assert fine <= 2 * coarse, (coarse, fine)


@pytest.mark.parametrize("n, law, enforcement", [
    (64, Coulomb(w=None, mu=0.5), "exact"), (64, Coulomb(w=1e-4, mu=0.5), "penalty"),
    pytest.param(256, Coulomb(w=None, mu=0.5), "exact", marks=pytest.mark.slow)])
def test_3d_coulomb_converges_without_the_proximal_fallback(monkeypatch, n, law, enforcement):
    """3D Coulomb on a random map between dissimilar layers: the accelerated fixed point of Tresca problems and
    the coupled Newton steps reach the tolerance by themselves, and give the proximal method's answer (at
    256^2 the fixed point without acceleration stalled and went on with the proximal method)."""
    import ngcontact.solvers.active_set_newton as asn
    load = cell_load(3, pressure=P, shear=(0.2 * P, 0.05 * P))
    old = _cell(3, n, friction=law, enforcement=enforcement, friction_method="proximal").solve(load)

    def refused(*args, **kwargs):
        raise AssertionError("the active-set method fell back to accelerated proximal gradients")
    monkeypatch.setattr(asn, "fista", refused)
    new = _cell(3, n, friction=law, enforcement=enforcement).solve(load)
    _agree(new, old, P)
    assert new.results["slip_fraction"] == pytest.approx(old.results["slip_fraction"], abs=2.0 / n ** 2)
    assert new.iterations < old.iterations


def _slipping(sol, dim: int, mu: float) -> np.ndarray:
    """The points where the shear reaches the threshold ``mu p`` (the complement of the stick set in contact)."""
    p = np.ravel(sol.fields["pressure"])
    q = np.sqrt(np.sum(np.reshape(sol.fields["shear"], (dim - 1, -1)) ** 2, axis=0))
    return (q >= mu * p * (1 - 1e-9)) & (p > 0)


@pytest.mark.parametrize("dim, n", [(2, 256), (3, 32)])
def test_exact_coulomb_is_the_limit_of_the_huber_law(dim, n):
    """Huber Coulomb at ``w``, ``w/4``, ``w/16`` approaches exact Coulomb at first order (each quarter of the
    width divides the error by about 4; pre-asymptotic, at least 3.4 in RMS and 3 in the max norm): the
    tractions, the mean tangential jump, and the stick set (which becomes the exact one).

    The Huber law lets a sticking point slip up to ``w`` (``J_t = w q / G``); the largest slip here is about
    ``5e-4``, so ``w = 8e-6`` is already a small width.  Both laws use the same normal penalty (with exact
    normal enforcement the spectral cell drops the width), so the only difference is the friction's
    regularization.
    """
    mu, shear = 0.5, (0.2 * P,) if dim == 2 else (0.2 * P, 0.05 * P)
    load = cell_load(dim, pressure=P, shear=shear)
    exact = _cell(dim, n, friction=Coulomb(w=None, mu=mu), enforcement="penalty").solve(load)
    t_ex = np.concatenate([np.reshape(exact.fields["shear"], (dim - 1, -1)), np.ravel(exact.fields["pressure"])[None]])
    slip_ex = _slipping(exact, dim, mu)
    assert 0 < np.count_nonzero(slip_ex) < np.count_nonzero(np.ravel(exact.fields["pressure"]) > 0)
    rms, top, jump, stick = [], [], [], []
    for w in (8e-6, 2e-6, 5e-7):
        huber = _cell(dim, n, friction=Coulomb(w=w, mu=mu), enforcement="penalty").solve(load)
        t = np.concatenate([np.reshape(huber.fields["shear"], (dim - 1, -1)), np.ravel(huber.fields["pressure"])[None]])
        rms.append(float(np.sqrt(np.mean((t - t_ex) ** 2))) / P)
        top.append(float(np.max(np.abs(t - t_ex))) / P)
        jump.append(abs(huber.results["far_face_jump"][0] - exact.results["far_face_jump"][0]))
        stick.append(int(np.count_nonzero(_slipping(huber, dim, mu) != slip_ex)))
    for e in (rms, jump):
        assert e[0] > 3.4 * e[1] > 3.4 ** 2 * e[2] > 0, e
    assert top[0] > 3 * top[1] > 9 * top[2], top
    assert top[2] < 0.02, top       # the error is far above the solver's tolerance, 1e-10, and small at w/16
    assert stick[0] >= stick[1] >= stick[2] == 0, stick
