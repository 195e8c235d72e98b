"""The separation of the epsilon study's errors into the modelling error and its discretization share
(:mod:`ngcontact.drivers.modelling_error`, :func:`ngcontact.drivers.study_epsilon.rates`)."""
from __future__ import annotations

import numpy as np
import pytest

from ngcontact.drivers import modelling_error as E
from ngcontact.drivers.study_epsilon import rates


def measures(field, reaction, probe, interface) -> dict:
    return {"field": np.asarray(field, float), "reactions": {"top": {"x": reaction[0], "y": reaction[1]}},
            "probes": np.asarray(probe, float).reshape(-1, 2), "interface": np.asarray(interface, float)}


def test_the_discretization_estimate_is_the_change_of_the_signed_difference():
    weights = np.array([1.0, 3.0])
    resolved = measures([[1.0, 0.0], [0.0, 2.0]], (10.0, 0.0), [1.0, 1.0], [4.0, 0.0])
    fine_resolved = measures([[1.1, 0.0], [0.0, 2.0]], (10.5, 0.0), [1.0, 1.2], [4.0, 1.0])
    # both solutions move by the same amount between the meshes: the difference does not change
    shift = E.combine(lambda a, b, c: a + (c - b), resolved, resolved, fine_resolved)
    assert shift["reactions"]["top"]["x"] == 10.5
    homogenized = E.combine(lambda r: r + 0.01, resolved)
    fine_homogenized = E.combine(lambda r: r + 0.01, fine_resolved)
    same = E.discretization_errors(resolved, homogenized, fine_resolved, fine_homogenized, weights)
    assert all(v == pytest.approx(0.0, abs=1e-15) for v in same.values()), same
    # the homogenized solution alone moves by d: the estimate is |d| in each error's own measure
    moved = E.combine(lambda r: r + 0.03, fine_resolved)
    est = E.discretization_errors(resolved, homogenized, fine_resolved, moved, weights)
    model = E.errors(fine_resolved, moved, weights)
    change = E.errors(fine_resolved, E.combine(lambda r: r + 0.02, fine_resolved), weights)
    assert est == pytest.approx(change, rel=1e-12)
    assert est["reaction"] == pytest.approx(0.02 * np.sqrt(2) / 10.5, rel=1e-12)
    assert model["reaction"] == pytest.approx(1.5 * est["reaction"], rel=1e-12)


def rows(errors, checks):
    return [{"N": n, "eps": 1.0 / n, "bundle_field": e, "bundle_field_discretization": c}
            for n, e, c in zip((4, 8, 16, 32), errors, checks)]


def test_rates_are_fitted_only_where_the_discretization_is_a_small_share():
    errors = [8e-3, 4e-3, 2e-3, 1e-3]
    fitted, used, refused = rates(rows(errors, [1e-5] * 4), ("bundle",))
    assert fitted["bundle"]["field"] == pytest.approx(1.0) and used["bundle"]["field"] == [4, 8, 16, 32]
    assert refused == {}
    # the finest level is the mesh's, not the model's: left out of the fit, and the rate is still 1
    fitted, used, refused = rates(rows(errors, [1e-5, 1e-5, 1e-5, 5e-4]), ("bundle",))
    assert used["bundle"]["field"] == [4, 8, 16] and fitted["bundle"]["field"] == pytest.approx(1.0)
    # two levels left: no rate, and why
    fitted, used, refused = rates(rows(errors, [1e-5, 1e-5, 1e-3, 5e-4]), ("bundle",))
    assert fitted["bundle"]["field"] is None
    assert refused["bundle"]["field"].startswith("2 level(s) qualify: at N = [16, 32] the discretization "
                                                 "estimate exceeds 0.1 of the error")


def test_an_error_at_round_off_has_no_rate_and_says_why():
    fitted, used, refused = rates(rows([2e-13, 1e-12, 3e-13, 1e-12], [1e-12] * 4), ("bundle",))
    assert fitted["bundle"]["field"] is None and used["bundle"]["field"] == []
    assert refused["bundle"]["field"] == ("the error is at round-off (1.0e-12 at most): the quantity is fixed by "
                                          "equilibrium, nothing to fit")
