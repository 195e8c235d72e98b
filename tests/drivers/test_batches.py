"""Batches of independent solves on workers: the same numbers as one process, failures named, Ctrl-C clean.

Requirements: a dask.distributed cluster (a real ``LocalCluster``, two
worker processes) and the local process pool give the serial results to
1e-12 for an ensemble and for sweeps of independent loads; a member whose
worker dies is retried and the batch completes; a member that always fails
ends the run with exit 3, one line naming it, and nothing written; Ctrl-C
stops the workers and leaves the output directory as it was.  Faults are
injected through the test-only ``NGCONTACT_TEST_FAULT``.
"""
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from ngcontact import cli
from ngcontact.runner import solve
from ngcontact.parallel import fork_server, free_cores
from ngcontact.parallel.batch_member import FAULT_ENV

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

ENSEMBLE = """kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "self_affine"
arrangement = "summit"
spectrum = {{ hurst = 0.8, rms_slope = 0.1, rolloff = 0.25, cutoff = {cutoff}, grid = {grid}, seed = 3 }}
[contact]
k_n = 1.0e3
enforcement = "exact"
[load]
pressure = [0.002, 0.01]
[discretization]
method = "spectral"
[ensemble]
members = {members}
"""

SPECTRAL_SWEEP = ENSEMBLE.split("[ensemble]")[0].replace("pressure = [0.002, 0.01]",
                                                          "pressure = [0.001, 0.003, 0.01]\nindependent = true")

FE_SWEEP = """kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "sinusoid"
amplitude = 0.05
period = 1.0
h_rough = 0.6
h_counter = 0.6
[contact]
k_n = 1.0e3
[load]
pressure = [0.01]
shear = [0.0, 0.001, 0.002]
independent = true
[discretization]
order = 2
maxh = 0.3
interface_maxh = 0.08
estimate = "off"
[solver]
rtol = 1e-10
"""


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def ensemble(tmp_path, members=4, grid=32):
    return write(tmp_path, f"ensemble_{members}_{grid}.toml",
                 ENSEMBLE.format(members=members, grid=grid, cutoff=4.0 / grid))


#: The FE cell's effective stiffness is a difference of compliances (the cell's minus the bonded
#: laminate's): its cancellation turns rounding of the factorization into relative differences of about
#: 1e-11 between processes of different history, so it is compared at this tolerance.
CANCELLING = ("effective_stiffness", 1e-9)


def differences(a, b, path="results", out=None):
    """``(path, relative difference)`` of every number of ``a`` that differs from ``b``'s by more than 1e-12."""
    out = [] if out is None else out
    if isinstance(a, dict):
        assert sorted(a) == sorted(b), path
        for k in (k for k in a if not k.endswith("seconds")):     # timings depend on where they were taken
            differences(a[k], b[k], f"{path}.{k}", out)
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            differences(x, y, f"{path}[{i}]", out)
    elif isinstance(a, float):
        rel = abs(a - b) / max(1.0, abs(a), abs(b))
        if rel > 1e-12:
            out.append((path, rel))
    else:
        assert a == b, path
    return out


def assert_same(a, b):
    """Every number equal to 1e-12 (relative to the larger magnitude, at least 1), the cancelling one to 1e-9."""
    key, tol = CANCELLING
    bad = [(p, r) for p, r in differences(a, b) if not (key in p and r <= tol)]
    assert not bad, bad


def numbers(report):
    """The results that do not depend on where they were computed (iteration residual lists included)."""
    return report["results"]


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None) as c:
        yield c.scheduler_address


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("batches")
    paths = {"ensemble": ensemble(tmp), "spectral": write(tmp, "spectral.toml", SPECTRAL_SWEEP.format(
        grid=32, cutoff=0.125)), "fe": write(tmp, "fe.toml", FE_SWEEP)}
    return paths, Serial(paths)


class Serial(dict):
    """The serial reports, solved on first use in this process with one thread, as a worker solves.

    (With NGSolve's task manager on several threads, assembled sums are added in another order: the
    effective stiffness, a Schur complement, then differs by about 1e-11.)
    """

    def __init__(self, paths):
        super().__init__()
        self.paths = paths

    def __missing__(self, name):
        before = os.environ.get("NGCONTACT_THREADS")
        os.environ["NGCONTACT_THREADS"] = "1"
        try:
            self[name] = solve(self.paths[name], workers=1)[0]
        finally:
            if before is None:
                del os.environ["NGCONTACT_THREADS"]
            else:
                os.environ["NGCONTACT_THREADS"] = before
        return self[name]


@pytest.fixture
def cluster_always_repays(monkeypatch):
    """Condition (4) of the Dask payoff rule held whatever the members cost, after one member solved here
    and the workers' imports awaited: these batches are too small to repay a cluster
    (:func:`test_a_dask_batch_too_small_to_repay_runs_serially`), and the tests below are of the numbers of
    the members the cluster solves."""
    from ngcontact.parallel import dask_payoff
    monkeypatch.setattr(dask_payoff, "MEASURED", 1)
    monkeypatch.setattr(dask_payoff.Probe, "warm_done",
                        lambda self: all(f.result(timeout=120) is not None for f in self._warming))
    monkeypatch.setattr(dask_payoff.DaskPayoff, "repaid", property(lambda self: True))


@pytest.mark.parametrize("name", ["ensemble", "spectral", pytest.param("fe", marks=pytest.mark.slow)])
def test_a_dask_cluster_gives_the_serial_numbers(cluster, scenes, name, cluster_always_repays):
    paths, serial = scenes
    report, _ = solve(paths[name], scheduler=cluster)
    assert_same(numbers(report), numbers(serial[name]))
    compute = report["compute"]
    assert (compute["executor"], compute["scheduler"], compute["workers"]) == ("dask", cluster, 2)
    assert compute["batches"][0]["executor"] == "dask"          # every member but the first solved there
    # the spectral loads are refined to the default tolerance each on its own, the last by the driver's own cell
    # (its grid is the report's: ngcontact.drivers.cell_members), so the batch holds the others
    members = {"ensemble": 4, "spectral": 2, "fe": 3}[name]
    assert [(b["label"], b["members"]) for b in compute["batches"]] == [
        ("ensemble" if name == "ensemble" else "loads", members)]
    assert serial[name]["compute"]["executor"] == "serial"


def test_a_dask_batch_too_small_to_repay_runs_serially(cluster, scenes):
    """The spectral sweep's two loads on the cluster: both solved in the run's process (a second member alone
    saves nothing on two workers), the report saying so, with the serial numbers."""
    paths, serial = scenes
    report, _ = solve(paths["spectral"], scheduler=cluster)
    assert_same(numbers(report), numbers(serial["spectral"]))
    batch = report["compute"]["batches"][0]
    assert (report["compute"]["executor"], batch["members"], batch["executor"]) == ("dask", 2, "serial")
    assert batch["decision"].startswith("all 2 members solved here")


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ensemble", "fe"])
def test_two_local_workers_give_the_serial_numbers(scenes, name):
    paths, serial = scenes
    seen = []
    report, _ = solve(paths[name], workers=2, batch_progress=lambda *a: seen.append(a))
    assert_same(numbers(report), numbers(serial[name]))
    assert (report["compute"]["executor"], report["compute"]["workers"]) == ("local", 2)
    total = 4 if name == "ensemble" else 3
    assert [s[1:] for s in seen] == [(k, total) for k in range(total + 1)]


@pytest.fixture
def local_workers_always_repay(monkeypatch, tmp_path):
    """Condition (1) of the local payoff rule held whatever the members cost (no start, fork or first
    member to repay, an idle machine, no measured cost) and the fork server's imports awaited before the
    rule looks: these batches are too small to repay workers, and the test below is of the numbers of the
    members the forked workers solve."""
    from ngcontact.parallel import judged_batches, local_pool
    for name in ("START_SECONDS", "FORK_SECONDS", "FIRST_MEMBER_SECONDS"):
        monkeypatch.setattr(judged_batches, name, 0.0)
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(free_cores, "core_seconds", lambda cores: None)
    monkeypatch.setattr(free_cores, "load_average", lambda: 0.0)
    ready = local_pool.LocalPool._ready
    monkeypatch.setattr(local_pool.LocalPool, "_ready",
                        lambda self: (self._server.wait(120) if self._server is not None else True) and ready(self))


def test_members_forked_by_the_fork_server_give_the_serial_numbers(scenes, local_workers_always_repay):
    """The ensemble's members after the first two, solved by workers forked from the fork server (the default
    local pool here): the serial numbers to 1e-12."""
    from ngcontact.parallel import local_pool
    assert fork_server.available() and local_pool.LocalPool(2).method == "forkserver"
    paths, serial = scenes
    report, _ = solve(paths["ensemble"], workers=2)
    assert_same(numbers(report), numbers(serial["ensemble"]))
    batch = report["compute"]["batches"][0]
    assert (report["compute"]["executor"], batch["members"], batch["executor"]) == ("local", 4, "local")
    assert "the other 2 on 2 workers" in batch["decision"]


@pytest.mark.slow
def test_independent_loads_differ_from_the_continuation_only_by_the_solver_tolerance(scenes, tmp_path):
    """Negative control of the mode: the chained sweep solves the same problems from other starts."""
    paths, serial = scenes
    chained = write(tmp_path, "chained.toml", FE_SWEEP.replace("independent = true\n", ""))
    report, _ = solve(chained, workers=1)
    for a, b in zip(report["results"]["loads"], serial["fe"]["results"]["loads"]):
        assert a["mean_closure"] == pytest.approx(b["mean_closure"], rel=1e-7)
    assert any(a["newton_iterations"] != b["newton_iterations"]
               for a, b in zip(report["results"]["loads"], serial["fe"]["results"]["loads"]))


@pytest.mark.slow
def test_a_killed_worker_is_replaced_and_the_run_completes(scenes, tmp_path, monkeypatch, capsys):
    paths, serial = scenes
    monkeypatch.setenv(FAULT_ENV, "member 1 (seed 4):1:kill")
    out = tmp_path / "out"
    assert cli.main(["run", paths["ensemble"], "--out", str(out), "--quiet", "--workers", "2"]) == 0
    assert_same(json.loads((out / "report.json").read_text())["results"], serial["ensemble"]["results"])


@pytest.mark.parametrize("workers", ["1", pytest.param("2", marks=pytest.mark.slow)])
def test_a_member_that_always_fails_ends_the_run_with_exit_3_and_writes_nothing(scenes, tmp_path, monkeypatch,
                                                                               capsys, workers):
    paths, _ = scenes
    monkeypatch.setenv(FAULT_ENV, "member 2 (seed 5):2:raise")
    out = tmp_path / "out"
    assert cli.main(["run", paths["ensemble"], "--out", str(out), "--quiet", "--workers", workers]) == 3
    err = capsys.readouterr().err
    assert err == (f"ngcontact: error: {paths['ensemble']}: ensemble: member 2 (seed 5) failed twice: "
                   "RuntimeError: injected fault (attempt 2)\n")
    assert not out.exists()


#: What the command line of a local worker holds: a spawned one's, or a fork server's (and its workers').
WORKER_MARKS = ("spawn_main", "from multiprocessing.forkserver import main")

#: The processes of two local workers: the fork server and the two it forks, or two spawned workers.
WORKER_PROCESSES = 3 if fork_server.available() else 2


def test_ctrl_c_stops_the_workers_and_leaves_the_output_directory_as_it_was(tmp_path):
    psutil = pytest.importorskip("psutil")
    scene = ensemble(tmp_path, members=400, grid=64)
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    # an idle machine (a batch stays in the run's process while other jobs keep the cores busy)
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""),
               **{free_cores.LOAD_ENV: "0"})
    # SIGINT as a terminal's run gets it, also where this test runs in a background job (which ignores it)
    proc = subprocess.Popen([sys.executable, "-m", "ngcontact.cli", "run", scene, "--out", str(out),
                             "--workers", "2"], stderr=subprocess.PIPE, text=True, env=env, cwd=str(tmp_path),
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    def command(child):
        try:
            return " ".join(child.cmdline())
        except psutil.Error:          # a child that exits (or is a zombie) while it is listed is not a worker
            return ""

    workers = []
    assert proc.stderr is not None
    for line in proc.stderr:          # plain progress lines: stderr is a pipe, not a terminal
        if "ensemble: " in line and "finished" in line:   # the workers start once a member has timed the batch
            workers = [c for c in psutil.Process(proc.pid).children(recursive=True)
                       if any(mark in command(c) for mark in WORKER_MARKS)]
            if len(workers) == WORKER_PROCESSES:
                break
    assert len(workers) == WORKER_PROCESSES
    proc.send_signal(signal.SIGINT)
    rest = proc.stderr.read()
    assert proc.wait(timeout=60) == 130, rest
    assert rest.rstrip().endswith("interrupted; the output directory is as it was"), rest
    assert sorted(os.listdir(out)) == ["notes.txt"] and (out / "notes.txt").read_text() == "mine"
    deadline = time.time() + 10
    while time.time() < deadline and any(w.is_running() and w.status() != psutil.STATUS_ZOMBIE for w in workers):
        time.sleep(0.2)
    assert not any(w.is_running() and w.status() != psutil.STATUS_ZOMBIE for w in workers)


def test_independent_loads_are_refused_with_friction(tmp_path):
    from ngcontact.errors import SceneError
    from ngcontact.scene import loader
    path = write(tmp_path, "friction.toml", FE_SWEEP.replace("k_n = 1.0e3", 'k_n = 1.0e3\nfriction = "tresca"\n'
                                                             "G = 0.001\nw = 1e-4"))
    with pytest.raises(SceneError, match=r"^load.independent = True: solves every load afresh, which a frictional "
                                         "load path does not allow"):
        loader.load(path)


def test_the_levels_of_a_convergence_study_are_a_batch_and_two_workers_give_the_serial_numbers(tmp_path,
                                                                                               monkeypatch):
    """Work-precision levels (order, refinement) of a manufactured study on two local workers: the rows and
    rates of one process, and the finest level's field rebuilt here from the member's vector.

    The error norms are compared to 1e-10 (relative to the larger magnitude, at least 1), not 1e-12: the
    sparse factorization's rounding moves the discrete solution by about 1e-11 between two processes
    (observed 7e-12 on an L2 error of 6.6e-4), as it does between two serial runs.
    """
    text = open(os.path.join(ROOT, "geometries", "verify_elasticity.toml")).read().replace(
        "orders = [1, 2, 3]", "orders = [1, 2]")
    path = write(tmp_path, "levels.toml", text)
    monkeypatch.setenv("NGCONTACT_THREADS", "1")
    serial, _ = solve(path, workers=1)
    report, outcome = solve(path, workers=2)
    assert (report["compute"]["executor"], report["compute"]["batches"][0]["members"]) == ("local", 6)
    keep = ("order", "level", "ndof", "l2", "h1", "relative_residual")
    for a, b in zip(report["results"]["rows"], serial["results"]["rows"]):
        assert [a[k] for k in keep[:3]] == [b[k] for k in keep[:3]]
        for k in keep[3:]:
            assert abs(a[k] - b[k]) <= 1e-10 * max(1.0, abs(a[k]), abs(b[k])), (a, b, k)
    assert len(report["results"]["rows"]) == len(serial["results"]["rows"]) == 6
    for p, rates in serial["results"]["rates"].items():
        assert report["results"]["rates"][p] == pytest.approx(rates, rel=1e-8)
    finest = outcome.vtk["finest"].fields                      # the finest level, rebuilt from its vector
    import ngsolve as ng
    error = finest["error"]
    l2 = ng.sqrt(ng.Integrate(ng.InnerProduct(error, error), outcome.vtk["finest"].mesh, order=2 * 2 + 4))
    assert l2 == pytest.approx(report["results"]["rows"][-1]["l2"], rel=1e-8)


def test_a_dask_cluster_fills_a_two_scale_cell_table_with_the_serial_numbers(cluster, tmp_path, monkeypatch):
    """The table levels of the two-scale loop (paper Sec. 3.5) as batches on a real LocalCluster."""
    from ngcontact.coupling import pressure_table as PT
    from ngcontact.drivers import run_two_scale as R
    from ngcontact.parallel import executor
    monkeypatch.setenv("NGCONTACT_THREADS", "1")
    path = write(tmp_path, "cell.toml", FE_SWEEP.replace("shear = [0.0, 0.001, 0.002]\n", "").replace(
        "independent = true\n", ""))
    tables = {}
    for name, ex in (("serial", executor.Serial()), ("dask", executor.DaskCluster(cluster))):
        with executor.use(ex):
            table = PT.CellTable(R.PressureSolve(path, 1.0), tol=0.02, map_tasks=R.executor_map)
            assert table.cover(0.002, 0.02)
            tables[name] = (table.as_dict(), ex.describe())
    (serial, _), (dask, where) = tables["serial"], tables["dask"]
    assert serial["cell_solves"] == dask["cell_solves"] >= 7            # five start nodes and a level of midpoints
    assert [b["label"] for b in where["batches"]][:2] == ["cell table level"] * 2
    assert_same(dask, serial)
