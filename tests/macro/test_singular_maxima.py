"""The corner check of a macro run's stress maxima (ngcontact.macro.singular_maxima): a singular maximum is
reported as mesh dependent, a smooth one (Lame's press fit) keeps an estimate with effectivity >= 1."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ngcontact.macro import discretization_error as DE
from ngcontact.macro import singular_maxima as SM

from tests.macro.test_discretization_error import _block_text, _lame_exact


def _ladder(name="von_mises_bone", error=1e3):
    return DE.Estimate(name=name, value=5.0e6, error=error, scale=5.0e6, ratio=0.2, orders=(2, 3, 4), how="ladder")


def test_a_corner_whose_stress_grows_at_every_level_makes_the_maximum_mesh_dependent():
    samples = [DE.Sample(v, (0.011, 0.18)) for v in (5.0e6, 5.01e6, 5.02e6)]
    corners = np.array([[0.0, 0.0], [0.011, 0.18]])
    near = np.array([[0.1e6, 4.9e6], [0.1e6, 5.0e6], [0.1e6, 5.1e6]])
    e = SM.judged(_ladder(), samples, near, corners, 2e-3)
    assert e.error is None and e.singular_at == pytest.approx((0.011, 0.18))
    assert "mesh dependent, singular at" in e.how
    acc = e.quantity(0.01)
    assert not acc["met"] and acc["singular_at"] == pytest.approx([0.011, 0.18])


def test_a_converging_sequence_keeps_the_larger_of_ladder_and_sequence():
    samples = [DE.Sample(v) for v in (5.0e6, 5.004e6, 5.005e6)]
    near = np.array([[4.0e6], [4.0e6], [4.0e6]])
    e = SM.judged(_ladder(error=10.0), samples, near, np.array([[0.0, 0.0]]), 2e-3)
    # the scene mesh's value is reported: the levels' move 5e3 plus the tail after the finest level
    assert e.value == 5.0e6 and e.error == pytest.approx(5e3 + 1.5 * 1e3 * 0.25 / 0.75)
    # a corner growing far below the body's maximum leaves it
    near = np.array([[1e5], [2e5], [3e5]])
    assert SM.judged(_ladder(), [DE.Sample(5e6)] * 3, near, np.array([[0.0, 0.0]]), 2e-3).error is not None


def _log_levels(a: float, b: float, levels: int = 3) -> list[float]:
    """A stress growing like ``a + b log(1/r)`` sampled at ``r ~ h_k = 2^-k h_0``: ``a + b k log 2``."""
    return [a + b * k * math.log(2.0) for k in range(levels)]


@pytest.mark.parametrize("error", [None, 10.0, 1e5, 5e6])
def test_a_corner_maximum_growing_like_log_one_over_h_is_mesh_dependent_whatever_the_ladder_says(error):
    """Constant rises per halving (log r at a corner): no limit, so no estimate, however large the ladder's
    (one as large as the whole growth once let it pass as converging)."""
    corners = np.array([[0.0, 0.0], [0.011, 0.18]])
    at = _log_levels(4.0e6, 0.2e6)
    near = np.array([[1e5, v] for v in at])
    samples = [DE.Sample(v, (0.011, 0.18), sampling=1e3) for v in at]
    e = SM.judged(_ladder(error=error), samples, near, corners, 2e-3, sampling=np.full_like(near, 1e3))
    assert e.error is None and e.singular_at == pytest.approx((0.011, 0.18)), e.how
    assert not e.quantity(0.01)["met"] and "mesh dependent, singular at" in e.how
    # the same growth of the corner alone, the body's maximum elsewhere and constant
    body = [DE.Sample(5.0e6, (0.5, 0.5), sampling=1e3)] * 3
    e = SM.judged(_ladder(error=error), body, near, corners, 2e-3)
    assert e.error is None and e.singular_at == pytest.approx((0.011, 0.18)), e.how
    # a rise at 0.8 of the last (a log r whose sample points still approach the vertex) grows too
    slowing = [4.0e6, 4.1e6, 4.18e6]
    assert SM.growing_corner(_ladder(error=error), [5e6] * 3, np.array([[v] for v in slowing])) == 0


def test_a_converging_corner_maximum_keeps_an_estimate_that_bounds_its_error():
    """Rises contracting by 2^-0.544 per halving (the slowest converging corner) or faster: a limit, and the
    reported error bounds the distance to it (the limit known: Q_inf - C rho^k)."""
    corners = np.array([[0.011, 0.18]])
    for rho in (2 ** -0.544, 0.5, 0.3):
        limit, c = 5.1e6, 0.1e6
        values = [limit - c * rho ** k for k in range(3)]
        near = np.array([[v] for v in values])
        for error in (None, 10.0):
            e = SM.judged(_ladder(error=error), [DE.Sample(v, (0.011, 0.18)) for v in values], near, corners, 2e-3)
            assert e.error is not None and e.singular_at is None, e.how
            true = limit - e.value       # the scene mesh's value is reported
            assert e.value == values[0] and 1.0 <= e.error / true <= 10.0, (rho, error, e.how)


def test_a_corners_rise_within_its_sampling_error_is_no_growth():
    """Each rise below the sampling error of the level before: a finer lattice finding the maximum, not a
    growing field; the body's maximum keeps an estimate."""
    corners = np.array([[0.011, 0.18]])
    at = _log_levels(4.0e6, 1e3)
    near = np.array([[v] for v in at])
    assert SM.growing_corner(_ladder(), [5e6] * 3, near) == 0
    assert SM.growing_corner(_ladder(), [5e6] * 3, near, np.full_like(near, 2e3)) is None
    e = SM.judged(_ladder(), [DE.Sample(v, sampling=2e3) for v in at], near, corners, 2e-3,
                  sampling=np.full_like(near, 2e3))
    assert e.error is not None and e.singular_at is None, e.how


def test_lames_press_fit_keeps_estimates_that_bound_the_error():
    """No corner of the quarter ring is singular (its straight sides are symmetry planes)."""
    from ngcontact.drivers import macro_accuracy as MA
    from ngcontact.fem.materials import isotropic
    from ngcontact.geometry import bodies as gm
    from ngcontact.laws import homogenized as il
    from ngcontact.macro import macro_problem as M
    from tests.macro import test_discretization_error as T
    order = 2
    g = gm.coaxial_plane_strain(T.A, T.B, T.C, maxh=0.3, order=order)
    sup = (M.Support(label="sym_x", components=("x",)), M.Support(label="sym_y", components=("y",)))
    prob = M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="inner", counter="outer",
                          materials={"inner": isotropic(T.E_IN, T.NU_IN), "outer": isotropic(T.E_OUT, T.NU_OUT)},
                          law=il.InterfaceLaw(normal=il.LinearLaw(kn=T.K_N)), gap=-T.DELTA, supports=sup, order=order)
    sol = M.solve(prob)

    class Scene:
        class output:
            points_per_element = 5

    def solve(problem, start):
        return M.solve(problem, start=start)
    samples = MA.order_samples(Scene, sol, solve)
    found = {e.name: e for e in SM.check(MA.estimates(samples, sol), sol, samples[order], solve)}
    for name, value in _lame_exact().items():
        e = found[name]
        assert e.error is not None and e.singular_at is None, f"{name}: {e.how}"
        assert e.error / abs(e.value - value) >= 1.0, f"{name}: {e.how}"


def test_a_block_whose_interface_ends_closed_on_its_free_side_is_mesh_dependent(tmp_path):
    """Where the interface ends on a free side while closed, the traction jumps: both bodies' maxima have no
    limit (the module's closed ends), found without the local levels."""
    from ngcontact.drivers import macro_accuracy as MA
    from ngcontact.drivers.run_macro import build_geometry, checked_equilibrium, problem_of, solve_scene
    from ngcontact.scene import loader
    path = tmp_path / "block.toml"
    path.write_text(_block_text())
    sc = loader.load(str(path))
    problem, _ = problem_of(sc, build_geometry(sc))
    sol = solve_scene(sc, problem)
    acc = MA.accuracy(sc, sol, lambda p, start: solve_scene(sc, p, start), checked_equilibrium(sol))
    q = {x["name"]: x for x in acc["quantities"]}
    assert not acc["met"] and q["von_mises_base"]["error"] is None
    # the ladder's singularity at the clamped corner stays where the ladder found it
    assert q["von_mises_base"]["singular_at"] == pytest.approx([0.02, -0.005])
    # the block's maxima: the interface ends on the block's free side while closed
    assert q["von_mises_block"]["error"] is None and "mesh dependent, singular at" in q["von_mises_block"]["how"]
    assert q["von_mises_block"]["singular_at"] == pytest.approx([0.02, 0.0])
    assert "(mesh dependent: singular at (0.02, 0))" in report_line(acc)


def report_line(acc: dict) -> str:
    from ngcontact.output import report
    return " ".join(report._error_text(q) for q in acc["quantities"])


def test_a_maximum_at_a_corner_that_neither_converges_nor_grows_is_mesh_dependent():
    samples = [DE.Sample(v, (0.011, 0.18)) for v in (6.03e6, 6.01e6, 6.04e6)]
    corners = np.array([[0.011, 0.18]])
    near = np.array([[6.03e6], [6.01e6], [6.04e6]])
    e = SM.judged(_ladder("tresca_bone"), samples, near, corners, 2e-3)
    assert e.error is None and "mesh dependent, singular at" in e.how
    # the same sequence away from every corner keeps at least its last difference
    away = [DE.Sample(s.value, (0.0, 0.1)) for s in samples]
    # (the scene mesh's value, reported, lies 1e4 from the finest level's)
    assert SM.judged(_ladder("tresca_bone"), away, near * 0.1, corners, 2e-3).error == pytest.approx(1e4 + 1.5 * 3e4)


def test_the_other_measure_of_a_singular_body_is_singular_too():
    found = [DE.Estimate(name="von_mises_bone", value=5e6, error=None, scale=5e6, ratio=0.2, orders=(2, 3, 4),
                         how="x", singular_at=(0.011, 0.18)),
             _ladder("tresca_bone"), _ladder("tresca_stem")]
    out = {e.name: e for e in SM.same_body(found)}
    assert out["tresca_bone"].error is None and out["tresca_bone"].singular_at == (0.011, 0.18)
    assert out["tresca_stem"].error is not None


def test_the_terminal_line_says_mesh_dependent():
    from ngcontact.output import report
    q = {"name": "von_mises_bone", "value": 5e6, "error": None, "relative_error": None, "singular_at": [0.011, 0.18]}
    assert report._error_text(q) == "(mesh dependent: singular at (0.011, 0.18))"
