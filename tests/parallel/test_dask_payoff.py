"""A run's batch goes to a Dask cluster only where its rest repays the members' trips (condition (4) of
:mod:`ngcontact.parallel.dask_payoff`): fake members of a known CPU cost, a real ``LocalCluster`` of two
one-thread worker processes.

The member :func:`burn` spends a given number of CPU seconds and returns the id of the process that ran it,
so a test sees where each member went.
"""
import functools
import os
import sys
import time

import pytest

from ngcontact.parallel import batch_executor, dask_payoff
from ngcontact.parallel.dask_cluster import DaskCluster
from ngcontact.parallel.dask_payoff import DaskPayoff
from ngcontact.parallel.worker_payoff import MemberClock


def burn(seconds: float) -> int:
    """A member of known cost: ``seconds`` of CPU time in the thread that runs it; that process's id."""
    t0 = time.thread_time()
    while time.thread_time() - t0 < seconds:
        pass
    return os.getpid()


class NominalClock(MemberClock):
    """Times every member solved here at ``seconds`` (wall and ``min(wall, CPU)``), its nominal cost: the
    rule's ``c`` is the test's, not what the machine's load and this process's other threads (the test
    cluster's scheduler, NGSolve's) made of it."""

    def __init__(self, seconds: float):
        super().__init__()
        self.seconds = seconds

    def __exit__(self, *exc) -> None:
        if exc[0] is None:
            self.times.append(self.seconds)
            self.walls.append(self.seconds)


def nominal(monkeypatch, seconds: float) -> None:
    """Each member solved in this process is timed at ``seconds`` (:class:`NominalClock`)."""
    monkeypatch.setattr(batch_executor, "MemberClock", functools.partial(NominalClock, seconds))


@pytest.fixture(scope="module")
def cluster():
    """Two worker processes, one thread each, that have imported NGSolve and this module (a warm cluster);
    no client of the test's own is left as Dask's default (the executor must work without one)."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as c, distributed.Client(c, set_as_default=False) as client:
        probe = dask_payoff.Probe(client, "warm")
        probe.warm(("ngsolve", __name__))
        for fut in probe._warming:
            fut.result(timeout=120)
        yield c.scheduler_address


@pytest.fixture
def dask(cluster):
    ex = DaskCluster(cluster)
    ex.start_on_demand(("ngsolve",))
    yield ex
    ex.close()


def test_condition_4_weighs_the_saving_on_the_rest_against_the_trips_and_a_workers_extra_time():
    last = DaskPayoff(member_seconds=0.1, rest=1, workers=2, round_trip=0.01, member_extra=0.0)
    assert last.saving == 0.0 and not last.repaid                       # one member is not split
    large = DaskPayoff(member_seconds=0.3, rest=6, workers=2, round_trip=0.02, member_extra=0.0)
    assert large.saving == pytest.approx(0.9) and large.cost == pytest.approx(0.06) and large.repaid
    slow = DaskPayoff(member_seconds=0.3, rest=6, workers=2, round_trip=0.02, member_extra=0.4)
    assert slow.cost == pytest.approx(3 * 0.42) and not slow.repaid     # a cluster whose members cost more
    assert not DaskPayoff(10.0, 6, 1, 0.0, 0.0).repaid and not DaskPayoff(10.0, 0, 2, 0.0, 0.0).repaid
    assert DaskPayoff(0.1, 2, 2, 0.2, -0.15).cost == pytest.approx(0.2)    # a faster cluster is not counted on
    scan = DaskPayoff(member_seconds=0.1, rest=6, workers=2, round_trip=0.01, member_extra=0.0, connect=0.45)
    assert scan.cost == pytest.approx(0.45 + 3 * 0.01) and scan.saving == pytest.approx(0.3) and not scan.repaid
    assert DaskPayoff(0.1, 6, 2, 0.01, 0.0).repaid                       # connected already: K spent
    assert "the other 6 on the cluster's 2 workers" in large.describe(2)
    assert "the other 6 in this process" in slow.describe(2)


def test_a_members_extra_time_on_a_worker_is_its_wall_time_there_over_its_time_here(tmp_path):
    """``w``: the median of a batch's members' wall seconds on the workers over ``c`` (each worker's slow first
    member left out), read as ``e = (w+ - 1) c`` for the members of another batch, ``w+`` the largest kept
    (the rule's bound, (5)); 1, so ``e = 0``, before any (and no ``w`` known); a cluster measured faster is
    not counted on."""
    assert dask_payoff.member_wall([0.5, 0.25, 0.26, 0.27, 0.9], 0.25) == pytest.approx(1.08)
    assert dask_payoff.member_wall([], 0.25) is None and dask_payoff.member_wall([0.3], 0.0) is None
    address = "tcp://127.0.0.1:1"
    assert dask_payoff.member_extra(address, 0.1) == 0.0 and not dask_payoff.wall_known(address)
    for w in (1.2, 3.0, 1.3):
        dask_payoff.remember_cost(address, "member_wall", w)
    assert dask_payoff.wall_known(address)
    assert dask_payoff.member_extra(address, 0.1) == pytest.approx(0.2)       # the largest ratio, 3.0
    assert dask_payoff.member_extra(address, 0.25) == pytest.approx(0.5)
    assert dask_payoff.cost_seconds(address, "member_wall") == pytest.approx(1.3)     # the median, not decisive
    dask_payoff.remember_cost("tcp://127.0.0.1:2", "member_wall", 0.5)
    assert DaskPayoff(0.1, 6, 2, 0.01, dask_payoff.member_extra("tcp://127.0.0.1:2", 0.1)).member_extra == 0.0


def test_the_measured_scan_is_not_sent_to_a_cluster_whose_workers_share_the_cores():
    """The measured scan's batch on a local cluster of two workers, with figures like the benchmark's: members
    of 0.105 s, a connection timed at 0.2 s, trips of 0.015 s.  With a member's extra time on a worker taken
    from its CPU time there (0.012 s), the other six would save 0.315 s against 0.281 s: sent, and slower
    than serial.  The probe's two trips and the members' wall time there (1.25 times their time here, two
    workers sharing the cores with the run's other jobs) make it 0.354 s: kept here.  The 256^2 ensemble's
    members of 0.235 s still repay the same cluster many times over."""
    def scan(extra, probe):
        return DaskPayoff(0.105, 6, 2, 0.015, extra, connect=0.2, probe=probe)

    assert scan(0.012, 0.0).repaid and scan(0.012, 0.0).cost == pytest.approx(0.281)
    kept = scan((1.25 - 1) * 0.105, 2 * 0.015)
    assert kept.saving == pytest.approx(0.315) and kept.cost == pytest.approx(0.35375) and not kept.repaid
    assert "the probe's two trips (0.03 s)" in kept.describe(2) and kept.describe(2).endswith("in this process")
    large = DaskPayoff(0.235, 14, 2, 0.015, (1.25 - 1) * 0.235, connect=0.2, probe=2 * 0.015)
    assert large.saving == pytest.approx(1.645) and large.cost == pytest.approx(0.74625) and large.repaid


def test_a_batch_whose_gain_lies_within_the_scatter_of_its_recorded_costs_stays_here():
    """(5): eight members of 0.1 s, six of them left on two workers (``n = 3``), connected.  The cluster's
    member ratios were measured at 1.1, 1.2 and 2.0, its trips at 0.01 and 0.03 s.  At the medians the gain
    is 0.3 - 3 (0.02 + 0.02) = 0.18 s, less than the recorded costs' spread above them,
    3 (0.01 + 0.8 x 0.1) = 0.27 s: at the largest costs the cluster saves nothing, and the batch stays.  Members
    of 0.3 s on a cluster whose ratios scatter from 1.0 to 1.3 gain 0.9 - 3 (0.03 + 0.09) = 0.54 s even at
    the largest: they go."""
    walls, trips = (1.1, 1.2, 2.0), (0.01, 0.03)
    address = "tcp://127.0.0.1:3"
    for w in walls:
        dask_payoff.remember_cost(address, "member_wall", w)
    for o in trips:
        dask_payoff.remember_cost(address, "round_trip", o)

    def payoff(c, address):
        return DaskPayoff(c, 6, 2, dask_payoff.largest_cost(address, "round_trip"),
                          dask_payoff.member_extra(address, c))

    at_medians = DaskPayoff(0.1, 6, 2, 0.02, (1.2 - 1) * 0.1)
    assert at_medians.repaid and at_medians.saving - at_medians.cost == pytest.approx(0.18)
    scattered = payoff(0.1, address)
    assert scattered.cost == pytest.approx(3 * (0.03 + 0.1)) and not scattered.repaid
    assert at_medians.saving - at_medians.cost < 3 * ((0.03 - 0.02) + (2.0 - 1.2) * 0.1)          # (5) fails
    clear = "tcp://127.0.0.1:4"
    for w in (1.0, 1.3, 1.1):
        dask_payoff.remember_cost(clear, "member_wall", w)
    for o in trips:
        dask_payoff.remember_cost(clear, "round_trip", o)
    large = payoff(0.3, clear)
    assert large.saving - large.cost == pytest.approx(0.9 - 3 * (0.03 + 0.09)) and large.repaid


def test_a_dask_batch_too_small_to_repay_the_trips_runs_serially_and_says_why(dask):
    """Three members of 0.1 s: after two here, the last one alone saves nothing, on any number of workers:
    the run never connects (no dask.distributed client, no trip timed)."""
    pids = dask.map(burn, [0.1] * 3, ["a", "b", "c"], label="small")
    assert pids == [os.getpid()] * 3
    batch = dask.describe()["batches"][-1]
    assert (batch["label"], batch["executor"]) == ("small", "serial")
    assert batch["decision"].startswith("2 members solved here") and "the other 1 in this process" in batch["decision"]
    assert "the connection to the scheduler (0.5 s" in batch["decision"]        # the estimate: never timed
    assert dask._client is None and dask_payoff.measured_costs(dask.address, "round_trip") == []


def test_a_small_batch_that_cannot_repay_the_connection_stays_here_and_connects_nothing(dask, monkeypatch):
    """The measured scan's batch: eight members of 0.1 s (timed at that, :class:`NominalClock`: a member
    timed slower here, on a busy machine, would make the saving the test weighs larger) on a cluster of two
    workers whose connection was timed at 0.45 s.  The other six would save 0.3 s on two workers, less than
    the connection alone: the batch stays here, connecting nothing.  Eight members of 0.3 s in a run
    already connected (``K`` spent) go there: 0.9 s saved against three trips (the record's of a
    millisecond, and the one timed now on the test machine: all count, at their largest), the members' wall
    time there recorded as that here."""
    nominal(monkeypatch, 0.1)
    dask_payoff.remember_cost(dask.address, "connect", 0.45)
    dask_payoff.remember_cost(dask.address, "workers", 2.0)
    pids = dask.map(burn, [0.1] * 8, [f"m{k}" for k in range(8)], label="scan")
    assert pids == [os.getpid()] * 8 and dask._client is None
    batch = dask.describe()["batches"][-1]
    assert batch["executor"] == "serial" and "the cluster's 2 workers would save 0.3 s on the other 6" in batch["decision"]
    assert "against 0.45 s of the connection to the scheduler (0.45 s" in batch["decision"]
    dask.client  # noqa: B018 - connected by an earlier batch: its cost is spent
    for _ in range(4):
        dask_payoff.remember_cost(dask.address, "round_trip", 0.001)
    dask_payoff.remember_cost(dask.address, "member_wall", 1.0)
    nominal(monkeypatch, 0.3)        # the trip timed now counts too, at the largest: 0.9 s saved against 3 o
    pids = dask.map(burn, [0.3] * 8, [f"m{k}" for k in range(8)], label="connected")
    assert dask.describe()["batches"][-1]["executor"] == "dask" and os.getpid() not in pids[-4:]


def test_a_large_dask_batch_goes_to_the_cluster_after_its_first_two_members(dask, monkeypatch):
    """Eight members of 0.3 s, on a cluster whose members were measured as fast as here: after two here, the
    connection is made (the other six would save 1.5 s on six workers, against the connection's estimate of
    0.5 s); at most one more member is solved here while the workers' imports are confirmed; then 0.9 s saved
    on the other six (or 0.6 s on five), against trips of milliseconds.  A member's wall time on a worker is
    recorded over its time here (0.3 s, as timed: :class:`NominalClock`): at least 1, the member's thread
    burning 0.3 s there."""
    nominal(monkeypatch, 0.3)
    dask_payoff.remember_cost(dask.address, "member_wall", 1.0)
    seen = []
    pids = dask.map(burn, [0.3] * 8, [f"m{k}" for k in range(8)], label="large",
                    progress=lambda *a: seen.append(a[1:]))
    here = pids.count(os.getpid())
    assert pids[:2] == [os.getpid()] * 2 and here <= 3 and len(set(pids[here:]) - {os.getpid()}) == 2
    assert seen == [(k, 8) for k in range(9)]                   # one count per member, wherever it ran
    batch = dask.describe()["batches"][-1]
    assert batch["executor"] == "dask" and f"the other {8 - here} on the cluster's 2 workers" in batch["decision"]
    (trip,), (_, wall), (connect,), (workers,) = (dask_payoff.measured_costs(dask.address, k)
                                                   for k in dask_payoff.COSTS)
    assert 0.0 <= trip < 0.3 and wall >= 1.0 and 0.0 < connect < 5.0 and workers == 2.0


def test_a_batch_whose_recorded_costs_scatter_across_the_break_even_stays_here(dask, monkeypatch):
    """Eight members of 0.1 s in a connected run, the cluster's member ratios recorded at 1.1, 1.2 and 2.0:
    at their median the other six would gain 0.3 - 3 (o + 0.02) s there, at the largest nothing (3 (o + 0.1) s
    of trips and extra time against 0.3 s saved): the batch stays here."""
    nominal(monkeypatch, 0.1)
    dask.client  # noqa: B018 - connected by an earlier batch
    for w in (1.1, 1.2, 2.0):
        dask_payoff.remember_cost(dask.address, "member_wall", w)
    pids = dask.map(burn, [0.1] * 8, [f"m{k}" for k in range(8)], label="scattered")
    assert pids == [os.getpid()] * 8
    batch = dask.describe()["batches"][-1]
    assert batch["executor"] == "serial" and "extra time on a worker (0.1 s)" in batch["decision"]
    assert dask_payoff.measured_costs(dask.address, "member_wall") == [1.1, 1.2, 2.0]     # nothing sent


def test_a_cluster_that_solved_no_member_gets_one_per_worker_before_the_rest(dask, monkeypatch):
    """Eight members of 0.3 s (waiting, so that their wall time there is theirs whatever the load) on a
    cluster with no member's time recorded: after two here (or three), one member per worker measures ``w``
    (about 1), and then the rest goes there too; only the rest's ``w`` is recorded (each of the part's members
    was its worker's first)."""
    nominal(monkeypatch, 0.3)
    pids = dask.map(nap, [0.3] * 8, [f"m{k}" for k in range(8)], label="first")
    here = pids.count(os.getpid())
    assert here <= 3 and os.getpid() not in pids[here:]
    batch = dask.describe()["batches"][-1]
    assert batch["executor"] == "dask" and "the first 2 there measured a member's time" in batch["decision"]
    assert f"the other {8 - here - 2} on the cluster's 2 workers" in batch["decision"]
    (wall,) = dask_payoff.measured_costs(dask.address, "member_wall")
    assert wall >= 1.0


def test_a_cluster_found_slow_by_its_first_members_keeps_the_rest_here(dask, monkeypatch):
    """Members timed at 0.1 s here that take 0.4 s on a worker (``w`` = 4), on a connected cluster with no
    member's time recorded: the first two there measure it, and the rest (four members: 0.2 s saved against
    2 (o + 0.3) s) stays here.  What the part cost is bounded: two members, not the rest."""
    nominal(monkeypatch, 0.1)
    dask.client  # noqa: B018 - connected by an earlier batch
    pids = dask.map(nap, [0.4] * 8, [f"m{k}" for k in range(8)], label="slow")
    here = [k for k, pid in enumerate(pids) if pid == os.getpid()]
    assert len(here) == 6 and len(set(pids) - {os.getpid()}) == 2 and here[-3:] == [5, 6, 7]
    batch = dask.describe()["batches"][-1]
    assert batch["executor"] == "serial" and batch["decision"].endswith(" in this process")
    assert "the first 2 there measured a member's time" in batch["decision"]
    assert not dask_payoff.wall_known(dask.address)     # the part's ``w`` decides its own batch only


def test_a_cluster_whose_members_were_measured_slower_keeps_the_batch_here(dask, monkeypatch):
    """The same eight members, on a cluster whose record says a member takes four times its time here (a
    worker sharing busy cores): 0.9 s more there, so the rest stays here, and the decision names that extra
    time."""
    nominal(monkeypatch, 0.3)
    dask_payoff.remember_cost(dask.address, "member_wall", 4.0)
    pids = dask.map(burn, [0.3] * 8, [f"m{k}" for k in range(8)], label="large")
    assert pids == [os.getpid()] * 8
    batch = dask.describe()["batches"][-1]
    assert batch["executor"] == "serial" and "extra time on a worker (0.9 s)" in batch["decision"]
    assert batch["decision"].endswith(" in this process")    # after two members here (or three: connected)


def nap(seconds: float) -> int:
    """A member that waits ``seconds`` without computing (a worker whose cores are busy with other jobs);
    the id of the process that ran it."""
    time.sleep(seconds)
    return os.getpid()


def test_a_worker_member_that_waits_for_its_cores_is_recorded_by_its_wall_time(dask, monkeypatch):
    """Members that take 0.3 s of wall time and almost no CPU time, as a worker's on cores other jobs keep
    busy: the record holds their wall time there over their time here (0.3 s, as timed), at least 1 (their
    CPU time there would make it near 0: a cluster whose members look free)."""
    nominal(monkeypatch, 0.3)
    pids = dask.map(nap, [0.3] * 8, [f"m{k}" for k in range(8)], label="waiting")
    assert dask.describe()["batches"][-1]["executor"] == "dask" and os.getpid() not in pids[-4:]
    (wall,) = dask_payoff.measured_costs(dask.address, "member_wall")       # the rest's, not the part's
    assert wall >= 1.0


def test_waiting_for_the_workers_imports_needs_no_default_client(cluster, tmp_path):
    """The probe of a run's client (never Dask's default) waits for the workers' imports: a module whose
    import takes 0.5 s is imported by every worker when the wait returns."""
    tag = f"warm_{os.getpid()}_{time.monotonic_ns()}"
    (tmp_path / f"{tag}.py").write_text(SLOW_MODULE.format(folder=str(tmp_path), seconds=0.5))
    ex = DaskCluster(cluster)
    try:
        ex.client.run(search_path, str(tmp_path), True)
        probe = dask_payoff.Probe(ex.client, "warm-wait")
        probe.warm((tag,))
        assert probe.wait_warm(60.0) and probe.warm_done()
        assert all(tag in m for m in ex.client.run(lambda: [m for m in sys.modules if m.startswith("warm_")]).values())
        probe.cancel()
    finally:
        ex.client.run(search_path, str(tmp_path), False)
        ex.close()


def test_a_cluster_used_directly_sends_every_member_there(cluster):
    """Without the run's judgement (:func:`ngcontact.parallel.executor.use` of a cluster made by hand) every
    member goes to the workers."""
    ex = DaskCluster(cluster)
    try:
        pids = ex.map(burn, [0.01] * 3, ["a", "b", "c"], label="direct")
        assert os.getpid() not in pids and ex.describe()["batches"][-1]["executor"] == "dask"
    finally:
        ex.close()


SLOW_MODULE = """import os, time
open(os.path.join({folder!r}, __name__ + ".began." + str(os.getpid())), "w").close()   # a worker began it
time.sleep({seconds!r})
"""


def started(folder, module: str) -> int:
    """How many workers have begun importing ``module`` (the markers its import leaves in ``folder``)."""
    return sum(name.startswith(module + ".began.") for name in os.listdir(folder))


def wait_for_probes(folder: str, module: str, workers: int) -> int:
    """A member that waits until ``workers`` probes are running (have begun importing ``module``)."""
    deadline = time.monotonic() + 60
    while started(folder, module) < workers:
        assert time.monotonic() < deadline, "the probes never started"
        time.sleep(0.02)
    return os.getpid()


def test_a_batch_kept_here_stops_its_running_probe_before_the_next_module(cluster, tmp_path):
    """Two members solved here end the batch while each worker's probe imports the first of three slow
    modules: the probe is cancelled, and once it has left the workers neither worker imported the second or the
    third."""
    tag = f"slow_{os.getpid()}_{time.monotonic_ns()}"
    modules = [f"{tag}_{k}" for k in range(3)]
    for module, seconds in zip(modules, (4.0, 1.0, 1.0)):     # the first long enough for both workers to begin it
        (tmp_path / f"{module}.py").write_text(SLOW_MODULE.format(folder=str(tmp_path), seconds=seconds))
    ex = DaskCluster(cluster)
    try:
        ex.client.run(search_path, str(tmp_path), True)
        ex.start_on_demand(modules)
        workers = len(ex.client.scheduler_info()["workers"])
        pids = ex.map(functools.partial(wait_for_probes, str(tmp_path), modules[0]), [workers, 0], ["a", "b"],
                      label="kept")
        assert pids == [os.getpid()] * 2 and ex.describe()["batches"][-1]["executor"] == "serial"
        assert "while the cluster's workers imported their modules" in ex.describe()["batches"][-1]["decision"]
        deadline = time.monotonic() + 60        # the cancelled probes end their running import, then leave
        while any(ex.client.run(kept_probes).values()):
            assert time.monotonic() < deadline, ex.client.run(kept_probes)
            time.sleep(0.1)
        imported = ex.client.run(lambda: sorted(m for m in sys.modules if m.startswith(tag)))
        assert list(imported.values()) == [modules[:1]] * workers
        assert started(tmp_path, modules[1]) == 0
    finally:
        ex.client.run(search_path, str(tmp_path), False)
        ex.close()


def search_path(folder: str, add: bool) -> None:
    """On a worker: ``folder`` added to (or removed from) the module search path."""
    import importlib
    if add:
        sys.path.insert(0, folder)
        importlib.invalidate_caches()
    elif folder in sys.path:
        sys.path.remove(folder)


def kept_probes(dask_worker) -> list:
    """The probe tasks of the batch ``kept`` a worker still holds (running, cancelled while running, or their
    results), with their states."""
    return [(key, ts.state) for key, ts in dask_worker.state.tasks.items() if "ngcontact-probe-kept-" in str(key)]


def test_a_probe_outside_a_dask_task_is_never_cancelled():
    assert dask_payoff.cancelled() is False


def test_a_package_this_process_loaded_is_imported_on_the_workers_before_a_member_needs_it(cluster):
    """A member imports lazily what the scene's load imported in the run's process (a measured scan's reader):
    the probe's warm-up imports every package loaded here on each worker first."""
    distributed = pytest.importorskip("distributed")

    def has(name):
        return name in sys.modules

    with distributed.Client(cluster, set_as_default=False) as client:
        assert not any(client.run(has, "mailbox").values())      # the workers have not imported it
        import mailbox  # noqa: F401  (a package of this process only, as a scan's reader in a run)
        assert "mailbox" in dask_payoff.loaded_packages()
        probe = dask_payoff.Probe(client, "loaded")
        probe.warm(())
        assert probe.wait_warm(60.0)
        assert all(client.run(has, "mailbox").values())
        probe.cancel()


def test_a_loaded_package_a_worker_cannot_import_does_not_fail_the_probe():
    seconds, result = dask_payoff.probe_task((), None, 3, ("no_package_of_this_name", "colorsys"))
    assert result == bytes(3) and seconds >= 0.0 and "colorsys" in sys.modules
    with pytest.raises(ImportError):                      # the members' own modules still must import
        dask_payoff.probe_task(("no_package_of_this_name",), None, 0)
