"""A rank waiting for rank 0 in :func:`ngcontact.distributed.world.broadcast` sleeps instead of polling.

Under ``mpiexec -n 2``: rank 0 works alone for a while (as it does making the
mesh or writing the report), then broadcasts a value.  Rank 1 receives it,
and its CPU time over the wait is a small part of the wait: MPICH's own
``bcast`` would poll all through it and take as much CPU time as rank 0's
work.
"""
from __future__ import annotations

import subprocess
import sys

import pytest
from test_mpi_macro import _env, needs_mpi

#: rank 0's work before it broadcasts [s]
WORK_S = 1.5

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
    assert wall >= WORK_S
    assert cpu <= 0.1 * WORK_S, f"rank 1 took {cpu:.2f} s of CPU over a wait of {wall:.2f} s"
