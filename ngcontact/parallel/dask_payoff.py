"""Whether the rest of a batch repays a Dask cluster's workers, or finishes faster in the run's own process.

A cluster's workers run already: unlike a local pool's
(:mod:`ngcontact.parallel.worker_payoff`) they have no start to repay, but
every member sent to them pays a trip, and they may be other machines, whose
cores the load of this one says nothing about.  With ``r`` members of a
batch still to solve, ``c`` seconds each in this process (the least wall
seconds of the members solved here), finishing them here takes ``r c``.
On the cluster's ``W`` workers the rest ends no sooner than::

    ceil(r / W) (c + e + o)

``W`` is the number of the cluster's worker processes (the scheduler's
list, not this machine's cores): a process solves one member at a time
(Netgen's mesher keeps global state,
:func:`~ngcontact.parallel.batch_member.run_member`), so a worker's threads
beyond its first add no member running beside another.  ``o`` is one
member's trip: the scheduler's round trip and the transfer of the member's
prepared state (its item) there and of its result back.  It is timed on
the cluster at each batch, as the batch's first members are solved here: a
probe task per worker carrying the next member's item and returning as many
bytes as the first member's result pickled, ``o`` being its wall time here
less the time it ran on the worker.  ``e`` is what a member costs on the
cluster's workers beyond its time here: ``e = (w - 1) c``, ``w`` the
median over a batch the cluster solved of a member's wall seconds on its
worker over that batch's ``c`` (a median, which each worker's first member,
reading files or importing what the probe did not, moves little).  Wall
seconds, not the worker's CPU seconds: the rest waits for the worker's
wall time, and a worker on a machine whose cores other jobs share (this
one, for a local cluster, whose workers then also share this process's
share of the cores) takes several times its CPU seconds to solve a member
that its CPU time shows as cheap as here; a ratio, not seconds, since
that slowdown scales with the member while a trip's fixed costs are in
``o``, so one batch's ``w`` reads for another of other members.  Both are
kept per scheduler address
(:data:`COSTS_FILE`, the last :data:`~ngcontact.parallel.batch_forecast.COSTS_KEPT`
of each), and ``e`` is never less than 0: a cluster whose members measured
faster than here (a faster machine) is not counted on.  Both sides are wall seconds, what the run
waits for here and there on the machines as other jobs load them now:
the local rule's ``min(wall, CPU)`` here (:mod:`ngcontact.parallel.worker_payoff`,
which reads the load from the free cores instead) would set a member's
CPU time here against its wall time there, and keep here every batch of
a busy machine whose cluster would still finish it sooner.

The cluster repays its trips when the rest ends sooner there::

    c (r - n)  >  K + n (o + e),    n = ceil(r / W)                           (4)

the time the workers save on the rest against the trips and extra time of
the members each worker solves, and ``K``, the connection and the probe
still to make.  The recorded costs scatter (the machines' other jobs, a
worker's caches) as much as the gain of a small batch, so (4) is read at
the largest of the kept ones, ``w+ = max w_i``, ``o+ = max o_i`` and the
connection's ``K+``, not at their medians: the gain
``G(K, o, w) = c (r - n) - K - n (o + (w - 1) c)`` falls as each cost grows,
so ``G(K+, o+, w+) > 0`` holds only where the gain is positive at every
cost recorded, that is where the gain at the medians exceeds the costs'
recorded spread above them::

    G(K~, o~, w~)  >  (K+ - K~) + n ((o+ - o~) + (w+ - w~) c)                (5)

(``~`` the medians): a batch whose forecast gain lies within the scatter of
its own recorded costs stays here.  The price is a bound that one slow
batch sets: a cluster once measured that slow keeps the batches that do
not repay it here until the last kept ``w`` have all been measured since,
by batches whose gain exceeds it (a batch kept here measures no ``w``).

Before the cluster has solved a member, no ``w`` is recorded, and none can
be assumed (its workers may share this machine's busy cores, or be faster
ones).  A batch whose rest (4) sends there at ``w = 1`` (its largest gain)
then sends only one member per worker first (``W`` of them)
and waits for them, its threads asleep: their wall seconds there over ``c``
are this batch's ``w``,
and (4) is read again for the rest with it (``K = 0``: spent).  Those
``W`` members cost ``w c + o`` there against ``W c`` here, so the part
loses time only on a cluster with ``w > W - o/c`` (a member more than ``W``
times slower there), and then at most ``(w - W) c + o``, not a batch's
rest.  Each is its worker's first member of the batch and carries
what a worker does once (the imports the probe did not make, files read,
caches filled), so its ``w`` decides this batch's rest only and is not
recorded: the ``w`` of a rest sent there is, over members most of which
are not a worker's first; until one is, each batch sends such a part.
The connection: the run's process imports dask.distributed and connects a
client to the scheduler (most of a second, in this process, so every
member waits for it) only for a batch whose rest repays that too; a run
whose batches all stay here never pays it, and so costs the serial run
(:meth:`~ngcontact.parallel.dask_cluster.DaskCluster.start_on_demand`
checks the address with a bare TCP connection instead).  ``K`` is the
connection's wall seconds as timed for the scheduler (the largest kept,
:data:`CONNECT_ESTIMATE` before any) and two trips ``2 o`` of the probe,
which this process waits through before the rest leaves (the workers'
imports confirmed, then the timed trip); 0 once connected: spent.
Before the connection, ``W``, ``o`` and ``e`` are the scheduler's record
(``o`` and ``e`` 0 before any), and ``W`` the rest ``r`` where the record
has none (every member its own worker: the largest saving, so a batch the
connection cannot repay even then stays here); once connected, (4) is
read again with the trip timed on the cluster and ``K = 0``.  A batch for which (4) fails stays in this
process, its record saying why (as the local rule's does); so does a batch
whose probe fails (a worker that cannot import the members' module).  A
batch that stays here cancels its probe, whose tasks import no further
module once cancelled (:meth:`Probe.cancel`).  Before
timing the trips, the probe imports the members' modules on every worker,
and then every top-level package loaded in this process (:func:`loaded_packages`):
a member imports lazily what the scene's load imported here (a measured
scan's reader and its dependencies cost its first solve on a fresh worker
several times a member's time), and each worker's first member would otherwise
pay it, unseen by the ``w`` of other batches; meanwhile this process goes
on solving members (a warm cluster's imports, a trip once connected, are
waited for, up to one member's time ``c``: then the rest is the ``r`` that (4)
weighed before the connection, not one member less); (4) is read once that is done and at least
:data:`MEASURED` members were solved here, and only then: as members are
solved here both sides of (4) shrink in proportion (the saving by about
``c (1 - 1/W)`` per member, the cost by ``(o + e) / W``), so a later look
would decide the same.  Before the connection, (4) is read once, after
:data:`MEASURED` members: ``K`` does not shrink as members are solved
here while the saving does, so a batch it keeps here would be kept by
every later look too.
"""
from __future__ import annotations

import importlib
import math
import pickle
import statistics
import sys
import time
from dataclasses import dataclass
from typing import Any, Sequence

from ngcontact.parallel import batch_forecast
from ngcontact.parallel.batch_member import in_worker, one_thread

#: Members solved in this process before the rest of a batch may go to the cluster (each timed; the least
#: time is ``c``): the first also pays what this process does once.
MEASURED = 2

#: The record of the clusters' costs beside the local workers' (:mod:`ngcontact.parallel.batch_forecast`): by
#: scheduler address, the last ``round_trip`` seconds measured (``o`` of (4)), ``member_wall`` (``w``, a
#: ratio), ``connect`` (``K`` less the probe's trips) and the cluster's ``workers`` (``W``, as the
#: connection found them).
COSTS_FILE, COSTS = "dask_costs.json", ("round_trip", "member_wall", "connect", "workers")

#: Wall seconds of the connection to a scheduler (``K``: dask.distributed imported in the run's process, a
#: client connected) before this scheduler's record has one (an estimate: the import alone is most of it).
CONNECT_ESTIMATE = 0.5

#: Seconds the probe of a batch may take before the batch is kept in this process.
PROBE_SECONDS = 30.0


@dataclass(frozen=True)
class DaskPayoff:
    """Condition (4) for the rest of a batch: ``rest`` members of ``member_seconds`` each on ``workers``
    worker processes of a cluster, each member's trip ``round_trip`` seconds (``o``) and its extra time on a
    worker ``member_extra`` (``e``); before the connection, its ``connect`` seconds and the ``probe``'s (``K``
    is their sum)."""

    member_seconds: float
    rest: int
    workers: int
    round_trip: float
    member_extra: float
    connect: float = 0.0
    workers_known: bool = True
    probe: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "member_extra", max(self.member_extra, 0.0))     # ``e >= 0``

    @property
    def per_worker(self) -> int:
        """``ceil(r / W)``: the members of the busiest worker."""
        return math.ceil(self.rest / max(self.workers, 1))

    @property
    def saving(self) -> float:
        """Seconds the workers save on the rest: ``c (r - ceil(r / W))``."""
        return self.member_seconds * (self.rest - self.per_worker)

    @property
    def cost(self) -> float:
        """Seconds the connection, the probe and the busiest worker's members add: ``K + ceil(r / W) (o + e)``."""
        return self.connect + self.probe + self.per_worker * (self.round_trip + self.member_extra)

    @property
    def repaid(self) -> bool:
        """Condition (4): the rest goes to the cluster."""
        return self.rest > 0 and self.workers > 1 and self.saving > self.cost

    def describe(self, solved: int) -> str:
        """One line for the report: what was measured and what was decided, after ``solved`` members here."""
        workers = (f"the cluster's {self.workers} worker{'s' if self.workers != 1 else ''}" if self.workers_known
                   else f"at most {self.workers} workers (the cluster's not known yet)")
        if self.repaid:
            where = (f"the other {self.rest} on the cluster" + ("" if self.connect == 0 else ", once connected")
                     + (f"'s {self.workers} workers" if self.workers_known else ""))
        else:
            where = f"the other {self.rest} in this process"
        connect = "" if self.connect == 0 else (
            f"the connection to the scheduler ({self.connect:.3g} s: dask.distributed imported and a client "
            f"connected in this process, as last timed there), the probe's two trips ({self.probe:.3g} s), ")
        return (f"{solved} member{'s' if solved > 1 else ''} solved here, the cheapest in "
                f"{self.member_seconds:.3g} s: {workers} would save {self.saving:.3g} s on the other {self.rest} "
                f"against {self.cost:.3g} s of {connect}trips ({self.round_trip:.3g} s each: the scheduler's round "
                f"trip, the member's state and result, timed on the cluster) and of a member's extra time on a "
                f"worker ({self.member_extra:.3g} s); {where}")


# ------------------------------------------------ the record, per scheduler address
#: the record of (4)'s costs per scheduler address (``w`` may be measured below 1; ``e`` is held at 0 where used)
RECORD = batch_forecast.CostRecord(COSTS_FILE, COSTS)


def member_extra(address: str, member_seconds: float) -> float:
    """``e = (w+ - 1) c`` of (4) for members of ``member_seconds`` (``c``) each, ``w+`` the largest of the last
    ``member_wall`` ratios measured at ``address`` (1 before any: then the batch sends only a part first,
    :func:`wall_known`)."""
    return (largest_cost(address, "member_wall", 1.0) - 1.0) * member_seconds


def wall_known(address: str) -> bool:
    """Whether the cluster at ``address`` has a ``w`` recorded; without one, a batch (4) sends there sends one
    member per worker first, whose wall seconds there measure it."""
    return bool(RECORD.measured("member_wall", address))


def member_wall(worker_seconds: Sequence[float], member_seconds: float) -> float | None:
    """``w`` of (4) as a batch measured it: the median of its members' wall ``worker_seconds`` on the
    cluster's workers over ``member_seconds`` (``c``, this process's); None without both."""
    if not worker_seconds or member_seconds <= 0.0:
        return None
    return statistics.median(worker_seconds) / member_seconds


def measured_costs(address: str, kind: str) -> list[float]:
    """The last costs of ``kind`` (:data:`COSTS`) timed on the cluster at ``address``, oldest first."""
    return RECORD.measured(kind, address)


def cost_seconds(address: str, kind: str, default: float = 0.0) -> float:
    """The median of the last costs of ``kind`` measured at ``address``, ``default`` before any."""
    return RECORD.median(kind, default, address)


def largest_cost(address: str, kind: str, default: float = 0.0) -> float:
    """The largest of the last costs of ``kind`` measured at ``address`` (``K+``, ``o+``, ``w+`` of (5)),
    ``default`` before any."""
    return max(RECORD.measured(kind, address), default=default)


def remember_cost(address: str, kind: str, seconds: float) -> None:
    """Add a cost of ``kind`` measured at ``address`` to the record (the last
    :data:`~ngcontact.parallel.batch_forecast.COSTS_KEPT` of each kind are kept)."""
    RECORD.remember(kind, seconds, address)


def connected(address: str, member_seconds: float, rest: int, workers: int,
              wall: float | None = None) -> DaskPayoff:
    """Condition (4) once connected (``K = 0``): the ``rest`` on the cluster's ``workers``, at the largest trip
    and member's wall ratio the record of ``address`` keeps (at ``wall``, a part's ``w``, where given)."""
    extra = member_extra(address, member_seconds) if wall is None else (wall - 1.0) * member_seconds
    return DaskPayoff(member_seconds, rest, workers, largest_cost(address, "round_trip"), extra)


# ------------------------------------------------ the probe
def probe_task(modules: Sequence[str], item: Any, nbytes: int, loaded: Sequence[str] = ()) -> tuple[float, bytes]:
    """On a worker: its start as a member's (one thread), ``modules`` imported (a failure fails the probe), then
    the packages ``loaded`` in the run's process (:func:`loaded_packages`; one that does not import here is
    passed over), ``item`` received; returns the seconds this took on the worker and ``nbytes`` bytes (a
    member's result's size).  A probe cancelled while it runs (its batch stayed in the run's process) starts
    and imports nothing more: Dask cannot stop a running task, so the task looks before each step
    (:func:`cancelled`)."""
    t0 = time.perf_counter()
    if not in_worker() and not cancelled():
        one_thread(ignore_sigint=False)
    for module in modules:
        if cancelled():
            break
        if module != "__main__":
            importlib.import_module(module)
    for package in loaded:
        if cancelled():
            break
        try:
            importlib.import_module(package)
        except Exception:  # a package of the run's process a worker lacks: its members lack it too
            pass
    return time.perf_counter() - t0, bytes(nbytes)


def loaded_packages() -> tuple[str, ...]:
    """The top-level packages loaded in this process (private ones and ``__main__`` left out): what a member
    may import lazily (a file format's reader and its dependencies, imported by the scene's load here and by
    the member's first solve on a worker), which the probe imports on the workers beforehand."""
    return tuple(sorted({name.partition(".")[0] for name in list(sys.modules)
                         if not name.startswith("_") and name.partition(".")[0] != "__main__"}))


def cancelled() -> bool:
    """Whether the task running this on a Dask worker has been cancelled by its client (released by the
    scheduler: the worker lets a running task go on, marked ``cancelled``); False outside a task."""
    try:
        from distributed import get_worker
        worker = get_worker()
        task = worker.state.tasks.get(worker.get_current_task())
    except (ImportError, ValueError, AttributeError, KeyError):    # not in a Dask task
        return False
    return task is None or task.state == "cancelled"


def result_bytes(result: Any) -> int:
    """The size of a member's result as it travels (pickled); 0 for one that does not pickle here."""
    try:
        return len(pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL))
    except Exception:  # a result only cloudpickle handles: its size is not counted
        return 0


class Probe:
    """The probe of one batch on the cluster behind ``client``: every worker imports ``modules``
    (:meth:`warm`, in the background), then the trips are timed (:meth:`round_trip`)."""

    def __init__(self, client, label: str):
        self.client = client
        self.label = label
        self.workers = list(client.scheduler_info()["workers"])
        self._warming: list = []
        self._sent: list = []         # every probe task submitted, until cancelled

    def _submit(self, modules, item, nbytes, loaded: Sequence[str] = ()) -> list:
        futures = [self.client.submit(probe_task, tuple(modules), item, nbytes, tuple(loaded), workers=[w],
                                      allow_other_workers=False, pure=False,
                                      key=f"ngcontact-probe-{self.label}-{k}-{time.time_ns()}")
                   for k, w in enumerate(self.workers)]
        self._sent += futures
        return futures

    def warm(self, modules: Sequence[str]) -> None:
        """Every worker imports ``modules`` now (in the background), then the packages this process has loaded
        (:func:`loaded_packages`)."""
        self._warming = self._submit(modules, None, 0, loaded_packages())

    def warm_done(self) -> bool:
        return all(f.done() for f in self._warming)

    def wait_warm(self, seconds: float) -> bool:
        """Wait at most ``seconds`` for the workers' imports (:meth:`warm`); whether they are done.  Each
        future is waited for by its own client (``distributed.wait`` looks for a default client, and the
        run's is none)."""
        deadline = time.perf_counter() + seconds
        for fut in self._warming:
            left = deadline - time.perf_counter()
            if left <= 0.0:
                break
            try:
                fut.result(timeout=left)
            except Exception:    # not done in time (or failed: the trip's timing raises the failure)
                pass
        return self.warm_done()

    def round_trip(self, item: Any, nbytes: int) -> float:
        """``o`` of (4) measured now: the median over the workers of a probe's wall time here, carrying
        ``item`` and returning ``nbytes``, less its time on the worker (this process waits meanwhile).  A
        probe that fails raises its error (after :data:`PROBE_SECONDS`: ``TimeoutError``)."""
        from distributed import as_completed
        for fut in self._warming:
            fut.result(timeout=PROBE_SECONDS)            # a worker that cannot import a module fails here
        sent = time.perf_counter()
        trips = []
        for fut in as_completed(self._submit((), item, nbytes), timeout=PROBE_SECONDS, loop=self.client.loop):
            on_worker, _ = fut.result()
            trips.append(max(time.perf_counter() - sent - on_worker, 0.0))
        return statistics.median(trips)

    def cancel(self) -> None:
        """Done with the probe (the batch decided where it runs, or ended): every probe task is cancelled (a
        queued one never runs, a running one imports no further module, :func:`probe_task`) and its result
        dropped on the worker."""
        sent, self._sent, self._warming = self._sent, [], []
        if sent:
            self.client.cancel(sent)
