"""What a cell problem is (no mesh) and what one load of it gives.

:class:`CellModel` is the physics of the cell problem of paper Sec. 3.4
(eqs. 49-51; the penalized form of eq. 65, or exact non-penetration, the
rigid limit ``k_n -> infinity``): the two bodies' elastic laws, the
interface's penalty ``k_n``, initial gap ``g`` and friction (eqs. 57, 65),
the displacement order and the stopping rules of the fixed points around
Newton's method.  :class:`~ngcontact.cell.fe.cell_problem.CellProblem`
discretizes and solves; a load's results are a
:class:`~ngcontact.cell.cell_solution.CellSolution`.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ng

from ngcontact.errors import ModelError
from ngcontact.fem import materials as _mat
from ngcontact.laws.friction import FrictionLaw


@dataclass(frozen=True)
class CellModel:
    """Physics of a cell problem (no mesh).

    Attributes
    ----------
    rough, counter
        Elastic laws of the two bodies.
    k_n
        Penalty stiffness [stress/length]; with ``enforcement = "exact"``
        the augmentation parameter of the augmented Lagrangian.
    gap
        Initial gap as a CoefficientFunction of the coordinates, or ``None``.
    friction
        :class:`~ngcontact.laws.friction.FrictionLaw` or ``None`` (frictionless).
    order
        Polynomial order of the displacements.
    macro_strain
        Assemble the macro strain term.
    interpolate_gap
        Replace the gap by its interpolant of the displacement order on ``S_C``.
    contact_bonus_order
        Extra integration order on ``S_C`` (the penalty has a kink).
    coulomb_rtol, coulomb_max_iter
        Stopping rule of the Coulomb fixed point.
    enforcement
        ``"penalty"`` (the Winkler layer of eq. 65) or ``"exact"``
        (non-penetration by an augmented Lagrangian,
        :mod:`ngcontact.cell.fe.contact_multiplier`).
    uzawa_rtol, uzawa_max_iter
        Stopping rule of Uzawa's iteration (:mod:`ngcontact.solvers.uzawa`).
    linear_trace
        Exact contact in 3D at ``order >= 2``: the displacements' trace on ``S_C`` of order 1, the bodies
        of ``order`` (:mod:`ngcontact.cell.fe.linear_trace`); ignored elsewhere.
    """

    rough: _mat.ElasticLaw
    counter: _mat.ElasticLaw
    k_n: float
    gap: ng.CoefficientFunction | None = None
    friction: FrictionLaw | None = None
    order: int = 2
    macro_strain: bool = False
    interpolate_gap: bool = True
    contact_bonus_order: int = 12
    coulomb_rtol: float = 1e-8
    coulomb_max_iter: int = 40
    enforcement: str = "penalty"
    uzawa_rtol: float = 1e-10
    uzawa_max_iter: int = 60
    linear_trace: bool = False

    def __post_init__(self):
        if self.enforcement not in ("penalty", "exact"):
            raise ModelError(f"enforcement = {self.enforcement!r}: must be 'penalty' or 'exact'")
        if not (self.uzawa_rtol > 0 and self.uzawa_max_iter >= 1):
            raise ModelError(f"uzawa_rtol = {self.uzawa_rtol!r}, uzawa_max_iter = {self.uzawa_max_iter!r}: "
                             "must be > 0 and >= 1")
