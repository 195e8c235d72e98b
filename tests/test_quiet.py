"""Native output kept off the terminal (:mod:`ngcontact.quiet`)."""
from __future__ import annotations

import ctypes
import os

import pytest

from ngcontact.quiet import quiet


def _c_printf(text: str) -> None:
    """Write through C's buffered standard output, as C++'s ``std::cout`` does."""
    ctypes.CDLL(None).printf(text.encode())


def test_native_output_inside_the_block_is_dropped_and_around_it_kept(capfd):
    os.write(1, b"before\n")
    _c_printf("buffered before\n")     # still in C's buffer when the block starts: must not be lost
    with quiet("stdout"):
        os.write(1, b"inside\n")
        _c_printf("buffered inside\n")  # still buffered when the block ends: must not appear after it
    os.write(2, b"stderr kept\n")
    _c_printf("after\n")
    ctypes.CDLL(None).fflush(None)
    out, err = capfd.readouterr()
    assert out == "before\nbuffered before\nafter\n"
    assert err == "stderr kept\n"


def test_both_streams_by_default_and_unknown_names_refused(capfd):
    with quiet():
        os.write(1, b"x\n")
        os.write(2, b"y\n")
    assert capfd.readouterr() == ("", "")
    with pytest.raises(ValueError, match="stdin"):
        with quiet("stdin"):
            pass


def test_a_periodic_3d_cell_is_built_without_netgen_announcing_its_identifications(capfd):
    from ngcontact.geometry.cell3d import flat_cell3d
    flat_cell3d(1.0, 0.5, 0.5, maxh=0.5)
    ctypes.CDLL(None).fflush(None)
    out, _ = capfd.readouterr()
    assert "identify" not in out
