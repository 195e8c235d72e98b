"""A VTK piece that fails to write, on rank 0 or on another rank, ends the run on every rank with that error,
and no rank waits for a collective call the others never make (:mod:`ngcontact.distributed.vtk_pieces`).

Was: rank 0's writer raising between sending a piece's path and the pieces' barrier left rank 0 in the
non-blocking barrier of its closing broadcast while the others sat in the blocking barrier of the pieces,
which MPI does not match: a hang.  A piece rank's failure left rank 0 in that barrier alone.

Two levels: the protocol with one thread per rank on a communicator that, like MPI, matches a blocking
barrier only with a blocking one (every wait bounded, so that a mismatch fails the test instead of hanging
it); and the ``mpi`` tier, the same under ``mpiexec -n 3`` (NGSolve's VTK writer replaced by one that fails
on the chosen rank, so that no mesh is needed).
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from types import SimpleNamespace

import pytest
from test_mpi_macro import _env, needs_mpi

from ngcontact.distributed.vtk_pieces import RankPieces, written
from ngcontact.distributed.world import World
from ngcontact.errors import OutputError

#: longest wait of any collective call of the fake communicator [s]: a mismatch fails after it
WAIT_S = 5.0
FULL = "No space left on device"


class _Shared:
    """What the ranks' threads share: a blocking barrier (bcast, allgather, Barrier) and a separate
    count for the non-blocking barrier, which MPI does not match with a blocking one either."""

    def __init__(self, size: int):
        self.size = size
        self.lock = threading.Lock()
        self.sync = threading.Barrier(size, timeout=WAIT_S)
        self.arrived = 0
        self.generation = 0
        self.box: list = [None] * size


class _Comm:
    """Rank ``rank``'s view of :class:`_Shared`, the calls of mpi4py's communicator the package makes."""

    def __init__(self, shared: _Shared, rank: int):
        self.shared, self.rank = shared, rank

    def Ibarrier(self):
        s = self.shared
        with s.lock:
            generation = s.generation
            s.arrived += 1
            if s.arrived == s.size:
                s.arrived, s.generation = 0, s.generation + 1
        deadline = time.monotonic() + WAIT_S

        def test():
            if time.monotonic() > deadline:
                raise TimeoutError(f"rank {self.rank}: the other ranks never entered the non-blocking barrier")
            return s.generation > generation
        return SimpleNamespace(Test=test)

    def Barrier(self):
        self.shared.sync.wait()

    def bcast(self, value):
        s = self.shared
        if self.rank == 0:
            s.box[0] = value
        s.sync.wait()
        got = s.box[0]
        s.sync.wait()
        return got

    def allgather(self, value):
        s = self.shared
        s.box[self.rank] = value
        s.sync.wait()
        got = list(s.box)
        s.sync.wait()
        return got


class _FailingVTK:
    """NGSolve's ``VTKOutput`` standing in: the mesh is the rank, whose piece fails where it is ``failing``."""

    failing = 0

    def __init__(self, ma, coefs, names, filename, subdivision, legacy):
        self.rank, self.filename = ma, filename

    def Do(self):
        if self.rank == self.failing:
            raise OSError(28, FULL)
        if self.rank:
            with open(f"{self.filename}_proc{self.rank}.vtu", "w") as fh:
                fh.write("<VTKFile/>\n")


def _outcome(world: World):
    item = SimpleNamespace(mesh=world.rank, fields={"u": SimpleNamespace(dim=3)}, subdivision=0,
                           pieces=RankPieces(world))
    return SimpleNamespace(vtk={"fields": item})


def _ranks(tmp_path, size: int, after_pieces=None) -> dict[int, BaseException | None]:
    """Run :func:`written` on ``size`` threads standing for ranks; rank 0's writer writes the field set's
    pieces, then calls ``after_pieces`` and writes the report.  What each rank ended with, by rank."""
    shared = _Shared(size)
    raised: dict[int, BaseException | None] = {}

    def rank(r: int) -> None:
        world = World(comm=_Comm(shared, r), rank=r, size=size)
        outcome = _outcome(world)

        def write():
            item = outcome.vtk["fields"]
            item.pieces.write(str(tmp_path / "fields"), item)
            if after_pieces is not None:
                after_pieces()
            (tmp_path / "report.json").write_text("{}")
        try:
            written(outcome, write)
            raised[r] = None
        except BaseException as exc:  # noqa: BLE001  (what each rank ends with is the result)
            raised[r] = exc

    threads = [threading.Thread(target=rank, args=(r,), daemon=True) for r in range(size)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=4 * WAIT_S)
    assert not any(t.is_alive() for t in threads), "a rank still waits"
    return raised


@pytest.mark.parametrize("failing", [0, 1], ids=["rank 0", "rank 1"])
def test_a_piece_that_fails_ends_every_rank_with_its_error(tmp_path, monkeypatch, failing):
    import ngsolve
    monkeypatch.setattr(ngsolve, "VTKOutput", _FailingVTK)
    monkeypatch.setattr(_FailingVTK, "failing", failing)
    raised = _ranks(tmp_path, 3)
    for r in range(3):
        assert isinstance(raised[r], OSError) and raised[r].errno == 28 and FULL in str(raised[r]), (r, raised[r])
    assert not (tmp_path / "report.json").exists()


def test_rank_0s_writer_failing_after_the_pieces_ends_every_rank_with_its_error(tmp_path, monkeypatch):
    """Was: the other ranks left with exit 0 while rank 0 failed (its closing broadcast carried no error)."""
    import ngsolve
    monkeypatch.setattr(ngsolve, "VTKOutput", _FailingVTK)
    monkeypatch.setattr(_FailingVTK, "failing", -1)

    def full():
        raise OutputError("--out D: writing failed ([Errno 28] No space left on device)")
    raised = _ranks(tmp_path, 3, full)
    assert all(type(raised[r]) is OutputError and str(raised[r]) == str(raised[0]) for r in range(3)), raised


def test_a_write_that_succeeds_writes_every_piece_and_the_pvtu(tmp_path, monkeypatch):
    import ngsolve
    monkeypatch.setattr(ngsolve, "VTKOutput", _FailingVTK)
    monkeypatch.setattr(_FailingVTK, "failing", -1)
    assert _ranks(tmp_path, 3) == {0: None, 1: None, 2: None}
    assert sorted(os.listdir(tmp_path)) == ["fields.pvtu", "fields_proc1.vtu", "fields_proc2.vtu", "report.json"]


SCRIPT = """
import os, sys, types
from types import SimpleNamespace
FAILING = int(sys.argv[2])


class VTKOutput:
    def __init__(self, ma, coefs, names, filename, subdivision, legacy):
        self.rank, self.filename = ma, filename

    def Do(self):
        if self.rank == FAILING:
            raise OSError(28, "No space left on device")
        if self.rank:
            with open(f"{self.filename}_proc{self.rank}.vtu", "w") as fh:
                fh.write("<VTKFile/>")


sys.modules["ngsolve"] = types.SimpleNamespace(VTKOutput=VTKOutput)   # no mesh needed
from mpi4py import MPI
from ngcontact.distributed.vtk_pieces import RankPieces, written
from ngcontact.distributed.world import World
from ngcontact.errors import OutputError
comm = MPI.COMM_WORLD
world = World(comm=comm, rank=comm.rank, size=comm.size)
item = SimpleNamespace(mesh=world.rank, fields={"u": SimpleNamespace(dim=3)}, subdivision=0, pieces=RankPieces(world))
outcome = SimpleNamespace(vtk={"fields": item})
try:
    written(outcome, lambda: item.pieces.write(os.path.join(sys.argv[1], "fields"), item))
    said = "ok"
except OSError as exc:
    said = f"OSError {exc.errno}"
# each rank's outcome in a file of its own: mpiexec forwards the ranks' stdout in chunks that may interleave
with open(os.path.join(sys.argv[1], f"outcome_{comm.rank}.txt"), "w") as fh:
    fh.write(f"{comm.rank} {said}")
"""


@pytest.mark.mpi
@needs_mpi
@pytest.mark.parametrize("failing", [0, 2], ids=["rank 0", "rank 2"])
def test_under_mpiexec_a_failing_piece_ends_every_rank_with_its_error(tmp_path, failing):
    script = tmp_path / "pieces.py"
    script.write_text(SCRIPT)
    proc = subprocess.Popen(["mpiexec", "-n", "3", sys.executable, str(script), str(tmp_path), str(failing)],
                            env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    try:
        out, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        pytest.fail("the ranks hang after a failed VTK piece")
    rows = sorted(p.read_text().split() for p in tmp_path.glob("outcome_*.txt"))
    assert rows == [[str(r), "OSError", "28"] for r in range(3)], (rows, out, err)

