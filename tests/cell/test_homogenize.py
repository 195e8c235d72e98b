"""Homogenized coefficients (paper eqs. 34, 42-43; Examples 26 and 27) and the direction bundle."""
import math

import numpy as np
import ngsolve as ng
import pytest

from ngcontact.geometry import profiles as pr
from ngcontact.geometry.cell3d import square_hills_cell
from ngcontact.cell.coefficients import coefficients, contact_normal, direction_bundle


def _cell(profile, arrangement="conforming", order=4, h=0.1):
    return pr.profile_cell(profile, arrangement=arrangement, h_rough=1.0, h_counter=1.0,
                           maxh=0.3, interface_maxh=h, order=order)


def _faces(profile):
    """Straight faces of a polygonal profile: (length, micro normal rough -> counter)."""
    out = []
    for p in profile.pieces:
        (xa, ya), (xb, yb) = p.start, p.end
        L = math.hypot(xb - xa, yb - ya)
        out.append((L, np.array([-(yb - ya), xb - xa]) / L))   # left normal of a left-to-right chain
    return out


def _closed_form_polygon(profile):
    """Example 27 from the face lengths a_i and angles beta_i: (k_n, k_t, k_nt) / (k_n / |T|)."""
    kn = kt = knt = 0.0
    for a, n in _faces(profile):
        beta = math.atan2(n[0], n[1])           # angle between the micro normal and n0
        kn += a * math.cos(beta) ** 2
        kt += a * math.sin(beta) ** 2
        knt += a * math.cos(beta) * math.sin(beta)
    return kn, kt, knt


def _rel(a, b):
    return abs(a - b) / max(abs(b), 1e-300)


def test_example27_rectangular_valley():
    profile = pr.rectangular_valley(0.4, 0.3)
    c = coefficients(_cell(profile, order=1), kn=1.0)
    kn, kt, knt = _closed_form_polygon(profile)
    # the table: faces parallel to S_0 (plateaus 0.6 + bottom 0.4), faces normal to S_0 (2 x 0.3)
    assert (kn, kt) == pytest.approx((1.0, 0.6), rel=1e-14) and abs(knt) < 1e-15
    assert _rel(c.k_n, kn) <= 1e-8 and _rel(c.k_t, kt) <= 1e-8
    assert abs(c.k_nt) <= 1e-8 * kn and abs(c.mu) <= 1e-8


def test_example27_triangular_sawtooth():
    profile = pr.triangular_valley(30, 60)
    c = coefficients(_cell(profile, order=1), kn=1.0)
    kn, kt, knt = _closed_form_polygon(profile)
    # faces at 30 and 60 degrees spanning the unit period: a_i = d / sin beta_i
    d = 1.0 / (1 / math.tan(math.radians(30)) + 1 / math.tan(math.radians(60)))
    a1, a2 = d / math.sin(math.radians(30)), d / math.sin(math.radians(60))
    b1, b2 = math.radians(30), math.radians(60)
    assert kn == pytest.approx(a1 * math.cos(b1) ** 2 + a2 * math.cos(b2) ** 2, rel=1e-14)
    assert knt == pytest.approx(a1 * math.cos(b1) * math.sin(b1) - a2 * math.cos(b2) * math.sin(b2),
                                rel=1e-14)
    assert _rel(c.k_n, kn) <= 1e-8 and _rel(c.k_t, kt) <= 1e-8 and _rel(c.k_nt, knt) <= 1e-8
    assert _rel(c.mu, knt / kn) <= 1e-8


def test_example27_semicircular_valley():
    a = 0.3
    c = coefficients(_cell(pr.semicircular_valley(a), order=4, h=0.1), kn=1.0)
    flat = 1.0 - 2 * a
    assert _rel(c.k_n, a * math.pi / 2 + flat) <= 1e-6
    assert _rel(c.k_t, a * math.pi / 2) <= 1e-6
    assert abs(c.k_nt) <= 1e-6


def test_example26_square_hills_summit_3d():
    kn = 200e9
    cell = square_hills_cell(0.4, 0.2, arrangement="summit", h_rough=0.5, h_counter=0.4, maxh=0.3)
    c = coefficients(cell, kn=kn)
    assert _rel(c.k_n, 0.16 * kn) <= 1e-8
    assert max(abs(v) for v in c.k_t + c.k_nt) <= 1e-8 * kn
    assert c.contact_fraction == pytest.approx(0.16, rel=1e-8)


def test_square_hills_conforming_3d_tangential_stiffness():
    cell = square_hills_cell(0.4, 0.2, arrangement="conforming", h_rough=0.5, h_counter=0.4,
                             maxh=0.3)
    c = coefficients(cell, kn=1.0)
    # walls normal to x: 2 faces of 0.4 x 0.2; same for y; everything else parallel to S_0
    assert c.k_n == pytest.approx(1.0, rel=1e-10)
    assert c.k_t == pytest.approx((0.16, 0.16), rel=1e-10)
    assert c.k_nt == pytest.approx((0.0, 0.0), abs=1e-12)


@pytest.mark.parametrize("name, make, tol", [
    ("rectangular", lambda: pr.rectangular_valley(0.4, 0.3), 1e-10),
    ("sawtooth", lambda: pr.triangular_valley(30, 60), 1e-10),
    # curved: the split arcs are meshed differently; both sit within the 1e-6 of Example 27
    ("semicircular", lambda: pr.semicircular_valley(0.3), 1e-6),
])
def test_coefficients_do_not_change_under_a_shift(name, make, tol):
    profile = make()
    ref = coefficients(_cell(profile), kn=1.0, gap=0.05, G=0.5)
    for fraction in (0.21, 0.64):
        c = coefficients(_cell(pr.shifted(profile, fraction)), kn=1.0, gap=0.05, G=0.5)
        np.testing.assert_allclose(c.K0, ref.K0, rtol=0, atol=tol)
        assert (c.g_n, c.g_t, c.G_n, c.G_t) == pytest.approx((ref.g_n, ref.g_t, ref.G_n, ref.G_t),
                                                             abs=tol)


def test_summit_arrangement_coefficients_are_the_plateaus_and_shift_invariant():
    profile = pr.rectangular_valley(0.4, 0.3)
    for fraction in (0.0, 0.1, 0.75):
        c = coefficients(_cell(pr.shifted(profile, fraction), "summit", order=1), kn=3.0)
        assert c.k_n == pytest.approx(3.0 * 0.6, rel=1e-12)
        assert c.k_t == pytest.approx(0.0, abs=1e-14)


def test_gap_terms_and_friction_thresholds_rectangular():
    g0, G = 0.02, 0.7
    c = coefficients(_cell(pr.rectangular_valley(0.4, 0.3), order=1), kn=2.0, gap=g0, G=G)
    # int beta_1 ds = projected length 1; int beta_2 ds = 0 (opposite walls)
    assert c.g_n == pytest.approx(2.0 * g0, rel=1e-12)
    assert c.g_t == pytest.approx(0.0, abs=1e-14)
    # G_n: walls (|beta_2| = 1, 2 x 0.3); G_t: faces parallel to S_0 (|beta_1| = 1, length 1)
    assert c.G_n == pytest.approx(G * 0.6, rel=1e-12)
    assert c.G_t == pytest.approx(G * 1.0, rel=1e-12)


def test_real_contact_set_weight_selects_one_face():
    """Weight = indicator of the ascending face of the sawtooth (as under shear)."""
    profile = pr.triangular_valley(30, 60)
    x_bottom = profile.pieces[0].end[0]
    cell = _cell(profile, order=1)
    w = ng.IfPos(ng.x - x_bottom, 1.0, 0.0)
    c = coefficients(cell, kn=1.0, weight=w)
    a2, n2 = _faces(profile)[1]
    assert _rel(c.k_n, a2 * n2[1] ** 2) <= 1e-8
    assert _rel(c.k_nt, a2 * n2[0] * n2[1]) <= 1e-8
    assert c.mu == pytest.approx(n2[0] / n2[1], rel=1e-8)   # -tan(60 deg): the wall pushes back
    assert c.contact_fraction == pytest.approx(a2, rel=1e-8)


def test_micro_normal_points_from_rough_into_counter_2d():
    cell = _cell(pr.rectangular_valley(0.4, 0.3), order=1)
    mesh, n = cell.mesh, contact_normal(cell)
    on = mesh.Boundaries("contact")
    left, right = ng.IfPos(0.5 - ng.x, 1.0, 0.0), ng.IfPos(ng.x - 0.5, 1.0, 0.0)
    bottom = ng.IfPos(-0.15 - ng.y, 1.0, 0.0)
    # left wall x = 0.3 (rough on its left): n = +e_x; right wall: n = -e_x; bottom: n = +e_y
    assert ng.Integrate(n[0] * left, mesh, definedon=on) == pytest.approx(0.3, rel=1e-12)
    assert ng.Integrate(n[0] * right, mesh, definedon=on) == pytest.approx(-0.3, rel=1e-12)
    assert ng.Integrate(n[1] * bottom, mesh, definedon=on) == pytest.approx(0.4, rel=1e-12)
    assert ng.Integrate(n[1], mesh, definedon=on) == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("arrangement", ["summit", "conforming"])
def test_micro_normal_points_from_rough_into_counter_3d(arrangement):
    cell = square_hills_cell(0.4, 0.2, arrangement=arrangement, h_rough=0.5, h_counter=0.4,
                             maxh=0.3)
    mesh, n = cell.mesh, contact_normal(cell)
    on = mesh.Boundaries("contact")
    assert ng.Integrate(n[2], mesh, definedon=on) == pytest.approx(1.0 if arrangement ==
                                                                   "conforming" else 0.16, rel=1e-12)
    if arrangement == "conforming":
        # hill wall at x = 0.7 has the rough body on its -x side: n = +e_x there
        wall = ng.IfPos(ng.x - 0.69, 1.0, 0.0) * ng.IfPos(0.71 - ng.x, 1.0, 0.0)
        assert ng.Integrate(n[0] * wall, mesh, definedon=on) == pytest.approx(0.08, rel=1e-12)


def test_direction_bundle_reproduces_the_coefficients():
    profile = pr.semicircular_valley(0.3)
    cell = _cell(profile)
    gap = 0.01 * (1 + ng.x)
    c = coefficients(cell, kn=5.0, gap=gap, G=0.3)
    b = direction_bundle(cell, kn=5.0, gap=gap, G=0.3)
    np.testing.assert_allclose(b.stiffness(), c.K0, rtol=1e-12, atol=1e-14)
    assert np.allclose(np.linalg.norm(b.n, axis=1), 1.0)
    assert (b.w * b.n[:, 0] * b.g).sum() == pytest.approx(c.g_n, rel=1e-12)
    proj_n0 = np.sqrt(np.clip(1 - b.n[:, 0] ** 2, 0, None))
    assert (b.G * proj_n0).sum() == pytest.approx(c.G_n, rel=1e-12)
    np.testing.assert_allclose(b.g, 0.01 * (1 + b.x[:, 0]), rtol=1e-12)


def test_direction_bundle_3d_full_contact():
    cell = square_hills_cell(0.4, 0.2, arrangement="conforming", h_rough=0.5, h_counter=0.4,
                             maxh=0.3)
    b = direction_bundle(cell, kn=2.0)
    c = coefficients(cell, kn=2.0)
    np.testing.assert_allclose(b.stiffness(), c.K0, atol=1e-12)
    assert b.n.shape[1] == 3 and (b.n[:, 0] >= -1e-12).all()   # n0 = e_z component first
