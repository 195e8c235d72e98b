"""The estimate of the whole-surface coefficients (:mod:`ngcontact.cell.fe.whole_surface_error`) against
Example 27's closed forms (paper eq. 34 on the faces of the shipped valleys), through the shipped scenes.

The semicircular valley of radius ``a`` in a unit period: ``k_t = pi a / 2`` (the arc), ``k_n = pi a / 2 +
1 - 2a`` (arc and plateaus), ``|S_C| / |T| = pi a + 1 - 2a``; its order-2 arcs miss them by ~1e-6 relative,
well above round-off, so the effectivity (estimate over true error) is held to [1, 10].  The rectangular and
triangular valleys are polygons: the mesh is their surface, the coefficients exact to round-off and the
effectivity undefined; there the estimate is held to round-off instead, a few ulps of the coefficients.
"""
import math
import os

import pytest

from ngcontact.drivers import run_cell
from ngcontact.output.report import Clock
from ngcontact.scene import loader

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _accuracy(name):
    out = run_cell.run(loader.load(os.path.join(ROOT, "geometries", "cells", name)), Clock())
    return out.results["accuracy"], {q["name"]: q for q in out.results["accuracy"]["quantities"]}


def test_the_semicircular_valleys_estimate_is_between_one_and_ten_times_its_error():
    a = 0.3
    exact = {"whole_surface_k_n": math.pi * a / 2 + 1 - 2 * a, "whole_surface_k_t": math.pi * a / 2,
             "whole_surface_contact_fraction": math.pi * a + 1 - 2 * a}
    accuracy, quantities = _accuracy("ex27_semicircular.toml")
    assert accuracy["estimated"] and accuracy["met"]
    for name, value in exact.items():
        q = quantities[name]
        error = abs(q["value"] - value)
        assert error > 1e-8 * value            # the curved surface's own error, far above round-off
        assert 1.0 <= q["error"] / error <= 10.0, (name, q["error"], error)


@pytest.mark.parametrize("name", ["ex27_rectangular.toml", "ex27_triangular.toml"])
def test_a_polygonal_valleys_estimate_is_round_off(name):
    accuracy, quantities = _accuracy(name)
    assert accuracy["estimated"] and accuracy["met"]
    assert {"whole_surface_k_n", "whole_surface_k_t", "whole_surface_contact_fraction"} <= set(quantities)
    for q in quantities.values():
        assert q["error"] <= 1e-13 * q["scale"], q


def test_example_26s_square_hills_are_exact_and_their_estimate_round_off():
    """Paper Example 26, the hip coating's hills of side 0.4 touching at their summits: ``k_n0 = 0.16 k_n`` on the
    real contact set, here the whole surface of the summit arrangement (3D, geometry order 2 and 3 alike)."""
    import tomllib
    with open(os.path.join(ROOT, "geometries", "cells", "hip_hills.toml"), "rb") as f:
        data = tomllib.load(f)
    del data["load"], data["solver"]
    data["contact"].update(k_n=1.0, geometric_only=True)
    out = run_cell.run(loader.from_dict(data), Clock())
    quantities = {q["name"]: q for q in out.results["accuracy"]["quantities"]}
    assert out.results["accuracy"]["met"]
    assert quantities["whole_surface_k_n"]["value"] == pytest.approx(0.16, rel=1e-13)
    assert all(q["error"] <= 1e-13 * q["scale"] for q in quantities.values())


def test_a_coefficient_beyond_the_tolerance_or_an_unestimated_surface_is_not_met():
    from ngcontact.cell.whole_surface import verdict
    whole = {"k_n": 0.8, "k_t": 0.4, "k_nt": 0.0, "contact_fraction": 1.3}
    late = verdict(whole, {"k_n": 1e-6, "k_t": 0.02, "k_nt": 0.0, "contact_fraction": 1e-6}, 0.01, "how")
    assert not late["met"]
    # k_t's error over its group's scale (k_n = 0.8); k_nt, zero at both orders, is not listed
    (kt,) = [q for q in late["quantities"] if q["name"] == "whole_surface_k_t"]
    assert kt["controlled_error"] == pytest.approx(0.02 / 0.8) and not kt["met"]
    assert "whole_surface_k_nt" not in {q["name"] for q in late["quantities"]}
    blind = verdict(whole, None, 0.01, "no higher order")
    assert not blind["met"] and not blind["estimated"] and blind["how"] == "not estimated: no higher order"
