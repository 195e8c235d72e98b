"""Observed convergence rates of the elasticity discretization (manufactured solutions).

For order ``p`` the L2 error must decay like ``h^(p+1)`` and the H1-seminorm
error like ``h^p``; the rates are least-squares slopes over three nested
levels and must lie within 0.25 of these values.  The default tier runs
orders 1 and 2 (3D: order 1); higher orders are marked slow.
"""
import numpy as np
import pytest

from ngcontact.verification import manufactured
from ngcontact.verification import rates as studies
from ngcontact.fem.materials import anisotropic, isotropic

TOLERANCE = 0.25

STEEL = isotropic(210.0, 0.3)
BONE = isotropic(17.0, 0.3)


def orthotropic():
    """An orthotropic Voigt matrix (so that the Voigt path is exercised)."""
    C = np.zeros((6, 6))
    C[:3, :3] = [[30.0, 8.0, 7.0], [8.0, 20.0, 6.0], [7.0, 6.0, 15.0]]
    C[3, 3], C[4, 4], C[5, 5] = 5.0, 6.0, 7.0
    return anisotropic(C)


LAWS = {
    "plane_strain": {"body": STEEL},
    "axisymmetric": {"body": BONE},
    "3d": {"body": STEEL},
    # two different materials, one of them anisotropic, bonded along the curved interface
    "periodic_cell": {"rough": STEEL, "counter": orthotropic()},
}

# setting -> (maxh of the generated mesh, refinements per level)
LEVELS = {
    "plane_strain": (0.25, (1, 2, 3)),
    "axisymmetric": (0.25, (1, 2, 3)),
    "3d": (1.0, (1, 2, 3)),
    "periodic_cell": (0.25, (1, 2, 3)),
}

FAST = [("plane_strain", 1), ("plane_strain", 2), ("axisymmetric", 1), ("axisymmetric", 2),
        ("periodic_cell", 1), ("periodic_cell", 2), ("3d", 1)]
SLOW = [("plane_strain", 3), ("plane_strain", 4), ("axisymmetric", 3), ("axisymmetric", 4),
        ("periodic_cell", 3), ("periodic_cell", 4), ("3d", 2), ("3d", 3)]


def observed_rates(setting, order):
    maxh, refinements = LEVELS[setting]
    if setting == "3d" and order == 1:
        refinements = (2, 3, 4)  # order 1 from one refinement on is still pre-asymptotic (rate ~1.8)
    if setting == "3d" and order == 3:
        refinements = (0, 1, 2)  # the third refinement has 80k dofs; too costly here
    level = manufactured.level_runner(setting, LAWS[setting], maxh)
    rows = studies.h_refinement(level, setting=setting, orders=(order,), maxh=maxh,
                                refinements=refinements)
    for r in rows:
        assert r["relative_residual"] < 1e-10, r
    return rows, studies.rates_by_order(rows)[order]


def check_rates(setting, order):
    rows, rates = observed_rates(setting, order)
    expected = studies.expected_rates(order)
    errors = [(r["h"], r["l2"], r["h1"]) for r in rows]
    for norm in ("l2", "h1"):
        assert abs(rates[norm] - expected[norm]) <= TOLERANCE, (
            f"{setting}, p = {order}: observed {norm} rate {rates[norm]:.3f}, expected "
            f"{expected[norm]:.0f} +- {TOLERANCE}; (h, L2, H1) = {errors}")


@pytest.mark.parametrize("setting, order", FAST)
def test_rates(setting, order):
    check_rates(setting, order)


@pytest.mark.slow
@pytest.mark.parametrize("setting, order", SLOW)
def test_rates_high_order(setting, order):
    check_rates(setting, order)


def test_fit_rate_recovers_a_power_law_and_needs_three_levels():
    h = np.array([0.1, 0.05, 0.025, 0.0125])
    assert studies.fit_rate(h, 3.0 * h ** 2.5) == pytest.approx(2.5, abs=1e-12)
    with pytest.raises(ValueError, match="at least 3"):
        studies.fit_rate(h[:2], h[:2] ** 2)
    with pytest.raises(ValueError, match="> 0"):
        studies.fit_rate(h[:3], [1.0, 0.0, 1.0])


def test_wrong_interface_load_breaks_convergence():
    """Without the traction jump the bonded two-material cell must not converge to u*."""
    rows, _ = observed_rates("periodic_cell", 2)
    maxh, refinements = LEVELS["periodic_cell"]
    prob = manufactured.problem("periodic_cell", LAWS["periodic_cell"], maxh,
                                refinements=refinements[-1], order=2)
    unloaded = manufactured.Problem(prob.setting, prob.mesh, prob.laws, prob.exact,
                                    dirichlet=prob.dirichlet, periodic=True)
    l2, _ = manufactured.errors(unloaded, manufactured.solve(unloaded, 2).gfu)
    assert l2 > 100 * rows[-1]["l2"]


def test_periodic_cell_solution_is_periodic():
    prob = manufactured.problem("periodic_cell", LAWS["periodic_cell"], 0.25, refinements=1, order=2)
    gfu = manufactured.solve(prob, 2).gfu
    mesh = prob.mesh
    for y in (-0.3, 0.2, 0.4):
        left = np.array(gfu(mesh(0.0, y)))
        right = np.array(gfu(mesh(1.0, y)))
        assert np.allclose(left, right, rtol=0, atol=1e-12), (y, left, right)


def test_interface_normal_points_from_rough_into_counter():
    import ngsolve as ng
    prob = manufactured.problem("periodic_cell", LAWS["periodic_cell"], 0.25, order=2)
    n = manufactured.interface_normal(prob)
    bnd = prob.mesh.Boundaries(prob.interface)
    # the flat parts of the interface (|x - 1/2| > 1/4) have n = +e_y
    flat = ng.IfPos(ng.x - 0.75, 1.0, 0.0) + ng.IfPos(0.25 - ng.x, 1.0, 0.0)
    assert ng.Integrate(flat * n[1], prob.mesh, ng.BND, definedon=bnd) == pytest.approx(0.5, rel=1e-10)


def test_an_order_at_round_off_is_exact_not_a_failed_rate(tmp_path):
    """Was: order 8 reproduces the smooth field to ~1e-13 on every level, the fitted 'rate' of the
    round-off is -0.2, and the report said verified: false."""
    import json
    import os

    from ngcontact import cli

    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    text = open(os.path.join(root, "geometries", "verify_elasticity.toml")).read()
    assert "orders = [1, 2, 3]" in text
    scene = tmp_path / "scene.toml"
    scene.write_text(text.replace("orders = [1, 2, 3]", "orders = [1, 8]"))
    assert cli.main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    res = json.loads((tmp_path / "out" / "report.json").read_text())["results"]
    assert res["orders_at_roundoff"] == [8] and list(res["rates"]) == ["1"]
    assert res["verified"] and abs(res["rates"]["1"]["l2"] - 2.0) < 0.05
    assert all(r["l2"] < res["roundoff_error_floor"]["l2"] for r in res["rows"] if r["order"] == 8)
