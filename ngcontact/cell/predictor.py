"""Start value of the cell problem: the rigid predictor.

The Newton solve of the cell problem (paper eqs. 49-51 in the penalized
variational form of eq. 65, :mod:`ngcontact.cell.cell_problem`) needs a start
for the first load under a prescribed pressure ``p``.  Its tangent is
singular in the far-face translation ``U_n`` while nothing is in contact, and
Newton's active-set updates converge slowly (each step halves the distance
of a contact edge) when they start with the whole surface ``S_C`` closed.

The *rigid predictor* sets the fluctuations to zero and translates the
counter by the normal approach ``d`` that minimizes the energy over rigid
normal translations alone, i.e. the root of

    R(d) = int_{S_C} k_n [d n.n0 - g]_+ (n.n0) ds - p |T| = 0

(the penalty layer alone carries the pressure: a Winkler foundation of
stiffness ``k_n``; the integrand is the normal part of the penalty force
``k_n [J.n - g]_+ n`` of eq. 65 for the rigid jump ``J = -U = d n0``).  Because
``k_n`` is much stiffer than the bodies, this under-estimates the contact
set, and Newton approaches the contact edges from the open side, where each
step moves them most of the way.  ``start="closed"`` of
:class:`~ngcontact.cell.cell_problem.CellProblem` restores the earlier start
instead: the counter pushed down by the largest gap plus ``p/k_n``
(:func:`max_gap`).
"""
from __future__ import annotations

import logging

import ngsolve as ng

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.measures import contact_integral, sample_surface
from ngcontact.laws import penalty as _contact
from ngcontact.solvers.newton import illinois_root

log = logging.getLogger(__name__)


def rigid_approach(problem, p: float) -> float:
    """Normal approach ``d`` of the rigid predictor: root of ``R(d)`` (module docstring).

    ``R`` is nondecreasing and piecewise linear in ``d`` at the
    quadrature points of the contact energy; the root is bracketed by
    doubling and found by the Illinois variant of regula falsi.  The
    predicted state has at least one quadrature point in contact, so
    the first tangent is regular in ``U_n``.
    """
    k_n, area = problem.model.k_n, problem.area
    n0 = problem.n[problem.dim - 1]
    dpar = ng.Parameter(0.0)
    pen = dpar * n0 if problem.gap is None else dpar * n0 - problem.gap
    force = k_n * _contact.positive_part(pen) * n0
    order = problem.contact_order

    def R(dv):
        dpar.Set(dv)
        return float(contact_integral(problem, force, order=order)) - p * area

    lo, flo = 0.0, R(0.0)
    scale = max_gap(problem) + p / k_n
    if flo >= 0.0:            # interference: already pressed at d = 0
        hi, fhi = lo, flo
        lo = -scale
        while (flo := R(lo)) >= 0.0:
            lo *= 2.0
    else:
        hi = scale
        while (fhi := R(hi)) <= 0.0:
            lo, flo, hi = hi, fhi, 2.0 * hi
    d = illinois_root(R, lo, flo, hi, fhi, ftol=1e-12 * p * area, xtol=1e-14 * abs(hi),
                      max_iter=200)
    log.debug("rigid predictor: approach %.6e for pressure %.6e", d, p)
    return d


def max_gap(problem) -> float:
    """Largest initial gap at the quadrature points of ``S_C`` (0 without gap)."""
    if problem.gap is None:
        return 0.0
    vals = sample_surface(problem, {"g": problem.gap})["g"]
    return float(max(vals.max(), 0.0))


def set_start(problem, load: CellLoad) -> None:
    """Put the start of a first load under a prescribed pressure into ``problem.gfu``.

    ``problem.start == "rigid"``: fluctuations zero, prescribed jumps kept,
    the counter translated by :func:`rigid_approach`; ``"closed"``: only
    ``U_n`` is set, to the largest gap plus ``p/k_n``.

    Raises
    ------
    ValueError
        The normal pressure is not positive (a free layer has no unique
        rigid position).
    """
    d = problem.dim
    vec, u_dofs = problem.gfu.vec, problem.u_dofs
    p = -load.traction[d - 1]
    if not p > 0:
        raise ValueError(f"normal pressure {p!r}: must be > 0 (a free layer has no unique "
                         "rigid position); prescribe a normal jump instead")
    if problem.start == "closed":
        vec[u_dofs[d - 1]] = -(max_gap(problem) + p / problem.model.k_n)
    else:
        vec[:] = 0.0
        for i in range(d):
            jump = load.jump[i]
            if jump is not None:
                vec[u_dofs[i]] = -jump
        vec[u_dofs[d - 1]] = -rigid_approach(problem, p)
