"""``scripts/random_map_accuracy.py``: the scene it poses for issue 35's first aim, and its smoke run.

The scene states ``method = "spectral"`` and ``discretization.tolerance`` and nothing else about its
discretization, so the grid is the refinement's; the reference scenes state their grid and switch the
estimate off.  Both are valid scenes (loaded as a user's would be).  The smoke run (``--quick``: a 16 x 16
map against 256 and 512 points) writes one row per load and the Tamaas row, measured or saying why not.
"""
import csv
import importlib.util
import os

import pytest

from ngcontact.scene import loader

_SPEC = importlib.util.spec_from_file_location(
    "random_map_accuracy", os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "random_map_accuracy.py"))
assert _SPEC is not None and _SPEC.loader is not None
S = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(S)


def test_the_posed_scene_sets_only_the_method_and_the_tolerance(tmp_path):
    path = tmp_path / "posed.toml"
    path.write_text(S.scene_text("tolerance = 0.01"))
    scene = loader.load(str(path))
    d = scene.discretization
    assert d.method == "spectral" and d.tolerance == 0.01 and d.grid is None
    assert scene.geometry.spectrum.grid == 64 and list(scene.load.pressure) == list(S.PRESSURES)
    fine = tmp_path / "fine.toml"
    fine.write_text(S.scene_text(f'grid = {S.REFERENCE}\nestimate = "off"'))
    assert loader.load(str(fine)).discretization.grid == S.REFERENCE


def test_richardson_extrapolates_a_geometric_sequence_and_keeps_a_non_monotone_one():
    assert S.richardson(1.0 + 0.4, 1.0 + 0.2, 1.0 + 0.1) == pytest.approx(1.0)
    assert S.richardson(1.0, 1.2, 1.1) == 1.1


@pytest.mark.slow
def test_the_quick_run_writes_a_row_per_load_and_the_tamaas_row(tmp_path):
    assert S.main([str(tmp_path), "--quick"]) == 0
    with open(tmp_path / "random_map_accuracy.csv") as fh:
        rows = list(csv.DictReader(fh))
    ours, peer = rows[:3], rows[3]
    assert [r["load"] for r in ours] == ["0", "1", "2"] and peer["solver"].startswith("tamaas")
    for r in ours:
        assert float(r["estimate"]) > 0 and float(r["effectivity"]) == pytest.approx(
            float(r["estimate"]) / float(r["true_error"]))
    assert peer["seconds"] or peer["note"].startswith("skipped")
    assert (tmp_path / "random_map_accuracy.png").stat().st_size > 0
