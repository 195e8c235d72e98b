"""Workers start with the run only where the last run of the same batch forecasts that condition (1) of
:mod:`ngcontact.parallel.worker_payoff` sends it to them (:mod:`ngcontact.parallel.batch_forecast`)."""
import os
import time

import pytest

from ngcontact import runner
from ngcontact.parallel import batch_forecast, executor, free_cores, judged_batches
from ngcontact.parallel.batch_forecast import Forecast
from ngcontact.scene import loader

from test_worker_payoff import burn

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@pytest.fixture
def cache(monkeypatch, tmp_path):
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path))
    return tmp_path


def test_a_record_is_read_back_and_a_broken_one_is_no_forecast(cache):
    assert batch_forecast.recorded("abc") is None
    batch_forecast.remember("abc", Forecast(16, 0.5, 1.25))
    assert batch_forecast.recorded("abc") == Forecast(16, 0.5, 1.25)
    batch_forecast.remember("abc", Forecast(16, 0.5, 1.25, 0.75, 0.125))
    assert batch_forecast.recorded("abc") == Forecast(16, 0.5, 1.25, 0.75, 0.125)
    for text in ("{", '{"members": 0, "member_seconds": 1, "lead_seconds": 0}', '{"members": 3}',
                 '{"members": 3, "member_seconds": 1, "lead_seconds": 0, "start_seconds": -1}',
                 '{"members": 3, "member_seconds": 1, "lead_seconds": 0, "first_seconds": NaN}'):
        (cache / batch_forecast.FOLDER / "abc.json").write_text(text)
        assert batch_forecast.recorded("abc") is None


@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_the_forecast_is_condition_1_on_the_cores_free_as_the_run_opens(monkeypatch, method):
    monkeypatch.setattr(judged_batches, "START_SECONDS", 2.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 1.0)
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    pool = executor.LocalPool(2, method=method)
    # 14 members after the two solved here, 0.5 s each, on an idle machine of two cores: 3.5 s saved
    # against 1 s of a first member and the 2 s start (and a fork: 0.05 s) less the lead; on the cores,
    # 7 CPU s against 2 x (2 + 1) s of spawned starts and first members, or one server's 2 s start shared
    # by the two workers: 2 x (1 + 0.05 + 1) = 4.1 s
    assert pool.repays(Forecast(16, 0.5, 1.5)) and pool.repays(Forecast(16, 0.5, 0.0))
    if method == "spawn":
        assert not pool.repays(Forecast(16, 0.4, 10.0))      # 5.6 CPU s do not repay 6 CPU s
    else:
        assert pool.repays(Forecast(16, 0.4, 10.0))          # 5.6 CPU s repay 4.1 CPU s
        assert not pool.repays(Forecast(16, 0.25, 10.0))     # 3.5 CPU s do not
    monkeypatch.setattr(free_cores, "load_average", lambda: 1.0)
    assert not pool.repays(Forecast(16, 0.5, 1.5))           # one core left: the workers would gain none
    assert not pool.repays(Forecast(8, 0.15, 10.0))          # the measured scan's kind: never repaid
    assert not executor.Serial().repays(Forecast(1000, 10.0, 10.0))


def idle_since_the_process_opened(monkeypatch, load: float) -> None:
    """A machine of two cores on which only this process has computed since the package was imported (0.5 s
    ago, :data:`~ngcontact.parallel.free_cores.OPENING`), with a one-minute load average of ``load`` left by
    the run that ended just before."""
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    monkeypatch.setattr(free_cores, "load_average", lambda: load)
    monkeypatch.setattr(free_cores, "core_seconds", lambda cores: time.process_time())
    monkeypatch.setattr(free_cores, "OPENING", (time.perf_counter() - 0.5, time.process_time(), time.process_time()))


def test_the_forecast_reads_the_cores_over_the_runs_opening_not_the_load_average(monkeypatch):
    """The serial run just before leaves a one-minute load average of 1.1 on an idle machine of two cores:
    read as other jobs, it would leave 0.9 cores free and never an early start.  The run's first look reads
    what the window opened with its process (its imports) left free: both cores."""
    monkeypatch.setattr(judged_batches, "START_SECONDS", 2.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 1.0)
    idle_since_the_process_opened(monkeypatch, load=1.1)
    pool = executor.LocalPool(2)
    assert pool.repays(Forecast(16, 0.5, 1.5))
    # a look at once after: still (2), its window opening at the process's (no sample since is old enough)
    assert "busy with other processes over the last" in pool.cores.reading().source
    monkeypatch.setattr(free_cores, "core_seconds", lambda cores: time.perf_counter() + time.process_time())
    monkeypatch.setattr(free_cores, "OPENING", (time.perf_counter() - 0.5, time.perf_counter(), time.process_time()))
    assert not executor.LocalPool(2).repays(Forecast(16, 0.5, 1.5))   # another job on a core all along
    monkeypatch.setattr(free_cores, "OPENING", (time.perf_counter() - 1e3, time.process_time(), time.process_time()))
    assert not executor.LocalPool(2).repays(Forecast(16, 0.5, 1.5))   # a window that old is no reading


@pytest.mark.parametrize("method", ["spawn", "forkserver"])
def test_before_a_worker_is_timed_the_forecast_takes_the_last_runs_own_start_and_first_member(monkeypatch,
                                                                                                method):
    """The 256^2 ensemble's kind: 14 members of 0.25 s after the two solved here.  Against the estimates
    (2 s start, 1 s first member) they would not repay; against what the last run's process measured before
    its batch (0.8 s of CPU, 0.5 s of them ahead of the batch) and its first member (0.03 s beyond the
    cheapest), they do, as the rule in the batch will find.  The shipped 64^2 ensemble's kind (30 members of
    0.04 s): 1.2 CPU s do not repay two spawned starts (2 x 0.83 s), and do repay a fork server's start
    shared by the two workers and their forks (2 x (0.4 + 0.05 + 0.03) = 0.96 s; 0.6 s saved against
    0.35 s of the start still ahead and 0.03 s)."""
    monkeypatch.setattr(judged_batches, "START_SECONDS", 2.0)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.05)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 1.0)
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    pool = executor.LocalPool(2, method=method)
    assert not pool.repays(Forecast(16, 0.25, 0.5))
    assert pool.repays(Forecast(16, 0.25, 0.5, start_seconds=0.8, first_seconds=0.03))
    assert not pool.repays(Forecast(16, 0.25, 0.5, start_seconds=5.0, first_seconds=3.0))   # held to the estimates
    shipped = Forecast(32, 0.04, 0.5, start_seconds=0.8, first_seconds=0.03)
    assert pool.repays(shipped) == (method == "forkserver")
    assert not pool.repays(Forecast(32, 0.03, 0.5, start_seconds=0.8, first_seconds=0.03))  # 0.9 CPU s: never


def test_workers_start_with_the_run_after_a_serial_run_of_the_batch_on_an_idle_machine(monkeypatch, cache):
    """The benchmark's sequence: a serial run records the batch, the next run with two workers starts them as
    it opens, although the serial run left a one-minute load average of 1.1; nothing measured a worker yet."""
    scene = loader.load(os.path.join(ROOT, "geometries", "cells", "self_affine_ensemble.toml"))
    members = runner.batch_members(scene)
    names = [f"m{k}" for k in range(members)]
    with runner.batches(scene, workers=1) as ex:
        ex.map(burn, [0.05] * members, names, label="ensemble")
    [record] = os.listdir(cache / batch_forecast.FOLDER)
    forecast = batch_forecast.recorded(record[:-len(".json")])
    assert forecast.start_seconds == pytest.approx(ex.timings[0]["lead_cpu"]) and forecast.start_seconds > 0
    assert 0.0 <= forecast.first_seconds < 0.05
    assert batch_forecast.measured_costs("start") == []
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.3)     # this test process's lead CPU is no start's
    idle_since_the_process_opened(monkeypatch, load=1.1)
    with runner.batches(scene, workers=2) as ex:
        assert ex.pools_started == 1 and ex.describe()["workers_started"] == "with the run"
        assert ex.wait_ready(120)
        assert os.getpid() not in ex.map(burn, [0.05] * members, names, label="ensemble")   # from the first
    # the batch's next record: ``c`` as the workers timed it, none solved here
    again = batch_forecast.recorded(record[:-len(".json")])
    assert again.members == members and 0.045 <= again.member_seconds < 0.5 and again.first_seconds is None


def test_workers_start_with_the_run_only_where_the_last_run_of_the_batch_says_they_take_it(monkeypatch, cache):
    scene = loader.load(os.path.join(ROOT, "geometries", "cells", "self_affine_ensemble.toml"))
    members = runner.batch_members(scene)
    names = [f"m{k}" for k in range(members)]
    with runner.batches(scene, workers=1) as ex:            # the serial run records the batch
        ex.map(burn, [0.01] * members, names, label="ensemble")
    [record] = os.listdir(cache / batch_forecast.FOLDER)
    forecast = batch_forecast.recorded(record[:-len(".json")])
    # each member burns 0.01 CPU s by process_time; the record's clock may read a hair less (0.00997 was seen)
    assert forecast.members == members and 0.009 <= forecast.member_seconds < 0.05
    with runner.batches(scene, workers=2) as ex:            # 30 x 0.01 s do not repay two workers
        assert ex.pools_started == 0
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.05)
    with runner.batches(scene, workers=2) as ex:            # they would now: started as the run opens
        assert ex.pools_started == 1 and ex._launched()
        assert ex.describe()["workers_started"] == "with the run"


def test_the_oldest_records_go_beyond_the_kept_number(monkeypatch, cache):
    monkeypatch.setattr(batch_forecast, "KEPT", 2)
    for k, name in enumerate("abc"):
        batch_forecast.remember(name, Forecast(4, 1.0, 0.0))
        os.utime(cache / batch_forecast.FOLDER / f"{name}.json", (k, k))
    batch_forecast.remember("d", Forecast(4, 1.0, 0.0))
    assert sorted(os.listdir(cache / batch_forecast.FOLDER)) == ["c.json", "d.json"]


def test_a_forecast_starts_workers_early_only_with_two_members_of_margin(monkeypatch):
    """The measured scan's kind, on a machine that has timed a fork server (0.7 s), a fork (0.05 s) and a
    first member (0.02 s): all 8 members of 0.112 s would just repay the two workers (0.9 CPU s against
    2 x (0.35 + 0.05 + 0.02) = 0.84 CPU s), the 6 after the two a batch without a forecast times here do
    not (0.67 CPU s): no worker starts with the run for it."""
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    for kind, seconds in (("server", 0.7), ("fork", 0.05), ("first_member", 0.02)):
        batch_forecast.remember_cost(kind, seconds)
    pool = executor.LocalPool(2, method="forkserver")
    assert pool.payoff(0.112, 8, 10.0).repaid and not pool.payoff(0.112, 6, 10.0).repaid
    assert not pool.repays(Forecast(8, 0.112, 10.0))
    assert pool.repays(Forecast(8, 0.2, 10.0))               # 1.2 CPU s after the two: started with the run


def spectrum(seed: int) -> tuple[int, float]:
    """A member whose number depends on its item alone (a seeded field's spectrum, 0.05 CPU s): the id of the
    process that ran it, and the number."""
    import numpy as np
    field = np.random.default_rng(seed).standard_normal((128, 128))
    burn(0.05)
    return os.getpid(), float(np.abs(np.fft.rfft2(field)).sum())


@pytest.fixture
def forecast_pool(monkeypatch):
    """A pool of two forked workers started with the run by a forecast of 8 members of 0.05 s (measured
    costs: no start ahead, a worker's first member 0.01 s), its fork server ready."""
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.01)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    pool = executor.LocalPool(2, method="forkserver")
    pool.start(("ngsolve",), Forecast(8, 0.05, 0.0, start_seconds=0.0, first_seconds=0.0))
    assert pool.wait_ready(120)
    yield pool
    pool.close()


def test_a_batch_its_forecast_sends_to_workers_goes_there_from_its_first_member(forecast_pool):
    """The run's first batch, forecast to repay the workers (8 x 0.05 s: 0.2 s saved against 0.01 s), goes
    to them whole: no member solved here to time it, the numbers those of the serial run; its record's
    ``c`` is the workers' (a member's CPU seconds after a worker's first)."""
    seeds, names = list(range(8)), [f"m{k}" for k in range(8)]
    out = forecast_pool.map(spectrum, seeds, names, label="forecast")
    serial = executor.Serial().map(spectrum, seeds, names, label="serial")
    assert os.getpid() not in [pid for pid, _ in out]
    assert [v for _, v in out] == [v for _, v in serial]
    batch = forecast_pool.describe()["batches"][-1]
    assert batch["executor"] == "local" and "none solved here" in batch["decision"]
    assert batch["decision"].endswith("all 8 on 2 workers")
    [timed] = forecast_pool.timings
    assert 0.045 <= timed["member_seconds"] < 0.5 and timed["first_seconds"] is None
    # the next batch of the run has no forecast: its first two members time it here
    again = forecast_pool.map(spectrum, seeds, names, label="second")
    assert [pid for pid, _ in again[:2]] == [os.getpid()] * 2
    assert [v for _, v in again] == [v for _, v in serial]


def test_a_forecast_of_another_batch_or_on_busy_cores_leaves_the_batch_to_its_own_members(monkeypatch,
                                                                                          forecast_pool):
    """A first batch of another size than the forecast's is timed here (its first two members); so is one
    whose cores other jobs keep busy now, and it stays here."""
    pids = forecast_pool.map(burn, [0.05] * 6, [f"m{k}" for k in range(6)], label="other size")
    assert pids[:2] == [os.getpid()] * 2
    forecast_pool.start((), Forecast(8, 0.05, 0.0, start_seconds=0.0, first_seconds=0.0))
    monkeypatch.setattr(free_cores, "load_average", lambda: 2.0 * len(free_cores.affinity()))
    pids = forecast_pool.map(burn, [0.05] * 8, [f"m{k}" for k in range(8)], label="busy")
    assert pids == [os.getpid()] * 8
    assert "busy with other processes" in forecast_pool.describe()["batches"][-1]["decision"]


def test_a_batch_forecast_to_repay_its_workers_solves_members_here_while_no_worker_is_ready(monkeypatch):
    """Workers whose start has more than a member's time ahead: the forecast batch solves members here
    meanwhile (none is lost, none solved twice), and sends the rest once a worker is ready."""
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.01)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.0)
    pool = executor.LocalPool(2, method="forkserver")
    try:
        pool.start(("ngsolve",), Forecast(40, 0.05, 0.0, start_seconds=0.0, first_seconds=0.0))
        # 0.2 s of the start ahead: more than a member, less than the 1 s the workers save on the batch
        monkeypatch.setattr(pool._server, "start_still", lambda server, fork: 0.2)
        pids = pool.map(burn, [0.05] * 40, [f"m{k}" for k in range(40)], label="starting")
        here = pids.count(os.getpid())
        assert len(pids) == 40 and here >= 1 and pids[:here] == [os.getpid()] * here
        batch = pool.describe()["batches"][-1]
        if here < 40:                   # a worker became ready during the batch: the rest went to the workers
            assert os.getpid() not in pids[here:] and batch["executor"] == "local"
            assert f"{here} solved here while the workers started" in batch["decision"]
    finally:
        pool.close()
