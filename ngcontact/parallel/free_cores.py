"""The cores other processes leave to a run: what its workers could use (:mod:`ngcontact.parallel.worker_payoff`).

Workers save time only on cores nobody else needs: on a machine whose cores
other jobs keep busy, a worker takes turns with them, and its start (a fresh
interpreter importing NGSolve) takes the cores the run's own process would
have had.  The payoff rule therefore counts ``f``, the cores of this
process's affinity set (``C`` of them, ``os.sched_getaffinity``) that other
processes leave free, measured over the last ``t`` wall seconds::

    f = C - (B - U) / t                                                  (2)

``B``: the CPU seconds spent on those cores by every process in the window
(``/proc/stat``, per core; time stolen by a hypervisor counts as spent);
``U``: the CPU seconds of the run itself (this process and its worker
processes, ``/proc/PID/stat``).  Where no window of at least
:data:`WINDOW_SECONDS` is open (the run's first look) or ``/proc`` is
missing, the others' use is the one-minute load average (the threads that
run or wait for a core; the run's own process among them, so an upper bound
of the others' use)::

    f = C - L_1                                                          (3)

``f`` is held to ``[0, C]``.  A reading's window ends now and opens at the
latest earlier sample at least :data:`WINDOW_SECONDS` old (each reading is
a sample), so a reading tells what the last seconds left free, and a look
that follows the previous one closely (a member solved in less than
:data:`WINDOW_SECONDS`) still reads (2) over the samples before, not (3):
right after another run on the same cores, (3) counts that run for up to a
minute (its load average decays with a time constant of 60 s) and would
read a machine that is idle now as busy.

The run's first look (whether its workers start with the run,
:mod:`ngcontact.parallel.batch_forecast`) comes about a second after the
process started, before any batch: its window opens as this module is
imported (:data:`OPENING`, as the package is, before NGSolve and the
scene's modules load), and (2) is read over the process's imports and the
scene's loading, where they span at least :data:`WINDOW_SECONDS` and at
most :data:`OPENING_SECONDS`.  (3) would count as another job's what the
machine ran in the last minute, such as the run just before this one: a
one-minute load average of 1 after one serial run leaves ``f <= 1`` on two
cores, and so no early start, on a machine that is idle.
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Callable, Iterable

#: Wall seconds a window must span for reading (2); shorter ones read the load average (3).
WINDOW_SECONDS = 0.25

#: Wall seconds beyond which the window opened as the process started (:data:`OPENING`) is too old to tell what
#: the cores are left now: a watch opened later starts a window of its own (and reads (3) at once).
OPENING_SECONDS = 60.0

#: Test-only: a one-minute load average read instead of the machine's (and no ``/proc/stat`` window), for the
#: tests that run the command line in a process of its own on a machine shared with other jobs.  Not a
#: setting of the package.
LOAD_ENV = "NGCONTACT_TEST_LOAD"

#: Clock ticks per second of ``/proc``'s CPU times.
TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def affinity() -> list[int]:
    """The cores this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return sorted(os.sched_getaffinity(0))
    return list(range(os.cpu_count() or 1))


def core_seconds(cores: Iterable[int]) -> float | None:
    """CPU seconds every process has spent on ``cores`` since boot (``/proc/stat``: user, nice, system, irq,
    softirq and steal time); None without ``/proc/stat`` or a line for each core."""
    if os.environ.get(LOAD_ENV):
        return None
    wanted = {f"cpu{k}" for k in cores}
    try:
        with open("/proc/stat") as f:
            lines = [line.split() for line in f if line.startswith("cpu")]
    except OSError:
        return None
    rows = [row for row in lines if row[0] in wanted]
    if len(rows) != len(wanted):
        return None
    busy = (1, 2, 3, 6, 7, 8)                   # user nice system (idle iowait) irq softirq steal
    return sum(int(row[i]) for row in rows for i in busy if i < len(row)) / TICKS


def process_seconds(pid: int) -> float:
    """CPU seconds of process ``pid`` (user and system, ``/proc/PID/stat``); 0 when it is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
    except (OSError, IndexError):
        return 0.0
    return (int(fields[11]) + int(fields[12])) / TICKS


def load_average() -> float | None:
    """The one-minute load average (``os.getloadavg``; :data:`LOAD_ENV` in tests), None where there is none."""
    if os.environ.get(LOAD_ENV):
        return float(os.environ[LOAD_ENV])
    try:
        return os.getloadavg()[0]
    except (OSError, AttributeError):
        return None


@dataclass(frozen=True)
class Reading:
    """``cores`` this process may run on, of which other processes kept ``busy`` busy (``source``: how it
    was measured)."""

    cores: int
    busy: float
    source: str

    @property
    def free(self) -> float:
        """``f`` of (2) or (3): the cores left to the run, in ``[0, cores]``."""
        return min(max(self.cores - self.busy, 0.0), float(self.cores))

    def describe(self) -> str:
        return f"{self.free:.2g} of {self.cores} cores free ({self.source})"


class CoreWatch:
    """The cores other processes left free since the last reading: (2), else (3).  ``workers`` gives the
    pids of the run's worker processes (their CPU time is the run's own); ``opening``: the first window
    opens where the process's did (:data:`OPENING`, if at most :data:`OPENING_SECONDS` old), not now."""

    def __init__(self, workers: Callable[[], Iterable[int]] = tuple, opening: bool = False):
        self.cores = affinity()
        self._workers = workers
        self._marks = [self._sample()]      # the samples a window may open at, oldest first
        if opening and OPENING[1] is not None and self._marks[0][0] - OPENING[0] <= OPENING_SECONDS:
            self._marks = [OPENING]

    def _sample(self) -> tuple[float, float | None, float]:
        own = time.process_time() + sum(process_seconds(pid) for pid in self._workers())
        return time.perf_counter(), core_seconds(self.cores), own

    def reading(self) -> Reading:
        """What the last window left free, (2), the window opening at the latest sample at least
        :data:`WINDOW_SECONDS` old; the load average, (3), where no sample is that old."""
        now = self._sample()
        opening = [m for m in self._marks if now[0] - m[0] >= WINDOW_SECONDS]
        (t0, spent0, own0), (t1, spent1, own1) = (opening[-1] if opening else self._marks[0]), now
        window = t1 - t0
        if spent0 is None or spent1 is None or window < WINDOW_SECONDS:
            load = load_average()
            if load is None:
                return Reading(len(self.cores), 0.0, "no load reading on this system: taken as free")
            return Reading(len(self.cores), load, f"one-minute load average {load:.2f}")
        start = opening[-1] if opening else self._marks[0]
        self._marks = [m for m in self._marks if m[0] >= start[0]] + [now]   # older ones open no later window
        busy = max((spent1 - spent0) - (own1 - own0), 0.0) / window
        return Reading(len(self.cores), busy, f"{busy:.2g} cores busy with other processes over the last "
                                              f"{window:.2g} s")


#: The first window's opening sample of the process, taken as the package is imported: (wall, CPU seconds
#: of every process on this process's cores, CPU seconds of this process), as :meth:`CoreWatch._sample`.
OPENING = CoreWatch()._marks[0]
