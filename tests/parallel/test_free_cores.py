"""The cores other processes leave to a run (:mod:`ngcontact.parallel.free_cores`), and the threads of the
run's own process while its workers compute."""
import os
import subprocess
import sys
import time

import pytest

from ngcontact.parallel import free_cores
from ngcontact.parallel.batch_member import threads_asleep
from ngcontact.parallel.free_cores import CoreWatch, Reading


def test_a_window_reads_the_others_use_of_the_cores_less_the_runs_own(monkeypatch):
    """(2) on a faked ``/proc/stat``: other processes spend one core's time on the two cores while this
    process computes on the other; its own CPU time is not counted as theirs."""
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    monkeypatch.setattr(free_cores, "core_seconds", lambda cores: time.perf_counter() + time.process_time())
    watch = CoreWatch()
    t0 = time.process_time()
    while time.process_time() - t0 < 0.4:
        pass
    reading = watch.reading()
    assert reading.busy == pytest.approx(1.0, abs=0.05) and reading.free == pytest.approx(1.0, abs=0.05)
    assert "busy with other processes over the last" in reading.source


def test_a_look_soon_after_the_last_reads_the_window_before_not_the_load_average(monkeypatch):
    """A member solved in less than ``WINDOW_SECONDS`` after the last look: the window opens at the sample
    before (still (2)), not at the last look, and never the load average, which right after another run on
    the same cores counts that run as busy.  (Wall seconds here: the faked ``/proc/stat`` has this process
    and one other core busy whatever the machine's load.)"""
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    monkeypatch.setattr(free_cores, "core_seconds", lambda cores: time.perf_counter() + time.process_time())
    monkeypatch.setattr(free_cores, "load_average", lambda: 1.9)        # the run just before, on 2 cores
    watch = CoreWatch()
    for seconds in (0.3, 0.1, 0.1):
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            pass
        reading = watch.reading()
        assert "busy with other processes over the last" in reading.source
        assert reading.free == pytest.approx(1.0, abs=0.05)
    window = float(reading.source.split("over the last ")[1].split(" s")[0])
    assert 0.45 <= window < 0.7         # opened as the watch did: the first look is only 0.2 s old at the third


def test_without_a_window_the_load_average_is_read_and_the_free_cores_stay_in_range(monkeypatch):
    monkeypatch.setattr(free_cores, "affinity", lambda: [0, 1])
    monkeypatch.setattr(free_cores, "core_seconds", lambda cores: None)
    monkeypatch.setattr(free_cores, "load_average", lambda: 0.5)
    assert CoreWatch().reading() == Reading(2, 0.5, "one-minute load average 0.50")
    assert Reading(2, 7.0, "").free == 0.0 and Reading(2, -1.0, "").free == 2.0
    monkeypatch.setattr(free_cores, "load_average", lambda: None)
    assert CoreWatch().reading().free == 2.0


def test_the_machines_own_reading_is_a_number_of_cores_it_has(monkeypatch):
    """The real ``/proc/stat`` of this machine (the conftest fakes it for the other tests)."""
    monkeypatch.undo()
    watch = CoreWatch()
    time.sleep(0.3)
    reading = watch.reading()
    assert 0.0 <= reading.free <= len(free_cores.affinity()) == reading.cores
    assert "over the last" in reading.source


def test_the_task_managers_threads_sleep_while_the_workers_compute():
    """Inside NGSolve's task manager, this process's idle threads look for work without pause (a tenth of
    a core here); while workers solve a batch they sleep (:func:`threads_asleep`)."""
    import ngsolve
    ngsolve.SetNumThreads(2)
    with ngsolve.TaskManager():
        with threads_asleep():
            t0 = time.process_time()
            time.sleep(1.0)
            asleep = time.process_time() - t0
    assert asleep < 0.03


def test_the_runs_process_loads_every_blas_on_one_thread():
    """The run's threads (:func:`ngcontact.runner.threads`) hold BLAS to one thread, a BLAS loaded inside
    them too (SciPy's own OpenBLAS), in a fresh interpreter that has not loaded it yet."""
    code = ("import os\nfrom ngcontact.runner import threads\nfrom threadpoolctl import threadpool_info\n"
            "with threads(2):\n    import scipy.linalg\n"
            "    print(max(d['num_threads'] for d in threadpool_info() if d['user_api'] == 'blas'))\n"
            "print('OPENBLAS_NUM_THREADS' in os.environ)")
    env = {k: v for k, v in os.environ.items() if k not in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                                           "MKL_NUM_THREADS")}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.split() == ["1", "False"]


def test_the_window_of_the_runs_first_look_opens_before_ngsolve_and_the_scene_modules_load():
    """The package opens the window (:data:`~ngcontact.parallel.free_cores.OPENING`) before its heavy imports,
    so that a run's first look, about a second later, reads (2) over them rather than the load average."""
    code = ("import sys\norder = []\nclass Seen:\n    def find_spec(self, name, path=None, target=None):\n"
            "        order.append(name)\nsys.meta_path.insert(0, Seen())\nimport ngcontact\n"
            "print(order.index('ngcontact.parallel.free_cores'), order.index('ngsolve'),"
            " order.index('ngcontact.scene.loader'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    opening, ngsolve, loader = map(int, out.stdout.split())
    assert opening < ngsolve and opening < loader
