"""The error of an FE cell that cannot be graded, by a second discretization and the difference.

Grading towards the contact edges (:mod:`ngcontact.cell.fe.edge_grading`) needs the flat 2D interface whose
edges are points on a line.  A 3D cell (edges are curves), a curved ``S_C`` (square hills, a conforming
profile) or a frictional load path (solved in order, not afresh per load) is estimated instead by solving
the same sweep once more on a richer discretization and comparing:

* **one order more on the same mesh** (``p -> p + 1``) wherever the enforcement allows it (the penalty in
  2D and 3D; exact contact in 2D).  Away from the contact edges the fields are smooth and the bulk's
  error falls by a factor ``h^(p+1)``-like with each order; at the edges the pressure behaves like
  ``sqrt(r)`` and the error of the edge location falls with ``p`` by a fixed factor of about
  ``2^(-1/2)`` per element layer it is smeared over, so the order raise at least halves the error of
  the contact fraction and of the mean closure (at worst it leaves the edge's contribution where it was
  and removes the bulk's);
* **the interface element size halved** (``h -> h/2``, the body mesh as before) where it does not: exact
  contact in 3D, held to order 1 (quadratic triangles leave corner nodes open inside a contact patch).
  The contact fraction of a uniform mesh converges like ``h`` (an edge cuts its elements anywhere, and
  the fraction counts the cut elements' area to first order), the closure like ``h^(3/2)`` or faster, so
  halving ``h`` halves the error at least.

In both, the error ``e_2`` of the richer solution is at most half the error ``e_1`` of the first, so
``|q_1 - q_2| >= e_1 - e_2 >= e_2``: the difference bounds the error of the richer solution, which is the
one reported (the same argument as the graded loop's and the spectral grid doubling's).  Because the
edge term of a uniform mesh does not fall monotonically (it depends on where the edge cuts its element),
the estimate is the difference times :data:`SAFETY` (2: it still bounds ``e_2`` where the ratio
``e_2/e_1`` is up to 2/3).  Per load: the contact fraction absolutely, the mean closure and the effective
stiffness relatively, as the refinement's estimates everywhere (:mod:`ngcontact.cell.admissibility`).
"""
from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Any, Callable

from ngcontact.cell.cell_solution import CellSolution, headline
from ngcontact.errors import ConvergenceError

log = logging.getLogger(__name__)
#: the run's progress lines
progress = logging.getLogger("ngcontact.progress")

#: estimate over the difference of the two discretizations (module docstring)
SAFETY = 2.0


@dataclass(frozen=True)
class SecondDiscretization:
    """The richer discretization of a cell: its order and interface element size, and in words."""

    order: int
    interface_maxh: float | None
    how: str

    def ndof(self, ndof: int, dim: int, order: int) -> int:
        """The dofs it will have, from the first's: ``((p+2)/(p+1))^dim`` times for an order raise, ``4``
        times (an upper bound: only the interface's elements shrink) for a halved 3D interface."""
        if self.order > order:
            return int(ndof * ((self.order + 1) / (order + 1)) ** dim)
        return int(ndof * 2 ** (dim - 1))


def second_of(dim: int, order: int, enforcement: str, interface_maxh: float) -> SecondDiscretization:
    """The richer discretization of a cell (module docstring): one order more where the enforcement allows
    it, else the interface element size halved."""
    if enforcement == "penalty" or dim == 2:
        return SecondDiscretization(order + 1, None, f"the sweep again at order {order + 1} on the same mesh: "
                                    f"{SAFETY:g} x the change (the order raise at least halves the error)")
    return SecondDiscretization(order, interface_maxh / 2, f"the sweep again with interface_maxh halved to "
                                f"{interface_maxh / 2:g}: {SAFETY:g} x the change (the contact fraction converges "
                                "like h, the closure faster)")


def change(first: list[CellSolution], second: list[CellSolution]) -> list[dict[str, float]]:
    """Per load, :data:`SAFETY` times the change of the contact fraction (absolute), the mean closure and the
    normal effective stiffness (relative; :func:`~ngcontact.cell.cell_solution.headline`)."""
    out = []
    for a, b in zip(first, second):
        qa, qb = headline(a.results), headline(b.results)
        est = {}
        for name in qb:
            d = abs(qb[name] - qa[name])
            est[name] = SAFETY * (d / abs(qb[name]) if name != "contact_fraction" and qb[name] != 0 else d)
        out.append(est)
    return out


@dataclass
class Compared:
    """The richer sweep, its estimates and the record of both discretizations."""

    solutions: list[CellSolution]
    estimates: list[dict[str, float]]
    levels: list[dict[str, Any]]


def compare(first: Callable[[], list[CellSolution]], second: Callable[[], list[CellSolution]],
            tolerance: float, required: bool, how: str) -> Compared:
    """Both sweeps, the estimate per load (module docstring); ``required`` and over ``tolerance``: the
    :class:`~ngcontact.errors.ConvergenceError` with the figures."""
    levels = []
    sweeps = []
    for name, run in (("scene", first), ("second", second)):
        t0 = time.perf_counter()
        sweeps.append(run())
        levels.append({"discretization": name, "seconds": time.perf_counter() - t0,
                       "contact_fraction": [s.results["contact_fraction"] for s in sweeps[-1]],
                       "mean_closure": [s.results["mean_closure"] for s in sweeps[-1]]})
        progress.info("FE error estimate, %s discretization: %.2f s", name, levels[-1]["seconds"])
    estimates = change(sweeps[0], sweeps[1])
    worst = max((max(e.values()) for e in estimates), default=0.0)
    if required and worst > tolerance:
        raise ConvergenceError(f"discretization.tolerance = {tolerance:g} not met: the estimate is {worst:.3g} "
                               f"({how}); refine interface_maxh or raise the order", {"levels": levels})
    return Compared(solutions=sweeps[1], estimates=estimates, levels=levels)
