"""The strength cell's entries (:mod:`ngcontact.drivers.strength_cell`): the one the package ships for the main
job is the current code's, an entry gives the correctors a computation gives, and any change of the cell,
its discretization, its stick stiffness or the code gives another key."""
from __future__ import annotations

import importlib.util
import logging
import os
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from ngcontact.coupling import strength as S
from ngcontact.drivers import build as B
from ngcontact.drivers import strength_cell as SC

ROOT = Path(__file__).resolve().parents[2]
HILLS = str(ROOT / "geometries" / "cells" / "hip_hills.toml")
_SPEC = importlib.util.spec_from_file_location("ship_strength_cell", ROOT / "scripts" / "ship_strength_cell.py")
assert _SPEC is not None and _SPEC.loader is not None
SHIP = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(SHIP)
#: the shipped entry's size must stay below (bytes): package data of a wheel
LARGEST_SHIPPED = 1_000_000
#: recomputed corrector states against the shipped ones, relative to the largest (round-off of one
#: factorization: the states agree to ~1e-14; the gold record compares its numbers at 1e-6)
STATES_RTOL = 1e-9


def coarse_hills(**discretization):
    """The hip-hills cell coarse enough to mesh and solve in a second (order 1: straight elements)."""
    sizes = {"maxh": 0.5, "interface_maxh": 0.25, "order": 1, **discretization}
    return B.recovery_cell_scene(HILLS, key="strength.cell", discretization=sizes)


def test_the_shipped_entry_is_the_main_job_cells_under_the_current_key():
    """The package ships one entry, under the key the current code computes for the main job's strength cell,
    readable and small."""
    _, _, key = SHIP.main_job_cell()
    assert SHIP.shipped() == [f"{key}.npz"], (
        f"the shipped strength cell {SHIP.shipped()} is not the current key {key} (the cell, its discretization, "
        "the code that computes it or the package's, NGSolve's or Netgen's version changed): run "
        "`python scripts/ship_strength_cell.py` and commit ngcontact/data/strength_cells")
    arrays = SC.read_entry(key, SC.SHIPPED)
    assert arrays is not None and arrays["states"].shape[0] == 7
    assert os.path.getsize(os.path.join(SC.SHIPPED, f"{key}.npz")) < LARGEST_SHIPPED


def test_a_change_of_the_cell_its_discretization_stiffness_or_code_changes_the_key(monkeypatch, tmp_path):
    cs = coarse_hills()
    key = SC.recovery_key(cs, 1e9)
    assert SC.recovery_key(coarse_hills(), 1e9) == key
    assert SC.recovery_key(coarse_hills(maxh=0.45), 1e9) != key
    assert SC.recovery_key(coarse_hills(order=2), 1e9) != key
    assert SC.recovery_key(B.recovery_cell_scene(HILLS, key="strength.cell", overrides={"k_n": 1e11},
                                                 discretization={"maxh": 0.5, "interface_maxh": 0.25, "order": 1}),
                           1e9) != key
    assert SC.recovery_key(cs, 2e9) != key
    package = tmp_path / "ngcontact"
    for rel in SC.SOURCES:
        (package / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(SC.PACKAGE / rel, package / rel)
    monkeypatch.setattr(SC, "PACKAGE", package)
    assert SC.recovery_key(cs, 1e9) == key
    with open(package / "coupling" / "strength.py", "a") as fh:
        fh.write("\n# an edit\n")
    assert SC.recovery_key(cs, 1e9) != key


def test_an_entry_is_computed_then_cached_then_shipped_with_the_same_correctors(monkeypatch, tmp_path, caplog):
    """Computed and cached on a miss; read back from the cache, and from the package's data, it gives the
    correctors of the computation (the same sampling of the same states on the mesh read back)."""
    cs, kt = coarse_hills(), 1e9
    monkeypatch.setattr(SC, "SHIPPED", str(tmp_path / "shipped"))
    cache = str(tmp_path / "cache")
    found = {}
    for want in ("computed", "cached"):
        problem, corr, source = SC.fixed_set_correctors(cs, kt, cache)
        assert source == want
        found[source] = (problem, corr)
    assert os.listdir(cache) == [f"{SC.recovery_key(cs, kt)}.npz"]
    monkeypatch.setattr(SC, "SHIPPED", cache)
    problem, corr, source = SC.fixed_set_correctors(cs, kt, str(tmp_path / "empty"))
    assert source == "shipped" and not os.path.exists(tmp_path / "empty")
    found[source] = (problem, corr)
    reference = found["computed"][1]
    for source in ("cached", "shipped"):
        p, c = found[source]
        assert p.ndof == found["computed"][0].ndof and p is not found["computed"][0]
        for b in S.BODIES:
            scale = np.abs(reference.unit[b]).max()
            assert np.abs(c.points[b] - reference.points[b]).max() < 1e-14
            assert np.abs(c.unit[b] - reference.unit[b]).max() < 1e-12 * scale, (source, b)
            assert np.abs(c.base[b] - reference.base[b]).max() <= 1e-12 * scale, (source, b)


def test_an_entry_whose_states_do_not_fit_its_mesh_is_recomputed_with_a_warning(monkeypatch, tmp_path, caplog):
    cs, kt = coarse_hills(), 1e9
    monkeypatch.setattr(SC, "SHIPPED", str(tmp_path / "shipped"))
    _, _, arrays = SC.compute_entry(cs, kt)
    key = SC.recovery_key(cs, kt)
    SC.write_entry(key, {**arrays, "states": arrays["states"][:, :-1]}, SC.SHIPPED)
    with caplog.at_level(logging.WARNING, logger="ngcontact.drivers.strength_cell"):
        _, _, source = SC.fixed_set_correctors(cs, kt, str(tmp_path / "cache"))
    assert source == "computed"
    assert [r.getMessage() for r in caplog.records] == [
        f"ngcontact: the strength cell's entry {key} in {SC.SHIPPED} is not used ({arrays['states'].shape[1] - 1} "
        f"unknowns in its states, {arrays['states'].shape[1]} on its mesh); recomputing it"]


@pytest.mark.slow
def test_the_shipped_entry_is_what_the_main_job_cell_computes_now():
    """The main job's cell meshed and solved again: its mesh and corrector states are the shipped ones
    (``STATES_RTOL``), and every module of the package the computation runs is one the key digests."""
    cs, kt, key = SHIP.main_job_cell()
    shipped = SC.read_entry(key, SC.SHIPPED)
    assert shipped is not None, "no shipped entry under the current key: run `python scripts/ship_strength_cell.py`"
    ran: set[str] = set()

    def profile(frame, event, arg):
        name = frame.f_code.co_filename
        if event == "call" and name.startswith(str(SC.PACKAGE)):
            ran.add(Path(name).relative_to(SC.PACKAGE).as_posix())
    sys.setprofile(profile)
    try:
        problem, states, arrays = SC.compute_entry(cs, kt)
    finally:
        sys.setprofile(None)
    unlisted = sorted(ran - set(SC.SOURCES) - {"quiet.py"})
    assert unlisted == [], f"modules the computation runs that the key does not digest: add them to SOURCES {unlisted}"
    assert arrays is not None
    np.testing.assert_array_equal(arrays["cell"], shipped["cell"])
    again = SC.problem_of_entry(cs, shipped)
    points = [np.array([v.point for v in m.vertices]) for m in (problem.mesh, again.mesh)]
    assert points[0].shape == points[1].shape and np.abs(points[0] - points[1]).max() < 1e-14
    scale = np.abs(shipped["states"]).max()
    err = np.abs(states - shipped["states"]).max() / scale
    assert err < STATES_RTOL, f"recomputed corrector states differ from the shipped ones by {err:.2e} (relative)"
