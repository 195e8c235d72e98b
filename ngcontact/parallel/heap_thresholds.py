"""The C heap's thresholds in a worker or a run whose environment fixed them (glibc's ``malloc``).

glibc serves an allocation above its *mmap threshold* by a fresh ``mmap``
and returns it to the kernel when freed; the kernel zero-fills every page
of the next one again.  By default the threshold adapts: once a freed block
was larger, later blocks of that size come from the heap and are reused.
Setting ``MALLOC_TRIM_THRESHOLD_`` in the environment (Dask's nanny does,
``65536``, so that workers give memory back to the system) freezes the
threshold at its start value of 128 KiB.  A spectral cell allocates and
frees FFT buffers of a few MiB in every step, so each step pays the page
faults of all its buffers: a member of a batch then costs several times the
CPU it costs in this process.  The variable also leaks into the process that
started a local Dask cluster (Dask's nanny sets it there before spawning its
workers), and so into every run that process starts: a run's own process
(:func:`ngcontact.runner.threads`) raises the thresholds as a worker does.

:func:`keep_freed_arrays` sets both thresholds once, where that variable is
set, to what the adaptive rule would reach for arrays up to
:data:`MMAP_THRESHOLD` bytes: blocks of that size stay in the heap, and the
heap is given back to the system beyond :data:`TRIM_THRESHOLD` bytes free.
Elsewhere (other C libraries, the variable unset) nothing changes.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import os

#: Blocks up to this size come from the heap and are reused (glibc's largest adaptive threshold on 64 bit).
MMAP_THRESHOLD = 32 * 2**20

#: Free memory at the heap's top beyond this is returned to the system.
TRIM_THRESHOLD = 2 * MMAP_THRESHOLD

#: The environment variables that freeze glibc's adaptive thresholds.
FREEZING = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TOP_PAD_", "MALLOC_MMAP_MAX_")

_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3      # mallopt's parameters (malloc.h)


def keep_freed_arrays() -> bool:
    """Raise the heap's thresholds where the environment froze them (module docstring); whether it did."""
    if not any(name in os.environ for name in FREEZING):
        return False
    name = ctypes.util.find_library("c")
    try:
        mallopt = ctypes.CDLL(name).mallopt
    except (OSError, AttributeError, TypeError):  # not glibc: no such thresholds
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))
