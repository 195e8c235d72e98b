"""The executor of a batch of independent solves, and the serial one (:mod:`ngcontact.parallel.executor`).

:class:`Executor` runs a batch member after member in this process, each
attempt by :func:`ngcontact.parallel.batch_member.run_member`, a failing
member once more; :class:`Serial` is that.  The local pool
(:mod:`ngcontact.parallel.local_pool`) and the Dask cluster
(:mod:`ngcontact.parallel.dask_cluster`) spread the same batch.
"""
from __future__ import annotations

import contextvars
import logging
import time
from typing import Any, Callable, Sequence

from ngcontact.errors import BatchError
from ngcontact.parallel.batch_member import ATTEMPTS, fault_from_env, reason, run_member
from ngcontact.parallel.free_cores import affinity
from ngcontact.parallel.worker_payoff import MemberClock

log = logging.getLogger("ngcontact.parallel.executor")

#: ``progress(label, finished, total)``, called at the start (0) and after every finished member.
Progress = Callable[[str, int, int], None]

#: the progress callback of the running batches (:func:`ngcontact.parallel.executor.use`)
PROGRESS: contextvars.ContextVar[Progress | None] = contextvars.ContextVar("ngcontact_progress", default=None)


def default_workers() -> int:
    """The cores this process may use."""
    return len(affinity())


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
        progress = progress or PROGRESS.get()
        if progress is not None:
            progress(label, 0, len(items))
        fault = fault_from_env()
        self.__dict__["_lead_cpu"] = time.process_time()   # this process's CPU seconds before the batch
        t0 = time.perf_counter()
        self.__dict__.pop("_spread", None)
        self.__dict__.pop("_worker_least", None)
        clock = self.__dict__["_clock"] = MemberClock()
        out = self._map(fn, list(items), list(names), label, progress, fault)
        self.record.append({"label": label, "members": len(items), "seconds": time.perf_counter() - t0,
                            **self.__dict__.pop("_spread", {})})
        self.timings.append({"members": len(items), "began": t0,
                             "member_seconds": clock.least if clock.times else self.__dict__.get("_worker_least"),
                             "lead_cpu": self.__dict__["_lead_cpu"],
                             "first_seconds": clock.times[0] - clock.least if len(clock.times) > 1 else None})
        return out

    @property
    def timings(self) -> list[dict]:
        """The batches this executor ran, as timed in this process: ``members``, when each ``began``
        (``time.perf_counter`` seconds), the least ``min(wall, CPU)`` seconds of its members solved in
        this process (``member_seconds``; where none was, the least CPU seconds of a worker's member after
        its first, None without one), this process's CPU seconds as it began
        (``lead_cpu``) and what its first member here took beyond the least (``first_seconds``; None
        with fewer than two here)."""
        return self.__dict__.setdefault("_timings", [])

    @property
    def member_clock(self) -> MemberClock:
        """The clock of the members of the running batch solved in this process."""
        return self.__dict__.setdefault("_clock", MemberClock())

    @property
    def record(self) -> list[dict]:
        """The batches this executor ran: label, number of members, wall seconds (in order); for a batch that
        chose where it ran (a local pool's), ``executor`` (``serial``: finished in this process, or ``local``)
        and the ``decision`` that chose it."""
        return self.__dict__.setdefault("_record", [])

    def _where(self, executor: str, decision: str) -> None:
        """Where the running batch went (``executor``) and why (``decision``): recorded with the batch."""
        self.__dict__["_spread"] = {"executor": executor, "decision": decision}

    def _map(self, fn, items, names, label, progress, fault) -> list:
        out = []
        for k, (item, name) in enumerate(zip(items, names)):
            with self.member_clock:
                out.append(self._member(fn, item, name, label, fault))
            if progress is not None:
                progress(label, k + 1, len(items))
        return out

    @staticmethod
    def _member(fn, item, name, label, fault):
        """One member in this process: its result, after one retry; a second failure ends the batch."""
        error: BaseException | None = None
        for attempt in range(ATTEMPTS):
            try:
                return run_member(fn, item, name, attempt, fault)
            except Exception as exc:  # retried once, then reported
                error = exc
                log.info("%s: %s failed (%s)%s", label, name, reason(exc),
                         "; retrying" if attempt + 1 < ATTEMPTS else "")
        assert error is not None
        raise BatchError(label, name, reason(error)) from error

    @staticmethod
    def _failed(label, name, failures, k, exc) -> None:
        failures[k] += 1
        log.debug("%s: %s: %s", label, name, getattr(exc, "detail", "") or reason(exc))
        log.info("%s: %s failed (%s)%s", label, name, reason(exc),
                    "; retrying" if failures[k] < ATTEMPTS else "")
        if failures[k] >= ATTEMPTS:
            raise BatchError(label, name, reason(exc)) from exc

    def start(self, modules: Sequence[str] = (), forecast=None) -> None:
        """Get the workers ready now, while this process prepares the batch (nothing to do here).

        ``modules``: what the members will import, imported by each worker as it starts; ``forecast``: the
        record of the run's first batch that said it repays them (:mod:`ngcontact.parallel.batch_forecast`).
        """

    def repays(self, forecast) -> bool:
        """Whether workers started now would take the run's batch (a
        :class:`~ngcontact.parallel.batch_forecast.Forecast` of it): never, without workers to start."""
        return False

    def start_on_demand(self, modules: Sequence[str] = ()) -> None:
        """Start workers only for a batch that will repay their start, each importing ``modules`` as it
        starts (nothing to start here)."""

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
