"""The cell-law cache: a bad entry is discarded and rebuilt with one warning; an unwritable cache costs only
the caching.  Before, a corrupt, truncated or unwritable entry made every macro run fail with exit 3, and a
tampered but valid entry was used silently (peak pressure 10.02 -> 10.36 MPa)."""
import json
import logging
import os

import numpy as np
import pytest

from ngcontact.coupling import cell_law

KEY = "k" * 64
ARRAYS = {"w": np.array([1.0, 2.0]), "n": np.array([[0.0, 1.0], [0.6, 0.8]]), "g": np.array([0.0, 0.1])}


def compute_counted(calls):
    def compute():
        calls.append(1)
        return {k: v.copy() for k, v in ARRAYS.items()}
    return compute


def fresh_entry(tmp_path):
    calls: list = []
    arrays, cached = cell_law.cached_bundle_arrays(KEY, compute_counted(calls), str(tmp_path))
    assert not cached and calls == [1]
    return tmp_path / f"{KEY}.npz"


def reread(tmp_path, caplog):
    calls: list = []
    with caplog.at_level(logging.WARNING, logger="ngcontact.coupling.cell_law"):
        arrays, cached = cell_law.cached_bundle_arrays(KEY, compute_counted(calls), str(tmp_path))
    for k in ARRAYS:
        np.testing.assert_array_equal(arrays[k], ARRAYS[k])
    return cached, calls, [r.getMessage() for r in caplog.records]


def test_a_good_entry_is_read_back_without_recomputing(tmp_path, caplog):
    fresh_entry(tmp_path)
    cached, calls, warnings = reread(tmp_path, caplog)
    assert cached and calls == [] and warnings == []


def rewrite(path, **changes):
    with np.load(path, allow_pickle=False) as data:
        content = {k: np.array(data[k]) for k in data.files}
    meta = json.loads(str(content["meta"]))
    for k, v in changes.items():
        if k in meta:
            meta[k] = v
        else:
            content[k] = v
    content["meta"] = np.array(json.dumps(meta))
    np.savez(path, **content)
    if not str(path).endswith(".npz"):
        os.replace(str(path) + ".npz", path)


@pytest.mark.parametrize("spoil, reason", [
    (lambda p: p.write_bytes(b"not an npz at all"), "unreadable"),
    (lambda p: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]), "unreadable"),
    (lambda p: rewrite(p, w=np.array([1.0, 2.5])), "checksum mismatch"),
    (lambda p: rewrite(p, version="0.0.0-other"), "version"),
    (lambda p: rewrite(p, key="x" * 64), "key"),
    (lambda p: rewrite(p, g=np.array([0.0, np.nan])), "non-finite"),
    (lambda p: rewrite(p, n=np.array([[0.0, 1.0]])), "shapes"),
])
def test_a_bad_entry_is_discarded_and_rebuilt_with_one_warning(tmp_path, caplog, spoil, reason):
    path = fresh_entry(tmp_path)
    spoil(path)
    cached, calls, warnings = reread(tmp_path, caplog)
    assert not cached and calls == [1]
    assert len(warnings) == 1 and "discarding the cache entry" in warnings[0] and reason in warnings[0], warnings
    caplog.clear()
    cached, calls, warnings = reread(tmp_path, caplog)
    assert cached, "the rebuilt entry is good again"


def test_a_cache_path_that_is_a_file_costs_only_the_caching(tmp_path, caplog):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    cached, calls, warnings = reread(blocker, caplog)
    assert not cached and calls == [1] and len(warnings) == 1 and "cannot be written" in warnings[0]


def test_a_garbage_entry_is_called_unreadable_without_numpys_advice(tmp_path, caplog):
    """Defect: the warning quoted numpy's "allow_pickle=True ... only if you trust the file" advice."""
    path = fresh_entry(tmp_path)
    path.write_bytes(b"\x80\x04garbage that looks like a pickle")
    cached, calls, warnings = reread(tmp_path, caplog)
    assert not cached and calls == [1] and len(warnings) == 1, warnings
    assert "unreadable" in warnings[0] and "discarding the cache entry" in warnings[0], warnings
    assert "pickle" not in warnings[0].lower() and "trust" not in warnings[0], warnings


@pytest.mark.parametrize("kind", ["directory", "symlink", "fifo"])
def test_an_entry_that_is_not_a_regular_file_is_left_alone_and_warned_about_once(tmp_path, caplog, kind):
    """Defect: a cache entry that was a directory was never removed: every later run recomputed and warned.
    The package writes regular files only; anything else under an entry's name is not its own: it is kept
    as it is, the entry goes under a second name, and the next runs read that one without a word."""
    path = tmp_path / f"{KEY}.npz"
    target = tmp_path / "elsewhere.txt"
    target.write_text("the user's")
    if kind == "directory":
        path.mkdir()
        (path / "inside.txt").write_text("the user's")
    elif kind == "symlink":
        path.symlink_to(target)
    else:
        os.mkfifo(path)
    cached, calls, warnings = reread(tmp_path, caplog)
    assert not cached and calls == [1] and len(warnings) == 1, warnings
    assert "not a cache entry" in warnings[0] and "left as it is" in warnings[0], warnings
    caplog.clear()
    for _ in range(2):
        cached, calls, warnings = reread(tmp_path, caplog)
        assert cached and calls == [] and warnings == [], warnings
    assert target.read_text() == "the user's"
    if kind == "directory":
        assert (path / "inside.txt").read_text() == "the user's"
    elif kind == "symlink":
        assert path.is_symlink() and os.readlink(path) == str(target)
