"""Worker processes never outlive the process that started them.

A parent killed with SIGKILL runs no cleanup of its own: its workers must
die with it (a death signal set in each worker, a watchdog on the parent's
pid), and the resource tracker of :mod:`multiprocessing` with them; the
next pool ends what an earlier run left behind, by the process ids it
recorded, and nothing else.  Every process is found through ``/proc`` and
checked by its start time, so that a reused pid is never taken for one of
these; whatever a failing test leaves is ended by the test itself.
"""
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from ngcontact.parallel import worker_lifetime

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc (Linux)")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

#: A batch of members that sleep: each member announces itself with a file, so the parent is killed while
#: every worker runs a member.
SCRIPT = textwrap.dedent("""\
    import os
    import sys
    import time

    from ngcontact.parallel.local_pool import LocalPool


    def member(path):
        with open(path, "w"):
            pass
        time.sleep(120)


    if __name__ == "__main__":
        folder = sys.argv[1]
        LocalPool(2, method=sys.argv[2]).map(member, [os.path.join(folder, f"m{k}") for k in range(4)],
                                             [f"m{k}" for k in range(4)])
""")


def stat(pid: int) -> tuple[int, str, int] | None:
    """``(parent pid, state, start time)`` of a process, None when it is gone."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return int(fields[1]), fields[0], int(fields[19])


def descendants(pid: int) -> dict[int, int]:
    """Every process below ``pid``: pid -> start time."""
    children: dict[int, list[int]] = {}
    starts = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            s = stat(int(name))
            if s is not None:
                children.setdefault(s[0], []).append(int(name))
                starts[int(name)] = s[2]
    out, todo = {}, [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            out[child] = starts[child]
            todo.append(child)
    return out


def alive(processes: dict[int, int]) -> dict[int, int]:
    """The processes still running (a zombie, dead but not yet reaped, is not running)."""
    out = {}
    for pid, start in processes.items():
        s = stat(pid)
        if s is not None and s[2] == start and s[1] != "Z":
            out[pid] = start
    return out


def end(processes: dict[int, int]) -> None:
    for pid in alive(processes):
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass


def wait_for(condition, seconds: float, step: float = 0.05):
    deadline = time.monotonic() + seconds
    while True:
        value = condition()
        if value or time.monotonic() > deadline:
            return value
        time.sleep(step)


@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_a_parent_killed_with_sigkill_takes_its_workers_and_the_resource_tracker_with_it(tmp_path, method):
    """Spawned workers, or a fork server and the two workers it forked (their parent is the server, which
    the run's end ends): none outlives the run killed while its members run."""
    script = tmp_path / "batch.py"
    script.write_text(SCRIPT)
    marks = tmp_path / "marks"
    marks.mkdir()
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""),
               XDG_RUNTIME_DIR=str(tmp_path))
    proc = subprocess.Popen([sys.executable, str(script), str(marks), method], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    below: dict[int, int] = {}
    try:
        started = wait_for(lambda: len(os.listdir(marks)) >= 2, 25.0)
        assert started, "the workers did not start their members"
        below = descendants(proc.pid)
        kinds = [open(f"/proc/{pid}/cmdline", "rb").read() for pid in below]
        if method == "spawn":
            assert sum(b"spawn_main" in k for k in kinds) == 2, kinds
        else:                           # the server and its two workers, forked: the server's command line
            assert sum(worker_lifetime.SERVER_MARK in k for k in kinds) == 3, kinds
            assert sum(stat(pid)[0] == proc.pid for pid in below) == 2      # the server, the tracker
        assert any(b"resource_tracker" in k for k in kinds), kinds
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=10)
        left = wait_for(lambda: not alive(below), 5.0)
        assert left, f"processes outlived their parent by 5 s: {alive(below)}"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        end(below)


def test_the_next_pool_ends_the_orphans_of_an_earlier_run_by_their_records_and_nothing_else(tmp_path, monkeypatch):
    """Records of an earlier run whose parent is gone: its workers still running are ended.  Spared: a
    worker of a parent still running, a process whose command line is not a worker's, a recorded pid whose
    start time differs (a reused pid)."""
    from ngcontact.parallel import local_pool, worker_lifetime
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    worker = [sys.executable, "-c", "from multiprocessing.spawn import spawn_main; import time; time.sleep(60)",
              "--multiprocessing-fork"]
    server = [sys.executable, "-c", "from multiprocessing.forkserver import main; import time; time.sleep(60)"]
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone_start = stat(gone.pid)[2]
    gone.wait()
    procs = {name: subprocess.Popen(cmd) for name, cmd in (
        ("orphan", worker), ("orphan server", server), ("of a live parent", worker),
        ("not a worker", ["sleep", "60"]), ("reused pid", worker))}
    try:
        starts = {name: wait_for(lambda p=p: stat(p.pid), 5.0)[2] for name, p in procs.items()}
        here = stat(os.getpid())[2]
        folder = worker_lifetime.record_dir()
        os.makedirs(folder, exist_ok=True)
        records = {
            "a.txt": f"parent {gone.pid} {gone_start}\nworker {procs['orphan'].pid} {starts['orphan']}\n"
                     f"worker {procs['orphan server'].pid} {starts['orphan server']}\n"
                     f"worker {procs['not a worker'].pid} {starts['not a worker']}\n"
                     f"worker {procs['reused pid'].pid} {starts['reused pid'] + 1}\n",
            "b.txt": f"parent {os.getpid()} {here}\nworker {procs['of a live parent'].pid} "
                     f"{starts['of a live parent']}\n",
        }
        for name, text in records.items():
            with open(os.path.join(folder, worker_lifetime.RECORD_PREFIX + name), "w") as f:
                f.write(text)
        pool = local_pool.LocalPool(2)
        try:
            pool.start()                                  # a new pool ends the orphans before it starts
            assert procs["orphan"].wait(timeout=5) == -signal.SIGKILL
            assert procs["orphan server"].wait(timeout=5) == -signal.SIGKILL
            assert all(p.poll() is None for name, p in procs.items() if not name.startswith("orphan"))
        finally:
            pool.close()
        # the record of the dead parent is done with, as is the pool's own once closed; the live parent's stays
        assert sorted(os.listdir(folder)) == [worker_lifetime.RECORD_PREFIX + "b.txt"]
        assert worker_lifetime.end_orphans() == []
    finally:
        for p in procs.values():
            if p.poll() is None:
                p.kill()
            p.wait()


@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_workers_spawned_by_a_thread_that_ends_live_on_with_their_parent(tmp_path, monkeypatch, method):
    """The kernel's death signal follows the *thread* that spawned a worker (or started a fork server): a
    pool started by a thread that then ends keeps its workers (they watch the parent's pid instead; the
    server asked for no death signal) and runs its batches."""
    import operator
    import threading

    from ngcontact.parallel import judged_batches, local_pool
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.0)          # every batch's rest goes to the workers
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.0)
    pool = local_pool.LocalPool(2, method=method)
    try:
        first = []

        def starter():             # starts the workers (or the server) and waits until they are ready
            pool.start()
            first.append(pool.map(operator.neg, [1.0, 2.0], ["a", "b"]))
            pool.wait_ready(120)

        thread = threading.Thread(target=starter)
        thread.start()
        thread.join()
        assert first == [[-1.0, -2.0]]
        server = pool._server.pid if method == "forkserver" else None
        workers = list(pool._pool._processes.values()) if method == "spawn" else []
        assert len(workers) == 2 or server is not None
        time.sleep(0.5)            # a death signal, had it been asked for, is on its way
        assert pool.map(operator.neg, [1.0, 2.0, 3.0, 4.0], ["a", "b", "c", "d"]) == [-1.0, -2.0, -3.0, -4.0]
        assert pool.describe()["batches"][-1]["executor"] == "local"
        if method == "spawn":
            assert list(pool._pool._processes.values()) == workers and all(w.is_alive() for w in workers)
        else:
            assert pool._server.pid == server and worker_lifetime.process_start(server) is not None
    finally:
        pool.close()


def environment(pid: int) -> dict[str, str]:
    """The environment process ``pid`` was started with (``/proc/PID/environ``)."""
    with open(f"/proc/{pid}/environ", "rb") as f:
        entries = f.read().split(b"\0")
    return dict(e.decode().split("=", 1) for e in entries if b"=" in e)


@pytest.mark.parametrize("between", ["pools", "workers"])
def test_a_fork_server_that_dies_is_restarted_with_one_thread_and_recorded(tmp_path, monkeypatch, between):
    """A fork server killed while the run goes on: the next batch's workers come from a new server started
    in the one-thread environment (not the run's: here ``NGCONTACT_THREADS=2``), entered in the pool's
    record (the orphan guard ends it) and stopped with the pool.  ``pools``: the server dies between two
    pools (a new pool starts it); ``workers``: it dies while a pool's workers are being asked for, and
    :mod:`multiprocessing` starts it again by itself."""
    import operator
    import signal

    from multiprocessing import forkserver

    from ngcontact.parallel import fork_server, judged_batches, local_pool
    from ngcontact.parallel.batch_member import BLAS_THREADS_ENV
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    monkeypatch.setenv("NGCONTACT_THREADS", "2")
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.0)          # every batch's rest goes to the workers
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.0)
    pool = local_pool.LocalPool(2, method="forkserver")
    try:
        pool.start()
        assert pool.wait_ready(120)
        assert pool.map(operator.neg, [1.0, 2.0, 3.0, 4.0], list("abcd")) == [-1.0, -2.0, -3.0, -4.0]
        first = pool._server.pid
        pool._discard()
        os.kill(first, signal.SIGKILL)
        assert wait_for(lambda: worker_lifetime.process_start(first) is None, 10)
        if between == "workers":            # multiprocessing's own restart, as a worker is asked for
            ctx = fork_server.context()
            worker = ctx.Process(target=operator.neg, args=(1.0,))
            worker.start()
            worker.join(30)
        # on the workers whatever the payoff rule would say of the new server's start
        assert pool._pool_map(operator.neg, [1.0, 2.0, 3.0, 4.0], list("abcd"), "after", None, None) == \
            [-1.0, -2.0, -3.0, -4.0]
        server = pool._server.pid
        assert server != first and server == forkserver._forkserver._forkserver_pid
        env = environment(server)
        assert env["NGCONTACT_THREADS"] == "1" and all(env[name] == "1" for name in BLAS_THREADS_ENV)
        assert fork_server.READY_ENV not in os.environ and os.environ["NGCONTACT_THREADS"] == "2"
        assert wait_for(lambda: pool._server.ready(), 60)
        _, entries = worker_lifetime.read_record(pool._server.record.path)
        assert server in [pid for pid, _ in entries]
    finally:
        pool.close()
    assert wait_for(lambda: worker_lifetime.process_start(server) is None, 10)
