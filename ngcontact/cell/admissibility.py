"""The checks a cell solution must pass to count as an answer, whichever method solved it.

A converged solver is not yet a right answer.  Each load's results are held against what the cell
problem of paper eqs. 49-51 demands of any solution:

* **pressure balance**: the interface force, the pressure field integrated accurately (its sign,
  compression positive, as reported), balances the far-face traction (``pressure_balance`` of the
  results: :func:`ngcontact.cell.fe.measures.pressure_balance`; on a grid, the mean of the grid's
  pressure against the load).  A mesh whose quadrature cannot see a contact patch satisfies its own
  discrete balance and misses this one by the share of the pressure it did not see;
* **small strain**: the cell's mean strain, its far-face jump over its height (``far_face_strain``,
  :mod:`ngcontact.cell.small_strain`), within the bound :data:`~ngcontact.cell.small_strain.SMALL_STRAIN`
  of the linear elasticity of eqs. 49-51, which neglects terms of the order of the strain.  It bounds the
  model, so its limit is that bound, not the scene's tolerance.

and, once per cell, what the model and its discretization assume:

* **small slope**: a cell whose roughness is carried by the gap of a flat interface (the small-slope model,
  both methods) neglects terms of relative order ``slope^2`` against the rough surface it stands for: its
  rms slope is held to ``sqrt(DEFAULT_TOLERANCE) = 0.1`` (:func:`gap_slopes`).  This bounds the model, not
  its discretization, so a scene's ``discretization.tolerance`` does not tighten it;
* **interface resolution**: an FE cell whose gap comes from a height map sees the map through its
  interface elements; an element larger than the map's spacing smooths it away
  (``interface_resolution = h / spacing <= 1``).

A check beyond the scene's accuracy (``discretization.tolerance``, else :data:`DEFAULT_TOLERANCE`) marks
the result as not meeting it; one beyond :data:`PLAINLY_WRONG` means the answer contradicts its own load
and is not reported as one.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from ngcontact.cell.cell_solution import headline, measure, scale
from ngcontact.cell.small_strain import SMALL_STRAIN

#: the accuracy a scene that states none is held to (relative)
DEFAULT_TOLERANCE = 0.01
#: a relative violation at which the result is no answer at all: the integrated pressure misses the load
#: by the load's own size
PLAINLY_WRONG = 1.0
#: the checks of each load: the results' key and what it measures
CHECKS = {"pressure_balance": "the accurately integrated interface force against the far-face traction "
                              "(relative)",
          "rms_slope": "the rms slope of the gap's roughness; the small-slope model neglects terms of order "
                       "slope^2 (limit: sqrt(0.01))",
          "interface_resolution": "the interface element size over the height map's spacing (limit 1: the "
                                  "map is resolved)",
          "far_face_strain": "the cell's mean strain, its far-face jump over its height; the linear elasticity of "
                             f"the cell neglects terms of the order of the strain (limit {SMALL_STRAIN:g})"}
#: the checks of a load that bound the model, with their own limit instead of the scene's tolerance
MODEL_LIMITS = {"far_face_strain": SMALL_STRAIN}


@dataclass(frozen=True)
class Check:
    """One check of one load: its value against its limit."""

    load: int | None            # None: a check of the cell, not of one load
    name: str
    value: float
    limit: float

    @property
    def ok(self) -> bool:
        return self.value <= self.limit

    @property
    def plainly_wrong(self) -> bool:
        """Only a load's balance can contradict the answer; the other checks bound its accuracy."""
        return self.name == "pressure_balance" and not self.value <= PLAINLY_WRONG

    def as_dict(self) -> dict[str, Any]:
        return dict(asdict(self), ok=self.ok, meaning=CHECKS[self.name])

    def message(self) -> str:
        where = "the cell" if self.load is None else f"load {self.load}"
        return f"{where}: {self.name} = {self.value:.3g} exceeds {self.limit:.3g} ({CHECKS[self.name]})"


def load_checks(k: int, results: dict[str, Any], tolerance: float) -> list[Check]:
    """The checks of load ``k`` whose results carry them, against ``tolerance`` or their :data:`MODEL_LIMITS`."""
    return [Check(k, name, float(results[name]), MODEL_LIMITS.get(name, tolerance)) for name in CHECKS
            if name in results]


def gap_slopes(gap: np.ndarray, period: float) -> tuple[float, float]:
    """The rms and the largest slope ``|grad g|`` of a periodic gap sampled on a uniform grid (2D: a line of
    points, 3D: ``[y, x]``), by central differences."""
    g = np.asarray(gap, float)
    h = period / g.shape[-1]
    parts = [(np.roll(g, -1, axis=a) - np.roll(g, 1, axis=a)) / (2 * h) for a in range(g.ndim)]
    slope = np.sqrt(sum(p ** 2 for p in parts))
    return float(np.sqrt(np.mean(slope ** 2))), float(slope.max())


def cell_checks(facts: dict[str, float]) -> list[Check]:
    """The checks of the cell itself from its ``facts`` (``rms_slope``, ``interface_resolution``)."""
    limits = {"rms_slope": float(np.sqrt(DEFAULT_TOLERANCE)), "interface_resolution": 1.0}
    return [Check(None, name, float(facts[name]), limits[name]) for name in limits if name in facts]


#: the quantities whose discretization error every refinement estimates, and how the estimate measures it; a
#: refinement may estimate more of a load's headline quantities (the spectral cell: the coefficients of eq. 34),
#: each in its :func:`~ngcontact.cell.cell_solution.measure`
ESTIMATED = {"contact_fraction": "absolute", "mean_closure": "relative", "normal_stiffness": "relative"}


def quantities(loads: list[dict[str, Any]], estimates: Sequence[dict[str, float]], tolerance: float,
               uncontrolled: Sequence[str] = (), scales: Sequence[dict[str, float]] = (),
               loose: Sequence[dict[str, str]] = ()) -> list[dict[str, Any]]:
    """Per load and estimated quantity: its value, the estimated error (absolute, relative to the value, and
    in the measure the refinement controls, :func:`~ngcontact.cell.cell_solution.measure`, with the scale it
    divides by: the refinement's ``scales`` per load where given), whether that meets ``tolerance`` and
    whether it counts in the verdict (``counted``: not for the ``uncontrolled`` quantities, which the
    refinement reports without holding them to the tolerance) and ``loose``: the refinement's statement that
    the estimate may exceed the error by more than ten times, with its reason (per load in ``loose`` where
    the method makes it, :func:`~ngcontact.cell.spectral.estimate_forms.loose_flags`), else ``None``."""
    out = []
    for k, (results, estimate) in enumerate(zip(loads, estimates)):
        head = headline(results)
        for name in (n for n in estimate if n in head):
            value, e = head[name], float(estimate[name])
            size = scales[k][name] if k < len(scales) and name in scales[k] else scale(name, head)
            absolute = e * size
            out.append({"load": k, "name": name, "value": value, "error": absolute,
                        "relative_error": absolute / abs(value) if value != 0 else None,
                        "controlled": measure(name), "scale": size, "controlled_error": e, "met": e <= tolerance,
                        "counted": name not in uncontrolled,
                        "loose": loose[k].get(name) if k < len(loose) else None})
    return out


def verdict(loads: list[dict[str, Any]], tolerance: float | None, cell: Sequence[Check] = (),
            estimates: Sequence[dict[str, float]] | None = None, how: str = "", reached: bool = True,
            uncontrolled: Sequence[str] = (), scales: Sequence[dict[str, float]] = (),
            loose: Sequence[dict[str, str]] = ()) -> tuple[dict[str, Any], list[Check]]:
    """The report's verdict on a sweep's results and its failed checks.

    ``{"tolerance", "tolerance_from", "met", "checks", "estimated", "quantities", "how"}``: ``cell`` are the
    checks of the cell itself (:func:`cell_checks`); ``estimates`` the refinement's per load (``None``: the
    discretization was not refined, and its error is not estimated), made as ``how`` says; ``reached =
    False``: the refinement stopped at its size bound before it could show the tolerance met (too few levels),
    so the verdict is not met whatever the estimates; ``uncontrolled``: estimated quantities the refinement
    does not hold to the tolerance (listed, not counted); ``scales``: per load what each estimate divides
    the absolute error by, ``loose`` per load the estimates that may exceed their error by more than ten
    times (:func:`quantities`).
    """
    limit = DEFAULT_TOLERANCE if tolerance is None else tolerance
    checks = list(cell) + [c for k, results in enumerate(loads) for c in load_checks(k, results, limit)]
    failed = [c for c in checks if not c.ok]
    estimated = quantities(loads, estimates, limit, uncontrolled, scales, loose) if estimates is not None else []
    out = {"tolerance": limit, "tolerance_from": "scene" if tolerance is not None else "default",
           "met": reached and not failed and all(q["met"] for q in estimated if q["counted"]),
           "checks": [c.as_dict() for c in checks],
           "estimated": estimates is not None, "quantities": estimated,
           "how": how if estimates is not None else (how or "not estimated: set discretization.tolerance to refine "
                                                             "the discretization and estimate its error")}
    return out, failed
