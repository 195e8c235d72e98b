"""Issue 35's second aim on one random 2D profile, posed as ``scripts/random_profile_accuracy.py`` poses it.

The profile of seed 7 (64 samples, the package's generator), its gap a tabulated CSV on a flat interface,
exact contact, three loads: with the defaults (no ``[discretization]``) every headline quantity is within
1 % of the converged value and every estimate at least its true error; with ``discretization.tolerance =
1e-4`` every quantity meets it, the stiffness too: its lightest load's narrow contact island, a few hundred
points wide at 2^18 to 2^20 points, sits at a sample of the profile, and its stiffness is sensitive to its
width; its edges once moved by half a step between those grids (the quartic's window wider than the island),
and the stated tolerance was out of reach (exit 3).  Their window now stays within half the way to the kink
(:func:`~ngcontact.cell.spectral.grid_measures.edge_offset`): the grid reached's change from the level before
bounds each error and is within the tolerance.
The converged value is the same scene on 2^17 points; its own error is bounded by its change from 2^16,
which is added to each true error (a bound where each doubling at least halves the error).  Seed 7 is the
profile whose second load's contact fraction the estimate on the default grid once missed: its edges,
located by the line, are off by a fraction of a step each, of one sign, while the error of the coarser
grids had the other sign.
"""
import importlib.util
import os

import pytest

from ngcontact import runner
from ngcontact.cell.cell_solution import headline
from ngcontact.scene import loader

_SPEC = importlib.util.spec_from_file_location(
    "random_profile_accuracy",
    os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "random_profile_accuracy.py"))
assert _SPEC is not None and _SPEC.loader is not None
S = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(S)

SEED = 7


def _results(tmp_path, name, text):
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    report, _ = runner.solve(str(path))
    return report["results"]


def test_a_kept_csv_gives_back_the_rows_and_their_verdict(tmp_path):
    """``--from-csv`` reads the rows an earlier run wrote, typed as that run held them: its CSV, verdict and exit
    status come back unchanged; a CSV of other columns is refused by name."""
    measured = {k: "" for k in S.KEYS}
    measured.update(seed=3, run="tolerance 1e-4", load=1, pressure=0.005, quantity="contact_fraction", counted=True,
                    met=True, grid=1048576, value=0.25, estimate=2e-6, reference=0.250001, true_error=1e-6,
                    measure="absolute", estimate_measure=2e-6, true_error_measure=1e-6, true_error_relative=4e-6,
                    reference_change=1e-7, error_to_finest=1e-6, effectivity=2.0, solve_seconds=18.0, aim="true error <= 0.0001", aim_met=True, seconds=20.5, note="grids [1024]")
    lost = {k: "" for k in S.KEYS}
    lost.update(seed=2, run="tolerance 1e-4", aim="true error <= 0.0001", aim_met=False, note="out of reach: exit 3")
    rows = [measured, lost]
    first = tmp_path / "first.csv"
    S.write_csv(str(first), list(S.KEYS), [[r[k] for k in S.KEYS] for r in rows])
    assert S.read_rows(str(first)) == rows
    assert S.main([str(tmp_path / "again"), "--from-csv", str(first)]) == S.OUT_OF_REACH
    assert (tmp_path / "again" / "random_profile_accuracy.csv").read_text() == first.read_text()
    assert "tolerance 1e-4: aim not met; 1 of 1 measured rows within it, out of reach on seeds [2]" in S.verdict(rows)
    other = tmp_path / "other.csv"
    other.write_text("seed,run\n1,defaults\n")
    with pytest.raises(SystemExit, match="not this script's CSV"):
        S.read_rows(str(other))


def test_the_posed_scenes_state_no_discretization_but_the_tolerance(tmp_path):
    gap = S.write_gap(str(tmp_path), SEED)
    for name, extra, given in (("defaults", S.RUNS["defaults"], set()), ("tol", S.RUNS["tolerance 1e-4"],
                                                                         {"tolerance"})):
        path = tmp_path / f"{name}.toml"
        path.write_text(S.scene_text(SEED, gap, extra))
        scene = loader.load(str(path))
        assert set(scene.discretization.given) == given and scene.contact.enforcement == "exact"
        assert list(scene.load.pressure) == list(S.PRESSURES)


@pytest.mark.slow
def test_a_random_profile_meets_the_aim_with_the_defaults_and_at_a_tolerance_of_1e_4(tmp_path):
    gap = S.write_gap(str(tmp_path), SEED)
    defaults = _results(tmp_path, "defaults", S.scene_text(SEED, gap, S.RUNS["defaults"]))
    k_n = defaults["whole_surface"]["k_n"]

    def reference(n: int) -> list[dict[str, float]]:
        return [headline(load) for load in _results(tmp_path, f"grid{n}", S.reference_text(SEED, gap, n, k_n))["loads"]]

    half, fine = reference(2 ** 16), reference(2 ** 17)
    accuracy = defaults["accuracy"]
    # every quantity is held in 2D, the stiffness too, and with the defaults every one meets 1 %
    assert all(q["counted"] and q["met"] for q in accuracy["quantities"]) and accuracy["met"]
    for q in accuracy["quantities"]:
        ref, other = fine[q["load"]][q["name"]], half[q["load"]][q["name"]]
        error = abs(q["value"] - ref) + abs(ref - other)
        where = (q["load"], q["name"], q["value"], q["error"], error)
        assert error <= S.DEFAULT_AIM * abs(ref) and q["error"] >= error, where
    # the stated 1e-4 is met: every quantity counted and met on the grid reached, its change from the level before
    # (a bound on its error where each doubling at least halves it) within the tolerance and below its estimate
    tol = _results(tmp_path, "tol", S.scene_text(SEED, gap, S.RUNS["tolerance 1e-4"]))
    assert tol["accuracy"]["met"] and all(q["counted"] and q["met"] for q in tol["accuracy"]["quantities"])
    before, last = (level["headline"] for level in tol["method"]["refinement"][-2:])
    for q in tol["accuracy"]["quantities"]:
        change = abs(last[q["load"]][q["name"]] - before[q["load"]][q["name"]]) / q["scale"]
        assert change <= S.TOLERANCE and q["controlled_error"] >= change, (q["load"], q["name"], change, q)
