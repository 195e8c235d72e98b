"""The checks a cell solution must pass to count as an answer, whichever method solved it.

A converged solver is not yet a right answer.  Each load's results are held against what the cell
problem of paper eqs. 49-51 demands of any solution:

* **pressure balance**: the interface force, the pressure field integrated accurately (its sign,
  compression positive, as reported), balances the far-face traction (``pressure_balance`` of the
  results: :func:`ngcontact.cell.fe.measures.pressure_balance`; on a grid, the mean of the grid's
  pressure against the load).  A mesh whose quadrature cannot see a contact patch satisfies its own
  discrete balance and misses this one by the share of the pressure it did not see.

A check beyond the scene's accuracy (``discretization.tolerance``, else :data:`DEFAULT_TOLERANCE`) marks
the result as not meeting it; one beyond :data:`PLAINLY_WRONG` means the answer contradicts its own load
and is not reported as one.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

#: the accuracy a scene that states none is held to (relative)
DEFAULT_TOLERANCE = 0.01
#: a relative violation at which the result is no answer at all: the integrated pressure misses the load
#: by the load's own size
PLAINLY_WRONG = 1.0
#: the checks of each load: the results' key and what it measures
CHECKS = {"pressure_balance": "the accurately integrated interface force against the far-face traction "
                              "(relative)"}


@dataclass(frozen=True)
class Check:
    """One check of one load: its value against its limit."""

    load: int
    name: str
    value: float
    limit: float

    @property
    def ok(self) -> bool:
        return self.value <= self.limit

    @property
    def plainly_wrong(self) -> bool:
        return not self.value <= PLAINLY_WRONG

    def as_dict(self) -> dict[str, Any]:
        return dict(asdict(self), ok=self.ok, meaning=CHECKS[self.name])

    def message(self) -> str:
        return (f"load {self.load}: {self.name} = {self.value:.3g} exceeds {self.limit:g} "
                f"({CHECKS[self.name]})")


def load_checks(k: int, results: dict[str, Any], tolerance: float) -> list[Check]:
    """The checks of load ``k`` whose results carry them."""
    return [Check(k, name, float(results[name]), tolerance) for name in CHECKS if name in results]


def verdict(loads: list[dict[str, Any]], tolerance: float | None) -> tuple[dict[str, Any], list[Check]]:
    """The report's verdict on a sweep's results (``{"tolerance", "met", "checks"}``) and its failed checks."""
    limit = DEFAULT_TOLERANCE if tolerance is None else tolerance
    checks = [c for k, results in enumerate(loads) for c in load_checks(k, results, limit)]
    failed = [c for c in checks if not c.ok]
    return {"tolerance": limit, "tolerance_from": "scene" if tolerance is not None else "default",
            "met": not failed, "checks": [c.as_dict() for c in checks]}, failed
