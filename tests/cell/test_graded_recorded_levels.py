"""The graded FE cell's estimate on recorded levels of the shipped scene (issue 35: effectivity, no solve).

The levels of ``scripts/graded_effectivity.py`` (``geometries/cells/westergaard_graded.toml`` to its tolerance
``1e-4``, penalty ``k_n = 1e6 E`` and exact contact, one thread: the same figures bit for bit run after run): per
load the headline quantities of the orders solved on the answer's mesh, the records
:func:`~ngcontact.cell.fe.grading_estimate.order_estimate` reads (the first order's changes over the last grading
step, the last order's contact set's move, its edge cells and stiffness record), and the true error of the
answer in its measure against the script's oracle (penalty: the same model graded 9 levels at order 7; exact:
Westergaard's closed forms moved by the layers' finite depth), on the rows the script judges.  ``exact 0.05 level
4`` is the check at grading level 4 that the refinement rejected and graded further: its estimate must bound the
error of that level's last order too, or the run would stop there.

Every estimate is at least its true error, and at most ten times it except the three rows of :data:`LOOSE`,
which sharper rules tried on these levels could not bring within ten without taking another below one:

* ``penalty 0.05`` stiffness (42): its orders' errors ``+4.0e-5, +1.2e-6, -2.1e-8`` (relative) change sign
  between the last two orders, the last value landing on the limit; the orders' tail alone would be 5.4 times
  its error, the grading's tail of the change at order 3 (``1.2e-5``) adds ``7.8e-7``.  The larger of the two
  tails instead of their sum leaves 36 here and takes ``penalty 0.5``'s stiffness to 0.77 (its orders' errors
  ``5.2e-6, 1.3e-6, 7.4e-7`` stall: it needs both); the grading tail times the orders' contraction, 6.5 here and
  0.57 there.
* ``penalty 0.5`` closure (14): the orders' errors ``-1.7e-5, -1.8e-7, -3.9e-10`` contract by 0.010 and then
  0.0023, faster than the one ratio of changes (0.010) shows, so its geometric tail alone is 4.6 times the
  error and the safety 3 of the orders' rule makes 14; ``penalty 0.05``'s closure, whose contraction slows
  (0.021, then 0.026), needs the safety: without it 0.83, and ``exact 0.5``'s 0.55 (1.1 with a safety 2).
* ``exact 0.2`` stiffness (10.4): the grading tail of the change at order 3 (``5.1e-5``) bounds that order's
  edges (its error ``7.2e-5``), which orders 4 and 5 reduce to ``4.9e-6``; the contact set's share beside it
  (``4.7e-5``) alone would be 9.6, but the same share alone is 1.13 at ``exact 0.5`` and, at the rejected
  level 4 of ``exact 0.05``, 0.82 (the run then stops there).
"""
import json
from pathlib import Path

import pytest

from ngcontact.cell.fe.grading_estimate import order_estimate

#: the rows above ten times their error, and why (module docstring)
LOOSE = {("penalty 0.05", "normal_stiffness"), ("penalty 0.5", "mean_closure"), ("exact 0.2", "normal_stiffness")}
NAMES = ("contact_fraction", "mean_closure", "normal_stiffness", "coefficient_k_n", "coefficient_g_n")

#: per load the recorded orders and true errors (module docstring): the ``orders`` and ``grading_change`` of each
#: load's :class:`~ngcontact.cell.fe.edge_grading.GradedSolve` in the script's run, beside its rows' errors
LEVELS = json.loads((Path(__file__).parent / "graded_recorded_levels.json").read_text())


def _orders(case: dict) -> list[dict]:
    """The recorded orders as :func:`order_estimate` reads them: every entry the case's records (the first
    order's changes and the last's contact set, edge cells and stiffness record are the ones read)."""
    keep = ("penalty", "k_n", "set_move", "edge_cells", "stiffness_edges", "changes")
    return [dict({k: case[k] for k in keep}, headline=dict(zip(NAMES, values)), grading_ratio=None)
            for values in case["values"]]


@pytest.mark.parametrize("key", sorted(LEVELS))
def test_the_graded_estimate_bounds_the_recorded_errors_within_ten_times_but_the_diagnosed_rows(key):
    case = LEVELS[key]
    estimate, _ = order_estimate(_orders(case), case["grading_change"])
    for name, error in case["true_error"].items():
        assert estimate[name] >= error, (key, name, estimate[name], error)
        if (key, name) not in LOOSE:
            assert estimate[name] <= 10.0 * error, (key, name, estimate[name], error)
