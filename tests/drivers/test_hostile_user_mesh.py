"""``ngcontact.solve_mesh`` with a hostile gap, found by the reliability audit of issue 35: refused before the
solve with the argument, its value and what is allowed, never a Newton failure on a non-finite start."""
import re

import pytest

from test_user_mesh import _refused

ALLOWED = ("a finite number of magnitude at most 1e+09 (the macro normal gap g0 in the mesh's length unit, "
           "< 0 an interference) or a CoefficientFunction")


@pytest.mark.parametrize("gap", [float("nan"), float("inf"), -1e300])
def test_a_gap_that_is_no_length_is_refused(gap):
    """Was: ConvergenceError 'the start value gives a non-finite energy or residual'."""
    _refused(re.escape(f"gap = {gap!r}: {ALLOWED}"), gap=gap)


def test_a_boolean_is_no_gap():
    """Was: accepted (a bool is an int) and solved as a gap of 1."""
    _refused(re.escape(f"gap = True: {ALLOWED}"), gap=True)
