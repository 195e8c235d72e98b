"""The separation of the epsilon study's errors into the modelling error and its discretization share
(:mod:`ngcontact.drivers.modelling_error`, :func:`ngcontact.drivers.study_epsilon.rates`), and the
three-mesh estimate (:mod:`ngcontact.drivers.richardson_tail`)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ngcontact.drivers import modelling_error as E
from ngcontact.drivers.richardson_tail import Tail, tail
from ngcontact.drivers.study_epsilon import discretization_record, estimates, rates


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


def test_the_three_mesh_estimate_is_the_geometric_tail_of_the_observed_ratio():
    # changes 0.04 then 0.01: ratio 1/4, tail 0.01 (1/4 + 1/16 + ...) = 0.01 / 3
    t = tail(0.04, 0.01)
    assert t.contracts and t.ratio == pytest.approx(0.25) and t.estimate == pytest.approx(0.01 / 3)
    # ratio 1/2: the tail is the last change itself (what the two-mesh rule takes); slower: more than it
    assert tail(0.02, 0.01).estimate == pytest.approx(0.01)
    assert tail(0.0125, 0.01).estimate == pytest.approx(0.04)
    # no contraction: the largest change, and the estimate says it is not a tail
    grown = tail(0.01, 0.03)
    assert not grown.contracts and grown.ratio == pytest.approx(3.0) and grown.estimate == 0.03
    assert tail(0.01, 0.01) == Tail(estimate=0.01, ratio=1.0, contracts=False)
    assert tail(0.0, 0.002) == Tail(estimate=0.002, ratio=None, contracts=False)
    assert tail(0.0, 0.0) == Tail(estimate=0.0, ratio=0.0, contracts=True)
    with pytest.raises(ValueError, match="norms"):
        tail(-1.0, 0.0)


def test_three_pairs_sum_the_tails_of_each_solution_s_changes():
    weights = np.array([1.0, 3.0])
    base = measures([[1.0, 0.0], [0.0, 2.0]], (10.0, 0.0), [1.0, 1.0], [4.0, 1.0])
    # the resolved solution moves by 0.04, then 0.01; the homogenized one with it by 0.04, then stops: the
    # difference does not change on the first step and does on the second, yet both solutions contract
    resolved = [E.combine(lambda r, a=a: r + a, base) for a in (0.0, 0.04, 0.05)]
    homogenized = [E.combine(lambda r, b=b: r + 0.1 + b, base) for b in (0.0, 0.04, 0.04)]
    # the homogenized probes move by 0.01, then 0.02: no contraction, its largest change stands
    for h, b in zip(homogenized, (0.0, 0.01, 0.03)):
        h["probes"] = base["probes"] + 0.1 + b
    pairs = list(zip(resolved, homogenized))
    est = estimates(pairs, weights, None)
    ref = resolved[-1]

    def moved(d):
        return E.errors(ref, E.combine(lambda r: r + d, ref), weights)

    for key in ("field", "reaction", "interface"):
        value, ratios, contracts = est[key]
        assert contracts and ratios == pytest.approx({"resolved": 0.25, "homogenized": 0.0}), key
        assert value == pytest.approx(moved(0.01)[key] / 3), key
    value, ratios, contracts = est["probe"]
    assert not contracts and ratios == pytest.approx({"resolved": 0.25, "homogenized": 2.0})
    assert value == pytest.approx(moved(0.01)["probe"] / 3 + moved(0.02)["probe"])
    # two pairs: the change of the difference between them, as before
    two = estimates(pairs[1:], weights, None)
    assert {k: v[0] for k, v in two.items()} == pytest.approx(
        E.discretization_errors(*pairs[1], *pairs[2], weights))
    assert all(v[1] is None for v in two.values())


def test_levels_whose_changes_do_not_contract_are_listed_in_the_results():
    study = SimpleNamespace(refinement=2.0, discretization_share=0.1, meshes=3)
    rows = [{"N": n, "bundle_probe_contracts": c, "bundle_field_contracts": True}
            for n, c in ((4, True), (8, False), (16, False))]
    record = discretization_record(rows, ("bundle",), study)
    assert record["meshes"] == 3 and record["largest_change"] == {"bundle": {"probe": [8, 16]}}
    assert "Richardson" in record["estimate"]
    assert discretization_record(rows, ("bundle",), SimpleNamespace(refinement=2.0, discretization_share=0.1,
                                                                    meshes=2)) == {"refinement": 2.0, "share": 0.1}
