"""``study.meshes = 3``: each level of the epsilon study on three discretizations, its errors the finest pair's
and each estimate the Richardson tail of the two changes (:mod:`ngcontact.drivers.richardson_tail`)."""
from __future__ import annotations

import os

import pytest

from ngcontact.cli import EXIT_SCENE
from ngcontact.cli import main as cli_main
from ngcontact.drivers.study_epsilon import run_study
from ngcontact.errors import SceneError
from ngcontact.scene import loader as scene_mod
from ngcontact.scene.resolved_scene import with_study_meshes

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BLOCK = os.path.join(ROOT, "geometries", "direct", "block_rect_valleys.toml")
CELL = os.path.join(ROOT, "geometries", "direct", "rect_valleys_cell.toml")


def small_block(tmp_path, meshes) -> str:
    """The shipped block study on few, coarse levels: order 2, N = 2, 3, 4, a far field of 0.25 m."""
    text = open(BLOCK).read().replace('cell = "rect_valleys_cell.toml"', f'cell = "{CELL}"')
    for old, new in (("order = 3", "order = 2"), ("maxh = 0.05 ", "maxh = 0.25 "),
                     ("elements_per_period = 8 ", "elements_per_period = 4 "),
                     ("periods = [4, 8, 16]", "periods = [2, 3, 4]"), ("band = 2.0 ", "band = 1.0 "),
                     ("interface_maxh = 0.01 ", "interface_maxh = 0.1 "),
                     ("grid = [100, 50]", f"grid = [20, 10]\nrefinement = 1.5\nmeshes = {meshes}")):
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / f"small_block_{meshes}.toml"
    path.write_text(text)
    return str(path)


def test_three_meshes_report_the_finest_pair_with_the_ratio_of_the_two_changes(tmp_path):
    res = run_study(scene_mod.load(small_block(tmp_path, 3)), laws=("linear",)).results
    rows = res["rows"]
    assert [r["N"] for r in rows] == [2, 3, 4]
    for r in rows:
        for key in ("field", "reaction", "probe", "interface"):
            est, contracts = r[f"linear_{key}_discretization"], r[f"linear_{key}_contracts"]
            ratios = [r[f"linear_{key}_ratio_{side}"] for side in ("resolved", "homogenized")]
            assert est >= 0 and isinstance(contracts, bool), (key, r)
            if contracts:
                assert all(q < 1 for q in ratios), (key, r)
            else:
                assert any(q is None or q >= 1 for q in ratios), (key, r)
                assert r["N"] in res["discretization"]["largest_change"]["linear"][key]
    disc = res["discretization"]
    assert disc["meshes"] == 3 and disc["refinement"] == 1.5 and "Richardson" in disc["estimate"]
    # the finest pair is solved on meshes refined twice by 1.5: about 1.5^4 the scene's unknowns
    scene_dofs = run_study(scene_mod.load(small_block(tmp_path, 2)), [2], laws=("linear",)).results
    assert "linear_field_ratio_resolved" not in scene_dofs["rows"][0] and "meshes" not in scene_dofs["discretization"]
    assert rows[0]["ndof_resolved"] > 2 * scene_dofs["rows"][0]["ndof_resolved"] / 1.5 ** 2


@pytest.mark.parametrize("value", [1, 4])
def test_meshes_other_than_two_or_three_are_refused(tmp_path, value):
    path = small_block(tmp_path, value)
    with pytest.raises(SceneError, match="study.meshes"):
        scene_mod.load(path)


def test_the_command_line_sets_meshes_for_the_epsilon_study_only(tmp_path, capsys):
    sc = scene_mod.load(small_block(tmp_path, 2))
    three = with_study_meshes(sc, 3)
    assert three.study.meshes == 3 and three.cell_scene is sc.cell_scene and sc.study.meshes == 2
    with pytest.raises(SceneError, match="study.meshes"):
        with_study_meshes(sc, 5)
    assert cli_main(["study", "accuracy", small_block(tmp_path, 2), "--meshes", "3"]) == EXIT_SCENE
    assert "--meshes: an option of the epsilon study only" in capsys.readouterr().err
