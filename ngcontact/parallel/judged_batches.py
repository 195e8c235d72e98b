"""Which members of a local pool's batch go to its workers: the payoff rule applied member by member.

A run's batches (:meth:`JudgedBatches.start_on_demand` or an early start) are judged: the first members
are solved in the run's own process, each timed, and the rest goes to the workers only where condition
(1) of :mod:`ngcontact.parallel.worker_payoff` holds for it: the rest's serial time against the workers'
start still ahead (``R``), a worker's first member (``F``: :func:`first_member_cost`) and the CPU
time of their starts (``S``: :func:`start_cost` for a spawned worker; :func:`server_cost` shared by the
``W`` workers of a fork server plus :func:`fork_cost` each; all as this machine timed them), on the cores
other processes leave free (``f``, :mod:`ngcontact.parallel.free_cores`, read at each look).  A start
that has begun is spent: the rule counts only what it has still to do (``R``) and the forks, so a pool
started with the run (:mod:`ngcontact.parallel.batch_forecast`, which counted the whole start) is never
charged for it twice.  A batch kept in this
process starts no worker; while the workers solve a batch, this process's NGSolve threads sleep
(:func:`~ngcontact.parallel.batch_member.threads_asleep`).

A run whose first batch the last run of it forecast to repay the workers
started them with the run; that batch goes to them from its first member,
none timed here, where (1) still holds for all of it with the recorded
``c`` on the cores free now (:meth:`JudgedBatches._sent_on_forecast`).  A
batch without a forecast starts no worker before (1) holds: a fork server
started as such a batch opens, its start then counted as spent, sent the
shipped measured scan's last members to workers whose first member paid
imports the record of other batches' first members did not show.

The rule is a mixin of :class:`~ngcontact.parallel.local_pool.LocalPool`, whose worker processes it starts,
uses and stops: this module holds the decision, that one the processes.
"""
from __future__ import annotations

import logging
import time
from abc import ABC, abstractmethod
from typing import Any, Sequence

from ngcontact.parallel import batch_forecast, worker_payoff
from ngcontact.parallel.batch_executor import Executor
from ngcontact.parallel.batch_member import threads_asleep
from ngcontact.parallel.free_cores import CoreWatch

log = logging.getLogger("ngcontact.parallel.executor")


#: CPU seconds of a local worker's start (a fresh interpreter importing NGSolve and the package) before
#: this machine has timed one (an estimate): ``S`` of :mod:`ngcontact.parallel.worker_payoff`.
START_SECONDS = 2.0


#: CPU seconds a worker's first member takes beyond the others before this machine has timed one
#: (an estimate): what the run's process paid before its batch and a fresh worker pays in its first member,
#: e.g. importing a measured surface's reader and reading its file; ``F`` of
#: :mod:`ngcontact.parallel.worker_payoff`.
FIRST_MEMBER_SECONDS = 1.0


#: CPU seconds of a worker's fork from a fork server before this machine has timed one (an estimate: the
#: fork, unpickling the start's data, the one-thread limits; ``S_fork`` of
#: :mod:`ngcontact.parallel.fork_server`).
FORK_SECONDS = 0.05


def start_cost(default: float | None = None) -> float:
    """``S``: the CPU seconds of a worker's start as this machine timed it
    (:func:`~ngcontact.parallel.batch_forecast.cost_seconds`), ``default`` (:data:`START_SECONDS`) before
    any."""
    return batch_forecast.cost_seconds("start", START_SECONDS if default is None else default)


def server_cost(default: float | None = None) -> float:
    """``S_server``: the CPU seconds of a fork server's start (a fresh interpreter importing NGSolve and the
    members' modules) as this machine timed it, ``default`` (:data:`START_SECONDS`) before any."""
    return batch_forecast.cost_seconds("server", START_SECONDS if default is None else default)


def fork_cost() -> float:
    """``S_fork``: the CPU seconds of a worker's fork from a fork server as this machine timed it,
    :data:`FORK_SECONDS` before any."""
    return batch_forecast.cost_seconds("fork", FORK_SECONDS)


def first_member_cost(default: float | None = None) -> float:
    """``F``: the CPU seconds of a worker's first member beyond the others, as this machine timed it,
    ``default`` (:data:`FIRST_MEMBER_SECONDS`) before any."""
    return batch_forecast.cost_seconds("first_member", FIRST_MEMBER_SECONDS if default is None else default)


class JudgedBatches(Executor, ABC):
    """An executor of worker processes whose batches the payoff rule judges (module docstring); the
    processes (:meth:`start`, :meth:`_pool_map`, :meth:`_abandon_start`) are the subclass's."""

    workers: int
    judged: bool
    _forecast: Any
    started: str
    _pool: Any
    _warming: list
    _spawned: float
    _modules: tuple[str, ...]

    @abstractmethod
    def start(self, modules: Sequence[str] = (), forecast: batch_forecast.Forecast | None = None) -> None:
        """Spawn the workers now, each importing ``modules``; ``forecast``: the record that said the run's
        first batch repays them (:meth:`_sent_on_forecast`)."""

    @abstractmethod
    def _pool_map(self, fn, items, names, label, progress, fault) -> list:
        """``fn`` over ``items`` on the workers."""

    @abstractmethod
    def _abandon_start(self) -> None:
        """Stop the workers (or what starts them) still starting."""

    @abstractmethod
    def _await_ready(self, seconds: float) -> bool:
        """Wait at most ``seconds`` until a worker can take a member; whether one can."""

    @abstractmethod
    def _launched(self) -> bool:
        """Whether the workers' start has begun (it is then spent)."""

    @abstractmethod
    def _ready(self) -> bool:
        """Whether a worker can take a member now."""

    @abstractmethod
    def _start_still(self, estimate: float | None) -> tuple[float, float]:
        """``(R, S)`` of condition (1), this process having spent ``estimate`` CPU seconds before its batch."""

    @abstractmethod
    def _worker_pids(self) -> list[int]:
        """The pids of the run's worker processes (and of what starts them)."""

    @property
    def cores(self) -> CoreWatch:
        """The watch of the cores other processes leave free: its first window opened as the process did
        (:data:`~ngcontact.parallel.free_cores.OPENING`), so that the run's first look reads what its
        imports and preparation left free, not the load average."""
        watch = self.__dict__.get("_cores")
        if watch is None:
            watch = self.__dict__["_cores"] = CoreWatch(self._worker_pids, opening=True)
        return watch

    def payoff(self, member_seconds: float, rest: int, lead: float = 0.0,
               first: float | None = None, lead_cpu: float | None = None) -> worker_payoff.Payoff:
        """Condition (1) of :mod:`ngcontact.parallel.worker_payoff` for ``rest`` members of
        ``member_seconds`` each, with the cores free now and the workers' start still ahead (less ``lead``
        seconds of the run before its batch, for a start with the run).  Where this machine has measured no
        worker yet, ``S`` is the CPU seconds this process spent before its batch (its interpreter, its
        imports and the batch's preparation: what a fresh worker repeats, and more), at most
        :data:`START_SECONDS`, and ``F`` what this process's own first member took beyond its cheapest
        (``first``, where two were solved), at most :data:`FIRST_MEMBER_SECONDS`; ``lead_cpu`` replaces this
        process's CPU seconds before its batch (a forecast's, read before any batch)."""
        cores = self.cores.reading()
        lead_cpu = self.__dict__.get("_lead_cpu") if lead_cpu is None else lead_cpu
        ahead, cpu = self._start_still(None if lead_cpu is None else min(lead_cpu, START_SECONDS))
        return worker_payoff.Payoff(member_seconds, rest, self.workers, max(ahead - lead, 0.0),
                                    first_member_cost(None if first is None else min(first, FIRST_MEMBER_SECONDS)),
                                    cpu, cores)

    def repays(self, forecast) -> bool:
        """Whether condition (1) of :mod:`ngcontact.parallel.worker_payoff` will send a batch (its
        :class:`~ngcontact.parallel.batch_forecast.Forecast`) to workers started now, with a margin: the
        members after the first ``MEASURED`` (the rest a batch without a forecast sends), of the forecast's
        seconds each, against the part of the start that the run's lead before its batch leaves ahead, a
        worker's first member and the starts' CPU time (before this machine has timed a worker: as the last
        run's process measured them), on the cores free as the run opens.  A batch so forecast goes to the
        workers from its first member (:meth:`_sent_on_forecast`, where (1) holds for all of it, which it
        then does by ``MEASURED`` members' work): one that (1) would send only without the margin (the
        measured scan's kind: 8 members of a tenth of a second) starts no worker before its batch."""
        return self.payoff(forecast.member_seconds, forecast.members - worker_payoff.MEASURED,
                           forecast.lead_seconds, forecast.first_seconds, forecast.start_seconds).repaid

    def start_on_demand(self, modules: Sequence[str] = ()) -> None:
        """Start no worker now: only once a batch's rest repays their start (:meth:`_judged_map`), each
        then importing ``modules`` and the module of the batch's member function as it starts.

        A batch kept in this process then costs exactly the serial run: no
        worker process ever takes a core from it, not even while the run sets
        up.
        """
        self.judged = True
        self._modules = tuple(dict.fromkeys(self._modules + tuple(modules)))

    def _judged_map(self, fn, items, names, label, progress, fault) -> list:
        """A batch of the run: members solved here, each timed, until the rest repays the workers (condition
        (1) of :mod:`ngcontact.parallel.worker_payoff`, after at least ``MEASURED`` members) and a worker is
        ready, or the batch ends here.

        Workers still starting when (1) fails are stopped (they take cores
        from this process); started ones are kept for the run's next batch.
        A pool not started is started once (1) holds (never for a batch kept
        here), its workers importing the members' module as they start, and
        this process solves members while they start.
        The run's first batch, where a forecast started the workers with the
        run, goes to them from its first member (:meth:`_sent_on_forecast`).
        """
        forecast, self._forecast = self._forecast, None      # the forecast is of the run's first batch
        done: list = []
        if forecast is not None and forecast.members == len(items):
            done = self._sent_on_forecast(fn, items, names, label, progress, fault, forecast)
            if len(done) == len(items):
                return done
        clock = self.member_clock            # each member solved here is timed by Executor._map
        while True:
            k = len(done)
            done += Executor._map(self, fn, items[k:k + 1], names[k:k + 1], label,
                                  shifted_progress(progress, k, len(items)), fault)
            if len(done) == len(items):
                self._where("serial", f"all {len(done)} members solved here"
                            + (" while the workers started" if self._launched() else ""))
                return done
            first = clock.times[0] - clock.least if len(clock.times) >= 2 else None
            payoff = self.payoff(clock.least, len(items) - len(done), first=first)
            log.debug("%s: look: %s", label, payoff.describe(len(done)))      # every look's inputs
            if not payoff.repaid:
                if self._launched() and not self._ready() and payoff.rest > 1:
                    self._abandon_start()   # (a last member here takes one member's time: the start goes on)
                if len(done) < worker_payoff.MEASURED:
                    continue        # the second member here measures what the first paid once: look again
                self._where("serial", payoff.describe(len(done)))
                log.debug("%s: %s", label, payoff.describe(len(done)))
                return done + Executor._map(self, fn, items[len(done):], names[len(done):], label,
                                            shifted_progress(progress, len(done), len(items)), fault)
            if not self._launched():
                if self.started == "never":
                    self.started = f"during batch '{label}'"
                self.start((fn.__module__,))
            if self._ready() and len(done) >= worker_payoff.MEASURED:
                self._where("local", payoff.describe(len(done)))
                log.debug("%s: %s", label, payoff.describe(len(done)))
                with threads_asleep():
                    return done + self._pool_map(fn, items[len(done):], names[len(done):], label,
                                                 shifted_progress(progress, len(done)), fault)

    def _sent_on_forecast(self, fn, items, names, label, progress, fault, forecast) -> list:
        """The run's first batch, whose workers a forecast started with the run: all of it to the workers
        from its first member, where (1) holds for the whole batch with the forecast's ``c`` and ``F`` and the
        cores free now; the members solved here, should (1) fail (the probe of :meth:`_judged_map` then
        decides, on members timed here), or should the batch end before a worker is ready.

        No member is solved here to time the batch: the last run of it timed
        its members (:mod:`ngcontact.parallel.batch_forecast`), and two of
        them here would delay the rest by ``2 c`` while ``ceil(n / W)`` rounds
        on the workers are no fewer than ``ceil((n - 2) / W) + 1``.  Nor do
        members go to this process beside the workers: on ``W`` workers over
        ``W`` cores a member here takes turns with them, not a core of its own.
        While no worker is ready, this process waits where the start has less
        than a member's time ``c`` still ahead (its threads asleep: the start
        has the core), else solves the next member.
        """
        done: list = []
        while len(done) < len(items):
            payoff = self.payoff(forecast.member_seconds, len(items) - len(done), first=forecast.first_seconds)
            log.debug("%s: look on the forecast: %s", label, payoff.describe(len(done), recorded=True))
            if not payoff.repaid:
                return done
            if self._ready():
                self._where("local", payoff.describe(len(done), recorded=True))
                with threads_asleep():
                    return done + self._pool_map(fn, items[len(done):], names[len(done):], label,
                                                 shifted_progress(progress, len(done), len(items)), fault)
            if payoff.start_ahead <= forecast.member_seconds:
                with threads_asleep():
                    if self._await_ready(forecast.member_seconds):
                        continue
            k = len(done)
            done += Executor._map(self, fn, items[k:k + 1], names[k:k + 1], label,
                                  shifted_progress(progress, k, len(items)), fault)
        self._where("serial", f"all {len(done)} members solved here while the workers started")
        return done

    def _start_ahead(self, start: float) -> float:
        """Seconds of the workers' start still to come (``R`` of :mod:`ngcontact.parallel.worker_payoff`), of
        ``start`` CPU seconds in all (``S``): all of it for a pool not started."""
        if self._pool is None:
            return start
        if not self._warming or any(w.done() for w in self._warming):
            return 0.0
        return max(start - (time.perf_counter() - self._spawned), 0.0)


def shifted_progress(progress, done: int, total: int | None = None):
    """``progress`` of the members after the first ``done`` of a batch of ``total`` (default: ``done`` more than
    the part reports): its counts shifted by ``done``."""
    if progress is None or done == 0 and total is None:
        return progress
    return lambda label, k, n: progress(label, k + done, n + done if total is None else total)
