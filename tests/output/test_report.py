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
