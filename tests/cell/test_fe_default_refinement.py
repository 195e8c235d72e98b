"""An FE cell scene that states no tolerance gets the default one and the cheapest size that meets it (issue 35,
"right by default"; ngcontact.cell.fe.default_refinement): its own answer where the estimate of one order more
meets 1 %, else refined as a stated tolerance refines it within discretization.budget_dofs; a budget spent first
is never silent (one warning line, accuracy.met = false, exit 0); discretization.estimate = "off" keeps a single
solve."""
import json
import logging
import math
import tomllib
from dataclasses import dataclass

import pytest

from ngcontact import cli
from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.cell.fe.default_refinement import BUDGET_KEY, sequence_shortfall
from ngcontact.cell.cell_solution import CellSolution
from ngcontact.cell.fe.observed_rate import dofs_to_meet, exponent
from ngcontact.cell.fe.second_discretization import HALVING_RATE, refine
from ngcontact.errors import ModelError
from ngcontact.drivers.build import cell_loads, cell_solver
from ngcontact.scene.loader import from_dict
from ngcontact.verification.moduli import e_star
from ngcontact.verification.westergaard import westergaard_contact_fraction, westergaard_p_star

from sinusoid_cell import sinusoid_cell

PRESSURE = 0.0034523            # p / p* = 0.2
#: Westergaard's sinusoid with exact contact on a coarse order-1 mesh: the contact fraction 0.40 against 0.295
SCENE = sinusoid_cell(k_n="1.0e4", pressure=f"{PRESSURE}", discretization="order = 1\nmaxh = 0.4\ninterface_maxh = 0.1")


def _exact() -> float:
    return westergaard_contact_fraction(PRESSURE, westergaard_p_star(e_star(1.0, 0.3, 1.0, 0.3), 0.01, 1.0))


def _run(tmp_path, text: str, capsys):
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    code = cli.main(["run", str(path), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    report = json.loads((tmp_path / "o" / "report.json").read_text()) if code == 0 else None
    return code, err, report


def test_the_unknowns_that_would_meet_the_tolerance_follow_the_observed_rate():
    """Errors falling like N^-a: a from the last two levels (else from the assumed ratio per level and the growth
    of the unknowns), and N = N_n (e_n / tol)^(1/a)."""
    a = exponent([1000, 4000], [0.08, 0.02], (0.5, 4.0))
    assert a == pytest.approx(1.0)
    assert dofs_to_meet(4000, 0.02, 0.01, a) == pytest.approx((8000, 1.0))
    # one level: the ratio 1/2 per level at four times the unknowns is a = 1/2
    assert exponent([1000], [0.04], (0.5, 4.0)) == pytest.approx(0.5)
    assert dofs_to_meet(1000, 0.04, 0.01, 0.5)[0] == pytest.approx(16000)
    # errors that do not fall, and no growth to assume a rate from: nothing extrapolated
    assert exponent([1000, 4000], [0.02, 0.03], (0.5, 0.0)) is None
    assert dofs_to_meet(1000, math.inf, 0.01, 1.0) is None


def test_a_2d_fe_cell_missing_one_percent_at_its_mesh_reaches_it_by_default_refinement():
    """Order 1 on an interface mesh of 0.1: the scene's own contact fraction is 0.1 off Westergaard's and its
    estimate says so; without a tolerance the cell is refined (graded towards its contact edges, then higher
    orders) until the estimate meets 1 %, and the estimate bounds the true error."""
    scene = from_dict(tomllib.loads(SCENE))
    loads, exact = cell_loads(scene), _exact()
    own = from_dict(tomllib.loads(SCENE + 'estimate = "estimate"\n'))
    alone = cell_solver(own).default_accuracy(0.01, loads)          # the scene's own answer, estimated only
    assert abs(alone.solutions[0].results["contact_fraction"] - exact) > 0.01
    assert alone.estimates[0]["contact_fraction"] > 0.01 and alone.scene_discretization
    cell = cell_solver(scene)
    done = cell.default_accuracy(0.01, loads)
    assert not done.scene_discretization and done.met and done.shortfall == ""
    assert len(done.per_load[0]["mesh_history"]) >= 3
    estimate = done.estimates[0]["contact_fraction"]
    error = abs(done.solutions[0].results["contact_fraction"] - exact)
    assert error <= estimate <= 0.01, (error, estimate)
    assert cell.unknowns() == done.per_load[0]["mesh_history"][-1]["ndof"] <= cell.budget


def test_a_budget_too_small_ends_with_one_warning_not_met_and_exit_0(tmp_path, capsys, caplog):
    """budget_dofs = 1000: the graded refinement stops at its second mesh; the run ends (exit 0) with the finest
    answer, accuracy.met = false, the shortfall in the report and at the top of report.html, and one warning
    line naming the estimate, the budget key and the unknowns meeting 1 % would take."""
    with caplog.at_level(logging.WARNING):
        code, err, report = _run(tmp_path, SCENE + "budget_dofs = 1000\n", capsys)
    assert code == 0, err
    acc = report["results"]["accuracy"]
    assert acc["tolerance_from"] == "default" and not acc["met"]
    assert f"{BUDGET_KEY} = 1000" in acc["shortfall"] and "meeting it would take about" in acc["shortfall"]
    history = report["results"]["loads"][0]["mesh_history"]
    assert max(h["ndof"] for h in history) <= 1000 < 2 * history[-1]["ndof"]
    lines = [r.getMessage() for r in caplog.records if r.levelname == "WARNING" and "accuracy not met" in r.getMessage()]
    assert len(lines) == 1, lines
    assert BUDGET_KEY in lines[0] and "the estimated" in lines[0] and "would take about" in lines[0]
    assert "accuracy NOT met" in err
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert page.index(BUDGET_KEY) < page.index("Key figures")


def test_the_opt_out_keeps_a_single_solve(tmp_path, capsys, monkeypatch):
    """discretization.estimate = "off": one solve per load on the scene's mesh, and the report says it is not
    estimated."""
    solves = []
    original = CellProblem.solve

    def counted(self, *args, **kwargs):
        solves.append(self.ndof)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(CellProblem, "solve", counted)
    code, err, report = _run(tmp_path, SCENE + 'estimate = "off"\n', capsys)
    assert code == 0, err
    acc = report["results"]["accuracy"]
    assert acc["how"] == "not estimated (discretization.estimate = off)" and not acc["estimated"]
    assert len(solves) == 1 and "mesh_history" not in report["results"]["loads"][0]


class _Unmeshable:
    """A refiner whose level 2 the mesher cannot build (level k: 1000 4^k dofs, fraction 0.5 + 0.1 / 2^k)."""

    rule = HALVING_RATE

    def level(self, k):
        if k == 2:
            raise ModelError("Netgen's mesher failed")
        return _Level(1000 * 4 ** k, 0.5 + 0.1 / 2 ** k)

    def describe(self, k):
        return f"level {k}"


@dataclass
class _Level:
    ndof: int
    fraction: float

    def unknowns(self) -> int:
        return self.ndof

    def sweep(self, loads):
        return [CellSolution(load=None, results={"contact_fraction": self.fraction, "mean_closure": 1.0})]


def test_a_level_the_mesher_cannot_build_ends_a_default_refinement_not_the_run():
    """Unrequired: the levels before it are the answer, not met, the reason in ``how``; required: the error."""
    done = refine(_Unmeshable(), [None], 1e-3, 10 ** 9, required=False)
    assert not done.met and len(done.levels) == 2 and "level 2 cannot be built (Netgen's mesher failed)" in done.how
    said = sequence_shortfall(done, 1e-3, 120_000)       # the warning says why it stopped, not only the budget
    assert f"{BUDGET_KEY} = 120000" in said and "stopped: level 2 cannot be built" in said
    with pytest.raises(ModelError):
        refine(_Unmeshable(), [None], 1e-3, 10 ** 9, required=True)


def test_a_projection_beyond_any_machine_is_said_to_be_out_of_reach():
    """An estimate falling like dofs^-0.06 does not project to a number of unknowns worth printing: the
    shortfall says the tolerance is out of reach of the refinement, with the rate; a reachable one keeps its
    figure."""
    from ngcontact.cell.fe.default_refinement import OUT_OF_REACH, shortfall
    from ngcontact.cell.fe.observed_rate import dofs_to_meet
    slow = shortfall(0.01, 120_000, "interface_maxh 0.00625, 17558 dofs", 0.209,
                     dofs_to_meet(17558, 0.209, 0.01, 0.06))
    assert "out of reach of this refinement" in slow and "dofs^-0.06" in slow and "about" not in slow
    assert f"{OUT_OF_REACH:.0e}" in slow
    fast = shortfall(0.01, 120_000, "interface_maxh 0.05, 17558 dofs", 0.02, dofs_to_meet(17558, 0.02, 0.01, 1.0))
    assert "meeting it would take about 3.5e+04 dofs" in fast and "out of reach" not in fast
