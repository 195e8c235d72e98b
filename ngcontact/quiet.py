"""Native output of NGSolve and Netgen kept off the user's terminal.

Some of NGSolve's and Netgen's C++ writes straight to the process's
standard output or error, past Python's ``sys.stdout`` and past the
message levels (``ngsolve.ngsglobals.msg_level``, Netgen's message
importance): Netgen's CSG mesher announces every periodic identification of
a 3D cell ("identify surfaces 12 and 13", twice per cell, in the middle of
``ngcontact run``'s progress lines), and ``VectorH1`` reports a flag that
only its component spaces read.  :func:`quiet` points the given file
descriptors at the null device for a block, after flushing what Python and
C's standard I/O hold, so that nothing written before the block is lost and
nothing written inside it appears after.
"""
from __future__ import annotations

import contextlib
import ctypes
import os
import sys

#: the streams :func:`quiet` may silence, by name: (file descriptor, the Python stream on it)
STREAMS = {"stdout": (1, lambda: sys.stdout), "stderr": (2, lambda: sys.stderr)}


_LIBC: list = []   # the C library, loaded at the first flush


def _flush_native() -> None:
    """Flush C's standard I/O buffers (``fflush(NULL)``), where C++'s ``std::cout`` lands."""
    try:
        if not _LIBC:
            _LIBC.append(ctypes.CDLL(None))
        _LIBC[0].fflush(None)
    except (OSError, AttributeError):   # no C library to reach (not on Linux or macOS): nothing buffered there
        pass


@contextlib.contextmanager
def quiet(*streams: str):
    """The block's native output on ``streams`` (``"stdout"``, ``"stderr"``; default both) discarded."""
    names = streams or tuple(STREAMS)
    unknown = [s for s in names if s not in STREAMS]
    if unknown:
        raise ValueError(f"streams {unknown!r}: must be among {tuple(STREAMS)}")
    fds = [STREAMS[s][0] for s in names]
    for s in names:
        STREAMS[s][1]().flush()
    _flush_native()
    saved = [os.dup(fd) for fd in fds]
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        for fd in fds:
            os.dup2(null, fd)
        yield
    finally:
        _flush_native()
        for fd, keep in zip(fds, saved):
            os.dup2(keep, fd)
            os.close(keep)
        os.close(null)
