"""Runs use NGSolve's task manager with the threads NGCONTACT_THREADS names (default: every available core)."""
import json
import os

import pytest

from ngcontact import cli

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE = os.path.join(ROOT, "geometries", "cells", "sinusoid.toml")


def _run(tmp_path, monkeypatch, value, name):
    if value is None:
        monkeypatch.delenv("NGCONTACT_THREADS", raising=False)
    else:
        monkeypatch.setenv("NGCONTACT_THREADS", value)
    out = tmp_path / name
    # threads, not accuracy: the scene's own discretization, not estimated (no second sweep)
    path = tmp_path / f"{name}.toml"
    path.write_text(open(SCENE, encoding="utf-8").read().replace("[discretization]\n",
                                                                   '[discretization]\nestimate = "off"\n'))
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    return json.loads((out / "report.json").read_text())


def test_the_report_states_the_threads_and_they_do_not_change_the_answer(tmp_path, monkeypatch):
    one = _run(tmp_path, monkeypatch, "1", "one")
    two = _run(tmp_path, monkeypatch, "2", "two")
    default = _run(tmp_path, monkeypatch, None, "default")
    assert one["threads"] == 1 and two["threads"] == 2
    assert default["threads"] == len(os.sched_getaffinity(0))
    for a, b in zip(one["results"]["loads"], two["results"]["loads"]):
        for key in ("contact_fraction", "mean_closure", "mean_pressure"):
            assert b[key] == pytest.approx(a[key], rel=1e-9, abs=1e-15), key


@pytest.mark.parametrize("value", ["0", "two", "-3"])
def test_a_bad_thread_count_is_refused_before_anything_is_written(tmp_path, monkeypatch, capsys, value):
    monkeypatch.setenv("NGCONTACT_THREADS", value)
    out = tmp_path / "out"
    assert cli.main(["run", SCENE, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"environment variable NGCONTACT_THREADS = {value!r}: the number of threads: an integer >= 1" in err
    assert not out.exists()


@pytest.mark.parametrize("n", [1, 2])
def test_blas_runs_on_one_thread_inside_a_run_and_gets_its_threads_back(n):
    """Inside ``runner.threads`` every BLAS library loaded (NGSolve's, NumPy's) is held at one thread, so
    that its spinning threads do not share the cores with NGSolve's task manager; after, as before."""
    import ngsolve  # noqa: F401  (loads NGSolve's BLAS)
    import numpy  # noqa: F401
    from threadpoolctl import threadpool_info
    from ngcontact import runner
    blas = [i for i in threadpool_info() if i["user_api"] == "blas"]
    if not blas:
        pytest.skip("no BLAS library with a thread pool is loaded")
    before = {i["filepath"]: i["num_threads"] for i in blas}
    with runner.threads(n):
        inside = {i["filepath"]: i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}
    after = {i["filepath"]: i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"}
    assert set(inside.values()) == {1}
    assert after == before


def test_one_thread_gives_the_same_cell_bit_for_bit():
    """On one thread the same scene gives the same numbers: the exact graded Westergaard cell's first level
    (``geometries/cells/westergaard_graded.toml`` with exact contact, p/p* = 0.5) meshed and solved twice gives
    the same mesh and the same headline numbers, bit for bit (bound 0).  Before ``runner.threads(1)`` told
    NGSolve one thread, its sparse Cholesky factorization ran in a pool on every core (here two, set first, as
    a run with more threads before it leaves them), and the stiffness differed by about 1e-9 of itself."""
    import dataclasses

    import numpy as np
    import pyngcore

    import ngcontact
    from ngcontact import runner
    from ngcontact.cell.cell_solution import headline
    from ngcontact.drivers.build import cell_loads, fe_cell
    scene = ngcontact.load(os.path.join(ROOT, "geometries", "cells", "westergaard_graded.toml"))
    scene = dataclasses.replace(scene, contact=dataclasses.replace(scene.contact, enforcement="exact", k_n=1e3))
    load = cell_loads(scene)[2]
    pyngcore.SetNumThreads(2)
    runs = []
    with runner.threads(1):
        for _ in range(2):
            problem = fe_cell(scene).graded([], scene.discretization.order)
            points = np.array([p.p for p in problem.mesh.ngmesh.Points()])
            runs.append((points, headline(problem.solve(load, first=True).results)))
    (p0, h0), (p1, h1) = runs
    assert np.array_equal(p0, p1)
    assert h0 == h1
    assert 0.49 < h0["contact_fraction"] < 0.51       # the load's own cell (Westergaard: 0.5)
