"""A run's batch goes to local workers only where its rest repays them (condition (1) of
:mod:`ngcontact.parallel.worker_payoff`): fake members of a known CPU cost, real workers.

The member :func:`burn` spends a given number of CPU seconds and returns the
id of the process that ran it, so a test sees where each member went.
"""
import os
import time

import pytest

from ngcontact.parallel import batch_forecast, free_cores, judged_batches, local_pool, worker_lifetime
from ngcontact.parallel.free_cores import Reading
from ngcontact.parallel.worker_payoff import MemberClock, Payoff


def burn(seconds: float) -> int:
    """A member of known cost: ``seconds`` of CPU time in the process that runs it; that process's id."""
    t0 = time.process_time()
    while time.process_time() - t0 < seconds:
        pass
    return os.getpid()


def test_condition_1_weighs_the_saving_on_the_rest_against_the_start_ahead_and_a_first_member():
    small = Payoff(member_seconds=0.13, rest=7, workers=2, start_ahead=0.0, first_member_seconds=1.0)
    assert small.saving == pytest.approx(3 * 0.13) and not small.repaid        # 7 members: 4 on one worker
    large = Payoff(member_seconds=0.65, rest=15, workers=2, start_ahead=0.5, first_member_seconds=1.0)
    assert large.saving == pytest.approx(7 * 0.65) and large.cost == 1.5 and large.repaid
    assert Payoff(10.0, 1, 2, 0.0, 0.0).saving == 0.0                             # one member is not split
    assert not Payoff(10.0, 0, 2, 0.0, 0.0).repaid and not Payoff(10.0, 5, 1, 0.0, 0.0).repaid
    assert "the other 7 in this process" in small.describe(1)
    assert "the other 15 on 2 workers" in large.describe(1)


def test_a_member_is_timed_by_its_cpu_seconds_when_the_process_waits_beside_it():
    clock = MemberClock()
    with clock:
        time.sleep(0.05)                 # wall time, no work: another process would have had the core
    with clock:
        burn(0.02)
    assert len(clock.times) == 2 and clock.times[0] < 0.01 <= 0.02 <= clock.times[1] < 0.04
    assert clock.least == clock.times[0]
    assert clock.walls[0] >= 0.05 and clock.walls[1] >= clock.times[1]       # the wall seconds, kept beside
    assert clock.least_wall == min(clock.walls) and MemberClock().least_wall == 0.0


@pytest.fixture
def ready_pool(monkeypatch):
    """Two started workers (the start is paid: ``R = 0``), a worker's first member estimated at 0.2 s."""
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.2)
    pool = local_pool.LocalPool(2)
    pool.start()
    assert pool.wait_ready(120)
    yield pool
    pool.close()


def test_a_batch_too_small_to_repay_workers_runs_serially_and_says_why(ready_pool):
    """Three members of 0.05 s: the workers would save 0.05 s on the other two, less than 0.2 s; after the
    second, none on the last one."""
    pids = ready_pool.map(burn, [0.05] * 3, ["a", "b", "c"], label="small")
    assert pids == [os.getpid()] * 3
    batch = ready_pool.describe()["batches"][-1]
    assert (batch["label"], batch["executor"]) == ("small", "serial")
    assert batch["decision"].startswith("2 members solved here") and "the other 1 in this process" in batch["decision"]
    assert ready_pool._launched() and ready_pool._ready()    # started workers (or server) kept for the next batch


def test_a_large_batch_goes_to_the_workers_after_its_first_two_members(ready_pool):
    """Twelve members of 0.05 s: 0.25 s saved on the other ten, more than 0.2 s."""
    names = [f"m{k}" for k in range(12)]
    pids = ready_pool.map(burn, [0.05] * 12, names, label="large")
    assert pids[:2] == [os.getpid()] * 2 and os.getpid() not in pids[2:]
    batch = ready_pool.describe()["batches"][-1]
    assert batch["executor"] == "local" and "the other 10 on 2 workers" in batch["decision"]


@pytest.mark.parametrize("method", local_pool.METHODS)
def test_workers_still_starting_are_stopped_when_the_batch_ends_here(method):
    """A pool started as the run begins, a batch of a few short members: finished here, the workers (or
    their fork server, still importing) stopped at once rather than left to take cores from this process."""
    pool = local_pool.LocalPool(2, method=method)
    try:
        pool.start()
        processes = list(pool._pool._processes.values()) if method == "spawn" else []
        server = pool._server.pid if method == "forkserver" else None
        assert pool.map(burn, [0.01] * 3, ["a", "b", "c"], label="tiny") == [os.getpid()] * 3
        assert pool._pool is None and pool._server is None
        assert pool.describe()["batches"][-1]["executor"] == "serial"
        assert server is None or worker_lifetime.process_start(server) is None
        deadline = time.monotonic() + 5.0
        while any(p.is_alive() for p in processes) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(p.is_alive() for p in processes)
    finally:
        pool.close()


def test_a_batch_kept_here_starts_no_worker_process():
    """Workers on demand: a batch whose rest does not repay them never spawns one, so it costs exactly the
    serial run (nothing takes a core from this process, not even while the run sets up)."""
    pool = local_pool.LocalPool(2)
    try:
        pool.start_on_demand(("ngsolve",))
        assert pool.pools_started == 0 and pool._pool is None and pool._server is None
        assert pool.map(burn, [0.02] * 4, ["a", "b", "c", "d"], label="small") == [os.getpid()] * 4
        assert pool.pools_started == 0 and pool._pool is None and pool._server is None
        assert pool.describe()["batches"][-1]["executor"] == "serial"
        assert pool.describe()["workers_started"] == "never"
    finally:
        pool.close()


def test_a_run_with_a_batch_starts_no_worker_before_its_batch_repays_them(monkeypatch, tmp_path):
    """The runner's context of a scene with a batch (an ensemble) spawns no worker as it opens (no record of
    an earlier run of it: :mod:`ngcontact.parallel.batch_forecast`); a small batch in it spawns none either."""
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path))
    from ngcontact import runner
    from ngcontact.scene import loader
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    scene = loader.load(os.path.join(root, "geometries", "cells", "self_affine_ensemble.toml"))
    assert runner.has_batches(scene)
    with runner.batches(scene, workers=2) as ex:
        assert isinstance(ex, local_pool.LocalPool) and ex.pools_started == 0
        assert ex.map(burn, [0.01] * 3, ["a", "b", "c"], label="small") == [os.getpid()] * 3
        assert ex.pools_started == 0


@pytest.fixture
def on_demand_pool(monkeypatch):
    """A pool whose workers start on demand, with no start to pay and no first member's extra: a batch of
    members that take time repays them where the cores are free."""
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.0)
    pool = local_pool.LocalPool(2)
    pool.start_on_demand(("ngsolve",))
    yield pool
    pool.close()


def test_workers_on_demand_start_inside_the_batch_that_repays_them(on_demand_pool):
    """A batch whose first member shows that its rest repays the workers starts them then (its members
    after the first two go to them once one is ready: how many depends on the machine's load)."""
    pids = on_demand_pool.map(burn, [0.02] * 20, [f"m{k}" for k in range(20)], label="large")
    assert on_demand_pool.pools_started == 1
    assert on_demand_pool.describe()["workers_started"] == "during batch 'large'"
    assert pids[:2] == [os.getpid()] * 2


def test_a_fork_servers_start_once_begun_is_spent_and_not_counted_again(monkeypatch):
    """Before the fork server starts, each of the two workers pays half its start and a fork (``S``) and
    waits for all of it (``R``); once it has started (with the run, as a forecast would start it), the rule
    in the batch counts only what its imports have still to do and the forks: a rest that does not repay
    the whole start (14 x 0.1 s against 2 x (1 + 0.05 + 0.1) CPU s) is sent once the start is paid."""
    monkeypatch.setattr(judged_batches, "START_SECONDS", 2.0)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.05)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.1)
    pool = local_pool.LocalPool(2, method="forkserver")
    try:
        before = pool.payoff(0.1, 14)
        assert before.start_cpu == pytest.approx(1.05) and before.start_ahead == pytest.approx(2.05)
        assert not before.repaid and before.core_cost == pytest.approx(2.3)
        pool.start(("ngsolve",))
        begun = pool.payoff(0.1, 14)
        assert begun.start_cpu == 0.05 and 0.05 <= begun.start_ahead <= 2.05
        assert pool.wait_ready(120)
        ready = pool.payoff(0.1, 14)
        assert (ready.start_cpu, ready.start_ahead) == (0.05, 0.05) and ready.repaid
        assert pool.map(burn, [0.1] * 16, [f"m{k}" for k in range(16)], label="spent")[2:].count(os.getpid()) == 0
        assert pool.payoff(0.1, 14).start_cpu == 0.0            # forked workers: nothing left to pay
    finally:
        pool.close()


def test_condition_1_counts_the_cores_other_processes_leave_and_the_work_of_the_starts():
    """A rest that repays two workers on an idle machine does not on one whose other jobs leave 1.5 cores
    (``P = 1.5``: 12 x 0.5 x 0.5 = 3 CPU s against 2 x (1.5 + 0.5)), nor on one they keep busy."""
    idle, half, busy = (Reading(2, b, "a test's") for b in (0.0, 0.5, 2.0))
    kw = dict(member_seconds=0.5, rest=12, workers=2, start_ahead=0.0, first_member_seconds=0.5, start_cpu=1.5)
    assert Payoff(**kw, cores=idle).repaid and Payoff(**kw, cores=idle).parallel == 2.0
    on_half = Payoff(**kw, cores=half)
    assert on_half.parallel == 1.5 and on_half.core_saving == pytest.approx(3.0) and on_half.core_cost == 4.0
    assert not on_half.repaid and "the other 12 in this process" in on_half.describe(2)
    on_busy = Payoff(**kw, cores=busy)
    assert on_busy.busy and not on_busy.repaid and "busy with other processes" in on_busy.describe(2)


@pytest.fixture
def busy_machine(monkeypatch):
    """Two cores, both kept busy by other processes (a load average of 2, no ``/proc/stat`` to read)."""
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    monkeypatch.setattr(free_cores, "load_average", lambda: 2.0)


def test_a_batch_on_a_machine_whose_cores_are_busy_runs_serially_and_says_why(busy_machine, on_demand_pool):
    """A batch that repays free workers (no start to pay, no first member's extra) stays in this process
    when other jobs keep the cores busy; no worker process is started for it, and its record says why."""
    pids = on_demand_pool.map(burn, [0.02] * 12, [f"m{k}" for k in range(12)], label="busy")
    assert pids == [os.getpid()] * 12 and on_demand_pool.pools_started == 0
    batch = on_demand_pool.describe()["batches"][-1]
    assert batch["executor"] == "serial"
    assert "0 of 2 cores free (one-minute load average 2.00)" in batch["decision"]
    assert "busy with other processes" in batch["decision"]


def test_started_workers_are_left_idle_while_other_jobs_keep_the_cores_busy(monkeypatch, ready_pool):
    """Workers already started do not take a batch while the cores are busy: they would only take turns
    with the other jobs."""
    monkeypatch.setattr(free_cores, "load_average", lambda: 2.0 * len(free_cores.affinity()))
    names = [f"m{k}" for k in range(12)]
    assert ready_pool.map(burn, [0.05] * 12, names, label="large") == [os.getpid()] * 12
    assert "busy with other processes" in ready_pool.describe()["batches"][-1]["decision"]


@pytest.mark.parametrize("method", local_pool.METHODS)
def test_a_workers_start_is_measured_and_kept_for_the_next_runs(method):
    """The workers' start (``S`` of condition (1)) is recorded on this machine: a spawned worker's CPU
    seconds once its imports are done, as each worker's start ends; a fork server's once its imports are
    done (NGSolve among them: more than a tenth of a second, less than a minute) and each forked worker's
    before its first member (a fork, which imports nothing again: less than half the server's; its CPU seconds
    are tens of milliseconds, the server's a few tenths where the imports' files are cached)."""
    pool = local_pool.LocalPool(2, method=method)
    try:
        pool.start(("ngsolve",))
        assert pool.wait_ready(120)
        if method == "spawn":
            deadline = time.monotonic() + 10.0
            while len(batch_forecast.measured_costs("start")) < 2 and time.monotonic() < deadline:
                time.sleep(0.05)          # the record is written as each start ends, beside this thread
            starts = batch_forecast.measured_costs("start")
            assert len(starts) == 2 and all(0.1 < s < 60.0 for s in starts)
            assert judged_batches.start_cost() == pytest.approx(sum(starts) / 2)
            return
        [server] = batch_forecast.measured_costs("server")
        assert 0.1 < server < 60.0 and judged_batches.server_cost() == server
        assert batch_forecast.measured_costs("fork") == [] and judged_batches.fork_cost() == 0.05
        import operator                   # a member whose module the server has imported (the forks' own cost)
        pool._pool_map(operator.neg, [1.0] * 4, list("abcd"), "forks", None, None)
        [fork] = batch_forecast.measured_costs("fork")
        assert 0.0 < fork < 0.5 * server and judged_batches.fork_cost() == fork
    finally:
        pool.close()


def test_a_workers_first_member_is_measured_beyond_the_cheapest_member_here(ready_pool):
    """``F``: members of 0.05 s everywhere, so a worker's first member costs next to nothing more."""
    assert judged_batches.first_member_cost() == 0.2          # the estimate, before any measurement
    ready_pool.map(burn, [0.05] * 12, [f"m{k}" for k in range(12)], label="large")
    [first] = batch_forecast.measured_costs("first_member")
    assert 0.0 <= first < 0.03 and judged_batches.first_member_cost() == first


def test_a_cost_is_the_median_of_the_last_ones_measured():
    assert batch_forecast.cost_seconds("start", default=2.5) == 2.5
    for s in (9.0, 1.0, 1.2, 1.4, 1.1, 1.3):
        batch_forecast.remember_cost("start", s)
    batch_forecast.remember_cost("first_member", 0.5)
    assert batch_forecast.measured_costs("start") == [1.0, 1.2, 1.4, 1.1, 1.3]
    assert batch_forecast.cost_seconds("start", 0.0) == 1.2 and batch_forecast.cost_seconds("first_member", 0.0) == 0.5


def blas_threads(_) -> int:
    """The most threads of any BLAS loaded in this process, after loading SciPy's own (``scipy.linalg``)."""
    import scipy.linalg  # noqa: F401 - loads SciPy's OpenBLAS where the process had not
    from threadpoolctl import threadpool_info
    return max(d["num_threads"] for d in threadpool_info() if d["user_api"] == "blas")


def test_workers_run_every_blas_on_one_thread_even_one_loaded_after_their_start(monkeypatch):
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.0)
    pool = local_pool.LocalPool(2)
    try:
        pool.start()
        assert pool.wait_ready(120)
        assert pool._pool_map(blas_threads, [0, 1, 2, 3], list("abcd"), "blas", None, None) == [1] * 4
    finally:
        pool.close()


def opened_after(pool, monkeypatch) -> list[int]:
    """The numbers of members solved here each time ``pool`` started its fork server."""
    opened: list[int] = []
    open_server = pool._open_server

    def recorded(*args, **kwargs):
        if pool._server is None:          # (a pool forked from a running server opens it again)
            opened.append(len(pool.member_clock.times))
        return open_server(*args, **kwargs)
    monkeypatch.setattr(pool, "_open_server", recorded)
    return opened


def test_a_batch_without_a_forecast_starts_no_server_while_its_members_are_timed(monkeypatch):
    """Four members of 0.02 s do not repay the workers (the estimated 1 s first member): the batch ends here
    and no fork server ever started, not even while its first members were timed."""
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 1.0)
    pool = local_pool.LocalPool(2, method="forkserver")
    opened = opened_after(pool, monkeypatch)
    try:
        pool.start_on_demand(("ngsolve",))
        assert pool.map(burn, [0.02] * 4, list("abcd"), label="small") == [os.getpid()] * 4
        assert opened == [] and pool._server is None and pool._pool is None
        assert pool.pools_started == 0 and pool.describe()["workers_started"] == "never"
        batch = pool.describe()["batches"][-1]
        assert batch["executor"] == "serial" and "the other 2 in this process" in batch["decision"]
    finally:
        pool.close()


def test_a_batch_that_repays_its_workers_starts_them_once_a_timed_member_shows_it(monkeypatch):
    """The fork server starts once a member timed here shows that the rest repays the workers, never as the
    batch opens; the members after the two that time the batch go to the workers once it is ready."""
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    pool = local_pool.LocalPool(2, method="forkserver")
    opened = opened_after(pool, monkeypatch)
    try:
        pool.start_on_demand(("ngsolve",))
        pids = pool.map(burn, [0.1] * 60, [f"m{k}" for k in range(60)], label="large")
        here = pids.count(os.getpid())
        assert len(opened) == 1 and opened[0] >= 1 and 2 <= here < 60 and pids[:here] == [os.getpid()] * here
        assert pool.pools_started == 1 and pool.describe()["workers_started"] == "during batch 'large'"
        batch = pool.describe()["batches"][-1]
        assert batch["executor"] == "local" and f"the other {60 - here} on 2 workers" in batch["decision"]
    finally:
        pool.close()

