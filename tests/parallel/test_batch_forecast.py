"""Workers start with the run only where the last run of the same batch forecasts that condition (1) of
:mod:`ngcontact.parallel.worker_payoff` sends it to them (:mod:`ngcontact.parallel.batch_forecast`)."""
import os

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
    for text in ("{", '{"members": 0, "member_seconds": 1, "lead_seconds": 0}', '{"members": 3}'):
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


def test_workers_start_with_the_run_only_where_the_last_run_of_the_batch_says_they_take_it(monkeypatch, cache):
    scene = loader.load(os.path.join(ROOT, "geometries", "cells", "self_affine_ensemble.toml"))
    members = runner.batch_members(scene)
    names = [f"m{k}" for k in range(members)]
    with runner.batches(scene, workers=1) as ex:            # the serial run records the batch
        ex.map(burn, [0.01] * members, names, label="ensemble")
    [record] = os.listdir(cache / batch_forecast.FOLDER)
    forecast = batch_forecast.recorded(record[:-len(".json")])
    assert forecast.members == members and 0.01 <= forecast.member_seconds < 0.05
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
