"""``scripts/accuracy_study_cost.py``: the sentence it publishes on issue 35's aims for the femur's study.

The verdict must say "not met" where an aim fails (fewer than four levels in a knob, errors that do not
fall level by level, a study of 20 runs or more of the scene) and "met" where it holds, from the study's
``results`` as ``ngcontact study accuracy`` writes them.
"""
import importlib.util
import os

_SPEC = importlib.util.spec_from_file_location(
    "accuracy_study_cost", os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "accuracy_study_cost.py"))
assert _SPEC is not None and _SPEC.loader is not None
S = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(S)


def study(errors: dict[str, list[float]], rate: float | None = 1.5) -> dict:
    """A study's results with one knob ``h``: a level per error, then the reference (error 0)."""
    n = len(next(iter(errors.values())))
    levels = [{"knob": "h", "reference": k == n, "own_scene": k == n - 1,
               "quantities": {q: {"error": e[k] if k < n else 0.0} for q, e in errors.items()}}
              for k in range(n + 1)]
    return {"levels": levels, "rates": {"h": {"variable": "maxh", "rates": {q: rate for q in errors}}}}


def test_every_aim_met_is_said_met():
    text = S.verdict(study({"peak_pressure": [4e-3, 2e-3, 1e-3], "safety_factor": [1e-2, 3e-3, 1e-3]}), 100.0, 10.0)
    assert "h 4: met." in text
    assert "Errors of peak_pressure: h 0.004, 0.002, 0.001 (falling; rate 1.5 in maxh)" in text
    assert "Errors of safety_factor: h 0.01, 0.003, 0.001 (falling; rate 1.5 in maxh)" in text
    assert text.endswith("10 runs (aim: fewer than 20): met.")


def test_each_missed_aim_is_said_not_met():
    text = S.verdict(study({"peak_pressure": [1e-4, 5e-5]}, rate=None), 300.0, 10.0)
    assert "h 3: not met." in text
    assert "Errors of peak_pressure: h 0.0001, 5e-05 (falling; no rate (round-off))" in text
    assert "safety_factor" not in text   # a quantity the scene does not report is left out
    assert text.endswith("30 runs (aim: fewer than 20): not met.")
    rising = S.verdict(study({"peak_pressure": [1e-4, 5e-5, 7e-5]}), 100.0, 10.0)
    assert "(not falling at every level; rate 1.5 in maxh)" in rising
