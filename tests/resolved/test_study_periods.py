"""``ngcontact study epsilon --periods``: levels given on the command line pass the checks of the scene's own.

With ``--periods 1 2 3`` on the rectangular-valley blocks the band of the coarsest level (``band * length /
1``) reaches the probes and the block faces; the study used to run and end in NaN (exit 3).
"""
import os

from ngcontact import cli

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BLOCKS = os.path.join(ROOT, "geometries", "direct", "block_rect_valleys.toml")


def test_levels_whose_band_reaches_the_probes_are_refused_before_any_work(tmp_path, capsys):
    out = tmp_path / "out"
    code = cli.main(["study", "epsilon", BLOCKS, "--periods", "1", "2", "3", "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and not out.exists()
    assert "study.periods (from --periods) = [1, 2, 3]: with these levels study.probes[0]" in err
    assert "outside the band of the coarsest level" in err and err.count("\n") == 1


def test_the_scene_s_own_levels_pass_the_same_check():
    from ngcontact.scene import loader
    from ngcontact.scene.resolved_scene import with_study_periods
    scene = loader.load(BLOCKS)
    assert with_study_periods(scene, scene.study.periods) == scene
    assert with_study_periods(scene, (8, 16, 32)).study.periods == (8, 16, 32)
