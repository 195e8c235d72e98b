"""The threads of the spectral cell's FFTs: those of the run (``NGCONTACT_THREADS``), on a grid that repays them.

A run computes on the threads ``NGCONTACT_THREADS`` names, every core available to the process without it
(:func:`ngcontact.runner.thread_count`); a batch worker is held to one
(:func:`ngcontact.parallel.batch_member.one_thread`), so that ``N`` workers use ``N`` cores.  The FFTs of the
spectral cell (``scipy.fft`` with ``workers=``) follow the same setting, but a transform is only split where
each thread gets at least :data:`POINTS_PER_THREAD` points of the grid::

    threads = min(T, max(1, n // POINTS_PER_THREAD))

``T`` the run's threads, ``n`` the points of one transform (all its fields).  A small transform splits into
pieces whose hand-over between threads costs more than the piece saves: the thousands of FFTs of a small
cell's solve then take more CPU time, and more wall time, than on one thread, and a batch of such cells
solved in the run's process ran slower than one worker solves it (section ``ensemble_executors`` of
docs/benchmarks.md: the serial runs against a local pool of one-thread workers).  The variable is read, not
validated: the runner refuses a bad value before a run starts, and a library call with one falls back to
every core.
"""
from __future__ import annotations

import os

THREADS_ENV = "NGCONTACT_THREADS"

#: Grid points one FFT thread takes at least (256 x 256: a transform of this size or smaller runs on one).
POINTS_PER_THREAD = 2 ** 16


def fft_workers(points: int | None = None) -> int:
    """The threads of one FFT of ``points`` grid points (any number where None): ``NGCONTACT_THREADS`` where it
    is an integer >= 1, else the cores available; at most one per :data:`POINTS_PER_THREAD` points."""
    raw = os.environ.get(THREADS_ENV, "")
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        n = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    if points is not None:
        n = min(n, max(1, int(points) // POINTS_PER_THREAD))
    return n
