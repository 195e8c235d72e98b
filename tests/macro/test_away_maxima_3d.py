"""The maxima away from the singular set in 3D and in two-scale runs (ngcontact.macro.away_maxima with
ngcontact.macro.singular_edges): a block on a clamped base has the edges where the clamp meets the free
sides and where the interface ends closed found, its base's global maximum grows with the order at the
clamp while its maximum outside the tubes converges, and the verdict counts the latter; the distance to a
singular set of points and segments; a two-scale run reports its maxima away with their estimates."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ngcontact.drivers import macro_accuracy as MA
from ngcontact.macro import away_maxima as AM
from ngcontact.macro import singular_edges as SE
from ngcontact.macro.singular_set import SingularSet
from ngcontact.output.report import accuracy_line
from ngcontact.output.report_html import accuracy_table
from ngcontact.scene import loader

#: a block (20 x 10 x 5 mm) on a base of the same footprint clamped at its bottom, pressed on its top
BLOCK_3D = """\
kind = "macro"
title = "3D block on a clamped base"

[materials.steel]
E = 210e9
nu = 0.3

[bodies]
rough = "steel"
counter = "steel"

[geometry]
shape = "file"
setting = "3d"
file = "block.step"
rough = { point = [10.0, 5.0, 2.5] }
counter = { point = [10.0, 5.0, -2.5] }

[geometry.boundaries.bottom]
plane = { point = [0.0, 0.0, -5.0], normal = [0.0, 0.0, 1.0] }

[geometry.boundaries.top]
plane = { point = [0.0, 0.0, 5.0], normal = [0.0, 0.0, 1.0] }

[interface]
law = "linear"
kn = 1e13
kt = 1e12

[[supports]]
boundary = "bottom"

[[loads]]
boundary = "top"
pressure = 1e6

[discretization]
order = 2
maxh = 0.004
"""


def _block_3d(tmp_path):
    from netgen.occ import Box, Compound, Pnt

    Compound([Box(Pnt(0, 0, 0), Pnt(20, 10, 5)), Box(Pnt(0, 0, -5), Pnt(20, 10, 0))]).WriteStep(
        str(tmp_path / "block.step"))
    path = tmp_path / "block.toml"
    path.write_text(BLOCK_3D)
    return loader.load(str(path))


def test_a_3d_clamp_edge_is_found_and_the_maximum_away_from_it_converges_with_the_order(tmp_path):
    from ngcontact.drivers.run_macro import build_geometry, problem_of, solve_scene
    from ngcontact.macro import singular_maxima as SM
    sc = _block_3d(tmp_path)
    problem, _ = problem_of(sc, build_geometry(sc))
    sol = solve_scene(sc, problem)
    ex = MA.exclusion_for(sc, sol)
    assert ex is not None and ex.radius == pytest.approx(AM.RADIUS_SHARE * 0.005) and not len(ex.points)
    curves = ex.record()["edges"]
    # the bottom's perimeter, where the clamp meets the base's free sides, and the interface's, closed
    for why, z in ((SE.CLAMPED, -0.005), (SE.CLOSED_END, 0.0)):
        mine = [c for c in curves if c["why"] == why]
        assert sum(c["length"] for c in mine) == pytest.approx(0.06), curves
        assert all(math.isclose(p[2], z, abs_tol=1e-12) for c in mine for p in c["ends"])
    assert {c["why"] for c in curves} == {SE.CLAMPED, SE.CLOSED_END}     # the convex free edges are not singular
    samples = MA.order_samples(sc, sol, lambda p, start: solve_scene(sc, p, start), exclusion=ex)
    by_order = [samples[q] for q in sorted(samples)]
    # the base's largest stress sits at its clamped corner and grows with every order; outside the tubes the
    # maximum converges: its differences shrink, and it has an estimate
    grows = [s["von_mises_counter"].value for s in by_order]
    assert grows[0] < grows[1] < grows[2] and grows[2] - grows[1] > 0.5 * (grows[1] - grows[0]), grows
    found = {e.name: e for e in MA.estimates(samples, sol)}
    assert found["von_mises_counter"].error is None
    away = found["von_mises_counter_away"]
    assert away.error is not None and away.ratio < 1.0, away.how
    for s in by_order:
        where = np.asarray(s["von_mises_counter_away"].location)
        assert ex.singular.distance(where)[0] >= ex.radius * (1 - 1e-9)       # outside the tubes or on them
    # the verdict counts the maxima away, not the global maxima (mesh dependent at the clamp or the closed end)
    settled = AM.settle(AM.inside_tubes(SM.at_closed_ends(list(found.values()), SM.closed_ends(sol)), ex), ex)
    acc = MA.verdict(settled, 0.5, None)
    q = {x["name"]: x for x in acc["quantities"]}
    for body in ("rough", "counter"):
        assert not q[f"von_mises_{body}"]["counted"] and q[f"von_mises_{body}"]["singular_at"] is not None
        assert q[f"von_mises_{body}_away"]["counted"] and q[f"von_mises_{body}_away"]["error"] is not None
    # the terminal line and the page name the singular edges
    acc["exclusion"] = ex.record()
    assert "of the singular edges (2 curves, 0.12 m: " in accuracy_line({"accuracy": acc})
    page = accuracy_table({"results": {"accuracy": acc}})
    assert "singular edge" in page and SE.CLAMPED in page


def test_the_distance_to_a_singular_set_of_points_and_segments():
    edges = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]])
    s = SingularSet(np.zeros((0, 3)), (), edges, (SE.CLAMPED, SE.CLAMPED))
    xyz = np.array([[0.5, 0.0, 0.3], [2.0, 0.5, 0.0], [-1.0, 0.0, 0.0], [0.5, 0.5, 0.0]])
    assert s.distance(xyz) == pytest.approx([0.3, 1.0, 1.0, 0.5])
    assert s.distance(xyz, upto=0.6) == pytest.approx([0.3, math.inf, math.inf, 0.5])
    rim = s.rim(0.1, 16)
    assert len(rim) and s.distance(rim) == pytest.approx(np.full(len(rim), 0.1))
    [curve] = s.curves()
    assert curve["length"] == pytest.approx(2.0) and curve["segments"] == 2
    assert sorted(map(tuple, curve["ends"])) == [(0.0, 0.0, 0.0), (1.0, 1.0, 0.0)]
    points = SingularSet.of_points(np.array([[0.0, 0.0]]), ("a re-entrant corner",))
    assert points.distance(np.array([[3.0, 4.0]])) == pytest.approx([5.0])
    assert points.rim(1.0, 8).shape == (8, 2)


#: the loop's cell and the press fit of tests/drivers/test_study_kinds.py, with a traction on the outer
#: ring's mantle, whose ends at the symmetry planes are singular points (a load with a traction ends there)
def _two_scale(tmp_path):
    from tests.drivers.test_study_kinds import two_scale_scene
    path = two_scale_scene(tmp_path, "")
    text = path.read_text().replace("[discretization]\n", '[[loads]]\nboundary = "mantle"\ntraction = [0.002, 0.0]\n'
                                                         "[discretization]\n")
    path.write_text(text)
    return loader.load(str(path))


def test_a_two_scale_run_reports_its_maxima_away_with_their_estimates(tmp_path):
    from ngcontact.drivers import run_macro as D
    from ngcontact.output.report import Clock
    out = D.run(_two_scale(tmp_path), Clock())
    acc = out.results["accuracy"]
    q = {x["name"]: x for x in acc["quantities"]}
    assert "two_scale_residual" in q and "cell_table_interpolation" in q
    ex = acc["exclusion"]
    for point in ([2.0, 0.0], [0.0, 2.0]):
        assert any(np.allclose(point, p) for p in ex["points"]), ex
    for name in ("von_mises_inner_away", "tresca_inner_away", "von_mises_outer_away", "tresca_outer_away"):
        assert q[name]["counted"] and q[name]["error"] is not None, q[name]["how"]
        assert min(math.dist(q[name]["location"], p) for p in ex["points"]) >= ex["radius"] * (1 - 1e-9)
    assert "*_away: outside" in accuracy_line(out.results)
