"""How a local pool's workers start (:mod:`ngcontact.parallel.local_pool`): a fork server's lifetime, whether
a worker can take a member, and what the start still costs.

A pool forks its workers from a fork server (:mod:`ngcontact.parallel.fork_server`) or spawns each
(``method``).  The payoff rule (:mod:`ngcontact.parallel.judged_batches`, condition (1) of
:mod:`ngcontact.parallel.worker_payoff`) asks the pool whether its start has begun (:meth:`PoolStart._launched`),
whether a worker is ready (:meth:`PoolStart._ready`) and the part of the start still ahead, ``R`` and ``S``
(:meth:`PoolStart._start_still`); its core watch counts the workers' and the server's processes
(:meth:`PoolStart._worker_pids`).
"""
from __future__ import annotations

from typing import Any

from ngcontact.parallel import fork_server
from ngcontact.parallel.judged_batches import JudgedBatches, fork_cost, server_cost, start_cost


class PoolStart(JudgedBatches):
    """The start of a local pool's workers: forked by a fork server or spawned (module docstring)."""

    method: str
    pools_started: int
    _server: fork_server.Server | None
    _forked: int
    _pool: Any

    def _open_server(self) -> fork_server.Server:
        """The pool's fork server, started now if it has none or its server has died (its imports go on
        beside this process, in the one-thread environment of :mod:`ngcontact.parallel.fork_server`; a
        server left to :mod:`multiprocessing` would restart with the run's own)."""
        if self._server is not None and not self._server.running():
            self._stop_server()
        if self._server is None:
            self._server = fork_server.acquire(self._modules)
            self._forked = 0
            self.pools_started += 1
        return self._server

    def _counted_pool(self) -> None:
        """A pool of workers forks from the server: counted as started (:attr:`pools_started`), the server's
        first one with the server (:meth:`_open_server`)."""
        self.pools_started += self._forked > 0
        self._forked += 1

    def _launched(self) -> bool:
        return self._pool is not None or self._server is not None

    def _ready(self) -> bool:
        """Whether a worker can take a member now: a started worker (spawn), or a fork server whose imports
        are done (its workers fork in milliseconds)."""
        if self._pool is not None and (self.method == "forkserver" or not self._warming
                                       or any(w.done() for w in self._warming)):
            return True
        return self._server is not None and self._server.ready()

    def _start_still(self, estimate: float | None) -> tuple[float, float]:
        """``(R, S)`` of condition (1): wall seconds of the workers' start still ahead and the CPU seconds
        each worker's start still costs, this process having spent ``estimate`` CPU seconds before its batch
        (the estimate of an interpreter's start before this machine has timed one).  A fork server's start,
        once begun, is spent: only what its imports have still to do delays the workers, and each costs its
        fork; before it has begun, each of the ``W`` workers pays a ``W``-th of it and its fork."""
        if self.method == "spawn":
            ahead = self._start_ahead(start_cost(estimate))
            return ahead, ahead
        if self._pool is not None:
            return 0.0, 0.0
        fork = fork_cost()
        if self._server is None:
            server = server_cost(estimate)
            return server + fork, server / self.workers + fork
        return self._server.start_still(server_cost(estimate), fork), fork

    def _stop_server(self) -> None:
        server, self._server = self._server, None
        if server is not None:
            fork_server.release(server)

    def _worker_pids(self) -> list[int]:
        pids = list((self._pool._processes or {}).keys()) if self._pool is not None else []
        return pids + ([self._server.pid] if self._server is not None else [])

    def _await_ready(self, seconds: float) -> bool:
        """Wait at most ``seconds`` until a worker can take a member (a fork server's imports done, or a
        spawned worker's start); whether one can."""
        if self._server is not None and self._pool is None:
            return self._server.wait(seconds)
        if self._warming:
            from concurrent.futures import FIRST_COMPLETED, wait
            wait(self._warming, timeout=seconds, return_when=FIRST_COMPLETED)
        return self._ready()

    def wait_ready(self, seconds: float = 120.0) -> bool:
        """Wait at most ``seconds`` until a worker can take a member (a started pool); whether one can."""
        if self._server is not None and self._pool is None:
            return self._server.wait(seconds)
        for warm in self._warming:
            warm.result(timeout=seconds)
        return self._ready()
