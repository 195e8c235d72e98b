"""The fork server of a local pool: NGSolve and the package imported once, every worker a fork of it.

A spawned worker (:func:`ngcontact.parallel.worker_lifetime.spawn_context`)
is a fresh interpreter that imports NGSolve and the package by itself,
most of a CPU second each.  Here a single fresh interpreter, the *server*
(:mod:`multiprocessing`'s ``forkserver``), imports them once (its
preload, the modules a pool's members need) and then forks each worker of
the pool from itself: a fork shares the imported modules, so a worker
starts in milliseconds.  The pool's start then costs one interpreter's
imports, not one per worker, and the server makes them beside the run's own
process.  In condition (1) of :mod:`ngcontact.parallel.worker_payoff`
each of ``W`` workers pays ``S = S_server / W + S_fork`` before the server
is started, and only ``S_fork`` once it is (its start is spent, whatever the
batch then decides: :meth:`Server.start_still`).

Threads.  ``fork`` copies only the thread that calls it; a lock that
another thread held (NGSolve's task manager, an OpenBLAS thread pool) would
stay locked in the worker.  The server is therefore started with NGSolve,
OpenBLAS, OpenMP and MKL on one thread
(:data:`~ngcontact.parallel.batch_member.BLAS_THREADS_ENV`,
``NGCONTACT_THREADS``): its imports start no thread, and the thread that
forks is its only one.  The run's own process (whose task manager may hold
threads) never forks; it asks the server over a socket.

Lifetime, beside the guards of :mod:`ngcontact.parallel.worker_lifetime`:

* the server waits on a pipe whose write end the run's process holds (a
  worker inherits a copy and closes it as it starts, :func:`leave_server`):
  when the run ends, even by SIGKILL, the server reads the end of the file
  and exits;
* a worker was forked by the server's only thread: it asks for the
  kernel's death signal when the server ends, and its watchdog watches the
  run's process too (by pid and start time: a reused pid has another);
* the server writes itself into a record of its own as its imports end
  (:mod:`ngcontact.parallel.fork_server_ready`, imported last): the run
  reads there that the server is ready, and a later pool ends the server of
  a killed run by that record, should it have outlived it.

Where no record can be written (no ``/proc``, no writable directory) or the
platform has no ``forkserver``, a pool spawns its workers (:func:`available`).
The server is :mod:`multiprocessing`'s one per process: the pools of a
process share it (:func:`acquire`), and the last to close stops it
(:func:`release`), where the package started it.
"""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
import time
from multiprocessing import forkserver
from multiprocessing.context import ForkServerContext, ForkServerProcess

from ngcontact.parallel import batch_forecast, worker_lifetime
from ngcontact.parallel.batch_member import BLAS_THREADS_ENV
from ngcontact.parallel.free_cores import process_seconds

#: The environment variable that tells the server's last import where to enter itself, whether the run's
#: main thread started it and the run's pid (``RECORD:1:PID``); the server removes it: no worker sees it.
READY_ENV = "NGCONTACT_FORK_SERVER_RECORD"

#: The module the server imports last: its imports are done.
READY_MODULE = "ngcontact.parallel.fork_server_ready"


class _ForkWorker(ForkServerProcess):
    """A worker forked by the server's only thread: the kernel's death signal follows the server.

    :mod:`multiprocessing` starts a new server by itself where the last has
    died (:func:`multiprocessing.forkserver.ensure_running`, as a worker is
    asked for), with the environment of the moment: the worker is therefore
    asked for within the server's one-thread environment, and a server so
    restarted is the pool's (:meth:`Server.follow`)."""

    by_main_thread = True

    def start(self) -> None:
        server = _SHARED
        with _single_threaded_environment(server.ready_value() if server is not None else None):
            super().start()
        if server is not None:
            server.follow()


class _ForkServer(ForkServerContext):
    Process = _ForkWorker


def context() -> ForkServerContext:
    """The ``forkserver`` context of a pool whose workers ask for the death signal of the server."""
    return _ForkServer()


def available() -> bool:
    """Whether pools may fork their workers from a server here: ``forkserver`` exists and a server's
    record can be written (its lifetime guard and its signal of readiness)."""
    return ("forkserver" in multiprocessing.get_all_start_methods()
            and worker_lifetime.process_start(os.getpid()) is not None)


def _server_pid() -> int | None:
    """The pid of this process's fork server as :mod:`multiprocessing` knows it (running or not)."""
    return getattr(forkserver._forkserver, "_forkserver_pid", None)


def _running_pid() -> int | None:
    """The pid of this process's running fork server, None when there is none or it has ended (left
    unreaped: :func:`multiprocessing.forkserver.ensure_running` reaps it and starts another)."""
    pid = _server_pid()
    return pid if pid is not None and worker_lifetime.process_start(pid) is not None else None


@contextlib.contextmanager
def _single_threaded_environment(ready: str | None):
    """Within the block, the environment a server is started with: every library on one thread, and
    :data:`READY_ENV` set to ``ready`` (unset for None); this process's own environment is restored after
    it."""
    values = {"NGCONTACT_THREADS": "1", **{name: "1" for name in BLAS_THREADS_ENV}}
    saved = {name: os.environ.get(name) for name in (*values, READY_ENV)}
    os.environ.update(values)
    if ready is None:
        os.environ.pop(READY_ENV, None)
    else:
        os.environ[READY_ENV] = ready
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def preloaded(modules) -> list[str]:
    """What the server imports of ``modules``: NGSolve's and the package's (a module of the caller's, or
    ``__main__``, each worker imports as a spawned one would: an error there ends a worker, not the
    server)."""
    return [m for m in modules if m.split(".")[0] in ("ngsolve", "ngcontact")]


class Server:
    """The fork server a pool uses: started here (``owned``) with its imports of ``modules`` running
    beside this process, or found running (someone else's, taken as ready)."""

    def __init__(self, modules: tuple[str, ...]):
        self.holders = 0                      # the pools that use it (:func:`acquire`)
        self.spawned = time.perf_counter()
        self.record: worker_lifetime.Record | None = None
        self.cpu: float | None = None         # the server's CPU seconds once ready (its start's cost)
        pid = _running_pid()
        self.owned = pid is None
        if self.owned:
            worker_lifetime.end_orphans()
            self.record = worker_lifetime.Record()
            forkserver.set_forkserver_preload(preloaded(modules) + [READY_MODULE])
            with _single_threaded_environment(self.ready_value()):
                forkserver.ensure_running()
            pid = _running_pid()
        assert pid is not None, "the fork server did not start"
        self.pid = pid
        self._ready = not self.owned or self.record is None or self.record.path is None

    def ready_value(self) -> str | None:
        """:data:`READY_ENV` for a server started now by this thread: its record, whether the run's main
        thread starts it, the run's pid (None for a server found running: not this pool's to record)."""
        if not self.owned or self.record is None:
            return None
        main = threading.current_thread() is threading.main_thread()
        return f"{self.record.path or ''}:{int(main)}:{os.getpid()}"

    def follow(self) -> None:
        """After a worker's start: where :mod:`multiprocessing` started another server in place of a dead
        one (in the one-thread environment, :class:`_ForkWorker`), that one is this pool's server now, its
        start spent."""
        pid = _running_pid()
        if pid is None or pid == self.pid or not self.owned:
            return
        self.pid = pid
        self._ready = self.record is None or self.record.path is None
        self.spawned = time.perf_counter()

    def running(self) -> bool:
        """Whether this is still the process's fork server and runs."""
        return _server_pid() == self.pid and worker_lifetime.process_start(self.pid) is not None

    def ready(self) -> bool:
        """Whether the server's imports are done (it has entered itself in its record); its CPU seconds
        then (:attr:`cpu`, the start's cost ``S_server``) are read as this is first seen."""
        if not self._ready and self.record is not None and self.record.path is not None:
            _, entries = worker_lifetime.read_record(self.record.path)
            if any(pid == self.pid for pid, _ in entries):
                self._ready = True
                self.cpu = process_seconds(self.pid)
                batch_forecast.remember_cost("server", self.cpu)
        return self._ready

    def wait(self, seconds: float) -> bool:
        """Wait at most ``seconds`` for :meth:`ready`; whether it is."""
        deadline = time.monotonic() + seconds
        while not self.ready() and time.monotonic() < deadline and self.running():
            time.sleep(0.01)
        return self.ready()

    def start_still(self, server: float, fork: float) -> float:
        """Wall seconds of a worker's start still ahead (``R``), of a server's start of ``server`` seconds
        and a fork's of ``fork``: what the server's imports have still to do, and the fork."""
        if self.ready():
            return fork
        return max(server - (time.perf_counter() - self.spawned), 0.0) + fork

    def stop(self) -> None:
        """End the server, if this pool started it (its workers have been stopped), and remove its record."""
        if not self.owned:
            return
        if _server_pid() == self.pid:
            with contextlib.suppress(OSError):
                os.kill(self.pid, signal.SIGKILL)   # idle (or importing): it holds nothing of the run's
            with contextlib.suppress(ChildProcessError, OSError):
                forkserver._forkserver._stop()      # type: ignore[attr-defined]  # reaps it, forgets its pipe
        if self.record is not None:
            self.record.remove()
        self.owned = False


_LOCK = threading.Lock()
_SHARED: Server | None = None     # the server this process's pools hold


def acquire(modules: tuple[str, ...]) -> Server:
    """The fork server for a pool: the one this process's pools hold, or a new one importing ``modules``
    (beside this process: this returns at once).  Each :func:`acquire` needs a :func:`release`."""
    global _SHARED
    with _LOCK:
        if _SHARED is None or not _SHARED.running():
            _SHARED = Server(modules)
        _SHARED.holders += 1
        return _SHARED


def release(server: Server) -> None:
    """A pool is done with ``server``: the last to release it stops it (where the package started it)."""
    global _SHARED
    with _LOCK:
        server.holders -= 1
        if server.holders <= 0:
            server.stop()
            if _SHARED is server:
                _SHARED = None


def leave_server() -> None:
    """In a forked worker as it starts: close its copy of the server's pipe (the server then ends with the
    run's process alone, not with the last of its workers)."""
    server = forkserver._forkserver
    fd = getattr(server, "_forkserver_alive_fd", None)
    if fd is not None:
        with contextlib.suppress(OSError):
            os.close(fd)
        server._forkserver_alive_fd = None  # type: ignore[attr-defined]
