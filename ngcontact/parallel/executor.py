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
* :class:`LocalPool` - a pool of worker processes on this machine, forked
  by a fork server that imports NGSolve and the package once
  (:mod:`ngcontact.parallel.fork_server`; ``spawn``, each a fresh
  interpreter, where there is none), never a fork of a process whose
  NGSolve task manager holds threads, each limited to one NGSolve thread
  so that ``N`` workers use ``N`` cores; a run's batch goes to them only where its
  rest repays their start (:mod:`ngcontact.parallel.worker_payoff`), and
  they start only then, or with the run where the last run of the same
  batch forecasts it (:mod:`ngcontact.parallel.batch_forecast`);
* :class:`DaskCluster` - the workers of a ``dask.distributed`` scheduler at
  an address; Dask is the cluster engine, this module only submits; a run's
  batch goes to them only where its rest repays the trips of its members
  (:mod:`ngcontact.parallel.dask_payoff`, timed on the cluster).

Failures (the attempt itself: :mod:`ngcontact.parallel.batch_member`): a member that raises (or whose
worker process dies) is run once more; a second failure ends the batch with :class:`~ngcontact.errors.BatchError`
naming the member and the reason, and no result of the batch is returned.
An interruption (``KeyboardInterrupt``, or any exception in the caller while
it waits) stops the workers before it propagates.

The batch a run uses is set once by the runner (:func:`use`) and read by
the code that has a batch (:func:`current`); without one, batches run
serially.  Any room that may import ``parallel`` uses it the same way, e.g.
the levels of a two-scale table in ``coupling/``::

    rows = executor.current().map(solve_level, [(scene, level) for level in levels],
                                  [f"level {k}" for k in range(len(levels))], label="table levels")

with ``solve_level`` a module-level function of plain data.  A script that
runs batches on local workers needs an ``if __name__ == "__main__":`` guard:
each worker imports the main module as it starts.
"""
from __future__ import annotations

import contextlib
import contextvars

from ngcontact.parallel.batch_executor import PROGRESS, Executor, Progress, Serial, default_workers
from ngcontact.parallel.dask_cluster import DaskCluster
from ngcontact.parallel.local_pool import LocalPool

__all__ = ["Executor", "Serial", "LocalPool", "DaskCluster", "Progress", "default_workers", "make", "current",
           "use", "local_workers", "MAX_WORKERS_PER_CORE"]

#: Local workers per core at most.  Each worker runs one NGSolve thread, so one per core keeps the cores
#: busy while the workers compute; but a worker also waits (its start, its imports and meshing, the time
#: between two members while the run's own process collects results), and a second worker per core fills
#: those gaps.  Beyond two the workers only take turns on the cores, while each costs a fresh
#: interpreter's start and its memory (NGSolve loaded in each).
MAX_WORKERS_PER_CORE = 2


def local_workers(workers: int | None = None, members: int | None = None) -> tuple[int, str | None]:
    """The local workers of a run: ``workers`` asked for (default: the cores), at most
    :data:`MAX_WORKERS_PER_CORE` per core and one per member of its batch (``members``, where known); and
    a line saying so when fewer than asked for are used (None otherwise)."""
    cores = default_workers()
    n = cores if workers is None else workers
    if members is not None:
        n = min(n, max(1, members))
    n = min(n, MAX_WORKERS_PER_CORE * cores)
    if workers is None or n == workers:
        return n, None
    why = (f"one per member of the batch ({members})" if n < MAX_WORKERS_PER_CORE * cores
           else f"at most {MAX_WORKERS_PER_CORE} per core ({cores} core{'s' if cores > 1 else ''})")
    return n, f"workers: {n} worker process{'es' if n > 1 else ''}, not the {workers} asked for: {why}"


def make(workers: int | None = None, scheduler: str | None = None, members: int | None = None) -> Executor:
    """The executor a run asks for: a scheduler's cluster, else a local pool of ``workers`` (default: the
    cores; capped by :func:`local_workers`, ``members`` being the size of the run's batches where known)."""
    if scheduler:
        return DaskCluster(scheduler)
    n, _ = local_workers(workers, members)
    return Serial() if n == 1 else LocalPool(n)


# ------------------------------------------------ the run's executor
_CURRENT: contextvars.ContextVar[Executor | None] = contextvars.ContextVar("ngcontact_executor", default=None)


def current() -> Executor:
    """The executor of the running batch-aware code (serial unless a caller set one with :func:`use`)."""
    return _CURRENT.get() or Serial()


@contextlib.contextmanager
def use(executor: Executor, progress: Progress | None = None):
    """Within the block, :func:`current` is ``executor`` and batches report to ``progress``; closed at the end."""
    token, ptoken = _CURRENT.set(executor), PROGRESS.set(progress)
    try:
        yield executor
    except BaseException:
        executor.abort()                 # an error or Ctrl-C: stop the workers now, even idle or warming up
        raise
    finally:
        _CURRENT.reset(token)
        PROGRESS.reset(ptoken)
        executor.close()
