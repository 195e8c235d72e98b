"""A pool of worker processes on this machine (:mod:`ngcontact.parallel.executor`).

Each worker is limited to one NGSolve thread, so that ``N`` workers use
``N`` cores.  They start in one of two ways (``method``):

* ``forkserver`` (the default where it exists): one fresh interpreter, the
  fork server, imports NGSolve and the members' modules once, beside this
  process, and forks every worker from itself in milliseconds
  (:mod:`ngcontact.parallel.fork_server`); never a fork of this process,
  whose NGSolve task manager may hold threads;
* ``spawn``: each worker a fresh interpreter importing them by itself.

A worker that dies counts a failure of the member it had started (its
start record, by pid); the members of the workers the pool then stops are
innocent.  Which members of a run's batch go to the workers is the payoff
rule's (:mod:`ngcontact.parallel.judged_batches`).
"""
from __future__ import annotations

import logging
import os
import time
from typing import Any, Sequence

from ngcontact.parallel.batch_executor import Executor
from ngcontact.parallel.judged_batches import shifted_progress
from ngcontact.parallel.batch_member import one_thread, run_member
from ngcontact.parallel import batch_forecast, fork_server, worker_lifetime
from ngcontact.parallel.pool_start import PoolStart

log = logging.getLogger("ngcontact.parallel.executor")


#: How a pool's workers start: forked by a fork server, or each a fresh interpreter.
METHODS = ("forkserver", "spawn")


class LocalPool(PoolStart):
    """A pool of ``workers`` worker processes on this machine (started on first use), forked by a fork
    server or spawned (``method``; default: ``forkserver`` where :func:`fork_server.available`)."""

    name = "local"

    def __init__(self, workers: int, method: str | None = None):
        if workers < 1:
            raise ValueError(f"workers = {workers}: must be >= 1")
        if method is None:
            method = "forkserver" if fork_server.available() else "spawn"
        if method not in METHODS:
            raise ValueError(f"method = {method!r}: must be one of {', '.join(METHODS)}")
        self.method = method
        self.workers = workers
        self._server: fork_server.Server | None = None   # the fork server, started with the pool
        self._forked = 0              # pools of workers forked by the current server
        self._pool: Any = None        # the ProcessPoolExecutor, started on first use
        self._started: Any = None     # the queue on which workers announce their start
        self._processes: dict = {}      # every worker process of the current pool, by pid
        self._lifetime: worker_lifetime.Record | None = None   # the current pool's record of its workers
        self._warming: list = []      # the warm-up tasks of an early start, one per worker
        self._spawned = 0.0           # when the current pool's workers were spawned (perf_counter seconds)
        self._modules: tuple[str, ...] = ()   # what a worker started on demand imports as it starts
        self.judged = False           # the run's batches: the rest of each goes to workers only where repaid
        self._forecast: Any = None    # the forecast that started the workers with the run, for its first batch
        self.pools_started = 0        # pools of worker processes spawned so far (none for a batch kept here)
        self.started = "never"        # when the workers first started: with the run, or during which batch

    def _start(self):
        """A new pool of workers (none running yet: they start as members are submitted)."""
        from concurrent.futures import ProcessPoolExecutor
        worker_lifetime.end_orphans()
        self._warming = []
        self._processes = {}
        self._lifetime = worker_lifetime.Record()
        self._spawned = time.perf_counter()
        if self.method == "forkserver":
            server = self._open_server()
            self._counted_pool()
            ctx: Any = fork_server.context()
            run = (os.getpid(), worker_lifetime.process_start(os.getpid()))
            args: tuple = (server.pid, self._lifetime.path, run)
        else:
            self.pools_started += 1
            ctx = worker_lifetime.spawn_context()
            args = (os.getpid(), self._lifetime.path, None)
        self._started = ctx.SimpleQueue()
        self._pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=ctx, initializer=_worker_start,
                                         initargs=(self._started, *args))
        return self._pool

    def _abandon_start(self) -> None:
        """Stop workers (or a fork server) still starting: they would take cores from this process."""
        self._discard()
        self._stop_server()

    def start(self, modules: Sequence[str] = (), forecast: batch_forecast.Forecast | None = None) -> None:
        """Spawn every worker now and let it import ``modules`` (what its members will need); ``forecast``: the last
        run's record of the run's first batch, which sends that batch to the workers from its first member where it
        still repays them (:meth:`_sent_on_forecast`).

        A spawned worker is a fresh interpreter: its start and imports take about a second, which the batch would
        otherwise wait for; a fork server makes them once, and its workers fork as a batch needs them.  For a caller
        that knows its batches will repay the workers (:mod:`ngcontact.parallel.worker_payoff`), this overlaps their
        start with what the run does before them (its own imports, the scene's meshes, a macro solve).  The pool
        spawns one process per submitted task while none is idle, so one warm-up task per worker starts them all.
        The run's batches then go to the workers only where they repay them (:meth:`_judged_map`).
        """
        self.judged = True
        self._modules = tuple(dict.fromkeys(self._modules + tuple(modules)))
        if forecast is not None:
            self._forecast = forecast
        if self._launched():
            return
        if self.started == "never":
            self.started = "with the run" if not self.record else f"after batch {len(self.record)}"
        if self.method == "forkserver":
            self._open_server()       # the workers fork once a batch sends them members
            return
        pool = self._start()
        self._warming = [pool.submit(_warm_up, self._modules) for _ in range(self.workers)]
        for warm in self._warming:
            warm.add_done_callback(_measured_start)

    def _map(self, fn, items, names, label, progress, fault) -> list:
        if len(items) == 1:
            self._where("serial", "a single member: solved in this process")
            return Executor._map(self, fn, items, names, label, progress, fault)
        if self.judged:
            return self._judged_map(fn, items, names, label, progress, fault)
        self._where("local", f"every member on the {self.workers} workers")
        self._modules = tuple(dict.fromkeys(self._modules + (fn.__module__,)))   # a server not started yet
        done = self._while_starting(fn, items, names, label, progress, fault)
        if len(done) == len(items):
            return done
        rest = self._pool_map(fn, items[len(done):], names[len(done):], label,
                              shifted_progress(progress, len(done)), fault)
        return done + rest

    def _while_starting(self, fn, items, names, label, progress, fault) -> list:
        """The first members, solved in this process while no worker has started yet.

        A pool started early (:meth:`start`) needs a second or two before its
        first worker takes a member.  This process would wait for it; it
        solves members itself instead, until a worker is ready.  A batch too
        small to repay the start is then done here, as fast as serially, and
        a large one loses nothing.
        """
        done: list = []
        while len(done) < len(items) and self._launched() and not self._ready():
            k = len(done)
            done += Executor._map(self, fn, items[k:k + 1], names[k:k + 1], label,
                                  shifted_progress(progress, k, len(items)), fault)
        if done:
            log.debug("%s: %d of %d members solved in this process while the workers started", label,
                      len(done), len(items))
        return done

    def _pool_map(self, fn, items, names, label, progress, fault) -> list:
        from concurrent.futures import FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool
        results: dict[int, Any] = {}
        failures = {k: 0 for k in range(len(items))}
        pending: dict[Any, int] = {}
        unsent: list[int] = []       # members whose submission found the pool already broken
        firsts: list[float] = []     # CPU seconds of the first member of each worker that had one here
        starts: list[float] = []     # CPU seconds of each such worker before its first member (its start)
        others: list[float] = []     # CPU seconds of the members after a worker's first
        pool = self._pool or self._start()

        def submit(k):
            try:
                pending[pool.submit(_pool_member, fn, items[k], names[k], failures[k], fault)] = k
            except BrokenProcessPool:    # a worker died while the batch was being submitted
                unsent.append(k)
                return
            # the pool spawns its workers on submission and forgets them once one dies: keep them
            self._processes.update(pool._processes or {})

        try:
            for k in range(len(items)):
                submit(k)
            while pending or unsent:
                broken = []
                if pending:
                    done, _ = wait(list(pending), return_when=FIRST_COMPLETED)
                    for fut in done:
                        k = pending.pop(fut)
                        try:
                            results[k], seconds, start = fut.result()
                        except BrokenProcessPool:
                            broken.append(k)
                            continue
                        except Exception as exc:
                            self._failed(label, names[k], failures, k, exc)
                            submit(k)
                            continue
                        (others if start is None else firsts).append(seconds)
                        starts += [] if start is None else [start]
                        if progress is not None:
                            progress(label, len(results), len(items))
                if broken or (unsent and not pending):
                    # a worker died: its member counts a failure; the members of the other workers are innocent,
                    # and so are those never sent (unless nothing had started: then they count)
                    lost = broken + [pending.pop(f) for f in list(pending)]
                    never, unsent[:] = list(unsent), []
                    culprits = self._running_on_dead_workers(names)
                    for k in lost or never:
                        # a worker that died before it started a member (it could not even start: a script
                        # without an ``if __name__ == "__main__":`` guard) leaves no culprit: all count
                        if names[k] in culprits or not culprits:
                            self._failed(label, names[k], failures, k, RuntimeError(
                                "its worker process died" if culprits else "the worker processes died before "
                                "they started it (a script run with workers needs an "
                                "'if __name__ == \"__main__\":' guard)"))
                    self._discard()
                    pool = self._start()
                    for k in sorted(set(lost + never)):
                        submit(k)
        except BaseException:
            self._discard()
            raise
        # ``c`` of a batch none of whose members ran here: the cheapest after a worker's first (its record)
        self.__dict__["_worker_least"] = min(others, default=None)
        least = self.member_clock.least if self.member_clock.times else self.__dict__["_worker_least"]
        if firsts and least is not None:     # ``F``: a first member's CPU beyond the cheapest here (or there)
            batch_forecast.remember_cost("first_member", max(sorted(firsts)[len(firsts) // 2] - least, 0.0))
        if starts and self.method == "forkserver":          # ``S_fork``: a forked worker's start
            batch_forecast.remember_cost("fork", sorted(starts)[len(starts) // 2])
        return [results[k] for k in range(len(items))]

    def _running_on_dead_workers(self, names) -> set[str]:
        """Members last started by worker processes that died by themselves (their start records, by pid).

        The pool terminates the other workers when one dies (exit status ``-SIGTERM``): their members are innocent.
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
        """Stop the workers now (a broken pool, an error, an interruption, the end of the run)."""
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
        self._forget(processes)

    def close(self) -> None:
        """End the workers: every batch has returned, so they are idle and hold nothing of the run; they are
        stopped at once rather than each left to finalize its interpreter (NGSolve loaded) while the run
        waits.  Then the fork server (where the pool started it)."""
        self._discard()
        self._stop_server()

    def _forget(self, processes) -> None:
        """The pool's workers have stopped: its record goes (kept while one runs on, for the next run to end).
        A worker reaped by the pool's own thread may read alive for a moment: its exit code is awaited."""
        if self._lifetime is not None and all(_exit_code(p) is not None for p in processes):
            self._lifetime.remove()

    def abort(self) -> None:
        self._discard()
        self._stop_server()

    def describe(self) -> dict:
        """The executor's report (:meth:`Executor.describe`) and when its workers first started
        (``workers_started``: ``with the run``, ``during batch '<label>'``, or ``never``)."""
        return {**super().describe(), "workers_started": self.started}


_STARTED = None


def _exit_code(proc, seconds: float = 2.0):
    """A joined worker's exit code.  The pool's own thread reaps its workers too: while it holds a dead
    worker's status, ``exitcode`` reads ``None`` for a moment, so ``None`` is read again until ``seconds``."""
    deadline = time.monotonic() + seconds
    while proc.exitcode is None and time.monotonic() < deadline:
        time.sleep(0.02)
    return proc.exitcode


def _worker_start(started, parent: int, record: str | None, run: tuple[int, int] | None) -> None:
    """A worker's start: it ends with ``parent`` (and with the run's process ``run``, pid and start time,
    where a fork server is the parent), then takes one thread."""
    global _STARTED
    worker_lifetime.die_with_parent(parent, record, run)
    if run is not None:
        fork_server.leave_server()
    _STARTED = started
    one_thread(ignore_sigint=True)


def _warm_up(modules: tuple[str, ...]) -> float:
    """A worker's imports as it starts; returns the worker's CPU seconds so far: its start's cost."""
    import importlib
    for module in modules:
        if module != "__main__":          # the submitting script: the spawn start has imported it already
            importlib.import_module(module)
    return time.process_time()


def _measured_start(warm) -> None:
    """A worker's start is done: its CPU seconds join the machine's record (``S`` of the payoff rule)."""
    if not warm.cancelled() and warm.exception() is None:
        batch_forecast.remember_cost("start", warm.result())


_SOLVED = 0


def _pool_member(fn, item, name, attempt, fault):
    """One member in a worker: its result, its CPU seconds, and for the worker's first member the worker's
    CPU seconds before it (its start; None for the others)."""
    global _SOLVED
    if _STARTED is not None:
        _STARTED.put((os.getpid(), name))
    t0 = time.process_time()
    result = run_member(fn, item, name, attempt, fault)
    _SOLVED += 1
    return result, time.process_time() - t0, t0 if _SOLVED == 1 else None
