"""One member of a batch of independent solves, run in whichever process gets it.

A member is one call ``fn(item)`` of a batch (:mod:`ngcontact.parallel.executor`).
This module holds what every executor shares about running one: the
attempt itself (:func:`run_member`: one member at a time per process,
because Netgen's mesher keeps global state), the failure as it crosses from
a worker (:class:`MemberFailure`: the type and first line of the exception,
and its traceback), a worker's start (:func:`one_thread`: NGSolve on one
thread, SIGINT left to the submitting process), the number of attempts, and
the test-only fault injection of the retry tests.
"""
from __future__ import annotations

import contextlib
import os
import sys
import threading
import traceback
from dataclasses import dataclass
from typing import Any, Callable

from ngcontact.parallel.heap_thresholds import keep_freed_arrays

#: Test-only fault injection, read in the submitting process: ``"MEMBER:ATTEMPTS:MODE"`` makes the member
#: named ``MEMBER`` fail on its first ``ATTEMPTS`` attempts, by raising (``raise``) or by ending its worker
#: process (``kill``).  Not a setting of the package: the tests of retries and failures use it.
FAULT_ENV = "NGCONTACT_TEST_FAULT"

#: The number of attempts of a member (the first and one retry).
ATTEMPTS = 2


@dataclass(frozen=True)
class _Fault:
    member: str
    attempts: int
    mode: str


def fault_from_env() -> _Fault | None:
    raw = os.environ.get(FAULT_ENV)
    if not raw:
        return None
    member, attempts, mode = raw.rsplit(":", 2)
    return _Fault(member, int(attempts), mode)


def run_member(fn: Callable[[Any], Any], item: Any, name: str, attempt: int, fault: _Fault | None) -> Any:
    """One attempt of one member, in whichever process runs it (NGSolve on one thread there)."""
    if fault is not None and fault.member == name and attempt < fault.attempts:
        if fault.mode == "kill" and _IN_WORKER:
            os._exit(70)
        raise RuntimeError(f"injected fault (attempt {attempt + 1})")
    try:
        with _ONE_AT_A_TIME:
            return fn(item)
    except Exception as exc:  # the package's errors take several arguments: they do not unpickle
        raise MemberFailure(reason(exc), traceback.format_exc()) from None


class MemberFailure(Exception):
    """A member's exception as it crosses from a worker: its type and first line, and the traceback."""

    def __init__(self, reason: str, detail: str = ""):
        super().__init__(reason, detail)
        self.reason = reason
        self.detail = detail

    def __str__(self) -> str:
        return self.reason


#: One member at a time per process: Netgen's mesher keeps global state, and a Dask worker may run threads.
#: Re-entrant: a member may run a batch of its own in its thread, one member after the other (a two-scale
#: level of an accuracy study tabulating its cell), which must not wait for itself.
_ONE_AT_A_TIME = threading.RLock()


#: True in a worker process (the test-only ``kill`` fault ends only a worker, never the submitting process).
_IN_WORKER = False


def in_worker() -> bool:
    """Whether this process has been made a worker (:func:`one_thread`)."""
    return _IN_WORKER


#: The variables by which the BLAS and OpenMP libraries a process loads later (SciPy's own OpenBLAS, loaded
#: by the first member that needs ``scipy.linalg``) learn their number of threads as they load.
BLAS_THREADS_ENV = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def one_thread(ignore_sigint: bool) -> None:
    """Worker start: NGSolve and BLAS on one thread (the libraries loaded already by ``threadpoolctl``, those
    loaded later by :data:`BLAS_THREADS_ENV`), the C heap's thresholds as in this process
    (:func:`~ngcontact.parallel.heap_thresholds.keep_freed_arrays`); a pool's workers leave SIGINT to the
    submitting process, which stops them."""
    global _IN_WORKER
    _IN_WORKER = True
    os.environ["NGCONTACT_THREADS"] = "1"
    for name in BLAS_THREADS_ENV:
        os.environ[name] = "1"
    keep_freed_arrays()
    if ignore_sigint:
        import signal
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    import ngsolve
    ngsolve.SetNumThreads(1)
    from threadpoolctl import threadpool_limits
    threadpool_limits(limits=1)     # nor BLAS threads (runner.threads): for the rest of the worker's life


@contextlib.contextmanager
def threads_asleep():
    """Within the block, the NGSolve task manager's threads of this process sleep between looks for work
    (``pyngcore.SuspendTaskManager``): while workers solve a batch, this process only waits, and its idle
    threads would otherwise spin on the cores the workers compute on.  Nothing where NGSolve is not loaded."""
    if "pyngcore" not in sys.modules:
        yield
        return
    from pyngcore import SuspendTaskManager
    with SuspendTaskManager(SLEEP_MICROSECONDS):
        yield


#: Microseconds the task manager's idle threads sleep between looks for work while workers compute.
SLEEP_MICROSECONDS = 10_000


def reason(exc: BaseException) -> str:
    if isinstance(exc, MemberFailure):
        return exc.reason
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}".rstrip(": ")
