"""The C heap's thresholds in a worker or a run whose environment froze them (ngcontact.parallel.heap_thresholds)."""
import os
import subprocess
import sys

import pytest

from ngcontact.parallel import heap_thresholds

PROBE = """
import resource, sys
import numpy as np
from ngcontact.parallel.heap_thresholds import keep_freed_arrays

def faults():
    start = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(50):
        a = np.ones(2**19)          # 4 MiB, allocated and freed like an FFT buffer of a step
        del a
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - start

faults()
before = faults()
changed = keep_freed_arrays()
faults()
print(before, faults(), changed)
"""


#: The same loop, before and inside a run's own context (``ngcontact.runner.threads``), not a worker's start.
RUN_PROBE = PROBE.split("faults()\nbefore")[0] + """
from ngcontact import runner
faults()
before = faults()
with runner.threads(1):
    faults()
    print(before, faults(), True)
"""


def _probe(env_extra: dict, probe: str = PROBE) -> tuple[int, int, bool]:
    env = {k: v for k, v in os.environ.items() if k not in heap_thresholds.FREEZING}
    # NumPy asks for transparent huge pages on arrays of 4 MiB and more; where the kernel grants them (it
    # depends on where the mapping happens to fall, so on every import before the probe's loop) an array
    # costs a few faults, not one per 4 KiB page, and the count no longer shows whether it was mapped afresh
    env.update(env_extra, NUMPY_MADVISE_HUGEPAGE="0")
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, check=True)
    before, after, changed = out.stdout.split()
    return int(before), int(after), changed == "True"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc thresholds: Linux only")
def test_a_frozen_threshold_is_raised_and_freed_arrays_are_reused():
    before, after, changed = _probe({"MALLOC_TRIM_THRESHOLD_": "65536"})   # what Dask's nanny sets
    assert changed
    assert before > 50 * 500            # every 4 MiB array mapped afresh: about 1024 page faults each
    assert after < before / 20          # reused from the heap


def test_nothing_changes_where_the_environment_sets_no_threshold():
    _, _, changed = _probe({})
    assert not changed


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc thresholds: Linux only")
def test_a_runs_own_process_reuses_freed_arrays_where_a_dask_cluster_froze_the_threshold():
    """A run started by a process that started a local Dask cluster inherits the nanny's variable: the run's
    own members (solved in its process) must not map every buffer afresh."""
    before, inside, _ = _probe({"MALLOC_TRIM_THRESHOLD_": "65536"}, RUN_PROBE)     # what Dask's nanny leaks
    assert before > 50 * 500
    assert inside < before / 20
