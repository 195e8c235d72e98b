"""The report: finite numbers only, with the path of any that is not; the stage clock."""
import math

import numpy as np
import pytest

from ngcontact.output.report import Clock, to_plain


def test_to_plain_converts_numpy_and_rejects_nan_with_its_path():
    assert to_plain({"a": np.float64(1.5), "b": np.arange(3), "c": np.bool_(True)}) == \
        {"a": 1.5, "b": [0, 1, 2], "c": True}
    with pytest.raises(ValueError, match=r"non-finite number nan at results\.x\[1\]"):
        to_plain({"x": [1.0, math.nan]})
    with pytest.raises(ValueError, match="inf"):
        to_plain({"y": np.array([np.inf])})


def test_to_plain_names_a_non_finite_entry_of_an_array_or_a_table_row_by_its_indices():
    grid = np.zeros((3, 4))
    grid[2, 1] = -np.inf
    with pytest.raises(ValueError, match=r"non-finite number -inf at results\.p\[2\]\[1\]"):
        to_plain({"p": grid})
    rows = [(np.float64(0.5), np.float64(1.0)), (np.float64(0.75), np.float64(math.nan))]
    with pytest.raises(ValueError, match=r"non-finite number nan at table\[1\]\[1\]"):
        to_plain([list(r) for r in rows], "table")
    assert to_plain([list(r) for r in rows[:1]], "table") == [[0.5, 1.0]]
    assert type(to_plain([np.float64(2.0)])[0]) is float
    assert to_plain(np.array([[1, 2]], dtype=np.int32)) == [[1, 2]] and to_plain(np.array([True])) == [True]


def test_clock_accumulates_stages():
    lines = []
    clock = Clock(lines.append)
    with clock.stage("mesh"):
        pass
    with clock.stage("mesh"):
        pass
    t = clock.total()
    assert set(t) == {"mesh", "total"} and t["total"] >= t["mesh"] >= 0
    assert len(lines) == 2 and "mesh" in lines[0]


def test_a_long_surface_line_is_drawn_through_its_envelope():
    from ngcontact.output.cell_plots import MAX_LINE_POINTS, line_points
    x = np.linspace(0.0, 1.0, 1_000_003)
    y = np.sqrt(np.clip(0.3 - np.abs(x - 0.5), 0.0, None))        # an edge at 0.2 and 0.8, its peak at 0.5
    y[777_777] = 9.0                                               # one spike
    xs, ys = line_points(x, y)
    assert len(xs) <= MAX_LINE_POINTS and np.all(np.diff(xs) > 0)
    assert ys.max() == 9.0 and xs[np.argmax(ys)] == x[777_777] and ys.min() == 0.0
    away = np.abs(x - x[777_777]) > 4 / MAX_LINE_POINTS          # two runs of points either side of the spike
    assert np.interp(x[away], xs, ys) == pytest.approx(y[away], abs=0.05)
    short = np.arange(10.0)
    assert [len(v) for v in line_points(short, short)] == [10, 10]
