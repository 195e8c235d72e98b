"""The shear table of a frictional cell: error control in jump and pressure, batches of independent solves,
growth only when asked for more, the disk cache, and the refusal of an asymmetric cell.

A synthetic cell stands in for the cell problem (the calls are counted): under a pressure p and a far-face
jump D it transmits the shear tau = 0.7 p tanh(D / (0.01 p)) and its interface takes the jump
s = D - 0.01 tau (the rest is the bulk's share), a stick-then-slide curve whose corner moves with p."""
import numpy as np
import pytest

from ngcontact.coupling import shear_table as S
from ngcontact.drivers import run_two_scale as R
from ngcontact.errors import ModelError
from ngcontact.laws import interface_energy as ie


def synthetic(calls, offset=0.0):
    def response(load):
        p, d = load
        calls.append(load)
        tau = 0.7 * p * np.tanh(d / (0.01 * p)) + offset * p
        return {"shear": float(tau), "jump": float(d - 0.01 * tau)}
    return response


def exact_shear(p, s):
    """The synthetic cell's shear at the interface jump s (inverting s(D) by bisection)."""
    lo, hi = 0.0, s + 0.01 * 0.7 * p + 1.0
    for _ in range(200):
        d = 0.5 * (lo + hi)
        tau = 0.7 * p * np.tanh(d / (0.01 * p))
        lo, hi = (d, hi) if d - 0.01 * tau < s else (lo, d)
    return 0.7 * p * np.tanh(lo / (0.01 * p))


def test_the_table_meets_its_tolerance_between_its_nodes():
    calls: list = []
    table = S.ShearTable(synthetic(calls), tol=0.02)
    assert table.cover(0.5, 1.0, 0.05)
    assert table.solves == len(calls) and table.rows and len(table.rows) >= 3
    assert max(table.jump_error, table.pressure_error) <= table.tol
    law = table.law()
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(200):
        p, s = rng.uniform(0.5, 1.0), rng.uniform(0.0, 0.05)
        got = ie.friction_traction(law, [0.0, s], p)[1]
        worst = max(worst, abs(got - exact_shear(p, s)) / 0.7)
    # the midpoint checks estimate the interpolation error; between the nodes it stays within a few tol
    assert worst <= 3 * table.tol, worst


def test_cell_solves_of_a_level_go_through_the_map_in_batches_and_a_covered_range_solves_nothing():
    batches: list = []

    def recording(task, items):
        batches.append(list(items))
        return [task(x) for x in items]

    calls: list = []
    table = S.ShearTable(synthetic(calls), tol=0.02, map_tasks=recording)
    table.cover(0.1, 1.0, 0.05)
    assert sum(len(b) for b in batches) == len(calls) - 1 == table.solves - 1   # one symmetry probe outside
    assert len(batches[0]) == 9 and max(len(b) for b in batches[1:]) > 3, [len(b) for b in batches]
    before = table.solves
    assert not table.cover(0.1, 1.0, 0.05) and table.solves == before
    assert not table.cover(0.2, 0.9, 0.01) and table.solves == before
    assert table.cover(0.1, 2.0, 0.05) and table.solves > before
    assert table.pressures[-1] == pytest.approx(2.0)


def test_a_range_that_moves_by_round_off_solves_no_row_again():
    """The loop asks for its range again after each growth of the law; the macro solution, and with it the range,
    moves a little each time (on the FE friction block by a relative 1.06e-6, just past the former slack of 1e-6,
    and four rows were added within 1e-6 of the last one).  A range beyond the rows by less than the tolerance
    is covered: no row is solved twice; one beyond it by more grows the table."""
    calls: list = []
    table = S.ShearTable(synthetic(calls), tol=0.02)
    table.cover(0.1, 1.0, 0.05)
    before, rows = table.solves, set(table.rows)
    moved = 1 + 1.06e-6
    assert not table.cover(0.1 / moved, 1.0 * moved, 0.05 * moved) and table.solves == before
    assert set(table.rows) == rows
    assert not table.cover(0.1, 1.0 * (1 + 0.5 * table.tol), 0.05) and table.solves == before
    assert table.cover(0.1, 1.0 * (1 + 2 * table.tol), 0.05) and table.solves > before


def test_the_cache_reproduces_the_table_and_its_law(tmp_path):
    calls: list = []
    table = S.ShearTable(synthetic(calls), tol=0.02)
    table.cover(0.1, 1.0, 0.05)
    R.store_shear("s" * 64, table, str(tmp_path))
    again_calls: list = []
    again, cached = R.cached_shear("s" * 64, synthetic(again_calls), 0.02, 1.0, S.serial_map, str(tmp_path))
    assert cached and again.law() == table.law()
    assert (again.jump_error, again.pressure_error, again.covered_jump) == \
        (table.jump_error, table.pressure_error, table.covered_jump)
    assert not again.cover(0.1, 1.0, 0.05) and not again_calls
    other, cached = R.cached_shear("t" * 64, synthetic([]), 0.02, 1.0, S.serial_map, str(tmp_path))
    assert not cached and not other.rows


def test_a_cell_that_shears_at_zero_jump_is_refused():
    table = S.ShearTable(synthetic([], offset=0.2), tol=0.02)
    with pytest.raises(ModelError, match="asymmetric"):
        table.cover(0.1, 1.0, 0.05)


def test_shear_keys_follow_the_cell_scene_and_differ_from_the_pressure_table(tmp_path):
    import os
    import shutil

    from ngcontact.drivers.build import cell_scene_of
    from ngcontact.scene.loader import load
    cells = os.path.join(os.path.dirname(__file__), "..", "..", "geometries", "cells")
    shutil.copy(os.path.join(cells, "rectangular_coulomb.toml"), tmp_path / "c.toml")
    scene = load(str(tmp_path / "c.toml"))
    key = R.shear_key(scene, 1.0, 0.01)
    assert key == R.shear_key(load(str(tmp_path / "c.toml")), 1.0, 0.01)
    assert key != R.table_key(scene, 1.0, 0.01) and key != R.shear_key(scene, 1.0, 0.02)
    assert key != R.shear_key(cell_scene_of(str(tmp_path / "c.toml"), key="k", overrides={"mu": 0.5}), 1.0, 0.01)


def _synthetic_task(load):
    return synthetic([])(load)


def test_a_shear_level_is_one_batch_of_the_executor_and_the_task_pickles():
    import os
    import pickle

    from ngcontact.parallel import executor
    batches: list = []

    class Recording(executor.Serial):
        def map(self, fn, items, names, *, label="batch", progress=None):
            batches.append((label, list(items), list(names)))
            return super().map(fn, items, names, label=label, progress=progress)

    with executor.use(Recording()):
        table = S.ShearTable(_synthetic_task, tol=0.05, map_tasks=R.shear_executor_map)
        table.cover(0.5, 1.0, 0.05)
    assert batches and all(label == "shear table level" for label, _, _ in batches)
    assert sum(len(items) for _, items, _ in batches) == table.solves - 1   # the symmetry probe is outside
    cells = os.path.join(os.path.dirname(__file__), "..", "..", "geometries", "cells")
    task = R.ShearSolve(os.path.join(cells, "rectangular_coulomb.toml"), 1.0, {"mu": 0.4})
    again = pickle.loads(pickle.dumps(task))
    assert again.path == task.path and again.overrides == {"mu": 0.4} and again._problem is None


SAW = """kind = "cell"
[materials.s]
E = 1.0
nu = 0.3
[bodies]
rough = "s"
counter = "s"
[geometry]
profile = "triangular"
period = 1.0
h_rough = 1.0
h_counter = 1.0
angles = [20.0, 20.0]
[contact]
k_n = 1000.0
friction = "coulomb"
mu = 0.3
w = 1e-5
[load]
pressure = [0.001]
[discretization]
order = 2
maxh = 0.25
interface_maxh = 0.1
"""


def test_a_sliding_sawtooth_cell_transmits_the_wedge_shear_with_the_signs_of_the_macro_law(tmp_path):
    """Far beyond slip onset the cell's shear over its pressure is the rigid wedge's (tan b + mu) / (1 - mu
    tan b); a positive far-face jump gives a positive interface jump and shear, a negative one the opposite,
    and the interface takes less than the far faces (the bulk has its share)."""
    import math
    (tmp_path / "saw.toml").write_text(SAW)
    task = R.ShearSolve(str(tmp_path / "saw.toml"), 1.0)
    t = math.tan(math.radians(20.0))
    wedge = (t + 0.3) / (1 - 0.3 * t)
    for d in (0.05, -0.05):
        r = task((1e-3, d))
        assert r["shear"] / 1e-3 == pytest.approx(math.copysign(wedge, d), rel=1e-6), r
        assert math.copysign(1.0, r["jump"]) == math.copysign(1.0, d) and 0 < abs(r["jump"]) < abs(d), r
    assert abs(task((1e-3, 0.0))["shear"]) <= 1e-6 * 1e-3   # symmetric: none at zero jump (to the solver)
