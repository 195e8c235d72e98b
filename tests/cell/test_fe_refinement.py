"""The FE cell's error estimate of the value it reports, and its tolerance on every FE cell (issue 35):
the observed-rate tail (ngcontact.cell.fe.observed_rate), the refinement loop behind its Refiner seam
(ngcontact.cell.fe.second_discretization) and the effectivity on the fast oracle."""
import json
import os
from dataclasses import dataclass

import pytest

from ngcontact import cli
from ngcontact.cell.cell_solution import CellSolution, worst_estimate
from ngcontact.cell.fe.observed_rate import Convergence
from ngcontact.cell.fe.second_discretization import HALVING_RATE, as_refinement, refine
from ngcontact.drivers.build import cell_loads, cell_solver, spectral_variant
from ngcontact.errors import ConvergenceError

from fe_cells import fe_scene
from test_cell_error import CURVED

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RULE = Convergence(floor=0.0, assumed=0.5, cap=0.7, safety=1.0)


def test_a_geometric_sequence_gives_the_exact_error_of_its_last_value():
    """``q_j = q + C rho^j``: the tail ``d_n rho / (1 - rho)`` is ``|q_n - q|`` (Richardson, observed order)."""
    q, rho = 0.3, 0.2
    values = [q + 0.01 * rho ** j for j in range(4)]
    estimate, remark = RULE.tail(values, relative=False)
    assert estimate == pytest.approx(abs(values[-1] - q), rel=1e-9) and remark == ""
    relative, _ = RULE.tail(values, relative=True)
    assert relative == pytest.approx(abs(values[-1] - q) / values[-1], rel=1e-9)
    assert Convergence(0.0, 0.5, 0.7, 3.0).tail(values, False)[0] == pytest.approx(3 * estimate, rel=1e-12)


def test_disagreeing_ratios_are_said_and_the_larger_taken():
    values = [1.0, 1.1, 1.11, 1.1105]           # ratios 0.1 then 0.05
    estimate, remark = RULE.tail(values, relative=False)
    assert estimate == pytest.approx(0.0005 * 0.1 / 0.9, rel=1e-9)
    assert "disagree (0.1, 0.05)" in remark and "larger taken" in remark


def test_the_guards_floor_cap_two_values_and_a_settled_sequence():
    floored = Convergence(floor=0.5, assumed=0.5, cap=0.7, safety=1.0)
    assert floored.tail([1.0, 1.1, 1.101], False)[0] == pytest.approx(0.001, rel=1e-9)   # ratio 0.01 -> 0.5
    est, remark = RULE.tail([1.0, 1.1, 1.3], False)                                      # growing: ratio 2
    assert est == pytest.approx(0.2 * 0.7 / 0.3, rel=1e-9) and "not contracting" in remark
    est, remark = RULE.tail([1.0, 1.1], False)                                           # the assumed ratio
    assert est == pytest.approx(0.1, rel=1e-9) and "two discretizations" in remark
    assert RULE.tail([2.0, 2.0, 2.0], True) == (0.0, "")


@dataclass
class _Level:
    """A stand-in discretization: its dofs and the contact fraction, closure and (where given) normal
    stiffness it answers."""

    ndof: int
    fraction: float
    closure: float = 1.0
    stiffness: float | None = None

    def unknowns(self) -> int:
        return self.ndof

    def sweep(self, loads):
        results = {"contact_fraction": self.fraction, "mean_closure": self.closure}
        if self.stiffness is not None:
            results["effective_stiffness"] = {"matrix": [[self.stiffness]], "components": ["n0"]}
        return [CellSolution(load=None, results=results)]


@dataclass
class _Halving:
    """A refiner whose level ``k`` has ``4^k`` times the dofs and the fraction ``0.5 + 0.1 / 2^k``."""

    rule: Convergence = HALVING_RATE

    def level(self, k):
        return _Level(1000 * 4 ** k, 0.5 + 0.1 / 2 ** k)

    def describe(self, k):
        return f"level {k}"


def test_the_loop_stops_at_three_levels_once_the_estimate_meets_the_tolerance():
    done = refine(_Halving(), [None], 0.1, 10 ** 9, required=True)
    assert [lv["discretization"] for lv in done.levels] == ["level 0", "level 1", "level 2"] and done.met
    assert done.estimates[0]["contact_fraction"] == pytest.approx(1.5 * 0.025, rel=1e-12)  # ratio 1/2, tail = d
    assert "level 0, level 1, level 2" in done.how


def test_a_tolerance_beyond_the_size_bound_fails_with_the_figures_or_is_flagged():
    with pytest.raises(ConvergenceError, match=r"tolerance = 0.001 not met: the estimate is 0.0375 "
                                               r"\(contact_fraction, absolute, at load 0\) on level 2 "
                                               r"\(16000 dofs\), and level 3 would have 64000 dofs, beyond 20000"):
        refine(_Halving(), [None], 1e-3, 20_000, required=True)
    done = refine(_Halving(), [None], 1e-3, 20_000, required=False)
    assert not done.met and done.solutions[0].results["contact_fraction"] == 0.525 and "beyond 20000" in done.how
    two = refine(_Halving(), [None], 0.1, 5_000, required=False)         # the third level beyond the bound
    assert two.met and len(two.levels) == 2 and "two discretizations" in two.how
    alone = refine(_Halving(), [None], 0.1, 2_000, required=False)
    assert alone.estimates == [{}] and not alone.met


def test_stem_grooves_estimates_the_error_of_its_reported_closure_within_1_to_10():
    """The shipped stem-groove cell (flat 2D, graded): against its spectral twin on 65,536 points (its closure
    there within 2e-8 of 262,144 points'), the mean closure's effectivity lies in [1, 10]; its contact fraction's
    true error is within the twin's collocation error, so only bounded by it."""
    scene = fe_scene("stem_grooves")      # the shipped scene is solved by the spectral cell; here its FE cell
    loads = cell_loads(scene)
    reference = spectral_variant(scene, 65536).sweep(loads)[0].results
    refined = cell_solver(scene).refine_to(0.01, loads, required=False)
    got, estimate = refined.solutions[0].results, refined.estimates[0]
    error = abs(got["mean_closure"] - reference["mean_closure"]) / reference["mean_closure"]
    assert error <= estimate["mean_closure"] <= 10 * error, (error, estimate)
    resolution = 2e-5      # the 2D spectral contact fraction's collocation error at 65,536 points
    assert abs(got["contact_fraction"] - reference["contact_fraction"]) <= estimate["contact_fraction"] + resolution


@pytest.mark.slow  # about 20 s on a loaded machine: the whole run; the loop's logic is tested above in ms
def test_a_curved_cell_takes_a_tolerance_and_ends_with_exit_3_out_of_reach(tmp_path, capsys, monkeypatch):
    """Once refused, a stated tolerance now refines a curved FE cell; a tolerance beyond the size bound (here
    lowered to 500 dofs) ends as the graded path does (exit 3, the figures in the message)."""
    from ngcontact.cell.fe import fe_cell
    monkeypatch.setattr(fe_cell, "MAX_DOFS", {2: 500, 3: 500})
    path = tmp_path / "curved.toml"
    path.write_text(CURVED.replace("interface_maxh = 0.1\n", "interface_maxh = 0.1\ntolerance = 1e-9\n"))
    code = cli.main(["run", str(path), "--out", str(tmp_path / "far"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 3 and "discretization.tolerance = 1e-09 not met" in err and "beyond 500" in err


@pytest.mark.slow  # about a minute on a loaded machine: four levels and the penalty's share
def test_a_curved_cell_meets_its_tolerance_and_reports_each_level(tmp_path, capsys):
    path = tmp_path / "curved.toml"
    path.write_text(CURVED.replace("interface_maxh = 0.1\n", "interface_maxh = 0.1\ntolerance = 0.5\n"))
    assert cli.main(["run", str(path), "--out", str(tmp_path / "ok"), "--quiet"]) == 0, capsys.readouterr().err
    report = json.loads((tmp_path / "ok" / "report.json").read_text())
    entry = report["results"]["loads"][0]
    assert entry["error_estimate"]["contact_fraction"] <= 0.5 and len(entry["discretizations"]) >= 3
    assert report["results"]["accuracy"]["tolerance_from"] == "scene"


def test_the_contact_edge_ladder_reports_the_contact_fraction_extrapolated_in_the_edge_size():
    """From three refined levels on, the contact edge's refiner reports the contact fraction as the
    extrapolation of the last three in the edge size (:mod:`ngcontact.cell.fe.edge_size_extrapolation`), its
    estimate the grid convergence index (1.25 x the correction), the last level's own value beside it; the
    closure keeps the geometric tail."""
    from ngcontact.cell.fe.contact_edge_refinement import ContactEdgeRefinement
    ladder = ContactEdgeRefinement(_Level(1000, 0.6), lambda grid: [],
                                   lambda points, h, grading: _Level(1000, 0.5 + 0.2 * h),
                                   interface_maxh=0.1, period=1.0)
    done = refine(ladder, [None], 0.005, 10 ** 9, required=True)
    assert len(done.levels) == 4 and done.met          # three refined levels: edge sizes 0.05, 0.025, 0.0125
    results = done.solutions[0].results
    assert results["contact_fraction"] == pytest.approx(0.5, abs=1e-12)
    assert results["contact_fraction_last_level"] == pytest.approx(0.5025, abs=1e-12)
    assert done.estimates[0]["contact_fraction"] == pytest.approx(1.25 * 0.0025, rel=1e-9)
    assert "load 0 contact_fraction: extrapolated, observed rate 1.00" in done.how


def test_the_contact_edge_ladder_takes_its_spectral_twins_bound_for_the_closure():
    """The ladder's closure does not change with the edge size (its geometric tail: zero), but the twin,
    the same continuum problem, answers 1.01 on the bound's grid (FLOOR_GRID points, whatever grid places the
    level's edge) and 1.012 on half and a quarter of it: the closure's estimate is the twin's bound
    ``1.25 |1 - 1.01| + 2 max(|1.01 - 1.012|, |1.012 - 1.012| / 2) = 0.0165`` (relative), in place of the
    tail, named in the record; the contact fraction, whose twin agrees with its extrapolation, keeps the
    extrapolation's estimate."""
    from ngcontact.cell.fe.contact_edge_refinement import FLOOR_GRID, ContactEdgeRefinement
    asked = []

    def twin_heads(grid):
        asked.append(grid)
        return [{"contact_fraction": 0.5, "mean_closure": 1.01 if grid == FLOOR_GRID else 1.012}]

    ladder = ContactEdgeRefinement(_Level(1000, 0.6), lambda grid: [],
                                   lambda points, h, grading: _Level(1000, 0.5 + 0.2 * h),
                                   interface_maxh=0.1, period=1.0, twin_heads=twin_heads)
    done = refine(ladder, [None], 0.05, 10 ** 9, required=True)
    assert len(done.levels) == 4 and done.met and set(asked) == {FLOOR_GRID, FLOOR_GRID // 2, FLOOR_GRID // 4}
    assert done.estimates[0]["mean_closure"] == pytest.approx(0.0165, rel=1e-9)
    assert done.estimates[0]["contact_fraction"] == pytest.approx(1.25 * 0.0025, rel=1e-9)
    assert ("load 0 mean_closure: the spectral twin: 1.25 |q - q_N| + 2 max(|q_N - q_N/2|, |q_N/2 - q_N/4| / 2), "
            f"N = {FLOOR_GRID} (0.0165) in place of the sequence's 0") in done.how
    assert "load 0 contact_fraction: " not in done.how.replace("load 0 contact_fraction: extrapolated", "")


def test_the_twins_bound_replaces_a_tail_that_overstates_and_takes_an_earlier_difference():
    """A closure falling by 0.002 per level (its geometric tail at the capped ratio 0.7, 3.5 times the last
    difference) whose twin answers near its last level's value: the twin's bound, not the tail, is its estimate.
    A twin whose last difference vanished (a crossing) is bounded by the one before it halved."""
    from ngcontact.cell.fe.contact_edge_refinement import FLOOR_GRID, ContactEdgeRefinement

    def twin_heads(grid):
        return [{"contact_fraction": 0.5, "mean_closure": {FLOOR_GRID: 1.0, FLOOR_GRID // 2: 1.0}.get(grid, 1.004)}]

    levels = iter([1.008, 1.006, 1.004, 1.002, 1.0])
    ladder = ContactEdgeRefinement(_Level(1000, 0.6, next(levels)), lambda grid: [],
                                   lambda points, h, grading: _Level(1000, 0.5 + 0.2 * h, next(levels)),
                                   interface_maxh=0.1, period=1.0, twin_heads=twin_heads)
    done = refine(ladder, [None], 0.05, 10 ** 9, required=True)
    assert len(done.levels) == 4
    # |1.002 - 1| 1.25 + 2 max(0, 0.004 / 2), relative to 1.002
    assert done.estimates[0]["mean_closure"] == pytest.approx((0.0025 + 0.004) / 1.002, rel=1e-9)


def test_the_ladder_refines_its_grading_where_the_stiffness_alone_misses_the_tolerance():
    """A stiffness whose error is the grading's (``0.05 gamma^2``, the same at every edge size) against a twin
    that answers the converged 1.0: after the edge sequence (three refined levels, the contact fraction's
    extrapolation within the tolerance) its bound ``1.25 |S - 1| / S`` = 0.0056 misses 0.005, so level 4 keeps
    the last edge size and takes the grading 0.3 / sqrt(2), whose stiffness meets it; the stiffness is counted,
    and the contact fraction stays the edge sequence's extrapolation."""
    from ngcontact.cell.fe.contact_edge_refinement import GRADING_STEP, ContactEdgeRefinement
    built = []

    def cell_at(points, h, grading):
        built.append((h, grading))
        return _Level(1000, 0.5 + 0.2 * h, stiffness=1.0 + 0.05 * grading ** 2)

    ladder = ContactEdgeRefinement(_Level(1000, 0.6, stiffness=1.1), lambda grid: [], cell_at, interface_maxh=0.1,
                                   period=1.0, twin_heads=lambda grid: [{"contact_fraction": 0.5,
                                                                         "normal_stiffness": 1.0}])
    done = refine(ladder, [None], 0.005, 10 ** 9, required=True)
    assert len(done.levels) == 5 and done.met and done.uncontrolled == () == as_refinement(done).uncontrolled
    assert built[-1] == (built[-2][0], pytest.approx(0.3 * GRADING_STEP)) and ladder.edge_levels == 3
    assert done.levels[3]["estimate"] > 0.005 >= done.levels[4]["estimate"]
    assert done.estimates[0]["normal_stiffness"] == pytest.approx(1.25 * 0.00225 / 1.00225, rel=1e-9)
    results = done.solutions[0].results
    assert results["contact_fraction"] == pytest.approx(0.5, abs=1e-12)
    assert results["contact_fraction_last_level"] == pytest.approx(0.5025, abs=1e-12)
    assert "grading 0.212" in done.levels[4]["discretization"]


def test_a_quantity_the_grading_does_not_reduce_missing_after_it_began_is_out_of_reach():
    """A closure that the grading's level moves off the twin's (0.0088 at grading 0.212) misses the tolerance
    after the edge sequence ended: no grading level reduces it, so a stated tolerance ends there (exit 3's
    error, naming the quantity), not at the most levels."""
    from ngcontact.cell.fe.contact_edge_refinement import ContactEdgeRefinement
    ladder = ContactEdgeRefinement(
        _Level(1000, 0.6, stiffness=1.1), lambda grid: [],
        lambda points, h, g: _Level(1000, 0.5 + 0.2 * h, closure=1.0 + 0.1 * (0.3 - g), stiffness=1.0 + 0.05 * g ** 2),
        interface_maxh=0.1, period=1.0,
        twin_heads=lambda grid: [{"contact_fraction": 0.5, "mean_closure": 1.0, "normal_stiffness": 1.0}])
    with pytest.raises(ConvergenceError, match="mean_closure missed the tolerance after the edge sequence ended "
                                               "at level 3") as info:
        refine(ladder, [None], 0.005, 10 ** 9, required=True)
    assert len(info.value.history["levels"]) == 5


def test_the_twin_floors_the_normal_coefficients_of_eq_34_too():
    """The bound ``1.25 |q_h - q_N| + 2 max(|q_N - q_N/2|, |q_N/2 - q_N/4| / 2)`` of each floored quantity, the
    coefficients ``k_n`` and ``g_n`` on the real contact set among them; a quantity the twin does not answer
    gets none."""
    from ngcontact.cell.fe.contact_edge_refinement import FLOOR_GRID, ContactEdgeRefinement

    def twin_heads(grid):
        fine = grid == FLOOR_GRID
        return [{"contact_fraction": 0.5, "coefficient_k_n": 12.0 if fine else 12.5,
                 "coefficient_g_n": 0.030 if fine else 0.031}]

    ladder = ContactEdgeRefinement(_Level(1000, 0.6), lambda grid: [],
                                   lambda points, h, grading: _Level(1000, 0.5),
                                   interface_maxh=0.1, period=1.0, twin_heads=twin_heads)
    floors = ladder.twin_floors([{"contact_fraction": 0.51, "coefficient_k_n": 12.2, "coefficient_g_n": 0.0302,
                                  "mean_closure": 1.0}], 1)[0]
    assert floors["coefficient_k_n"][0] == pytest.approx(1.25 * 0.2 + 2 * 0.5, rel=1e-12)
    assert floors["coefficient_g_n"][0] == pytest.approx(1.25 * 0.0002 + 2 * 0.001, rel=1e-9)
    assert floors["contact_fraction"][0] == pytest.approx(1.25 * 0.01, rel=1e-9) and "mean_closure" not in floors


def test_the_contact_edge_ladder_is_not_taken_as_converged_before_its_extrapolation():
    """Levels whose contact fraction and closure do not change meet any tolerance by their geometric tail
    after three levels; the contact edge's ladder still solves a third refined level (four in all), the
    extrapolation's premise, and a plain refiner stops at three."""
    from ngcontact.cell.fe.contact_edge_refinement import ContactEdgeRefinement
    ladder = ContactEdgeRefinement(_Level(1000, 0.5), lambda grid: [],
                                   lambda points, h, grading: _Level(1000, 0.5),
                                   interface_maxh=0.1, period=1.0)
    assert len(refine(ladder, [None], 0.01, 10 ** 9, required=True).levels) == 4

    @dataclass
    class Constant(_Halving):
        def level(self, k):
            return _Level(1000, 0.5)

    assert len(refine(Constant(), [None], 0.01, 10 ** 9, required=True).levels) == 3


def test_the_worst_estimate_names_its_quantity_measure_and_load():
    per_load = [{"contact_fraction": 0.002, "normal_stiffness": 0.5}, {"mean_closure": 0.0166}]
    assert worst_estimate(per_load) == "0.5 (normal_stiffness, relative, at load 0)"
    assert worst_estimate(per_load, skip=("normal_stiffness",)) == "0.0166 (mean_closure, relative, at load 1)"
    assert worst_estimate([{}], skip=()) == "no estimate"
