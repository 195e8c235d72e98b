"""The discretization error of the finest of three discretizations: the Richardson tails of the changes.

A level of the epsilon study solved on the discretizations ``h``, ``h/r`` and ``h/r^2``
(``study.meshes = 3``, ``r = study.refinement``) gives of each quantity three values of the resolved
solution, ``R_0, R_1, R_2``, and three of the homogenized one, ``H_0, H_1, H_2``; the error reported is the
finest pair's signed difference ``e_2 = H_2 - R_2`` (:mod:`ngcontact.drivers.modelling_error`).  Let ``R``
and ``H`` be the limits as the meshes are refined on by ``r``; the modelling error is ``e = H - R`` and

    |e_2 - e| <= |R_2 - R| + |H_2 - H|.

Each solution's two changes, measured in the quantity's own norm relative to the finest resolved solution
(:func:`~ngcontact.drivers.modelling_error.change`), are

    d_1 = |X_0 - X_1|,   d_2 = |X_1 - X_2|,   q = d_2 / d_1  (the observed ratio),   X = R or H,

and ``X_2 - X = sum_{k >= 2} (X_k - X_(k+1))``, so ``|X_2 - X| <= sum_{k >= 2} |X_k - X_(k+1)|`` by the
triangle inequality in every norm: it holds for vector quantities (the field, the probes, the reactions)
whose changes turn from one refinement to the next, and for a scalar whose changes alternate in sign, where
the signed sum is smaller still.  If each change is at most ``q`` times the one before, as the two observed
ones are, the sum is at most the geometric tail

    |X_2 - X| <= d_2 (q + q^2 + ...) = d_2 q / (1 - q)     (q < 1),

the Richardson estimate (:func:`tail`); the estimate of the finest pair's discretization error is the sum of
the two solutions' tails.  It takes the contraction each solution's changes show, not one an element order
promises: the resolved solution, with the re-entrant corners of its valleys, contracts more slowly than the
homogenized one, and its own ``q`` carries that.  A tail is at least ``d_2`` once ``q >= 1/2`` (the two-mesh
rule's estimate of the finer pair presumes ``q <= 1/2``), and smaller than ``d_2`` only where the changes
themselves fall faster than by half.

Why each solution, not the difference ``e_k``: the two solutions converge each at its own rate, and their
changes may cancel in one step of the difference and not in the next (both move together from the coarsest
meshes; on the finer step the homogenized one has stopped and the resolved one still moves).  The ratio of
the difference's changes then shows a contraction neither solution has (slower or faster), and its tail
rests on an assumption about the difference that neither solution's convergence implies; the sum of the
solutions' tails bounds ``|e_2 - e|`` under the stated assumption on each.

Where a solution's ratio does not contract (``q >= 1``, or ``d_1 = 0 < d_2``) its changes support no tail:
the sequence is not yet asymptotic, or the quantity is at the level of its solver's tolerance.  That
solution's term is then its largest change ``max(d_1, d_2)`` (``contracts`` false), no smaller than either
step the discretizations took, and the study's results list the levels where it was used.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tail:
    """The estimate of a quantity's finest discretization error from its two changes (module docstring).

    ``ratio``: the observed ``d_2 / d_1`` (``None`` where ``d_1 = 0 < d_2``; ``0`` where nothing moved);
    ``contracts``: whether the estimate is the geometric tail (else the largest change).
    """

    estimate: float
    ratio: float | None
    contracts: bool


def tail(first: float, second: float) -> Tail:
    """:class:`Tail` of the changes ``first = d_1`` (coarse to middle) and ``second = d_2`` (middle to fine)."""
    if first < 0 or second < 0:
        raise ValueError(f"changes are norms: got {first!r} and {second!r}")
    if second == 0:
        return Tail(estimate=0.0, ratio=0.0, contracts=True)
    if first == 0:
        return Tail(estimate=second, ratio=None, contracts=False)
    q = second / first
    if q < 1:
        return Tail(estimate=second * q / (1.0 - q), ratio=q, contracts=True)
    return Tail(estimate=max(first, second), ratio=q, contracts=False)
