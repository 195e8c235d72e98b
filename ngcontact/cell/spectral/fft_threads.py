"""The threads of the spectral cell's FFTs: those of the run (``NGCONTACT_THREADS``).

A run computes on the threads ``NGCONTACT_THREADS`` names, every core available to the process without it
(:func:`ngcontact.runner.thread_count`); a batch worker is held to one
(:func:`ngcontact.parallel.batch_member.one_thread`), so that ``N`` workers use ``N`` cores.  The FFTs of the
spectral cell (``scipy.fft`` with ``workers=``) follow the same setting.  The variable is read, not
validated: the runner refuses a bad value before a run starts, and a library call with one falls back to
every core.
"""
from __future__ import annotations

import os

THREADS_ENV = "NGCONTACT_THREADS"


def fft_workers() -> int:
    """The threads of one FFT: ``NGCONTACT_THREADS`` where it is an integer >= 1, else the cores available."""
    raw = os.environ.get(THREADS_ENV, "")
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n >= 1:
        return n
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
