"""The discretization error of the finest of three discretizations: the Richardson tail of two changes.

A level of the epsilon study solved on the discretizations ``h``, ``h/r`` and ``h/r^2``
(``study.meshes = 3``, ``r = study.refinement``) gives three signed differences ``e_0, e_1, e_2`` of each
quantity (homogenized minus resolved, :mod:`ngcontact.drivers.modelling_error`) and two changes, each
measured in the quantity's own norm relative to the finest resolved solution
(:func:`~ngcontact.drivers.modelling_error.change`):

    d_1 = |e_0 - e_1|,   d_2 = |e_1 - e_2|,   q = d_2 / d_1  (the observed ratio).

Let ``e`` be the limit of ``e_k`` as the meshes are refined on by ``r`` (the modelling error).  Then

    e_2 - e = sum_{k >= 2} (e_k - e_(k+1)),   |e_2 - e| <= sum_{k >= 2} |e_k - e_(k+1)|

by the triangle inequality, in every norm: it holds for vector quantities (the field, the probes, the
reactions) whose changes turn from one refinement to the next, and for a scalar whose changes alternate in
sign, where the signed sum is smaller still.  If each change is at most ``q`` times the one before, as the
two observed ones are, the sum is at most the geometric tail

    |e_2 - e| <= d_2 (q + q^2 + ...) = d_2 q / (1 - q)     (q < 1),

the Richardson estimate (:func:`tail`) of the finest pair's discretization error.  It takes the
contraction the changes show, not one an element order promises: a quantity near a corner singularity
contracts more slowly than its smooth part, and the observed ``q`` carries that.  It is at least ``d_2``
once ``q >= 1/2`` (the two-mesh rule's estimate of the finer pair, ``d_2``, presumes ``q <= 1/2``), and
smaller than ``d_2`` only where the changes themselves fall faster than by half.

Where the ratio does not contract (``q >= 1``, or ``d_1 = 0 < d_2``) the changes support no tail: the
sequence is not yet asymptotic, or the quantity is at the level of its solver's tolerance.  The estimate is
then the largest change ``max(d_1, d_2)`` (``contracts`` false), no smaller than either step the
discretizations took, and the study's results list the levels where it was used.
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
