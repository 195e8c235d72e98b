"""The spectral refinement's estimate against the true error of the grid it reports (issue 35's effectivity).

Each oracle is refined as a run refines it (:func:`~ngcontact.cell.spectral.refinement.sweep_to_tolerance`)
and the estimate of each load's contact fraction (absolute), mean closure (relative) and coefficients of
eq. 34 on the real contact set (relative to their whole-surface values) on the reported grid is held
against its difference from the same cell's value on a grid 16 (2D) or 4 (3D, per direction; 8 in the
slow tier) times finer: the layers have finite depth, so the converged value is the cell's own.
There the estimate bounds the error (effectivity at least 1).  Its upper side, at most 10 times the error,
holds where the errors fall geometrically (the sequences built here) and on Westergaard's sinusoid past the
change of its edge locator; on the oracles it fails where the reported grid's error is small by chance or
falls faster than the differences before it show (``scripts/spectral_effectivity.py`` lists them,
``docs/benchmarks.md``).
"""
import numpy as np
import pytest

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral.estimate_forms import GUARDED, RICHARDSON, tail_estimate
from ngcontact.cell.spectral.refinement import ORDER_RATE, sweep_to_tolerance
from ngcontact.geometry.random_surface import self_affine

NU, H = 0.3, 0.01
#: the penalty of the cell whose 2D stiffness (the collocated set's) lags the other quantities
K_N = 3e3
QUANTITIES = (("contact_fraction", False), ("mean_closure", True))


def _cell(dim, gap, n):
    return SpectralCell(dim=dim, period=1.0, grid=n, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                        gap=gap(n), k_n=1e3, enforcement="exact", tol=1e-12, max_iter=100000)


def _westergaard(n):
    return 2 * H * np.sin(np.pi * np.arange(n) / n) ** 2


PROFILE = self_affine(dim=2, grid=64, hurst=0.8, rms_slope=0.1, seed=5)


def _random_profile(n):
    closed = np.append(PROFILE, PROFILE[0])
    return np.interp(np.arange(n) / n, np.arange(65) / 64, closed.max() - closed)


def _bisinusoid(n):
    s = np.arange(n) / n
    return H * (2 - np.cos(2 * np.pi * s[None, :]) - np.cos(2 * np.pi * s[:, None]))


def effectivities(dim, gap, pressures, first, tolerance, finer):
    """Per load and quantity ``(estimate, true error)`` of the reported grid, and that grid."""
    loads = [cell_load(dim, pressure=p) for p in pressures]
    refined = sweep_to_tolerance(lambda n: _cell(dim, gap, n), loads, tolerance, first, dim, 2 ** 22)
    grid = refined.history[-1]["grid"]
    reference = _cell(dim, gap, grid * finer).sweep(loads)
    out = []
    for k, (sol, ref, est) in enumerate(zip(refined.solutions, reference, refined.estimates)):
        for name, relative in QUANTITIES:
            exact = ref.results[name]
            error = abs(sol.results[name] - exact) / (abs(exact) if relative else 1.0)
            out.append((name, est[name], error))
        # the coefficients of eq. 34 on the real contact set, relative to their whole-surface values
        head, fine = headline(sol.results), headline(ref.results)
        for name in (n for n in est if n.startswith("coefficient_")):
            out.append((name, est[name], abs(head[name] - fine[name]) / refined.scales[k][name]))
    return out, grid


ORACLES = {"westergaard": (2, _westergaard, (0.000863, 0.00345, 0.00863), 64, 16),
           "random_profile": (2, _random_profile, (0.001, 0.003, 0.01), 64, 16),
           "bisinusoid_3d": (3, _bisinusoid, (0.001, 0.004, 0.01), 8, 4)}


@pytest.mark.parametrize("oracle", sorted(ORACLES))
def test_the_estimate_bounds_the_error_of_the_reported_grid(oracle):
    dim, gap, pressures, first, finer = ORACLES[oracle]
    rows, grid = effectivities(dim, gap, pressures, first, 2e-2 if dim == 3 else 1e-2, finer)
    assert grid >= first * 8                       # four levels at least
    for name, estimate, error in rows:
        assert estimate >= error, (oracle, name, estimate, error)


@pytest.mark.slow
@pytest.mark.parametrize("oracle, tolerance", [("westergaard", 1e-4), ("random_profile", 1e-3),
                                               ("bisinusoid_3d", 1e-2)])
def test_the_estimate_bounds_the_error_at_tighter_tolerances(oracle, tolerance):
    dim, gap, pressures, first, finer = ORACLES[oracle]
    first, finer = (16, 8) if dim == 3 else (first, finer)
    rows, _ = effectivities(dim, gap, pressures, first, tolerance, finer)
    for name, estimate, error in rows:
        assert estimate >= error, (oracle, name, estimate, error)


def test_a_vanished_last_difference_is_bounded_by_the_one_before():
    """A symmetric coincidence (the same value on two grids) estimates from the earlier differences."""
    estimate, form, remark = tail_estimate([0.40, 0.50, 0.52, 0.52], relative=False)
    # differences 0.1, 0.02, 0: the envelope is the largest of 0, 0.02 / 2 and 0.1 / 4, at the floor 1/2
    assert form == GUARDED and estimate == pytest.approx(0.1 / 4) and "vanished" in remark


def test_disagreeing_rates_take_the_guarded_bound_at_the_larger_ratio():
    # differences 0.4, 0.04, 0.028: ratios 0.1 and 0.7 disagree; the larger, 0.7, is the rate
    estimate, form, _ = tail_estimate([1.0, 1.4, 1.44, 1.468], relative=False)
    assert form == GUARDED and estimate == pytest.approx(0.4 / 4 * 0.7 / 0.3)


def test_a_last_contraction_twice_as_fast_as_the_one_before_is_bounded_on_the_levels_since():
    """Differences 0.1, 0.005, 2e-5: the last contraction (0.004) is far faster than the one before (0.05), a
    regime set in at the level before (module docstring of :mod:`~ngcontact.cell.spectral.estimate_forms`).  The
    bound is taken on the levels since: the difference before the last shrunk by twice the contraction before
    it, ``0.005 * 0.1``, at first order beyond, not the first difference carried at first order (``0.1 / 4``);
    the estimate from coarser grids (``regime`` off) keeps the whole window's envelope."""
    values = [1.0, 1.1, 1.105, 1.10502]
    estimate, form, remark = tail_estimate(values, relative=False)
    assert form == GUARDED and estimate == pytest.approx(0.005 * 0.1) and "the levels since" in remark
    assert tail_estimate(values, relative=False, regime=False)[0] == pytest.approx(0.1 / 4)
    # the contraction before (0.4) at least 1/4: the difference before the last shrunk at first order, the first
    # difference dropped (its first-order term, 1 / 4, is the larger), the tail at the slower rate, 0.4 held to 1/2
    estimate, form, _ = tail_estimate([0.0, 1.0, 1.4, 1.44], relative=False)
    assert form == GUARDED and estimate == pytest.approx(0.4 / 2)
    assert tail_estimate([0.0, 1.0, 1.4, 1.44], relative=False, regime=False)[0] == pytest.approx(1.0 / 4)
    # a last contraction less than twice as fast as the one before: the whole window's envelope
    estimate, _, remark = tail_estimate([1.0, 1.1, 1.14, 1.16], relative=False)
    assert estimate == pytest.approx(max(0.02, 0.04 / 2, 0.1 / 4) * 0.5 / 0.5) and "the levels since" not in remark


def _geometric(rate, exact=1.0, size=0.01, levels=5):
    return [exact + size * rate ** k for k in range(levels)]


@pytest.mark.parametrize("name, rate", [("contact_fraction", 0.3), ("contact_fraction", 0.2), ("mean_closure", 0.3),
                                        ("mean_closure", 0.25)])
def test_a_geometric_sequence_takes_richardson_at_its_observed_rate(name, rate):
    """Where the window's two ratios agree the estimate is Richardson's tail at the observed rate (at least the
    quantity's order), times the spread: on an exactly geometric error it is between 1 and 10 times that
    error, and below the guarded bound."""
    values = _geometric(rate)
    relative = name == "mean_closure"
    estimate, form, remark = tail_estimate(values, relative, ORDER_RATE[name])
    d = abs(values[-1] - values[-2]) / (values[-1] if relative else 1.0)
    used = max(rate, ORDER_RATE[name])
    assert form == RICHARDSON and remark == f"rate {used:.2g}"
    assert estimate == pytest.approx(2.0 * d * used / (1 - used))
    error = abs(values[-1] - 1.0)                 # the exact value is 1: absolute and relative alike
    assert 1.0 <= estimate / error <= 10.0


def test_a_slow_geometric_sequence_keeps_the_guarded_bound_where_that_is_smaller():
    # a contact fraction contracting by 0.6: Richardson's tail times 2, 3 d, exceeds the guarded d * 0.6 / 0.4
    values = _geometric(0.6)
    estimate, form, _ = tail_estimate(values, False, ORDER_RATE["contact_fraction"])
    d = values[-2] - values[-1]
    assert form == GUARDED and estimate == pytest.approx(d * 0.6 / 0.4)
    assert estimate >= abs(values[-1] - 1.0)


@pytest.mark.parametrize("name", ["contact_fraction", "mean_closure"])
def test_richardson_never_assumes_a_rate_faster_than_the_quantitys_order(name):
    """A contact fraction or a mean closure contracting by 1/10 per level is estimated at first order (rate
    1/2): the mean closure's error, carried by the pressure at the edges, may follow two fast ratios with a
    first-order stretch (the module docstring)."""
    values = _geometric(0.1)
    relative = name == "mean_closure"
    estimate, form, _ = tail_estimate(values, relative, ORDER_RATE[name])
    d = abs(values[-2] - values[-1]) / (values[-1] if relative else 1.0)
    assert form == RICHARDSON and estimate == pytest.approx(2.0 * d)
    assert estimate >= abs(values[-1] - 1.0)


def test_the_estimate_is_within_ten_times_the_error_where_that_error_is_not_small_by_chance():
    """Issue 35's upper side on Westergaard's sinusoid (layers of depth 1) refined to 1e-3 from 64 points.
    Its edges come to be located by the quartic on 512 points; before, a difference across that change
    bounded the quartic's error by the line's, a hundred times larger (module docstring of
    :mod:`~ngcontact.cell.spectral.refinement`), and the estimates of the contact fraction and the coefficients
    exceeded the error by as much.  A stop waits for three differences on the quartic's levels (on 4096
    points): there every quantity of each load is estimated within [1, 10] times its error, the lightest load's
    included, whose error changes sign just after the locator's change.  The 2D stiffness, of the set with its
    edges located (:mod:`~ngcontact.cell.spectral.grid_measures`), meets 1e-3 there too; at the lightest load its
    differences fall by 20 and then by 240, and its guarded bound is taken on the levels since that change of
    regime (:mod:`~ngcontact.cell.spectral.estimate_forms`), not on the earlier difference carried at first
    order (which exceeded its error 256 times)."""
    from ngcontact.cell.spectral.refinement import STIFFNESS
    dim, gap, pressures, first, finer = ORACLES["westergaard"]
    loads = [cell_load(dim, pressure=p) for p in pressures]
    refined = sweep_to_tolerance(lambda n: _cell(dim, gap, n), loads, 1e-3, first, dim, 2 ** 12)
    grid = refined.history[-1]["grid"]
    reference = _cell(dim, gap, grid * finer).sweep(loads)
    for k, (sol, ref, est) in enumerate(zip(refined.solutions, reference, refined.estimates)):
        head, exact = headline(sol.results), headline(ref.results)
        for name in est:
            effectivity = est[name] / (abs(head[name] - exact[name]) / refined.scales[k][name])
            assert 1.0 <= effectivity <= 10.0, (k, name, effectivity)
    assert grid == 4096 and refined.met and max(e[STIFFNESS] for e in refined.estimates) <= 1e-3
    assert not refined.capped


def test_a_2d_stiffness_that_misses_the_tolerance_is_refined_until_it_meets_it():
    """The 2D stiffness is held to the tolerance (module docstring of :mod:`~ngcontact.cell.spectral.refinement`).
    With a penalty (:data:`K_N`) it is the collocated set's, first order in the grid step
    (:mod:`~ngcontact.cell.spectral.grid_measures`): on Westergaard's sinusoid at 1e-3 every other quantity meets it
    on 4096 points, the stiffness on a finer grid, within the cap of three more levels; every estimate there bounds
    its error."""
    from ngcontact.cell.spectral.refinement import STIFFNESS, STIFFNESS_LEVELS
    dim, gap, pressures, first, finer = ORACLES["westergaard"]
    loads = [cell_load(dim, pressure=p) for p in pressures]

    def penalty(n):
        return SpectralCell(dim=dim, period=1.0, grid=n, rough=Layer(1.0, NU, 1.0), counter=Layer(1.0, NU, 1.0),
                            gap=gap(n), k_n=K_N, enforcement="penalty", tol=1e-12, max_iter=100000)
    refined = sweep_to_tolerance(penalty, loads, 1e-3, first, dim, 2 ** 22)
    grid = refined.history[-1]["grid"]
    assert refined.met and 4096 < grid <= 4096 * 2 ** STIFFNESS_LEVELS and refined.estimate <= 1e-3
    assert max(e[STIFFNESS] for e in refined.estimates) <= 1e-3
    reference = penalty(grid * finer).sweep(loads)
    for k, (sol, ref, est) in enumerate(zip(refined.solutions, reference, refined.estimates)):
        head, exact = headline(sol.results), headline(ref.results)
        for name in est:
            assert est[name] >= abs(head[name] - exact[name]) / refined.scales[k][name], (k, name)


def test_a_coefficient_is_not_taken_as_geometric_where_the_contact_fraction_is_not():
    """The coefficients of eq. 34 rest on the fraction's edges: a ``g_n`` whose own ratios agree takes the guarded
    bound where the fraction of its load does (a vanished last difference), and Richardson where it does not."""
    from ngcontact.cell.spectral.estimate_forms import guarded_bound
    from ngcontact.cell.spectral.refinement import sweep_estimates

    def history(fractions):                     # every level's edges located by the quartic
        return [{"headline": [{"contact_fraction": f, "coefficient_g_n": g}], "whole_surface": {"k_n": 1.0, "g_n": 1.0},
                 "edges_fitted": [True]} for f, g in zip(fractions, _geometric(0.3, levels=4))]
    g_n = _geometric(0.3, levels=4)
    d = [abs(b - a) for a, b in zip(g_n[:-1], g_n[1:])][::-1]
    estimates, _, forms = sweep_estimates(history([0.40, 0.50, 0.52, 0.52]))
    assert forms[0] == {"contact_fraction": GUARDED, "coefficient_g_n": GUARDED}
    assert estimates[0]["coefficient_g_n"] == pytest.approx(guarded_bound(d)[0])
    _, _, forms = sweep_estimates(history(_geometric(0.3, levels=4)))
    assert forms[0] == {"contact_fraction": RICHARDSON, "coefficient_g_n": RICHARDSON}


def test_a_stop_waits_for_three_differences_on_the_levels_whose_edges_the_quartic_located():
    """Two fitted differences cannot show a rate (module docstring of
    :mod:`~ngcontact.cell.spectral.refinement`): a load whose edges were fitted on the last three levels still
    defers a stop to a scene's own tolerance; on four it does not."""
    from ngcontact.cell.spectral.refinement import MIN_LEVELS, locator_changing

    def history(fitted):
        return [{"edges_fitted": [f], "headline": [{}]} for f in fitted]
    assert MIN_LEVELS == 4
    assert locator_changing(history([False, False, True, True, True]))
    assert not locator_changing(history([False, True, True, True, True]))
    assert not locator_changing(history([False] * 5))


def test_after_a_deferred_stop_the_estimate_is_at_most_the_deferred_one_plus_the_last_difference():
    """``|e_k| <= |e_(k-1)| + |q_k - q_(k-1)|``: the carried bound replaces a larger own estimate, in each
    quantity's measure (the mean closure relative to its value on each level), and leaves a smaller one."""
    from ngcontact.cell.spectral.estimate_forms import CARRIED
    from ngcontact.cell.spectral.refinement import carried

    whole = {"k_n": 1.0, "g_n": 1.0}
    history = [{"headline": [{"contact_fraction": 0.30, "mean_closure": 2.0}], "whole_surface": whole},
               {"headline": [{"contact_fraction": 0.31, "mean_closure": 2.2}], "whole_surface": whole}]
    estimates = [{"contact_fraction": 0.001, "mean_closure": 1.0}]
    forms = [{"contact_fraction": RICHARDSON, "mean_closure": GUARDED}]
    assert carried([{"contact_fraction": 0.05, "mean_closure": 0.1}], history, estimates, forms) == 1
    assert estimates[0]["contact_fraction"] == 0.001 and forms[0]["contact_fraction"] == RICHARDSON
    assert estimates[0]["mean_closure"] == pytest.approx((0.1 * 2.0 + 0.2) / 2.2)
    assert forms[0]["mean_closure"] == CARRIED


def test_on_levels_of_the_line_the_contact_fraction_and_coefficients_take_the_guarded_bound():
    """The line's first-order error jumps with the edges' position between points: two agreeing ratios of its
    differences are a coincidence (module docstring of :mod:`~ngcontact.cell.spectral.refinement`).  A load
    whose edges are not all fitted takes the guarded bound for the fraction and ``g_n``, the mean closure
    (not on the edges) Richardson's tail."""
    from ngcontact.cell.spectral.estimate_forms import guarded_bound
    from ngcontact.cell.spectral.refinement import sweep_estimates
    values = _geometric(0.3, levels=4)
    history = [{"headline": [{"contact_fraction": v, "coefficient_g_n": v, "mean_closure": v}],
                "whole_surface": {"k_n": 1.0, "g_n": 1.0}, "edges_fitted": [fitted]}
               for v, fitted in zip(values, (True, True, True, False))]
    estimates, _, forms = sweep_estimates(history)
    assert forms[0] == {"contact_fraction": GUARDED, "coefficient_g_n": GUARDED, "mean_closure": RICHARDSON}
    d = [abs(b - a) for a, b in zip(values[:-1], values[1:])][::-1]
    assert estimates[0]["contact_fraction"] == pytest.approx(guarded_bound(d)[0])


PROFILE_11 = self_affine(dim=2, grid=64, hurst=0.8, rms_slope=0.1, seed=11)


def _random_profile_11(n):
    closed = np.append(PROFILE_11, PROFILE_11[0])
    return np.interp(np.arange(n) / n, np.arange(65) / 64, closed.max() - closed)


def test_a_stalled_error_on_an_unresolved_island_is_bounded_by_the_islands_share():
    """The seed-11 profile (loads 0.001, 0.003, 0.01) at p = 0.001 holds a contact island narrower than a step on grids 256 to 1024: its
    error stalls over 512 and 1024 while the differences vanish (module docstring of
    :mod:`~ngcontact.cell.spectral.contact_edges`).  Refined to 1e-2 the island's share bounds the contact
    fraction, ``k_n`` and ``g_n`` of the load within [1, 10] times their error (``g_n`` was 0.56), on the
    grid the differences alone chose."""
    from ngcontact.cell.spectral.contact_edges import ISLAND
    loads = [cell_load(2, pressure=p) for p in (0.001, 0.003, 0.01)]
    refined = sweep_to_tolerance(lambda n: _cell(2, _random_profile_11, n), loads, 1e-2, 64, 2, 2 ** 10)
    assert refined.history[-1]["grid"] == 1024 and refined.history[-1]["islands"][0]["points"] == 1
    head, exact = headline(refined.solutions[0].results), headline(_cell(2, _random_profile_11, 16384).sweep(
        loads)[0].results)
    for name in ("contact_fraction", "coefficient_k_n", "coefficient_g_n"):
        effectivity = refined.estimates[0][name] / (abs(head[name] - exact[name]) / refined.scales[0][name])
        assert refined.forms[0][name] == ISLAND and 1.0 <= effectivity <= 10.0, (name, effectivity)
    assert any("contact island" in remark for remark in refined.remarks)


def test_on_westergaards_sinusoid_at_light_loads_an_estimate_beyond_ten_times_the_error_is_flagged():
    """At p = 0.0004 and 0.0015 the errors of the quantities on the edges fall by 6 to 25 per doubling once the
    quartic locates the edges, faster than the differences before show: the guarded bounds exceed the errors by
    78 to 406 times.  Each estimate bounds its error, and each above ten times it carries the estimator's own
    flag with its reason, listed in the report's remarks."""
    loads = [cell_load(2, pressure=p) for p in (0.0004, 0.0015)]
    refined = sweep_to_tolerance(lambda n: _cell(2, _westergaard, n), loads, 1e-2, 64, 2, 2 ** 22)
    reference = _cell(2, _westergaard, 2 ** 16).sweep(loads)
    loose = 0
    for k, (sol, ref) in enumerate(zip(refined.solutions, reference)):
        head, exact = headline(sol.results), headline(ref.results)
        for name in refined.estimates[k]:
            effectivity = refined.estimates[k][name] / (abs(head[name] - exact[name]) / refined.scales[k][name])
            assert effectivity >= 1.0, (k, name, effectivity)
            if effectivity > 10.0:
                assert "an earlier difference bounds it" in refined.flags[k][name], (k, name, effectivity)
                loose += 1
    assert loose >= 5
    assert any(remark.startswith("may exceed the error by more than 10 times") for remark in refined.remarks)


def test_contact_islands_of_a_periodic_mask_and_the_share_of_the_unresolved_ones():
    """Runs of contact wrap around the period; an island of fewer than four points holds its points and one open
    point on each side (eq. 34 on them: ``K0 = k_n |S| / |T|``, ``g_n = k_n mean(1_S g0)``)."""
    from ngcontact.cell.spectral.contact_edges import islands, unresolved_share
    on = np.array([1, 0, 1, 1, 0, 0, 0, 1], bool)
    assert sorted(islands(on)) == [(2, 2), (7, 2)]
    assert islands(np.ones(8, bool)) == [] and islands(np.zeros(8, bool)) == []
    cell = _cell(2, _westergaard, 64)
    p = np.zeros(64)
    p[10] = 1.0                                  # one point: unresolved
    p[30:40] = 1.0                               # ten points: resolved
    share = unresolved_share(cell, p)
    assert share["points"] == 1 and share["islands"] == 1
    assert share["share"]["contact_fraction"] == pytest.approx(3 / 64)
    assert share["share"]["coefficient_g_n"] == pytest.approx(cell.k_n * cell.g0[9:12].sum() / 64)
    p[10] = 0.0
    assert unresolved_share(cell, p)["share"] == {}


def test_3d_contact_islands_across_the_period_and_the_share_of_the_narrow_ones():
    """In 3D an island is 4-connected across the period too; one without a run of four points along either
    direction of the grid is unresolved, and its share holds its points and their open 4-neighbours."""
    from ngcontact.cell.spectral.contact_edges import narrow_islands, periodic_labels, unresolved_share
    on = np.zeros((16, 16), bool)
    on[0, 5] = on[15, 5] = True                 # two points joined across the period: narrow
    on[6:11, 6:11] = True                       # five by five: resolved
    on[3, 14:16] = on[3, 0:2] = True            # four in a row across the period, one point wide: narrow
    labels, n = periodic_labels(on)
    assert n == 3 and labels[0, 5] == labels[15, 5] and labels[3, 15] == labels[3, 0]
    narrow, count, points = narrow_islands(on)
    assert count == 2 and points == 2 and narrow.sum() == 6 and not narrow[8, 8]
    cell = _cell(3, _bisinusoid, 16)
    p = np.where(on, 1.0, 0.0)
    share = unresolved_share(cell, p)
    ring = narrow.copy()
    for axis in (0, 1):
        ring |= np.roll(narrow, 1, axis=axis) | np.roll(narrow, -1, axis=axis)
    assert share["islands"] == 2 and share["share"]["contact_fraction"] == pytest.approx(ring.sum() / 256)
    assert ring.sum() == 2 + 6 + 4 + 10         # the pair and its 6 open neighbours, the row and its 10
    assert share["share"]["coefficient_g_n"] == pytest.approx(cell.k_n * cell.g0[ring].sum() / 256)
    p[0, 5] = p[15, 5] = p[3] = 0.0
    assert unresolved_share(cell, p)["share"] == {} and unresolved_share(cell, np.ones((16, 16)))["islands"] == 0


def test_an_island_raises_an_estimate_below_its_share_and_a_loose_guarded_bound_is_flagged():
    """:func:`~ngcontact.cell.spectral.contact_edges.island_floor` raises only the estimates below the share (in
    their measure); :func:`~ngcontact.cell.spectral.estimate_forms.loose_flags` flags a guarded estimate above ten
    times the tail its last difference leaves at the last rate, never a Richardson one, nor an island's share (a
    stalled island's error is not measured by the last difference)."""
    from ngcontact.cell.spectral.contact_edges import ISLAND, island_floor
    from ngcontact.cell.spectral.estimate_forms import loose_flags, tail_left
    whole = {"k_n": 2.0, "g_n": 1.0}
    history = [{"grid": 2 ** j, "whole_surface": whole, "headline": [{"contact_fraction": f, "coefficient_g_n": g}],
                "islands": [{"points": 1, "islands": 1, "share": {"contact_fraction": 0.01,
                                                                  "coefficient_g_n": 0.002}}]}
               for j, (f, g) in enumerate(((0.30, 0.1), (0.32, 0.11), (0.321, 0.1101)))]
    estimates = [{"contact_fraction": 0.004, "coefficient_g_n": 0.05}]
    forms = [{"contact_fraction": GUARDED, "coefficient_g_n": RICHARDSON}]
    remarks = island_floor(history, estimates, forms)
    assert len(remarks) == 1 and "the smallest island 1 point(s)" in remarks[0]
    assert estimates == [{"contact_fraction": 0.01, "coefficient_g_n": 0.05}]
    assert forms == [{"contact_fraction": ISLAND, "coefficient_g_n": RICHARDSON}]
    left, rate = tail_left([0.30, 0.32, 0.321])  # differences 0.02, 0.001: rate 0.05
    assert rate == pytest.approx(0.05) and left == pytest.approx(0.001 * 0.05 / 0.95)
    assert loose_flags(history, estimates, forms) == [{}]
    flags = loose_flags(history, estimates, [{"contact_fraction": GUARDED, "coefficient_g_n": RICHARDSON}])
    assert set(flags[0]) == {"contact_fraction"} and "an earlier difference bounds it" in flags[0]["contact_fraction"]


def test_contractions_that_disagree_flag_an_estimate_of_any_form_above_ten_times_the_faster_tail():
    """Where the last contraction is at least twice as slow as the one before, the estimate (which takes the
    slower) is flagged when above ten times the tail its last difference leaves at the faster one, Richardson's
    too, with both contractions; contractions that agree flag nothing."""
    from ngcontact.cell.spectral.estimate_forms import faster_contraction, loose_flags, loose_reason
    values = [1.0, 1.0 - 3.2e-4, 1.0 - 3.2e-4 - 6.4e-5, 1.0 - 3.2e-4 - 6.4e-5 - 3.5e-5]   # 0.2, then 0.55
    left, before, last = faster_contraction(values)
    assert (before, last) == (pytest.approx(0.2), pytest.approx(0.546875))
    assert left == pytest.approx(3.5e-5 * 0.2 / 0.8)
    assert loose_reason(values, 8.6e-5, RICHARDSON) == ""                     # 9.8 times: within
    reason = loose_reason(values, 8.8e-5, RICHARDSON)                        # 10.1 times
    assert reason.startswith("10.1 times") and "disagree (0.2, then 0.55)" in reason
    steady = [1.0, 1.0 - 3.2e-4, 1.0 - 3.2e-4 - 1.0e-4, 1.0 - 3.2e-4 - 1.0e-4 - 3.5e-5]   # 0.31, then 0.35
    assert faster_contraction(steady) is None and loose_reason(steady, 1e-3, RICHARDSON) == ""
    history = [{"whole_surface": {}, "headline": [{"mean_closure": v}]} for v in values]
    flags = loose_flags(history, [{"mean_closure": 2e-4}], [{"mean_closure": GUARDED}])  # 5.7 and 22.9 times
    assert "the last two contractions disagree" in flags[0]["mean_closure"]


def test_on_the_random_profile_the_mean_closure_estimate_loose_by_ten_is_flagged():
    """The random profile's sweep at tolerance 1e-3, its lightest load: the mean closure's error falls about five times from
    the coarser grid while the last difference only halves (contractions 0.19, then 0.55), so the estimate
    exceeds its error by about ten times; it bounds it, and the estimator says it may be loose, with both
    contractions."""
    loads = [cell_load(2, pressure=p) for p in (0.001, 0.003, 0.01)]        # the three loads stop on grid 4096
    # (the largest here: every quantity but the stiffness meets 1e-3 there, the stiffness is capped)
    refined = sweep_to_tolerance(lambda n: _cell(2, _random_profile, n), loads, 1e-3, 64, 2, 2 ** 12)
    exact = _cell(2, _random_profile, 2 ** 16).sweep(loads)[0].results["mean_closure"]
    error = abs(refined.solutions[0].results["mean_closure"] - exact) / abs(exact)
    assert refined.history[-1]["grid"] == 4096 and refined.estimates[0]["mean_closure"] >= error
    assert "the last two contractions disagree" in refined.flags[0]["mean_closure"]


def test_a_window_across_an_islands_resolution_is_also_taken_on_the_resolved_levels():
    """A difference from a level with an unresolved island to the first without is the island's error, not a term
    of the resolved sequence (module docstring of :mod:`~ngcontact.cell.spectral.contact_edges`): the mean closure
    is also estimated on the resolved levels alone and the smaller estimate reported; an island still unresolved
    on the last level leaves the whole window's estimate."""
    from ngcontact.cell.spectral.contact_edges import resolved_run
    from ngcontact.cell.spectral.refinement import sweep_estimates
    values = [1.0, 1.002, 1.010, 1.0104, 1.0106]              # differences 0.002, 0.008, 4e-4, 2e-4

    def history(unresolved):
        return [{"headline": [{"mean_closure": v}], "whole_surface": {"k_n": 1.0, "g_n": 1.0},
                 "islands": [{"islands": u, "points": 2 if u else 9, "share": {}}]} for v, u in zip(values, unresolved)]
    assert resolved_run(history([1, 1, 0, 0, 0]), 0) == 3 and resolved_run(history([0, 0, 0, 0, 1]), 0) == 0
    assert resolved_run([{"headline": [{}]}], 0) == 1                       # no record: resolved
    whole, _, _ = tail_estimate(values, relative=True, order_rate=ORDER_RATE["mean_closure"])
    assert whole == pytest.approx(0.008 / 4 / values[-1])                  # the envelope of the difference across
    estimates, remarks, forms = sweep_estimates(history([1, 1, 0, 0, 0]))
    # two resolved differences 4e-4, 2e-4: the guarded envelope max(2e-4, 4e-4 / 2) at the first-order rate 1/2
    assert forms[0]["mean_closure"] == GUARDED
    assert estimates[0]["mean_closure"] == pytest.approx(2e-4 / values[-1])
    assert any("the levels of resolved islands" in remark for remark in remarks)
    estimates, _, _ = sweep_estimates(history([1, 1, 0, 0, 1]))
    assert estimates[0]["mean_closure"] == pytest.approx(whole)


def test_on_the_seed_11_profile_the_mean_closure_after_its_island_resolves_is_within_ten_times_its_error():
    """The seed-11 profile at p = 0.003 holds an island of 3 points on 1024 points and of 4 to 15 on 2048 to 8192
    (refined to 1e-3, reported on 8192).  Its mean closure's window held the difference across the island's
    resolution, whose first-order envelope set the estimate at 11 times the error; on the resolved levels it is
    within [1, 10] times it, and every estimate of the sweep still bounds its error (8192 points the largest grid:
    every quantity but the stiffness meets 1e-3 there, the stiffness is capped, not met)."""
    loads = [cell_load(2, pressure=p) for p in (0.001, 0.003, 0.01)]
    refined = sweep_to_tolerance(lambda n: _cell(2, _random_profile_11, n), loads, 1e-3, 64, 2, 2 ** 13)
    assert refined.history[-1]["grid"] == 8192
    assert [h["islands"][1]["islands"] > 0 for h in refined.history[-4:]] == [True, False, False, False]
    reference = _cell(2, _random_profile_11, 2 ** 16).sweep(loads)
    for k, (sol, ref) in enumerate(zip(refined.solutions, reference)):
        head, exact = headline(sol.results), headline(ref.results)
        for name, estimate in refined.estimates[k].items():
            effectivity = estimate / (abs(head[name] - exact[name]) / refined.scales[k][name])
            assert effectivity >= 1.0, (k, name, effectivity)
            if (k, name) == (1, "mean_closure"):
                assert effectivity <= 10.0 and refined.forms[k][name] == GUARDED, effectivity


@pytest.mark.parametrize("args, says", [(["--held-out", "1,x"], "'1,x': comma-separated non-negative integer"),
                                        (["--held-out", "-3"], "non-negative"),
                                        (["--held-out", "1", "--publish"], "the five oracles only")])
def test_the_effectivity_scripts_held_out_seeds_are_refused_unless_integers_and_unpublished(tmp_path, capsys,
                                                                                           args, says):
    import os
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
    import spectral_effectivity
    with pytest.raises(SystemExit) as exit_:
        spectral_effectivity.main([str(tmp_path / "out")] + args)
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and "--held-out" in err and says in err
    assert not (tmp_path / "out").exists()
    assert [o.name for o in spectral_effectivity.held_out([3])] == ["random_2d_seed3"]
