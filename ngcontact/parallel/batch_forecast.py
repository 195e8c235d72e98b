"""What a run's batch cost the last time the same batch ran on this machine: whether its workers may start early.

Condition (1) of :mod:`ngcontact.parallel.worker_payoff` needs ``c``, the
seconds of one member, and ``c`` is only known once members have been
solved in the run's process: a local pool's workers are therefore started
on demand, as a batch's first members have shown that its rest repays
them.  Their start (``R``) then falls inside the batch.  Started with the
run instead, it would overlap with what the run does before its batch (its
imports, the scene's preparation), but only a batch that (1) sends to the
workers may pay for that: any other must cost exactly the serial run.

The forecast is (1) itself, read with what the last run of the same batch
measured: ``c`` (the least ``min(wall, CPU)`` seconds of its members solved
in its process) and the seconds from the opening of the run's batches to
the start of its first batch (``lead``), during which workers started with
the run start; so ``R`` is the start's wall time less ``lead``.  Where this
machine has timed no worker yet, ``S`` and ``F`` are estimated as the rule
estimates them in the batch, from what the last run's process measured:
its CPU seconds before its batch (``start``) and what its first member
took beyond its cheapest (``first``).  The cores free as the run opens are
(2) of :mod:`ngcontact.parallel.free_cores`, over the window of the run's
imports and preparation (the one-minute load average, (3), only where no
window is open: it would count the run just before this one, a serial run
of the same batch, as another job, and no early start would ever pass).
Nothing is guessed: a batch never run on this machine has no forecast, and
its workers start on demand.
The forecast chooses when the workers start, and it sends the run's first
batch to them from its first member where (1) still holds for the whole
batch with the recorded ``c`` on the cores free as the batch opens
(:meth:`~ngcontact.parallel.judged_batches.JudgedBatches._sent_on_forecast`);
where it does not, (1) decides on the batch's own members, and workers
started early for a batch that (1) then keeps in this process are stopped
while they start.  A batch sent whole to the workers is recorded with
``c`` as the workers timed it (the least CPU seconds of a member after a
worker's first).

A record is one small JSON file per batch, named by the SHA-256 of the
run's description (the scene, the package version), in ``batches`` under
the cell-law cache directory (``$NGCONTACT_CACHE``, default
``~/.cache/ngcontact``; at most :data:`KEPT`, the oldest removed first); a
record that cannot be read or written costs only the forecast.

Beside them, ``worker_costs.json`` holds the last :data:`COSTS_KEPT`
measurements of what a local worker costs on this machine: its start
(``S`` of (1): each worker's own CPU time once its imports are done) and its
first member's extra (``F``: the CPU time of a worker's first member less
the cheapest member of the batch solved in the run's process); their
medians replace the estimates
:data:`~ngcontact.parallel.judged_batches.START_SECONDS` and
:data:`~ngcontact.parallel.judged_batches.FIRST_MEMBER_SECONDS` once
measured.
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
from dataclasses import dataclass

log = logging.getLogger("ngcontact.parallel.executor")

#: Folder of the records under the cache directory.
FOLDER = "batches"

#: Records kept at most (the oldest go first): the runs of scenes in many folders do not fill the cache.
KEPT = 256

#: The record of a local worker's costs as this machine timed them, by kind: ``start`` (CPU seconds of a
#: spawned worker's start, until its imports are done), ``first_member`` (CPU seconds a worker's first member
#: took beyond the cheapest member of its batch solved in the run's process), ``server`` (CPU seconds of a
#: fork server's start, until its imports are done) and ``fork`` (CPU seconds of a worker forked by it,
#: before its first member: :mod:`ngcontact.parallel.fork_server`).
COSTS_FILE = "worker_costs.json"
COSTS = ("start", "first_member", "server", "fork")

#: Measured costs kept per kind; the payoff rule takes their median.
COSTS_KEPT = 5


@dataclass(frozen=True)
class Forecast:
    """The last run's first batch: ``members``, the least seconds of one solved in its process
    (``member_seconds``), the seconds from the opening of its batches to that batch's start
    (``lead_seconds``), the CPU seconds of its process before that batch (``start_seconds``) and what its
    first member there took beyond the least (``first_seconds``; None with fewer than two there)."""

    members: int
    member_seconds: float
    lead_seconds: float
    start_seconds: float | None = None
    first_seconds: float | None = None


def key(description: str) -> str:
    """The record's name of a run described by ``description`` (its scene and version as text)."""
    return hashlib.sha256(description.encode()).hexdigest()


def folder() -> str:
    cache = os.environ.get("NGCONTACT_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "ngcontact")
    return os.path.join(cache, FOLDER)


def recorded(name: str) -> Forecast | None:
    """The forecast recorded under ``name``, None if there is none (or it cannot be read)."""
    try:
        with open(os.path.join(folder(), f"{name}.json")) as f:
            data = json.load(f)
        forecast = Forecast(int(data["members"]), float(data["member_seconds"]), float(data["lead_seconds"]),
                            *(None if data.get(k) is None else float(data[k])
                              for k in ("start_seconds", "first_seconds")))
    except (OSError, ValueError, KeyError, TypeError):
        return None
    seconds = (forecast.member_seconds, forecast.lead_seconds, forecast.start_seconds, forecast.first_seconds)
    if forecast.members < 1 or not all(t is None or t >= 0.0 for t in seconds):
        return None
    return forecast


def remember(name: str, forecast: Forecast) -> None:
    """Record ``forecast`` under ``name`` for the next run."""
    _write(f"{name}.json", {"members": forecast.members, "member_seconds": forecast.member_seconds,
                            "lead_seconds": forecast.lead_seconds, "start_seconds": forecast.start_seconds,
                            "first_seconds": forecast.first_seconds})


def _write(file: str, data: dict) -> None:
    """``data`` as the record ``file`` (written whole under another name, then renamed; the oldest records
    beyond :data:`KEPT` removed); a record that cannot be written is only logged."""
    path = os.path.join(folder(), file)
    partial = f"{path}.{os.getpid()}.partial"
    try:
        os.makedirs(folder(), exist_ok=True)
        with open(partial, "w") as f:
            json.dump(data, f)
        os.replace(partial, path)
        records = sorted(os.scandir(folder()), key=lambda e: e.stat().st_mtime)
        for old in records[:max(len(records) - KEPT, 0)]:
            os.remove(old.path)
    except OSError as exc:
        log.debug("no record %s in %s (%s)", file, folder(), exc)
        try:
            os.remove(partial)
        except OSError:
            pass


@dataclass(frozen=True)
class CostRecord:
    """Timed costs kept in the record ``file`` (of :func:`folder`), the last :data:`COSTS_KEPT` of each of
    ``kinds``: this machine's (``scope`` ``None``) or one entry per ``scope`` (a Dask scheduler's address,
    :mod:`ngcontact.parallel.dask_payoff`).  A value outside ``[least, 1e4)`` s is a damaged record's and is
    dropped."""

    file: str
    kinds: tuple[str, ...]
    least: float = 0.0

    def _data(self) -> dict:
        try:
            with open(os.path.join(folder(), self.file)) as f:
                data = json.load(f)
        except (OSError, ValueError):
            return {}
        return data if isinstance(data, dict) else {}

    def measured(self, kind: str, scope: str | None = None) -> list[float]:
        """The last costs of ``kind``, oldest first."""
        data = self._data()
        try:
            costs = [float(s) for s in (data if scope is None else data[scope])[kind]]
        except (ValueError, KeyError, TypeError):
            return []
        return [s for s in costs if self.least <= s < 1e4]

    def median(self, kind: str, default: float, scope: str | None = None) -> float:
        """The median of the last costs of ``kind``, ``default`` before any."""
        costs = sorted(self.measured(kind, scope))
        if not costs:
            return default
        mid = len(costs) // 2
        return costs[mid] if len(costs) % 2 else 0.5 * (costs[mid - 1] + costs[mid])

    def remember(self, kind: str, seconds: float, scope: str | None = None) -> None:
        """Add a cost of ``kind`` to the record (a scope's entry beside the others')."""
        entry = {k: self.measured(k, scope) for k in self.kinds}
        entry[kind] = (entry[kind] + [float(seconds)])[-COSTS_KEPT:]
        if scope is None:
            _write(self.file, entry)
        else:
            data = self._data()
            data[scope] = entry
            _write(self.file, data)


#: this machine's record of a local worker's costs (:data:`COSTS`)
WORKER_COSTS = CostRecord(COSTS_FILE, COSTS)


def measured_costs(kind: str) -> list[float]:
    """The last costs of ``kind`` (:data:`COSTS`) this machine timed, oldest first."""
    return WORKER_COSTS.measured(kind)


def cost_seconds(kind: str, default: float) -> float:
    """CPU seconds of a worker's cost ``kind`` on this machine (:data:`COSTS`): the median of the last
    :data:`COSTS_KEPT` measured, ``default`` before any."""
    return WORKER_COSTS.median(kind, default)


def remember_cost(kind: str, seconds: float) -> None:
    """Add a measured cost of ``kind`` (:data:`COSTS`) to the machine's record."""
    WORKER_COSTS.remember(kind, seconds)


def early(executor, name: str, members: int | None) -> Forecast | None:
    """The forecast by which ``executor`` should start its workers with the run (None: it should not): the
    last run of the batch recorded under ``name``, of as many ``members``, where it says that condition (1)
    sends the batch to them (:meth:`~ngcontact.parallel.executor.Executor.repays`)."""
    forecast = recorded(name)
    if forecast is not None and forecast.members == members and executor.repays(forecast):
        return forecast
    return None


def remember_run(name: str, executor, opened: float) -> None:
    """Record under ``name`` the first batch of ``executor`` with members solved in this process: its
    members, their least seconds, its start's lead over ``opened`` (``time.perf_counter`` seconds when
    the run's batches opened), this process's CPU seconds before it and its first member's extra."""
    timed = next((t for t in executor.timings if t["member_seconds"] is not None), None)
    if timed is not None:
        remember(name, Forecast(timed["members"], timed["member_seconds"], max(timed["began"] - opened, 0.0),
                                timed["lead_cpu"], timed["first_seconds"]))
