"""The machine of the executor tests: an idle one, with a cache of its own for every test.

The payoff rule (:mod:`ngcontact.parallel.worker_payoff`) counts the cores other processes leave free and a
worker's start as measured on this machine.  The tests run beside other jobs: unless a test fakes a busy
machine itself, the reading is that of an idle one (no ``/proc/stat`` window, a load average of zero), and
the measured starts go to a cache directory of the test's own.
"""
import pytest

from ngcontact.parallel import free_cores


@pytest.fixture(autouse=True)
def idle_machine(monkeypatch, tmp_path):
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(free_cores, "core_seconds", lambda cores: None)
    monkeypatch.setattr(free_cores, "load_average", lambda: 0.0)
