"""The number of local workers: never more than the batch has members, nor more than twice the cores.

Every worker is a fresh interpreter (its start, its memory); past the
cores they only share them.  A request above the cap is cut to it, with one
line saying so.  Nothing here starts a worker.
"""
import pytest

from ngcontact import runner
from ngcontact.parallel import executor
from ngcontact.scene import loader

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
spectrum = {{ hurst = 0.8, rms_slope = 0.1, rolloff = 0.25, cutoff = 0.125, grid = 32, seed = 3 }}
[contact]
k_n = 1.0e3
enforcement = "exact"
[load]
pressure = [{pressures}]
independent = true
[discretization]
method = "spectral"
"""


def sweep(tmp_path, members: int):
    path = tmp_path / f"sweep_{members}.toml"
    path.write_text(SWEEP.format(pressures=", ".join(f"{0.001 * (k + 1):g}" for k in range(members))))
    return loader.load(str(path))


def test_make_caps_the_workers_at_twice_the_cores_and_at_the_batch():
    cap = executor.MAX_WORKERS_PER_CORE * executor.default_workers()
    assert executor.MAX_WORKERS_PER_CORE == 2
    assert executor.make(1000).workers == cap
    assert executor.make(1000, members=3).workers == min(3, cap)
    assert isinstance(executor.make(1000, members=1), executor.Serial)
    assert executor.make(2, members=12).workers == 2                  # a request below both caps is kept


@pytest.mark.parametrize("members", [12, 3])
def test_a_run_asking_for_1000_workers_gets_at_most_one_per_member_and_two_per_core_with_one_line(
        tmp_path, members):
    scene = sweep(tmp_path, members)
    assert runner.batch_members(scene) == members
    notes = []
    with runner.batches(scene, workers=1000, start=False, note=notes.append) as ex:
        assert ex.workers == min(members, 2 * executor.default_workers())
        assert ex._pool is None                                      # asked for on demand: nothing started
    assert len(notes) == 1, notes
    cores = executor.default_workers()
    if members < 2 * cores:
        assert notes[0] == f"workers: {members} worker processes, not the 1000 asked for: one per member of " \
                           f"the batch ({members})"
    else:
        assert notes[0] == f"workers: {2 * cores} worker processes, not the 1000 asked for: at most 2 per " \
                           f"core ({cores} cores)"


def test_a_request_within_the_caps_says_nothing(tmp_path):
    scene = sweep(tmp_path, 12)
    notes = []
    with runner.batches(scene, workers=2, start=False, note=notes.append) as ex:
        assert ex.workers == 2
    assert notes == []
