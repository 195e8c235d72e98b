"""Worker processes that never outlive the process that started them (:mod:`ngcontact.parallel.local_pool`).

A parent that stops normally, or on SIGINT or SIGTERM, stops its workers
itself.  A parent killed with SIGKILL runs no code: without the guards
below its workers would wait for tasks forever (each holds the write end of
the pool's queues, so they never read an end of file), and hold the
parent's stdout.  Three guards, for three ways a worker can miss the end:

* **a death signal**: on Linux each worker asks the kernel, as it starts,
  for SIGKILL when its parent ends (``prctl(PR_SET_PDEATHSIG)``), then
  checks that its parent is still the process that spawned it (a parent
  that died before could not send it) and exits at once if not.  The
  kernel sends the signal when the *thread* that spawned the worker ends,
  so it is asked for only by workers spawned by the parent's main thread
  (:func:`spawn_context` records which thread spawned each worker), whose
  end is the parent's;
* **a watchdog** thread in each worker that compares the parent's pid with
  the one it started with every :data:`WATCH_SECONDS` and ends the worker
  once it differs (the worker was handed to another process): for workers
  spawned by another thread, and systems without the death signal; a
  worker forked by a fork server (:mod:`ngcontact.parallel.fork_server`,
  the server being its parent) also watches the run's process, by pid and
  start time;
* **records**: each pool writes the pids of its parent and of its workers,
  with their start times, to a small file in :func:`record_dir`; a pool
  about to start ends the workers of records whose parent is gone
  (:func:`end_orphans`), should any have escaped the two guards above.  A
  process is ended only when it is provably one of these workers: the same
  pid *and* start time (a reused pid has another), a worker's (or a fork
  server's) command line, and this user's.

The resource tracker of :mod:`multiprocessing`, a child of the parent too,
reads a pipe whose write ends only the parent and its workers hold: once
they are gone it reads the end of file, releases what it tracked and exits
by itself.
"""
from __future__ import annotations

import itertools
import logging
import os
import signal
import sys
import threading
import time
from multiprocessing.context import SpawnContext, SpawnProcess

log = logging.getLogger("ngcontact.parallel.executor")

#: Seconds between two looks of a worker's watchdog at its parent's pid.
WATCH_SECONDS = 0.5

#: Name of every record file (``pool-<parent pid>-<parent start>-<n>.txt``).
RECORD_PREFIX = "pool-"

#: Linux ``prctl`` option: the signal a process receives when its parent ends.
_PR_SET_PDEATHSIG = 1

#: What the command line of a ``spawn`` worker holds (Python's own ``multiprocessing.spawn`` start).
_WORKER_MARKS = (b"from multiprocessing.spawn import spawn_main", b"--multiprocessing-fork")

#: What the command line of a fork server holds, and so of each worker it forks
#: (:mod:`ngcontact.parallel.fork_server`).
SERVER_MARK = b"from multiprocessing.forkserver import main"


# ------------------------------------------------------------------ parent
class _Worker(SpawnProcess):
    """A spawned worker that knows whether the parent's main thread spawned it (``by_main_thread``)."""

    by_main_thread = False

    def start(self) -> None:
        self.by_main_thread = threading.current_thread() is threading.main_thread()
        super().start()       # the spawn start pickles this object, attribute included, for the worker


class _Spawn(SpawnContext):
    Process = _Worker


def spawn_context() -> SpawnContext:
    """The ``spawn`` context of a pool whose workers know which thread of the parent spawned them."""
    return _Spawn()


def record_dir() -> str:
    """Where pools record their workers: ``$XDG_RUNTIME_DIR/ngcontact`` (a per-user directory that does
    not survive a reboot, as no pid does), else ``workers`` in the cell-law cache directory
    (``$NGCONTACT_CACHE``, default ``~/.cache/ngcontact``)."""
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime and os.path.isdir(runtime):
        return os.path.join(runtime, "ngcontact")
    cache = os.environ.get("NGCONTACT_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "ngcontact")
    return os.path.join(cache, "workers")


_COUNT = itertools.count()


class Record:
    """The record file of one pool: a line ``parent PID START``, then one ``worker PID START`` per worker
    (each written by the worker as it starts).  ``path`` is None where no record can be written (no
    ``/proc`` to read start times from, or a directory this user may not write): the pool runs without."""

    def __init__(self):
        self.path: str | None = None
        start = process_start(os.getpid())
        if start is None:
            return
        folder = record_dir()
        name = f"{RECORD_PREFIX}{os.getpid()}-{start}-{next(_COUNT)}.txt"
        try:
            os.makedirs(folder, mode=0o700, exist_ok=True)
            partial = os.path.join(folder, "." + name)
            with open(partial, "w") as f:       # written whole under another name: a record is never half
                f.write(f"parent {os.getpid()} {start}\n")
            os.replace(partial, os.path.join(folder, name))
        except OSError as exc:
            log.debug("no record of the pool's workers in %s (%s)", folder, exc)
            return
        self.path = os.path.join(folder, name)

    def remove(self) -> None:
        """The pool's workers are gone: its record too."""
        if self.path is not None:
            try:
                os.unlink(self.path)
            except OSError:
                pass
            self.path = None


def end_orphans() -> list[int]:
    """End the workers recorded by parents that are gone; remove their records.  Returns the pids ended."""
    folder = record_dir()
    try:
        names = sorted(n for n in os.listdir(folder) if n.startswith(RECORD_PREFIX))
    except OSError:
        return []
    ended = []
    for name in names:
        path = os.path.join(folder, name)
        parent, workers = read_record(path)
        if parent is None or process_start(parent[0]) == parent[1]:
            continue                                  # not a record, or its parent still runs
        for pid, start in workers:
            if process_start(pid) == start and _is_our_worker(pid):
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError:
                    continue
                ended.append(pid)
        try:
            os.unlink(path)
        except OSError:
            pass
    if ended:
        log.warning("ngcontact: ended %d worker process%s left by an earlier run that was killed (pid %s)",
                    len(ended), "" if len(ended) == 1 else "es", ", ".join(map(str, ended)))
    return ended


def read_record(path: str) -> tuple[tuple[int, int] | None, list[tuple[int, int]]]:
    """A record's ``(parent pid, start)`` (None if it has none) and its workers' ``(pid, start)``."""
    parent, workers = None, []
    try:
        with open(path) as f:
            lines = f.read().splitlines()
    except (OSError, UnicodeDecodeError):
        return None, []
    for line in lines:
        fields = line.split()
        if len(fields) != 3 or not (fields[1].isdigit() and fields[2].isdigit()):
            continue                                   # a line cut short by a worker ended as it wrote it
        entry = (int(fields[1]), int(fields[2]))
        if fields[0] == "parent" and parent is None:
            parent = entry
        elif fields[0] == "worker":
            workers.append(entry)
    return parent, workers


def process_start(pid: int) -> int | None:
    """A running process's start time (clock ticks after boot, ``/proc/PID/stat``), None when there is no
    such process (or it has ended and waits to be reaped) or no ``/proc``."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
    except (OSError, IndexError):
        return None
    if fields[0] in (b"Z", b"X"):
        return None
    return int(fields[19])


def _is_our_worker(pid: int) -> bool:
    """Whether ``pid`` runs as this user with the command line of a ``spawn`` worker, of a fork server or of
    a worker forked by one."""
    try:
        if os.stat(f"/proc/{pid}").st_uid != os.getuid():
            return False
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            cmdline = f.read()
    except OSError:
        return False
    return all(mark in cmdline for mark in _WORKER_MARKS) or SERVER_MARK in cmdline


# ------------------------------------------------------------------ worker
def die_with_parent(parent: int, record: str | None, run: tuple[int, int] | None = None) -> None:
    """In a worker as it starts: end with ``parent`` (the pid of the process that spawned it) and with the
    run's process ``run`` (pid and start time; a fork server's worker: its parent is the server), and enter
    the worker in its pool's ``record``."""
    import multiprocessing
    if getattr(multiprocessing.current_process(), "by_main_thread", False):
        death_signal()
    if os.getppid() != parent or run is not None and process_start(run[0]) != run[1]:
        os._exit(1)                          # the parent is gone already (before it could signal)
    threading.Thread(target=_watch, args=(parent, run), name="ngcontact-parent-watch", daemon=True).start()
    enter(record)


def enter(record: str | None) -> None:
    """Enter this process in a pool's ``record`` (``worker PID START``; nothing without one)."""
    start = process_start(os.getpid())
    if record is not None and start is not None:
        try:
            with open(record, "a") as f:      # one short line appended: the lines of workers do not mix
                f.write(f"worker {os.getpid()} {start}\n")
        except OSError:
            pass                                # the record is gone: its parent has ended the pool


def death_signal() -> None:
    """SIGKILL for this process when the thread that spawned it ends (Linux ``prctl``; elsewhere nothing)."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):          # no prctl: the watchdog alone
        return
    prctl.argtypes = [ctypes.c_int] + [ctypes.c_ulong] * 4
    prctl.restype = ctypes.c_int
    prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)


def _watch(parent: int, run: tuple[int, int] | None) -> None:
    while True:
        time.sleep(WATCH_SECONDS)
        if os.getppid() != parent or run is not None and process_start(run[0]) != run[1]:
            os._exit(1)
