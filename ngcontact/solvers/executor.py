"""One executor behind every batch of independent solves.

A batch is a list of members ``fn(item)``, each a whole solve that needs
nothing from the others (independent loads of a cell, levels of an epsilon
study, realizations of a random surface).  ``fn`` is a module-level function
and ``item`` plain data (a scene description, numbers): a worker builds its
own meshes from them, and the result comes back as plain data (dicts,
NumPy arrays).  No mathematics here; the members are solved exactly as in
one process, so a batch gives the same numbers however it is spread.

Executors:

* :class:`Serial` - in this process, one member after the other (one
  worker, or a single member);
* :class:`LocalPool` - a pool of worker processes on this machine
  (``spawn``: a fresh interpreter, never a fork of a process whose NGSolve
  task manager holds threads), each limited to one NGSolve thread so that
  ``N`` workers use ``N`` cores;
* :class:`DaskCluster` - the workers of a ``dask.distributed`` scheduler at
  an address; Dask is the cluster engine, this module only submits.

Failures (the attempt itself: :mod:`ngcontact.solvers.batch_member`): a member that raises (or whose
worker process dies) is run once more; a second failure ends the batch with :class:`~ngcontact.errors.BatchError`
naming the member and the reason, and no result of the batch is returned.
An interruption (``KeyboardInterrupt``, or any exception in the caller while
it waits) stops the workers before it propagates.

The batch a run uses is set once by the runner (:func:`use`) and read by
the code that has a batch (:func:`current`); without one, batches run
serially.  Any room that may import ``solvers`` uses it the same way, e.g.
the levels of a two-scale table in ``coupling/``::

    rows = executor.current().map(solve_level, [(scene, level) for level in levels],
                                  [f"level {k}" for k in range(len(levels))], label="table levels")

with ``solve_level`` a module-level function of plain data.  A script that
runs batches on local workers needs an ``if __name__ == "__main__":`` guard:
the workers are spawned interpreters that import the main module.
"""
from __future__ import annotations

import contextlib
import contextvars
import logging
import os
import time
from typing import Any, Callable, Sequence

from ngcontact.errors import BatchError, NgcontactError
from ngcontact.solvers.batch_member import ATTEMPTS, fault_from_env, in_worker, one_thread, reason, run_member

log = logging.getLogger(__name__)

#: ``progress(label, finished, total)``, called at the start (0) and after every finished member.
Progress = Callable[[str, int, int], None]

def default_workers() -> int:
    """The cores this process may use."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


# --------------------------------------------------------------- executors
class Executor:
    """Runs batches: :meth:`map` returns ``[fn(item) for item in items]`` in order."""

    #: worker processes (or cores of the cluster) the batch is spread over
    workers = 1
    name = "serial"

    def map(self, fn: Callable[[Any], Any], items: Sequence[Any], names: Sequence[str], *,
            label: str = "batch", progress: Progress | None = None) -> list:
        if len(items) != len(names) or len(set(names)) != len(names):
            raise ValueError("a batch needs one distinct name per member")
        progress = progress or _PROGRESS.get()
        if progress is not None:
            progress(label, 0, len(items))
        fault = fault_from_env()
        t0 = time.perf_counter()
        out = self._map(fn, list(items), list(names), label, progress, fault)
        self.record.append({"label": label, "members": len(items), "seconds": time.perf_counter() - t0})
        return out

    @property
    def record(self) -> list[dict]:
        """The batches this executor ran: label, number of members, wall seconds (in order)."""
        return self.__dict__.setdefault("_record", [])

    def _map(self, fn, items, names, label, progress, fault) -> list:
        out = []
        for k, (item, name) in enumerate(zip(items, names)):
            error: BaseException | None = None
            for attempt in range(ATTEMPTS):
                try:
                    out.append(run_member(fn, item, name, attempt, fault))
                    break
                except Exception as exc:  # retried once, then reported
                    error = exc
                    log.info("%s: %s failed (%s)%s", label, name, reason(exc),
                                "; retrying" if attempt + 1 < ATTEMPTS else "")
            else:
                assert error is not None
                raise BatchError(label, name, reason(error)) from error
            if progress is not None:
                progress(label, k + 1, len(items))
        return out

    def start(self, modules: Sequence[str] = ()) -> None:
        """Get the workers ready now, while this process prepares the batch (nothing to do here).

        ``modules``: what the members will import, imported by each worker as it starts.
        """

    def start_on_demand(self) -> None:
        """Start workers only for a batch that will repay their start (nothing to start here)."""

    def close(self) -> None:
        """Release the workers (nothing to release here)."""

    def abort(self) -> None:
        """Stop the workers at once (the run failed or was interrupted)."""
        self.close()

    def describe(self) -> dict:
        """Where the batches ran, for the report: the executor, its workers (one NGSolve thread each, a
        single member in this process), a cluster's scheduler address, and the batches it ran."""
        out: dict[str, Any] = {"executor": self.name, "workers": self.workers}
        address = getattr(self, "address", None)
        if address is not None:
            out["scheduler"] = address
        out["batches"] = [dict(b) for b in self.record]
        return out


class Serial(Executor):
    """Every member in this process, in order."""


#: Wall seconds a local pool's workers take to start (fresh interpreters importing NGSolve and the package,
#: all at once; measured 1.5 to 2.5 s for two on the 2-core machine here).
START_SECONDS = 2.0


class LocalPool(Executor):
    """A pool of ``workers`` spawned worker processes on this machine (started on first use)."""

    name = "local"

    def __init__(self, workers: int):
        if workers < 1:
            raise ValueError(f"workers = {workers}: must be >= 1")
        self.workers = workers
        self._pool = None
        self._started = None
        self._processes: dict = {}      # every worker process of the current pool, by pid
        self.on_demand = False

    def _start(self):
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor
        ctx = multiprocessing.get_context("spawn")
        self._started = ctx.SimpleQueue()
        self._processes = {}
        self._pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=ctx, initializer=_worker_start,
                                         initargs=(self._started,))
        return self._pool

    def start(self, modules: Sequence[str] = ()) -> None:
        """Spawn every worker now and let it import ``modules`` (what its members will need).

        A worker is a fresh interpreter: its start and imports take about a
        second, which the batch would otherwise wait for.  Called when a run
        knows it will have a batch, this overlaps with what the run does
        before it (its own imports, the scene's meshes, a macro solve).  The
        pool spawns one process per submitted task while none is idle, so one
        warm-up task per worker starts them all.
        """
        if self._pool is not None:
            return
        pool = self._start()
        for _ in range(self.workers):
            pool.submit(_warm_up, tuple(modules))

    def start_on_demand(self) -> None:
        """Until the workers are started, a batch solves its first member in this process and starts them
        only if the rest will repay their start (:meth:`_worth_starting`); else the whole batch runs here.

        For runs whose batches are few, small and unknown in advance (the
        levels of a two-scale cell table: a handful of 0.2 s cell solves
        each, none at all on a warm cache), where two fresh interpreters
        importing NGSolve on a 2-core machine would cost more than they save.
        """
        self.on_demand = True

    def _worth_starting(self, seconds: float, rest: int) -> bool:
        """Whether ``rest`` more members of ``seconds`` each finish sooner on the workers, start included."""
        return rest * seconds * (1.0 - 1.0 / self.workers) > START_SECONDS

    def _map(self, fn, items, names, label, progress, fault) -> list:
        if len(items) == 1:
            return Executor._map(self, fn, items, names, label, progress, fault)
        if self._pool is None and self.on_demand:
            t0 = time.perf_counter()
            first = Executor._map(self, fn, items[:1], names[:1], label, None, fault)
            seconds = time.perf_counter() - t0
            if progress is not None:
                progress(label, 1, len(items))
            shifted = None if progress is None else (lambda lb, k, n: progress(lb, k + 1, n + 1))
            here = not self._worth_starting(seconds, len(items) - 1)
            log.debug("%s: first member %.3g s; the other %d run %s", label, seconds, len(items) - 1,
                      "in this process" if here else f"on {self.workers} workers")
            rest = (Executor._map if here else LocalPool._pool_map)(self, fn, items[1:], names[1:], label,
                                                                    shifted, fault)
            return first + rest
        return self._pool_map(fn, items, names, label, progress, fault)

    def _pool_map(self, fn, items, names, label, progress, fault) -> list:
        from concurrent.futures import FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool
        results: dict[int, Any] = {}
        failures = {k: 0 for k in range(len(items))}
        pending: dict[Any, int] = {}
        pool = self._pool or self._start()

        def submit(k):
            pending[pool.submit(_pool_member, fn, items[k], names[k], failures[k], fault)] = k
            # the pool spawns its workers on submission and forgets them once one dies: keep them
            self._processes.update(pool._processes or {})

        try:
            for k in range(len(items)):
                submit(k)
            while pending:
                done, _ = wait(list(pending), return_when=FIRST_COMPLETED)
                broken = []
                for fut in done:
                    k = pending.pop(fut)
                    try:
                        results[k] = fut.result()
                    except BrokenProcessPool:
                        broken.append(k)
                        continue
                    except Exception as exc:
                        self._failed(label, names[k], failures, k, exc)
                        submit(k)
                        continue
                    if progress is not None:
                        progress(label, len(results), len(items))
                if broken:
                    # a worker died: its member counts a failure; the members of the other workers are innocent
                    lost = broken + [pending.pop(f) for f in list(pending)]
                    culprits = self._running_on_dead_workers(names)
                    for k in lost:
                        # a worker that died before it started a member (it could not even start: a script
                        # without an ``if __name__ == "__main__":`` guard) leaves no culprit: all count
                        if names[k] in culprits or not culprits:
                            self._failed(label, names[k], failures, k, RuntimeError(
                                "its worker process died" if culprits else "the worker processes died before "
                                "they started it (a script run with workers needs an "
                                "'if __name__ == \"__main__\":' guard)"))
                    self._discard()
                    pool = self._start()
                    for k in lost:
                        submit(k)
        except BaseException:
            self._discard()
            raise
        return [results[k] for k in range(len(items))]

    @staticmethod
    def _failed(label, name, failures, k, exc) -> None:
        failures[k] += 1
        log.debug("%s: %s: %s", label, name, getattr(exc, "detail", "") or reason(exc))
        log.info("%s: %s failed (%s)%s", label, name, reason(exc),
                    "; retrying" if failures[k] < ATTEMPTS else "")
        if failures[k] >= ATTEMPTS:
            raise BatchError(label, name, reason(exc)) from exc

    def _running_on_dead_workers(self, names) -> set[str]:
        """Members last started by worker processes that died by themselves (their start records, by pid).

        The pool terminates the other workers when one dies (exit status
        ``-SIGTERM``): their members are innocent and are not counted.
        """
        import signal
        last: dict[int, str] = {}
        assert self._started is not None
        while not self._started.empty():
            pid, name = self._started.get()
            last[pid] = name
        processes = dict(self._processes)
        if self._pool is not None:
            processes.update(self._pool._processes or {})
        for proc in processes.values():
            proc.join(timeout=2)             # reap: a dead process may still look alive
        died = {pid for pid, proc in processes.items() if _exit_code(proc) not in (None, -signal.SIGTERM)}
        return {name for pid, name in last.items() if pid in died}

    def _discard(self) -> None:
        """Stop the workers now (a broken pool, an error, an interruption)."""
        pool, self._pool = self._pool, None
        if pool is None:
            return
        processes = list((pool._processes or {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for p in processes:
            if p.is_alive():
                p.terminate()
        for p in processes:
            p.join(timeout=5)
            if p.is_alive():  # a worker that does not stop on SIGTERM
                p.kill()
                p.join(timeout=5)

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def abort(self) -> None:
        self._discard()


_STARTED = None


def _exit_code(proc, seconds: float = 2.0):
    """A joined worker's exit code.  The pool's own thread reaps its workers too: while it holds a dead
    worker's status, ``exitcode`` reads ``None`` for a moment, so ``None`` is read again until ``seconds``."""
    deadline = time.monotonic() + seconds
    while proc.exitcode is None and time.monotonic() < deadline:
        time.sleep(0.02)
    return proc.exitcode


def _worker_start(started) -> None:
    global _STARTED
    _STARTED = started
    one_thread(ignore_sigint=True)


def _warm_up(modules: tuple[str, ...]) -> None:
    import importlib
    for module in modules:
        importlib.import_module(module)


def _pool_member(fn, item, name, attempt, fault):
    if _STARTED is not None:
        _STARTED.put((os.getpid(), name))
    return run_member(fn, item, name, attempt, fault)


class DaskCluster(Executor):
    """The workers of the ``dask.distributed`` scheduler at ``address`` (e.g. ``tcp://10.0.0.5:8786``)."""

    name = "dask"

    def __init__(self, address: str):
        self.address = address
        self._client = None

    @property
    def client(self):
        """The connection to the scheduler, made on first use."""
        if self._client is None:
            try:
                from distributed import Client
            except ImportError as exc:  # pragma: no cover - a dependency of the package
                raise NgcontactError(f"scheduler {self.address!r}: dask.distributed is not installed") from exc
            try:
                self._client = Client(self.address, timeout=30, set_as_default=False)
            except Exception as exc:
                raise NgcontactError(f"scheduler {self.address!r}: cannot connect ({reason(exc)})") from exc
            info = self._client.scheduler_info()["workers"].values()
            self.workers = max(1, sum(w.get("nthreads", 1) for w in info))
        return self._client

    def start(self, modules: Sequence[str] = ()) -> None:
        """Connect to the scheduler now: an address that does not answer fails before any solve."""
        self.client  # noqa: B018 - the property connects

    def _map(self, fn, items, names, label, progress, fault) -> list:
        from distributed import as_completed
        client = self.client
        results: dict[int, Any] = {}
        failures = {k: 0 for k in range(len(items))}
        index: dict[Any, int] = {}

        def submit(k):
            fut = client.submit(_dask_member, fn, items[k], names[k], failures[k], fault, pure=False,
                                key=f"ngcontact-{label}-{names[k]}-{failures[k]}-{time.time_ns()}")
            index[fut] = k
            return fut

        futures = as_completed([submit(k) for k in range(len(items))], loop=client.loop)
        try:
            for fut in futures:
                k = index.pop(fut)
                if fut.status == "finished":
                    results[k] = fut.result()
                    if progress is not None:
                        progress(label, len(results), len(items))
                    continue
                exc = fut.exception()
                LocalPool._failed(label, names[k], failures, k, exc)
                futures.add(submit(k))
        except BaseException:
            client.cancel(list(index))
            raise
        return [results[k] for k in range(len(items))]

    def close(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None


def _dask_member(fn, item, name, attempt, fault):
    if not in_worker():
        one_thread(ignore_sigint=False)
    return run_member(fn, item, name, attempt, fault)


def make(workers: int | None = None, scheduler: str | None = None) -> Executor:
    """The executor a run asks for: a scheduler's cluster, else a local pool of ``workers`` (default: the cores)."""
    if scheduler:
        return DaskCluster(scheduler)
    n = default_workers() if workers is None else workers
    return Serial() if n == 1 else LocalPool(n)


# ------------------------------------------------ the run's executor
_CURRENT: contextvars.ContextVar[Executor | None] = contextvars.ContextVar("ngcontact_executor", default=None)
_PROGRESS: contextvars.ContextVar[Progress | None] = contextvars.ContextVar("ngcontact_progress", default=None)


def current() -> Executor:
    """The executor of the running batch-aware code (serial unless a caller set one with :func:`use`)."""
    return _CURRENT.get() or Serial()


@contextlib.contextmanager
def use(executor: Executor, progress: Progress | None = None):
    """Within the block, :func:`current` is ``executor`` and batches report to ``progress``; closed at the end."""
    token, ptoken = _CURRENT.set(executor), _PROGRESS.set(progress)
    try:
        yield executor
    except BaseException:
        executor.abort()                 # an error or Ctrl-C: stop the workers now, even idle or warming up
        raise
    finally:
        _CURRENT.reset(token)
        _PROGRESS.reset(ptoken)
        executor.close()
