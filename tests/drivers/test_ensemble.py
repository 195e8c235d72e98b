"""Ensembles of random surfaces: mean and 95 % band per load, a band that shrinks like M^(-1/2).

Requirement: the law of a surface class is the mean over realizations, with
a confidence band that vanishes for identical members and narrows like
``1/sqrt(M)`` for independent ones.
"""
import json

import numpy as np
import pytest

from ngcontact import cli
from ngcontact.errors import SceneError
from ngcontact.runner import solve
from ngcontact.scene import loader

SCENE = """kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "{profile}"
arrangement = "summit"
spectrum = {{ hurst = 0.8, rms_slope = {rms}, rolloff = 0.25, cutoff = 0.0625, grid = 32, seed = 3 }}
[contact]
k_n = 1.0e3
enforcement = "{enforcement}"
[load]
pressure = [0.002, 0.01]
[discretization]
method = "spectral"
[ensemble]
members = {members}
"""
QUANTITIES = ("contact_fraction", "k_n0", "effective_stiffness", "mean_closure")


def ensemble_scene(tmp_path, members=16, rms=0.1, profile="self_affine", enforcement="exact"):
    path = tmp_path / f"ensemble_{members}_{rms}.toml"
    path.write_text(SCENE.format(members=members, rms=rms, profile=profile, enforcement=enforcement))
    return str(path)


def test_identical_members_have_a_zero_band(tmp_path):
    # penalty: under exact non-penetration the flat surface in full contact has an infinite interface stiffness
    report, outcome = solve(ensemble_scene(tmp_path, members=4, rms=0.0, enforcement="penalty"), workers=1)
    r = report["results"]
    assert r["ensemble"]["seeds"] == [3, 4, 5, 6]
    for entry in r["loads"]:
        for q in QUANTITIES:
            assert entry[q]["half_width"] == 0.0 and entry[q]["low"] == entry[q]["high"] == entry[q]["mean"], q
        assert entry["contact_fraction"]["mean"] == 1.0          # rms 0: the flat surface is in full contact
    assert all(s["rate"] is None for s in r["shrinkage"].values())
    assert "ensemble_band" not in outcome.plots and "ensemble_law" in outcome.plots


def test_the_band_of_a_real_ensemble_shrinks_like_one_over_root_m(tmp_path):
    report, _ = solve(ensemble_scene(tmp_path), workers=1)
    r = report["results"]
    members = np.array([[[m[k][q] for q in QUANTITIES] for k in range(2)] for m in r["members"]])
    assert len(members) == 16 and len({tuple(m.ravel()) for m in members}) == 16   # distinct realizations
    for k, entry in enumerate(r["loads"]):
        for i, q in enumerate(QUANTITIES):
            assert entry[q]["mean"] == pytest.approx(members[:, k, i].mean(), rel=1e-14)
            assert 0 < entry[q]["half_width"] < abs(entry[q]["mean"]), (q, entry[q])
    for q in QUANTITIES:
        s = r["shrinkage"][q]
        assert s["members"] == [4, 8, 16]
        assert abs(s["rate"] + 0.5) <= 0.15, (q, s)


def test_the_cli_writes_the_law_with_its_band(tmp_path):
    out = tmp_path / "out"
    assert cli.main(["run", ensemble_scene(tmp_path, members=8), "--out", str(out), "--quiet", "--workers", "1"]) == 0
    report = json.loads((out / "report.json").read_text())
    assert sorted(report["files"]) == ["ensemble.csv", "ensemble_band.png", "ensemble_law.png",
                                       "ensemble_members.csv", "ensemble_shrinkage.csv"]
    assert (out / "ensemble_law.png").stat().st_size > 10_000


def test_an_ensemble_needs_a_random_surface(tmp_path):
    text = SCENE.format(members=4, rms=0.1, profile="flat3d", enforcement="exact").replace(
        'spectrum = { hurst = 0.8, rms_slope = 0.1, rolloff = 0.25, cutoff = 0.0625, grid = 32, seed = 3 }\n', "")
    path = tmp_path / "flat.toml"
    path.write_text(text)
    with pytest.raises(SceneError, match="ensemble = '...': realizations of a random surface need geometry.profile "
                                         "= 'self_affine'"):
        loader.load(path)
