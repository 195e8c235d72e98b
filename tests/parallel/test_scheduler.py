"""A scheduler address: its form checked at once, a scheduler that does not answer named within seconds.

A malformed address (``garbage``, ``http://...``) is refused before any
connection, by dask's own parsing; a well-formed address where no
scheduler answers ends the run after :data:`CONNECT_SECONDS` with exit 2
and one line (no traceback of a half-made client as the interpreter ends).
"""
import os
import socket
import subprocess
import sys
import time

import pytest

from ngcontact import runner
from ngcontact.errors import SceneError
from ngcontact.parallel import dask_cluster, executor
from ngcontact.scene import loader

pytest.importorskip("distributed")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

SWEEP = """kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "self_affine"
arrangement = "summit"
spectrum = { hurst = 0.8, rms_slope = 0.1, rolloff = 0.25, cutoff = 0.125, grid = 32, seed = 3 }
[contact]
k_n = 1.0e3
enforcement = "exact"
[load]
pressure = [0.001, 0.003, 0.01]
independent = true
[discretization]
method = "spectral"
"""


def free_port() -> int:
    """A local port nothing listens on (taken from the system, then let go)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("address, problem", [
    ("garbage", "missing port number"),
    ("http://10.0.0.5:8786", "unknown scheme 'http'"),
    ("tcp://10.0.0.5", "missing port number"),
    ("tcp://10.0.0.5:port", "invalid port"),
    ("tcp://10.0.0.5:99999", "port 99999 is not in 1..65535"),
    ("tcp://:8786", "no host"),
    ("inproc://x", "unknown scheme 'inproc'"),
    (" tcp://10.0.0.5:8786", "unknown scheme ' tcp'"),
])
def test_a_malformed_address_is_refused_at_once_naming_the_allowed_forms(address, problem):
    t0 = time.monotonic()
    with pytest.raises(dask_cluster.SchedulerError) as info:
        executor.make(2, address)
    assert time.monotonic() - t0 < 5.0
    assert info.value.address == address
    assert problem in info.value.allowed
    assert "tcp://HOST:PORT or HOST:PORT" in info.value.allowed
    with pytest.raises(SceneError) as named:                  # the runner names the key
        runner.check_scheduler(address, "compute.scheduler")
    assert (named.value.path, named.value.value, named.value.allowed) == ("compute.scheduler", address,
                                                                          info.value.allowed)


@pytest.mark.parametrize("address", ["tcp://10.0.0.5:8786", "10.0.0.5:8786", "localhost:8786",
                                     "tcp://[::1]:8786", "tls://scheduler.example:8786", "ws://h:1"])
def test_well_formed_addresses_are_taken_without_connecting(address):
    t0 = time.monotonic()
    ex = executor.make(2, address)
    assert isinstance(ex, executor.DaskCluster) and ex.address == address
    assert time.monotonic() - t0 < 5.0


def test_a_plain_tcp_address_is_read_and_reached_without_importing_dask_distributed():
    """dask.distributed's import is most of a second: a run whose batches stay in its process never pays it
    (:mod:`ngcontact.parallel.dask_payoff`, ``K``), also not for reading and checking its address."""
    code = ("import socket, sys\n"
            "from ngcontact.parallel import executor\n"
            "with socket.socket() as s:\n"
            "    s.bind(('127.0.0.1', 0)); s.listen()\n"
            "    for address in ('tcp://10.0.0.5:8786', 'localhost:8786', 'tcp://[::1]:8786'):\n"
            "        executor.make(2, address)\n"
            "    executor.make(2, f'tcp://127.0.0.1:{s.getsockname()[1]}').start_on_demand()\n"
            "assert 'distributed' not in sys.modules, 'imported'\n")
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr


def test_a_scheduler_that_does_not_answer_ends_the_run_in_seconds_with_exit_2_and_one_line(tmp_path):
    scene = tmp_path / "sweep.toml"
    scene.write_text(SWEEP)
    address = f"tcp://127.0.0.1:{free_port()}"
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    t0 = time.monotonic()
    done = subprocess.run([sys.executable, "-m", "ngcontact", "run", str(scene), "--out", str(tmp_path / "out"),
                           "--quiet", "--scheduler", address], env=env, capture_output=True, text=True,
                          timeout=120)
    seconds = time.monotonic() - t0
    assert done.returncode == 2, done.stderr
    assert done.stderr == (f"ngcontact: error: {scene}: --scheduler = '{address}': no dask.distributed "
                           f"scheduler answered there within 5 s: start one there (dask scheduler) or correct "
                           f"the address\n")
    assert seconds < 20.0
    assert not (tmp_path / "out").exists()


def test_a_scheduler_first_used_by_a_batch_that_does_not_answer_is_named_by_the_run(tmp_path):
    """Without a batch known in advance (a two-scale table's levels) the scheduler is reached at the first
    batch, inside the driver: the run still names it, within seconds."""
    scene = tmp_path / "sweep.toml"
    scene.write_text(SWEEP)
    address = f"127.0.0.1:{free_port()}"
    t0 = time.monotonic()
    with pytest.raises(SceneError) as info:
        with runner.batches(loader.load(str(scene)), scheduler=address, start=False):
            executor.current().map(abs, [1.0, -2.0], ["a", "b"])
    assert time.monotonic() - t0 < 15.0
    assert (info.value.path, info.value.value) == ("scheduler", address)
    assert info.value.allowed.startswith("no dask.distributed scheduler answered there within 5 s")
