"""The epsilon study's discretization estimates against a much finer mesh pair: the rule of
:func:`ngcontact.drivers.richardson_tail.tail` (1.5 delta / (r - 1) with two meshes; with three the observed
ratio's tail, or the bound of the presumed 1/r where larger) bounds the error of the pair it reports, on the
smallest study of the tests."""
from __future__ import annotations

from dataclasses import replace

import pytest

from ngcontact.drivers import modelling_error as E
from ngcontact.drivers import run_resolved as drv
from ngcontact.drivers import study_epsilon as S
from ngcontact.scene import loader as scene_mod
from tests.resolved.test_three_meshes import small_block

#: the oracle pair's meshes: the scene's refined by 9 (6 and 4 times finer than the reported pair's)
ORACLE = 9.0
LAWS = ("bundle", "linear")


@pytest.mark.parametrize("meshes", [2, 3])
def test_the_study_s_discretization_estimate_bounds_the_error_of_its_pair(tmp_path, meshes):
    sc = scene_mod.load(small_block(tmp_path, meshes))
    st, N = sc.study, 2
    bundle = S.cell_bundle(sc)
    row = S.level(sc, N, bundle, laws=LAWS)
    # the level's own sample points and its finest pair, then the oracle pair on the same points
    eps = drv.eps_of(sc, N)
    points, weights, body = E.sample_grid(sc, st.band * eps)
    sampling = E.body_sampling(sc, eps, st.band * drv.eps_of(sc, min(st.periods)))
    fine = S.solve_pair(S.refined(sc, st.refinement ** (meshes - 1)), N, bundle, LAWS, points, body, sampling)
    oracle = S.solve_pair(S.refined(sc, ORACLE), N, bundle, LAWS, points, body, sampling)
    assert oracle["ndof_resolved"] > 12 * fine["ndof_resolved"]
    at_oracle = replace(sampling, layer_body=oracle["layer_body"])
    effectivity = {}
    for law in LAWS:
        assert E.errors(fine["resolved"], fine["laws"][law], weights) == pytest.approx(
            {k: row[f"{law}_{k}"] for k in ("field", "reaction", "moment", "probe", "interface")}, rel=1e-9)
        true = E.discretization_errors(fine["resolved"], fine["laws"][law], oracle["resolved"],
                                       oracle["laws"][law], weights, at_oracle)
        effectivity.update({f"{law}_{k}": row[f"{law}_{k}_discretization"] / v for k, v in true.items()})
    assert len(effectivity) == 14
    # every estimate bounds its error by at most ten times (issue 35's aim): with two meshes 1.1 to 7.9, with
    # three 2.3 to 9.2, the faster observed ratios (0.24 to 0.62 against the presumed 2/3) held at the larger of
    # their tail and the presumed rate's bound
    assert all(1.0 <= e <= 10.0 for e in effectivity.values()), effectivity
    # the resolved contact fraction: 1 + 0.3 of 1.6 per period, its closed set's edges at the valleys' corners,
    # found by every mesh: the meshes agree to round-off, and so does the estimate with the oracle
    assert row["contact_fraction_resolved"] == pytest.approx(1.3, abs=1e-12)
    assert abs(oracle["contact_fraction_resolved"] - row["contact_fraction_resolved"]) <= \
        row["contact_fraction_resolved_discretization"] + 1e-12
