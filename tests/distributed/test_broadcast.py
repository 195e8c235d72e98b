"""A rank waiting for rank 0 in :func:`ngcontact.distributed.world.broadcast` sleeps instead of polling, and
what rank 0 sends through it (:func:`ngcontact.distributed.macro_run._on_root`) is what every rank raises.

Under ``mpiexec -n 2``: rank 0 works alone for a while (as it does making the
mesh or writing the report), then broadcasts a value.  Rank 1 receives it,
and its CPU time over the wait is a small part of the wait: MPICH's own
``bcast`` would poll all through it and take as much CPU time as rank 0's
work.
"""
from __future__ import annotations

import subprocess
import sys
from types import SimpleNamespace

import pytest
from test_mpi_macro import _env, needs_mpi

from ngcontact.distributed.macro_run import _on_root
from ngcontact.distributed.world import World
from ngcontact.errors import BatchError, ConvergenceError, GeometryError, NgcontactError, SceneError

#: rank 0's work before it broadcasts [s]
WORK_S = 1.5
#: how much later than rank 0 rank 1 may leave the first broadcast and start its clock [s]: a few of its sleeps
#: (``world.POLL_S``) and the broadcast's delivery
START_SKEW_S = 0.05

SCRIPT = f"""
import time
from mpi4py import MPI
from ngcontact.distributed.world import World, broadcast
comm = MPI.COMM_WORLD
world = World(comm=comm, rank=comm.rank, size=comm.size)
broadcast(world)                                   # both start together
wall, cpu = time.perf_counter(), time.process_time()
if world.root:
    end = time.perf_counter() + {WORK_S}
    while time.perf_counter() < end:               # rank 0 computes alone
        pass
value = broadcast(world, {{"mesh": [1, 2, 3]}} if world.root else None)
print(comm.rank, value == {{"mesh": [1, 2, 3]}}, time.perf_counter() - wall, time.process_time() - cpu, flush=True)
"""


@pytest.mark.mpi
@needs_mpi
def test_a_rank_waiting_for_rank_0_gets_its_value_and_sleeps_meanwhile(tmp_path):
    path = tmp_path / "wait.py"
    path.write_text(SCRIPT)
    done = subprocess.run(["mpiexec", "-n", "2", sys.executable, str(path)], env=_env(), capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    rows = {int(r): (got, float(wall), float(cpu)) for r, got, wall, cpu in
            (line.split() for line in done.stdout.splitlines())}
    assert rows[0][0] == rows[1][0] == "True"
    got, wall, cpu = rows[1]
    assert wall >= WORK_S - START_SKEW_S            # it waited for rank 0's work
    assert cpu <= 0.1 * WORK_S, f"rank 1 took {cpu:.2f} s of CPU over a wait of {wall:.2f} s"


class _Comm:
    """One process standing for the ranks of ``broadcast``: rank 0's value is kept, the others receive it."""

    def __init__(self):
        self.sent = None

    def Ibarrier(self):
        return SimpleNamespace(Test=lambda: True)

    def bcast(self, value):
        if value is not None:
            self.sent = value
        return self.sent


class _Unpicklable(RuntimeError):
    def __init__(self):
        super().__init__("holds a function")
        self.f = lambda: None


@pytest.mark.parametrize("error", [SceneError("geometry.width", -1.0, "must be > 0"),
                                   ConvergenceError("Newton did not converge", {"residuals": [1.0, 0.5]}),
                                   GeometryError("width", 0.0, "must be > 0"),
                                   BatchError("loads", "load 2", "diverged")], ids=type)
def test_rank_0s_error_is_raised_alike_on_every_rank(error):
    """A package error raised by ``make()`` on rank 0 reaches the other ranks as the same class with the same
    arguments (its exit status the same on every rank), and a value as the value."""
    comm = _Comm()
    ranks = [World(comm=comm, rank=r, size=2) for r in (0, 1)]

    def make():
        raise error
    for world in ranks:
        with pytest.raises(type(error)) as got:
            _on_root(world, make)
        assert str(got.value) == str(error) and vars(got.value) == vars(error)
    assert [_on_root(w, lambda: {"mesh": [1, 2]}) for w in ranks] == [{"mesh": [1, 2]}] * 2


def test_an_error_that_does_not_pickle_still_reaches_every_rank():
    """Rank 0 sends what it can: an error that cannot cross as itself crosses as the package's base error
    naming its class and message, so that no rank waits for a value that never comes."""
    comm = _Comm()
    with pytest.raises(_Unpicklable):
        _on_root(World(comm=comm, rank=0, size=2), lambda: (_ for _ in ()).throw(_Unpicklable()))
    assert comm.sent is not None
    with pytest.raises(NgcontactError, match="on rank 0: _Unpicklable: holds a function"):
        _on_root(World(comm=comm, rank=1, size=2), lambda: None)
