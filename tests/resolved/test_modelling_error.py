"""The separation of the epsilon study's errors into the modelling error and its discretization share
(:mod:`ngcontact.drivers.modelling_error`, :func:`ngcontact.drivers.study_epsilon.rates`), and the
three-mesh estimate (:mod:`ngcontact.drivers.richardson_tail`)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ngcontact.drivers import modelling_error as E
from ngcontact.drivers import resolved_accuracy as ra
from ngcontact.drivers.richardson_tail import Tail, of_values, tail
from ngcontact.drivers.study_epsilon import TWO_MESHES, discretization_record, estimates, rates
from ngcontact.macro import discretization_error as DE


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
    # changes 0.0125 then 0.01: ratio 0.8, slower than the presumed 1/2: tail 0.01 0.8 / 0.2, times the safety
    t = tail([0.0125, 0.01], 2.0)
    assert t.contracts and t.ratio == pytest.approx(0.8) and t.estimate == pytest.approx(1.5 * 0.04)
    # ratio 1/2: 1.5 times the last change (what the two-mesh rule presumes at r = 2)
    assert tail([0.02, 0.01], 2.0).estimate == pytest.approx(0.015)
    # faster than the presumed 1/2, the two disagree: the larger of the observed tail with the safety (0.005)
    # and the presumed bound without it (0.01 x 1)
    fast = tail([0.04, 0.01], 2.0)
    assert fast.contracts and fast.ratio == pytest.approx(0.25) and fast.estimate == pytest.approx(0.01)
    # r = 1.5, presumed 2/3: an observed 0.6 gives 1.5 x 0.006 x 1.5 = 0.0135 over the presumed 0.006 x 2
    assert tail([0.01, 0.006], 1.5).estimate == pytest.approx(1.5 * 0.006 * 1.5)
    # the two tails cross at q = 4/7 (r = 1.5): 2 d_n below, continuous through q0 = 2/3 (3 d_n there)
    assert tail([0.01, 0.004], 1.5).estimate == pytest.approx(0.004 * 2)
    assert tail([0.03, 0.02 - 1e-12], 1.5).estimate == pytest.approx(3 * 0.02)
    # the coarsest value's error adds its seen changes to both: 1.5 (0.05 + 0.01 / 3) over 0.05 + 0.01
    assert tail([0.04, 0.01], 2.0, member=0).estimate == pytest.approx(1.5 * (0.05 + 0.01 / 3))
    # no contraction: the largest change continued at the presumed contraction 1/r, and the estimate says so
    grown = tail([0.01, 0.03], 2.0)
    assert not grown.contracts and grown.ratio == pytest.approx(3.0) and grown.estimate == pytest.approx(0.045)
    assert tail([0.01, 0.03], 1.5).estimate == pytest.approx(1.5 * 0.03 * 2)
    assert tail([0.01, 0.01], 2.0) == Tail(estimate=0.015, ratio=1.0, contracts=False)
    assert tail([0.0, 0.002], 2.0) == Tail(estimate=pytest.approx(0.003), ratio=None, contracts=False)
    assert tail([0.0, 0.0], 2.0) == Tail(estimate=0.0, ratio=0.0, contracts=True)
    with pytest.raises(ValueError, match="norms"):
        tail([-1.0, 0.0], 2.0)
    with pytest.raises(ValueError, match="refinement"):
        tail([0.01], 1.0)


def test_one_rule_for_two_meshes_the_resolved_default_and_the_study():
    # one change at r = 2: the coarser value's error 3 |d| (a resolved run's default), the finer's 1.5 |d|
    assert of_values([1.0, 1.01], 2.0, member=0).estimate == pytest.approx(0.03)
    assert of_values([1.0, 1.01], 2.0).estimate == pytest.approx(0.015)
    # r = 1.5: the presumed contraction 2/3, the finer value's error 1.5 |d| (2/3) / (1/3) = 3 |d|
    assert of_values([1.0, 1.01], 1.5).estimate == pytest.approx(0.03)
    # three values: the coarsest's error adds the changes after it to the tail (ratio 0.8)
    assert of_values([1.0, 1.0125, 1.0225], 2.0, member=0).estimate == pytest.approx(1.5 * (0.0225 + 0.04))
    # round-off: 1.5 times the change, no contraction presumed
    assert of_values([1.3, 1.3 + 1e-12], 2.0, member=0, noise=1e-8).estimate == pytest.approx(1.5e-12, rel=1e-3)
    d = ra.h_step_estimate("q", DE.Sample(2.0), DE.Sample(2.1), 2)
    assert d.error == pytest.approx(of_values([2.0, 2.1], ra.HALVING, member=0).estimate) and "1.5 x |d|" in d.how


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
    est = estimates(pairs, weights, None, 2.0)
    ref = resolved[-1]

    def moved(d):
        return E.errors(ref, E.combine(lambda r: r + d, ref), weights)

    for key in ("field", "reaction", "interface"):
        value, ratios, contracts = est[key]
        assert contracts and ratios == pytest.approx({"resolved": 0.25, "homogenized": 0.0}), key
        # ratio 1/4, faster than the presumed 1/2: the presumed bound 0.01 x 1 over the observed 1.5 x 0.01 / 3
        assert value == pytest.approx(moved(0.01)[key]), key
    value, ratios, contracts = est["probe"]
    assert not contracts and ratios == pytest.approx({"resolved": 0.25, "homogenized": 2.0})
    assert value == pytest.approx(moved(0.01)["probe"] + 1.5 * moved(0.02)["probe"])
    # two pairs: from the change of the difference between them, 1.5 delta / (r - 1)
    for r in (2.0, 1.5):
        two = estimates(pairs[1:], weights, None, r)
        assert {k: v[0] for k, v in two.items()} == pytest.approx(
            {k: 1.5 * v / (r - 1) for k, v in E.discretization_errors(*pairs[1], *pairs[2], weights).items()})
    assert all(v[1] is None for v in two.values())


def test_levels_whose_changes_do_not_contract_are_listed_in_the_results():
    study = SimpleNamespace(refinement=2.0, discretization_share=0.1, meshes=3)
    rows = [{"N": n, "bundle_probe_contracts": c, "bundle_field_contracts": True}
            for n, c in ((4, True), (8, False), (16, False))]
    record = discretization_record(rows, ("bundle",), study)
    assert record["meshes"] == 3 and record["largest_change"] == {"bundle": {"probe": [8, 16]}}
    assert "Richardson" in record["estimate"]
    two = discretization_record(rows, ("bundle",), SimpleNamespace(refinement=2.0, discretization_share=0.1, meshes=2))
    assert two == {"refinement": 2.0, "share": 0.1, "estimate": TWO_MESHES} and "1.5 delta / (r - 1)" in TWO_MESHES
