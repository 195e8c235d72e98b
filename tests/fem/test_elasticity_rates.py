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
        ("periodic_cell", 1), ("periodic_cell", 2)]
SLOW = [("plane_strain", 3), ("plane_strain", 4), ("axisymmetric", 3), ("axisymmetric", 4),
        ("periodic_cell", 3), ("periodic_cell", 4), ("3d", 1), ("3d", 2), ("3d", 3)]


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


def test_an_order_alone_at_round_off_is_exact_not_a_failed_rate(tmp_path):
    """Was: orders = [10] alone (errors of 1e-14 on every level) reported verified: false with a 'rate' of -1.4:
    the round-off floor was a fraction of the study's largest error, itself round-off."""
    import json
    import os

    from ngcontact import cli

    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    text = open(os.path.join(root, "geometries", "verify_elasticity.toml")).read()
    scene = tmp_path / "scene.toml"
    scene.write_text(text.replace("orders = [1, 2, 3]", "orders = [10]"))
    assert cli.main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    res = json.loads((tmp_path / "out" / "report.json").read_text())["results"]
    assert res["orders_at_roundoff"] == [10] and res["rates"] == {} and res["orders_without_rate"] == {}
    assert res["verified"] is True and "round-off" in res["verdict"]
    assert all(r["l2"] < res["roundoff_error_floor"]["l2"] for r in res["rows"])


def _rows(order, l2, h1):
    return [{"order": order, "level": k + 1, "h": 0.25 / 2 ** (k + 1), "l2": a, "h1": b}
            for k, (a, b) in enumerate(zip(l2, h1))]


def test_an_order_with_too_few_levels_above_round_off_says_so_instead_of_not_verified():
    """An order whose finest level sits at round-off keeps two levels: too few for a rate.  That is said
    (orders_without_rate, the verdict), it is no failed rate; with nothing else to judge the study is not
    verified, and the verdict says why."""
    h = np.array([0.125, 0.0625, 0.03125])
    rows = (_rows(1, h ** 2, h) + _rows(5, [1e-9, 1e-11, 1e-13], [1e-7, 1e-9, 1e-13])
            + _rows(10, [2e-14, 3e-14, 4e-14], [2e-13, 3e-13, 4e-13]))
    floor = {"l2": 1e-12, "h1": 1e-12}
    out = studies.judge(rows, floor, tolerance=0.25)
    assert list(out["rates"]) == [1] and out["orders_at_roundoff"] == [10] and out["orders_without_rate"] == {5: 2}
    assert out["verified"] is True
    assert "order 5: 2 of 3 levels lie above the round-off floor, too few for a rate (3 needed)" in out["verdict"]
    alone = studies.judge(_rows(5, [1e-9, 1e-11, 1e-13], [1e-7, 1e-9, 1e-13]), floor, tolerance=0.25)
    assert alone["verified"] is False and alone["rates"] == {}
    assert alone["verdict"].startswith("no order could be judged: order 5: 2 of 3 levels")
