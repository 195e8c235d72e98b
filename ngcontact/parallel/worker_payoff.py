"""Whether the rest of a batch repays a local pool's workers, or finishes faster in the run's own process.

A batch (:mod:`ngcontact.parallel.executor`) of ``n`` members, each a whole
solve of about ``c`` seconds on one core (the members of an ensemble are
draws of one surface class, the loads or levels of a batch solves of one
size), on ``W`` workers.  With ``r`` members still to solve, finishing them
here takes ``r c``.  On the workers the rest ends

* no sooner than ``R + F + c ceil(r / W)``: the workers take members only after
  the part of their start still ahead, ``R`` wall seconds (none once a
  worker has started), and each worker's first member pays what this
  process paid before the batch and a fresh interpreter has not (the
  libraries a member imports beyond NGSolve, the files it reads), ``F``;
* no sooner than ``(r c + W (S + F)) / P``: the work of the rest, of each
  worker's start (``S`` CPU seconds: an interpreter importing NGSolve and
  the members' modules; for workers forked by a fork server, a ``W``-th of
  the server's start and a fork, and only the fork once the server's start
  has begun: :mod:`ngcontact.parallel.fork_server`) and of its first
  member, on the ``P = min(W, f)``
  cores the run gets, ``f`` being the cores other processes leave free
  (:mod:`ngcontact.parallel.free_cores`, eq. 2 or 3): on busy cores a
  worker only takes turns with other jobs, and its start takes the cores of
  this process.

The workers repay themselves when both bounds end before ``r c``::

    c (r - ceil(r / W))  >  R + F      and      r c (P - 1)  >  W (S + F)      (1)

the time the workers save on the rest against the time they cost before
they save any, and the cores they would gain against the work they add.
On a free machine (``P = W = 2``) the second reads ``r c > 2 (S + F)``,
the first with the start's CPU time for its wall time; with ``f <= 1``
(other jobs keep the cores busy) no batch repays workers, whatever its
size: it stays here, and its record says why.

``c`` is measured, never guessed: every batch (but one that the last run of
it on this machine timed, :mod:`ngcontact.parallel.batch_forecast`) solves
its first members in this process and times each as ``min(wall, CPU)`` seconds of this process
(CPU seconds are the member's work whatever else runs beside it: other
processes' load and the workers' own start, which takes cores from this
process while it runs; wall seconds where NGSolve's threads solve it in
less wall time than CPU time); ``c`` is the least of these times, since
noise only adds to a member's time and the first member also pays what
this process does once (a lazy import, a cache filled).  ``S`` and ``F``
are measured too, by the workers (``S``: a worker's CPU seconds once its
imports are done; ``F``: its first member's CPU seconds less ``c``), and
kept per machine (:func:`~ngcontact.parallel.batch_forecast.cost_seconds`).
On a machine that has measured no worker yet, ``S`` is the CPU seconds this
process spent before its batch (a fresh worker repeats its interpreter and
imports, and the batch's preparation is on top; at most
:data:`~ngcontact.parallel.judged_batches.START_SECONDS`, for a process
that computed long before its batch) and ``F`` what this
process's first member took beyond its cheapest, at most
:data:`~ngcontact.parallel.judged_batches.FIRST_MEMBER_SECONDS` (so the
first look waits for a second member; without a batch, the estimates
:data:`~ngcontact.parallel.judged_batches.START_SECONDS` and
:data:`~ngcontact.parallel.judged_batches.FIRST_MEMBER_SECONDS`).  That
``F`` holds no import a forked worker is spared: the fork server preloads
NGSolve, the runner's worker modules and the members' module, all of which
this process imported before its batch (it made the batch's items with
them), so its first member's extra is only what a member does once per
process beyond them (lazy imports, files read, caches filled), which a
forked worker repeats, plus the spread of the members' own times (the
first is one draw, the cheapest the least of two): an upper estimate of a
forked worker's ``F``, until one is timed.  ``R``
is ``S`` less the time the workers have had since they were spawned: a
start on busy cores takes longer, which the second condition counts.

``P = min(W, f)`` in the second condition is the share of the cores the
workers get: other jobs that keep ``C - f`` cores busy keep them while the
workers run (a fair scheduler gives each runnable thread its turn, and
their demand is what (2) measured), so ``W`` workers get the ``f`` cores
left, and at most ``W``.  Where ``f`` is only a little above 1 the saving
``r c (P - 1)`` is small and the workers' ``W (S + F)`` can outweigh it:
that batch is faster in this process, which has a core of its own.

(1) is read after every member solved here, and the rest goes to the
workers only once (1) holds after :data:`MEASURED` members and a worker is
ready.  A batch whose first :data:`MEASURED` members fail (1) ends here at
once: the least time can only be smaller than it.  Both sides of (1) shrink as members
are solved here: in the first, the left by about ``c (1 - 1/W)`` per member,
the right by ``c`` while ``R > 0``; in the second, the left by
``c (P - 1)``, the right as the start is paid (the part of ``S`` ahead is
``R``); so a batch that repays its workers at first still does while they
start, and one whose workers start late is
finished here as soon as (1) fails.  ``f`` is read anew at each look: on a
machine whose other jobs take the cores meanwhile, the rest stays here.
When (1) fails, workers still starting are stopped at once (a starting
worker takes a core from this process).

Never slower than serial, also on a shared machine: no worker starts while
other jobs keep the cores busy (``f <= 1``), and the workers of a run are
started on demand
(:meth:`LocalPool.start_on_demand
<ngcontact.parallel.judged_batches.JudgedBatches.start_on_demand>`), only once (1)
holds, so a batch whose rest never repays them is the serial batch, no
worker process spawned; one whose workers were started and then stopped
had at most a few members solved beside starting workers (bounded by
their time times the share of the cores the workers took); a batch sent to
the workers satisfies (1), so its rest ends sooner than serially by the
margin of (1) when the estimates hold, and a batch whose workers start
later than ``R`` keeps being solved here meanwhile (:meth:`LocalPool._judged_map
<ngcontact.parallel.judged_batches.JudgedBatches._judged_map>`).  A large batch
(``r c`` well above ``R + F``) goes to the workers after :data:`MEASURED`
members, so it keeps its speedup, less their share.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

from ngcontact.parallel.free_cores import Reading

#: Members solved in this process before the rest of a batch may go to the workers (each timed; the least
#: time is ``c``): the first also pays what this process does once.
MEASURED = 2


@dataclass(frozen=True)
class Payoff:
    """Condition (1) for the rest of a batch: ``rest`` members of ``member_seconds`` each on ``workers``
    workers, against ``start_ahead`` wall seconds of their start still to come (``R``),
    ``first_member_seconds`` of a worker's first member (``F``), ``start_cpu`` CPU seconds of each worker's
    start still to be paid (``S``; none for started workers) and the ``cores`` other processes leave free
    (a :class:`~ngcontact.parallel.free_cores.Reading`; None: every core)."""

    member_seconds: float
    rest: int
    workers: int
    start_ahead: float
    first_member_seconds: float
    start_cpu: float = 0.0
    cores: Reading | None = None

    @property
    def parallel(self) -> float:
        """``P = min(W, f)``: the cores the workers would compute on."""
        return float(self.workers) if self.cores is None else min(float(self.workers), self.cores.free)

    @property
    def saving(self) -> float:
        """Seconds the workers save on the rest, once they take members: ``c (r - ceil(r / W))`` (a member
        is not split: one member alone saves nothing)."""
        return self.member_seconds * (self.rest - math.ceil(self.rest / self.workers))

    @property
    def cost(self) -> float:
        """Seconds before they save any: ``R + F``."""
        return self.start_ahead + self.first_member_seconds

    @property
    def core_saving(self) -> float:
        """CPU seconds of the rest that the workers' extra cores take over: ``r c (P - 1)``."""
        return self.rest * self.member_seconds * (self.parallel - 1.0)

    @property
    def core_cost(self) -> float:
        """CPU seconds the workers add: ``W (S + F)``."""
        return self.workers * (self.start_cpu + self.first_member_seconds)

    @property
    def busy(self) -> bool:
        """Whether other processes leave the workers no core of their own (``P <= 1``)."""
        return self.parallel <= 1.0

    @property
    def repaid(self) -> bool:
        """Condition (1): the rest goes to the workers."""
        return (self.rest > 0 and self.workers > 1 and not self.busy and self.saving > self.cost
                and self.core_saving > self.core_cost)

    def describe(self, solved: int, recorded: bool = False) -> str:
        """One line for the report: what was measured and what was decided, after ``solved`` members here;
        ``recorded``: ``c`` is the last run's of the same batch on this machine (a forecast,
        :mod:`ngcontact.parallel.batch_forecast`), the ``solved`` members here only filled the workers' start."""
        cores = "" if self.cores is None else f"; {self.cores.describe()}"
        if recorded:
            first = (f"the last run of this batch here timed its cheapest member at {self.member_seconds:.3g} s; "
                     f"{solved or 'none'} solved here while the workers started{cores}")
        else:
            first = (f"{solved} member{'s' if solved > 1 else ''} solved here, the cheapest in "
                     f"{self.member_seconds:.3g} s{cores}")
        others = f"the other {self.rest}" if solved else f"all {self.rest}"
        if self.busy and self.rest > 0 and self.workers > 1:
            return (f"{first}: the cores are busy with other processes, so {self.workers} workers would only "
                    f"take turns with them; {others} in this process")
        where = f"{others} on {self.workers} workers" if self.repaid else f"{others} in this process"
        return (f"{first}: {self.workers} workers would save {self.saving:.3g} s on {others} "
                f"against {self.start_ahead:.3g} s of their start still ahead and "
                f"{self.first_member_seconds:.3g} s of a worker's first member, and on {self.parallel:.2g} "
                f"cores {self.core_saving:.3g} CPU s against {self.core_cost:.3g} CPU s of their starts "
                f"({self.start_cpu:.3g} s each) and first members; {where}")


class MemberClock:
    """Times members solved in this process: ``min(wall, CPU)`` seconds of each (:attr:`least` of them) and
    their wall seconds (:attr:`least_wall`)."""

    def __init__(self):
        self.times: list[float] = []
        self.walls: list[float] = []
        self._wall = self._cpu = 0.0

    def __enter__(self) -> "MemberClock":
        self._wall, self._cpu = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            wall = time.perf_counter() - self._wall
            self.walls.append(wall)
            self.times.append(min(wall, time.process_time() - self._cpu))

    @property
    def least(self) -> float:
        """Seconds of the cheapest member solved here (zero before the first): ``c`` of condition (1)."""
        return min(self.times, default=0.0)

    @property
    def least_wall(self) -> float:
        """Wall seconds of the quickest member solved here (zero before the first): ``c`` of condition (4) of
        :mod:`ngcontact.parallel.dask_payoff`."""
        return min(self.walls, default=0.0)
