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
