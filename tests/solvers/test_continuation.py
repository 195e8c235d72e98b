"""The continuation ladder: rungs, refinement of a failed rung, and the error when it cannot go on."""
import pytest

from ngcontact.errors import ConvergenceError
from ngcontact.solvers import continuation as C


class Reachable:
    """A fake solve that converges only within a ratio ``reach`` of the width it last solved."""

    def __init__(self, reach: float, floor: float = 0.0):
        self.reach, self.floor = reach, floor
        self.state = None          # the last width solved: the "state" the next solve starts from
        self.calls: list[tuple[float, bool]] = []

    def solve_at(self, w, last):
        self.calls.append((w, last))
        if w < self.floor or (self.state is not None and self.state / w > self.reach):
            raise ConvergenceError(f"no convergence at {w:g}", {})
        self.state = w
        return {"width": w}

    def save(self):
        return self.state

    def restore(self, s):
        self.state = s


def test_rungs_divide_by_the_ratio_and_only_the_last_is_solved_to_full_tolerance():
    f = Reachable(reach=100.0)
    rungs = C.ladder(f.solve_at, f.save, f.restore, start=1e-3, target=1e-6)
    widths = [r["width"] for r in rungs]
    assert widths == pytest.approx([1e-3, 1e-4, 1e-5, 1e-6])
    assert [last for _, last in f.calls] == [False, False, False, True]


def test_a_failed_rung_is_retried_from_the_last_solved_one_with_a_smaller_ratio():
    f = Reachable(reach=4.0)     # a ratio of 10 fails, sqrt(10) = 3.16 works
    rungs = C.ladder(f.solve_at, f.save, f.restore, start=1e-3, target=1e-5)
    widths = [r["width"] for r in rungs]
    assert widths[0] == pytest.approx(1e-3) and widths[-1] == pytest.approx(1e-5)
    assert all(a / b <= 4.0 * (1 + 1e-12) for a, b in zip(widths, widths[1:]))
    assert len(f.calls) > len(widths)      # failed attempts happened and were retried


def test_a_ladder_that_cannot_reach_the_target_says_how_far_it_got():
    f = Reachable(reach=100.0, floor=3e-5)
    with pytest.raises(ConvergenceError, match=r"solved down to width 3\.16e-05; at 2\.74e-05") as info:
        C.ladder(f.solve_at, f.save, f.restore, start=1e-3, target=1e-6)
    assert "continuation in the Huber width from 0.001 to 1e-06" in str(info.value)
    assert [r["width"] for r in info.value.history["continuation"]][-1] >= 3e-5
