"""The executor of batches: results in order, a failing member retried once, a second failure named.

Faults are injected through the test-only variable ``NGCONTACT_TEST_FAULT``
(``MEMBER:ATTEMPTS:MODE``), read where the batch is submitted; the members
are ``operator.neg`` so that a spawned worker needs nothing of the tests.
"""
import operator
import os

import time

import pytest

from ngcontact.errors import BatchError
from ngcontact.parallel import batch_member, executor, judged_batches, local_pool, worker_lifetime

ITEMS = [1.5, -2.0, 3.25, 7.0, -0.5]
NAMES = [f"m{k}" for k in range(len(ITEMS))]
EXPECTED = [-x for x in ITEMS]


@pytest.fixture
def pool():
    p = executor.LocalPool(2)
    yield p
    p.close()


def test_serial_runs_every_member_in_order_and_reports_progress():
    seen = []
    out = executor.Serial().map(operator.neg, ITEMS, NAMES, label="toy", progress=lambda *a: seen.append(a))
    assert out == EXPECTED
    assert seen == [("toy", k, len(ITEMS)) for k in range(len(ITEMS) + 1)]


def _inner_batch(x):
    """A member that runs a serial batch of its own (a two-scale level of an accuracy study tabulating its cell)."""
    return sum(executor.Serial().map(operator.neg, [x, x], ["a", "b"]))


def test_a_member_may_run_a_serial_batch_of_its_own():
    assert executor.Serial().map(_inner_batch, ITEMS, NAMES) == [2 * e for e in EXPECTED]


def test_names_must_be_distinct():
    with pytest.raises(ValueError, match="one distinct name per member"):
        executor.Serial().map(operator.neg, ITEMS, ["a"] * len(ITEMS))


@pytest.mark.parametrize("make", [executor.Serial, lambda: None], ids=["serial", "pool"])
def test_a_member_failing_once_is_retried_and_the_batch_completes(monkeypatch, pool, make):
    monkeypatch.setenv(batch_member.FAULT_ENV, "m2:1:raise")
    ex = make() or pool
    assert ex.map(operator.neg, ITEMS, NAMES) == EXPECTED


def test_a_killed_worker_is_replaced_and_its_member_retried(monkeypatch, pool):
    monkeypatch.setenv(batch_member.FAULT_ENV, "m3:1:kill")
    assert pool.map(operator.neg, ITEMS, NAMES, label="toy") == EXPECTED
    monkeypatch.delenv(batch_member.FAULT_ENV)
    assert pool.map(operator.neg, ITEMS, NAMES) == EXPECTED      # the pool works on afterwards


@pytest.mark.parametrize("mode", ["raise", "kill"])
def test_a_member_failing_twice_ends_the_batch_naming_it(monkeypatch, pool, mode):
    monkeypatch.setenv(batch_member.FAULT_ENV, f"m1:2:{mode}")
    with pytest.raises(BatchError) as info:
        pool.map(operator.neg, ITEMS, NAMES, label="toy")
    assert info.value.member == "m1"
    reason = "its worker process died" if mode == "kill" else "injected fault (attempt 2)"
    assert str(info.value) == f"toy: m1 failed twice: RuntimeError: {reason}"


def test_a_serial_member_failing_twice_names_the_original_error(monkeypatch):
    def bad(x):
        raise ZeroDivisionError("no inverse of 0\nsecond line")
    with pytest.raises(BatchError, match=r"^toy: m0 failed twice: ZeroDivisionError: no inverse of 0$"):
        executor.Serial().map(bad, [0.0], ["m0"], label="toy")


def test_make_chooses_serial_pool_or_cluster():
    assert isinstance(executor.make(1), executor.Serial)
    assert isinstance(executor.make(3), executor.LocalPool) and executor.make(3).workers == 3
    dask = executor.make(2, "tcp://127.0.0.1:1")         # connects on first use only
    assert isinstance(dask, executor.DaskCluster) and dask.address == "tcp://127.0.0.1:1"
    assert executor.current().name == "serial"
    with executor.use(executor.LocalPool(2)) as ex:
        assert executor.current() is ex
    assert executor.current().name == "serial"


@pytest.fixture
def workers_always_repay(monkeypatch):
    """No start ahead, no first member's extra: every batch's rest goes to workers (condition (1) of
    :mod:`ngcontact.parallel.worker_payoff` holds for any member that takes time)."""
    monkeypatch.setattr(judged_batches, "START_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", 0.0)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.0)


@pytest.mark.parametrize("method", local_pool.METHODS)
def test_a_started_pool_has_its_workers_running_before_the_first_batch_and_records_its_batches(
        workers_always_repay, method):
    """Spawned workers run once started; a fork server runs (its workers fork as a batch sends them
    members).  A second start keeps them, and the batch runs on them."""
    ex = executor.LocalPool(2, method=method)
    try:
        ex.start()
        server = ex._server
        ex.start()                                           # a second start keeps the same workers
        assert ex._server is server and ex.pools_started == 1
        if method == "spawn":
            processes = list(ex._pool._processes.values())
            assert len(processes) == 2 and all(p.is_alive() for p in processes)
        else:
            assert ex._pool is None and worker_lifetime.process_start(server.pid) is not None
        assert ex.wait_ready(120)
        assert ex.map(operator.neg, ITEMS, NAMES, label="toy") == EXPECTED
        if method == "spawn":
            assert list(ex._pool._processes.values()) == processes   # the batch ran on the started workers
        else:                 # forked by the server as the batch's rest was sent: no other pool started
            assert 1 <= len(ex._pool._processes) <= 2 and ex._server is server and ex.pools_started == 1
        assert ex.describe()["executor"] == "local" and ex.describe()["workers"] == 2
        assert ex.describe()["batches"][-1]["executor"] == "local"
        assert [(b["label"], b["members"]) for b in ex.describe()["batches"]] == [("toy", len(ITEMS))]
    finally:
        ex.close()
    assert method == "spawn" or worker_lifetime.process_start(server.pid) is None   # the server ends with it


def test_runs_with_batches_start_their_workers_at_once_and_others_do_not():
    from ngcontact.runner import has_batches
    from ngcontact.scene import loader
    import os
    geometries = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(__file__))), "geometries")
    with_batches = {"cells/self_affine_ensemble.toml", "verify_elasticity.toml"}
    for name in ("femur_stem.toml", "femur_stem_two_scale.toml", "cells/sinusoid.toml",
                 "cells/self_affine_ensemble.toml", "cells/westergaard_graded.toml",
                 "direct/block_rect_valleys.toml", "verify_elasticity.toml", "cells/ex27_rectangular.toml"):
        assert has_batches(loader.load(os.path.join(geometries, name))) == (name in with_batches), name


def test_every_shipped_scene_says_whether_it_has_batches():
    """Every scene ``run`` accepts goes through :func:`has_batches` before its solve; a scene shape it did
    not expect (a geometric-only cell has no ``[load]``) must not end the run there."""
    import glob
    import os
    from ngcontact.runner import has_batches
    from ngcontact.scene import loader
    root = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(__file__))), "geometries")
    paths = sorted(glob.glob(os.path.join(root, "**", "*.toml"), recursive=True))
    assert len(paths) > 30
    for path in paths:
        scene = loader.load(path)
        assert isinstance(has_batches(scene), bool), path


@pytest.mark.parametrize("method", local_pool.METHODS)
def test_a_run_that_fails_while_its_workers_start_stops_them_at_once(method):
    ex = executor.LocalPool(2, method=method)
    with pytest.raises(KeyboardInterrupt):
        with executor.use(ex):
            ex.start()
            processes = list(ex._pool._processes.values()) if method == "spawn" else []
            server = ex._server.pid if method == "forkserver" else None
            raise KeyboardInterrupt
    assert ex._pool is None and ex._server is None
    assert server is None or worker_lifetime.process_start(server) is None
    # the pool's manager thread reaps the workers too; until it has recorded an exit code, is_alive() of
    # a worker that is gone can still say True, so allow that bookkeeping a moment
    deadline = time.monotonic() + 2.0
    while any(p.is_alive() for p in processes) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(p.is_alive() for p in processes)


@pytest.mark.parametrize("start_seconds, on_workers", [(1e9, False), (0.0, True)])
def test_a_pool_started_on_demand_uses_its_workers_only_where_they_repay_their_start(
        monkeypatch, start_seconds, on_workers):
    """The first member runs here and times the batch; the rest go to the workers only if
    ``rest * seconds * (1 - 1/workers)`` exceeds the workers' start (``START_SECONDS``) and a worker's first
    member (``FIRST_MEMBER_SECONDS``)."""
    monkeypatch.setattr(judged_batches, "START_SECONDS", start_seconds)
    monkeypatch.setattr(judged_batches, "FORK_SECONDS", start_seconds)
    monkeypatch.setattr(judged_batches, "FIRST_MEMBER_SECONDS", 0.0)
    ex = executor.LocalPool(2)
    ex.start_on_demand()
    seen = []
    try:
        out = ex.map(operator.neg, ITEMS, [f"m{k}" for k in range(len(ITEMS))], label="toy",
                     progress=lambda label, k, n: seen.append((k, n)))
        assert out == [-x for x in ITEMS]
        assert (ex.pools_started > 0) == on_workers, ex.describe()   # workers (or their fork server) started
        assert seen[0] == (0, len(ITEMS)) and seen[-1] == (len(ITEMS), len(ITEMS))
        assert [k for k, _ in seen] == sorted(k for k, _ in seen) and {n for _, n in seen} == {len(ITEMS)}
    finally:
        ex.close()


def test_an_early_pool_solves_members_here_until_a_worker_has_started(monkeypatch, workers_always_repay):
    """A pool started early (``start``) takes members only once a worker is ready: before that this process
    solves them (a worker process runs with ``NGCONTACT_THREADS=1``, this one without it).  Every batch's
    first two members are solved here: they time the batch (:mod:`ngcontact.parallel.worker_payoff`)."""
    monkeypatch.delenv("NGCONTACT_THREADS", raising=False)
    names = [f"m{k}" for k in range(6)]
    ex = executor.LocalPool(2)
    seen = []
    try:
        ex.start(("ngsolve",))            # a worker's start imports NGSolve: far longer than these members
        here = ex.map(os.getenv, ["NGCONTACT_THREADS"] * 6, names, label="toy",
                      progress=lambda label, k, n: seen.append((k, n)))
        assert here == [None] * 6
        assert seen == [(k, 6) for k in range(7)]
        assert ex.wait_ready(120)
        assert ex.map(os.getenv, ["NGCONTACT_THREADS"] * 6, names, label="toy") == [None] * 2 + ["1"] * 4
    finally:
        ex.close()


def test_members_whose_submission_finds_the_pool_broken_are_sent_again(monkeypatch):
    """A worker that dies while the batch is still being submitted breaks the pool under the submitting
    loop (``submit`` raises): those members are sent again to a fresh pool, not lost."""
    from concurrent.futures.process import BrokenProcessPool
    ex = executor.LocalPool(2)
    start = ex._start
    calls = {"pools": 0}

    def flaky_start():
        pool = start()
        calls["pools"] += 1
        if calls["pools"] == 1:          # the first pool refuses the third submission as a broken one would
            submit, sent = pool.submit, []

            def refusing(*args, **kwargs):
                sent.append(1)
                if len(sent) == 3:
                    raise BrokenProcessPool("a child process terminated abruptly")
                return submit(*args, **kwargs)
            monkeypatch.setattr(pool, "submit", refusing)
        return pool

    monkeypatch.setattr(ex, "_start", flaky_start)
    try:
        assert ex.map(operator.neg, ITEMS, NAMES, label="toy") == EXPECTED
        assert calls["pools"] == 2
    finally:
        ex.close()
