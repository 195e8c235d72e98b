"""A damaged mesh file a new user may hand in, found by the reliability audit of issue 35: refused when the scene
loads (exit 2, one line naming ``geometry.file`` and what is wrong), never listed as faces of no area at NaN
centroids."""
from ngcontact import cli

from test_cad_model import SCENE, write_block_on_base_meshes


def test_a_truncated_netgen_mesh_is_refused_as_damaged(tmp_path, capsys):
    """Was: Netgen read the points of a .vol cut in half as garbage of one value, and the run ended with
    'boundaries.bottom matches no face', listing every face with area 0 and centroid (nan, nan, nan)."""
    write_block_on_base_meshes(tmp_path)
    data = (tmp_path / "bb.vol").read_bytes()
    (tmp_path / "bb.vol").write_bytes(data[:len(data) // 2])
    text = SCENE.format(extra="", loaded="top").replace('file = "bb.step"', 'file = "bb.vol"').replace(
        'rough = { name = "block" }', "rough = { index = 0 }").replace(
        "counter = { point = [1.0, 0.5, -0.5] }", "counter = { index = 1 }")
    (tmp_path / "s.toml").write_text(text)
    out = tmp_path / "out"
    for argv in (["check", str(tmp_path / "s.toml")], ["run", str(tmp_path / "s.toml"), "--out", str(out), "--quiet"]):
        assert cli.main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "geometry.file = 'bb.vol': " in err, err
        assert "of zero volume" in err and "damaged or truncated" in err, err
        assert not out.exists()
