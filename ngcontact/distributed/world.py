"""The MPI world a run was launched in: ``mpiexec -n N ngcontact run SCENE`` (or ``--mpi``).

A launch by ``mpiexec`` is recognised by the variables its process manager
sets (MPICH's ``PMI_SIZE``, Open MPI's ``OMPI_COMM_WORLD_SIZE``); more than
one rank makes the macro solve distributed (:mod:`ngcontact.distributed.macro_run`).
``mpi4py`` comes with the optional extra ``ngcontact[mpi]``; a launch on
several ranks without it, or ``--mpi`` without it, is refused with what to
install, before anything is solved or written.
"""
from __future__ import annotations

import os
import pickle
import time
from dataclasses import dataclass
from typing import Any

from ngcontact.errors import ModelError, NgcontactError

#: what to install for MPI runs
INSTALL = "pip install 'ngcontact[mpi]' (mpi4py and mpich, which gives mpiexec)"

#: seconds between a waiting rank's looks at whether the others have reached :func:`broadcast`
POLL_S = 0.002

#: environment variables holding the number of ranks, by process manager (MPICH / Hydra, Open MPI)
SIZE_VARIABLES = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE")
#: ... and this process's rank
RANK_VARIABLES = ("PMI_RANK", "OMPI_COMM_WORLD_RANK")


@dataclass(frozen=True)
class World:
    """``comm`` (mpi4py's ``COMM_WORLD``), this process's ``rank`` and the number of ranks ``size``."""

    comm: Any
    rank: int
    size: int

    @property
    def root(self) -> bool:
        """Rank 0: it meshes, post-processes and writes."""
        return self.rank == 0


def _variable(names: tuple[str, ...], default: int) -> int:
    for name in names:
        value = os.environ.get(name, "")
        if value.isdigit():
            return int(value)
    return default


def launched_ranks() -> int:
    """The number of ranks ``mpiexec`` started this process among (1 outside ``mpiexec``)."""
    return _variable(SIZE_VARIABLES, 1)


def launched_rank() -> int:
    """This process's rank under ``mpiexec`` (0 outside it): only rank 0 prints and writes."""
    return _variable(RANK_VARIABLES, 0)


def world(requested: bool = False) -> World | None:
    """The MPI world of a distributed run, or ``None`` for a run in one process.

    ``requested``: ``--mpi`` was given (then ``mpi4py`` must be there even on
    one rank).  Raises :class:`~ngcontact.errors.ModelError` naming the
    extra to install where ``mpi4py`` is missing.
    """
    ranks = launched_ranks()
    if ranks <= 1 and not requested:
        return None
    try:
        from mpi4py import MPI
    except ImportError as exc:
        how = f"launched by mpiexec on {ranks} ranks" if ranks > 1 else "--mpi"
        raise ModelError(f"{how}: a distributed run needs mpi4py, which is not installed; {INSTALL}") from exc
    comm = MPI.COMM_WORLD
    if comm.size <= 1 and not requested:
        return None
    return World(comm=comm, rank=comm.rank, size=comm.size)


def broadcast(world: World, value: Any = None) -> Any:
    """Rank 0's ``value`` on every rank, the ranks that reach it first asleep until all have.

    MPICH's blocking calls poll without pause: a rank waiting in ``bcast`` while rank 0 works alone
    (makes the mesh, writes the report) keeps a core busy that rank 0, or another job, needs.  Here
    every rank enters a non-blocking barrier and tests it every :data:`POLL_S` seconds, sleeping in
    between; once all have entered, rank 0's value is broadcast (pickled by mpi4py).
    """
    arrived = world.comm.Ibarrier()
    while not arrived.Test():
        time.sleep(POLL_S)
    return world.comm.bcast(value)


def sent_error(exc: BaseException, rank: int = 0) -> bytes:
    """``("error", exc)`` pickled for the other ranks; an exception that does not come back from pickling as
    itself (its class's arguments are not its ``args``, or it holds what does not pickle) is sent as a
    :class:`~ngcontact.errors.NgcontactError` with its class, message and the ``rank`` it was raised on, so that
    the sending rank always sends and every rank raises (none waits for a value that never comes)."""
    try:
        sent = pickle.dumps(("error", exc))
        pickle.loads(sent)
        return sent
    except Exception:  # noqa: BLE001  (any failure to pickle or unpickle)
        return pickle.dumps(("error", NgcontactError(f"on rank {rank}: {type(exc).__name__}: {exc}")))


def raise_sent(sent: bytes) -> None:
    """Raise the exception :func:`sent_error` pickled."""
    raise pickle.loads(sent)[1]
