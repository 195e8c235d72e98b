"""Whether the rest of a batch repays a local pool's workers, or finishes faster in the run's own process.

A batch (:mod:`ngcontact.parallel.executor`) of ``n`` members, each a whole
solve of about ``c`` seconds (the members of an ensemble are draws of one
surface class, the loads or levels of a batch solves of one size), on ``W``
workers.  With ``r`` members still to solve, finishing them here takes
``r c``; on the workers it takes about ``r c / W``, but only once the
workers can take members: after the part of their start still ahead, ``R``
(spawning a fresh interpreter and importing NGSolve; none once a worker has
started), and after each worker has solved a first member, which pays what
this process paid before the batch and a fresh interpreter has not (the
libraries a member imports beyond NGSolve, such as a measured surface's
reader, the files it reads), ``F``.  The workers repay themselves when::

    r c (1 - 1/W)  >  R + F                                              (1)

the time the workers save on the rest against the time they cost before
they save any.

``c`` is measured, never guessed: every batch solves its first members in
this process and times each as ``min(wall, CPU)`` seconds of this process
(CPU seconds are the member's work whatever else runs beside it: other
processes' load and the workers' own start, which takes cores from this
process while it runs; wall seconds where NGSolve's threads solve it in
less wall time than CPU time); ``c`` is the least of these times, since
noise only adds to a member's time and the first member also pays what
this process does once (a lazy import, a cache filled).  ``R`` is an
estimate of a fresh worker's start
(:data:`~ngcontact.parallel.judged_batches.START_SECONDS`) less the time the
workers have had since they were spawned; ``F`` an estimate
(:data:`~ngcontact.parallel.judged_batches.FIRST_MEMBER_SECONDS`).

(1) is read after every member solved here, and the rest goes to the
workers only once (1) holds after :data:`MEASURED` members and a worker is
ready.  A batch whose first member already fails (1) ends here at once: the
least time can only be smaller than it.  Both sides of (1) shrink as members
are solved here: the left by ``c (1 - 1/W)`` per member, the right by
``c`` while ``R > 0``; so a batch that repays its workers at first still
does while they start, and one whose workers start late is finished here
as soon as (1) fails.  When (1) fails, workers still starting are stopped
at once (a starting worker takes a core from this process).

Never slower than serial: the workers of a run are started on demand
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

import time
from dataclasses import dataclass

#: Members solved in this process before the rest of a batch may go to the workers (each timed; the least
#: time is ``c``): the first also pays what this process does once.
MEASURED = 2


@dataclass(frozen=True)
class Payoff:
    """Condition (1) for the rest of a batch: ``rest`` members of ``member_seconds`` each on ``workers``
    workers, against ``start_ahead`` seconds of their start still to come and ``first_member_seconds`` of a
    worker's first member."""

    member_seconds: float
    rest: int
    workers: int
    start_ahead: float
    first_member_seconds: float

    @property
    def saving(self) -> float:
        """Seconds the workers save on the rest, once they take members: ``r c (1 - 1/W)``."""
        return self.rest * self.member_seconds * (1.0 - 1.0 / self.workers)

    @property
    def cost(self) -> float:
        """Seconds before they save any: ``R + F``."""
        return self.start_ahead + self.first_member_seconds

    @property
    def repaid(self) -> bool:
        """Condition (1): the rest goes to the workers."""
        return self.rest > 0 and self.workers > 1 and self.saving > self.cost

    def describe(self, solved: int) -> str:
        """One line for the report: what was measured and what was decided, after ``solved`` members here."""
        where = f"the other {self.rest} on {self.workers} workers" if self.repaid else \
            f"the other {self.rest} in this process"
        return (f"{solved} member{'s' if solved > 1 else ''} solved here, the cheapest in {self.member_seconds:.3g} s: "
                f"{self.workers} workers would save {self.saving:.3g} s on the other {self.rest} against "
                f"{self.start_ahead:.3g} s of their start still ahead and {self.first_member_seconds:.3g} s "
                f"of a worker's first member; {where}")


class MemberClock:
    """Times members solved in this process: ``min(wall, CPU)`` seconds of each; :attr:`least` of them."""

    def __init__(self):
        self.times: list[float] = []
        self._wall = self._cpu = 0.0

    def __enter__(self) -> "MemberClock":
        self._wall, self._cpu = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            self.times.append(min(time.perf_counter() - self._wall, time.process_time() - self._cpu))

    @property
    def least(self) -> float:
        """Seconds of the cheapest member solved here (zero before the first): ``c`` of condition (1)."""
        return min(self.times, default=0.0)
