"""The discretization error of a value from its changes over a sequence of refined meshes: one rule, two users.

A quantity ``X`` computed on meshes ``h, h/r, h/r^2, ...`` (``r`` the refinement factor, coarsest first) has
the values ``X_0, X_1, ..., X_n`` and the changes ``d_k = |X_(k-1) - X_k|``, each measured in the quantity's own
norm (a scalar's absolute difference; for the epsilon study's vector errors, :func:`~ngcontact.drivers.
modelling_error.change`).  With ``X`` the limit as the meshes are refined on by ``r``, ``X_j - X =
sum_(k > j) (X_(k-1) - X_k)``, so by the triangle inequality in every norm

    |X_j - X| <= d_(j+1) + ... + d_n + sum_(k > n) d_k.

If each change beyond the last is at most ``q`` times the one before, the unseen sum is at most the geometric tail
``d_n (q + q^2 + ...) = d_n q / (1 - q)``, and the estimate (:func:`tail`) is

    E_j = SAFETY (d_(j+1) + ... + d_n + d_n q / (1 - q)),      SAFETY = 1.5
    (:data:`ngcontact.macro.discretization_error.SAFETY`, as for the macro's ladder: a sharp extrapolation sits
    at an effectivity of 1 and falls below it as often as above).

Which ``q``
    * One change (two meshes): the presumed contraction ``q = r^-RATE`` with :data:`RATE` = 1, an error at
      least linear in ``h``.  Both users' quantities are integrals of the solution over the domain or of the
      traction over the contact surface, whose error is held by the edges of the closed set and the corners
      where the bodies' faces meet; a corner singularity ``r^lambda`` of plane elasticity has
      ``lambda >= 1/2``, so such an integral converges at least like ``h^(2 lambda) >= h``
      (:mod:`ngcontact.drivers.resolved_accuracy`, with the observed contractions on its oracles).  With
      ``r = 2``: the error of the coarser value is ``E_0 = 1.5 d / (1 - 1/2) = 3 d`` (a resolved run's
      default estimate of its own mesh, one uniform refinement), that of the finer ``E_1 = 1.5 d`` (the
      epsilon study's errors, which are the refined pair's).
    * Two changes or more (three meshes): the observed ratio ``q = d_n / d_(n-1)`` where it is slower than
      the presumed ``r^-RATE``, else the presumed: the larger of the two.  The resolved solution with the
      re-entrant corners of its valleys contracts more slowly than the homogenized one, and its own ``q``
      carries that; a faster observed fall is pre-asymptotic, since with those corners (``lambda`` about
      0.54) the L2 norms and the integrals converge like ``h^(2 lambda)``, about linearly, however fast they
      fall on coarse meshes.  On the smallest block of the tests (order 2, ``r = 1.5``) the L2 error over
      the bodies showed the resolved ratio 0.24 on the meshes ``h, h/1.5, h/2.25`` and fell about linearly
      beyond: its tail at the observed ratio was 0.996 of the error against the meshes ``h/18``.  Where ``q >= 1``, or
      ``d_(n-1) = 0 < d_n``, the changes support no tail (the sequence is not yet asymptotic, or the quantity
      sits at its solver's tolerance): the unseen sum is then taken as the largest change continued at the
      presumed contraction, ``max_k d_k q0 / (1 - q0)`` with ``q0 = r^-RATE`` (``contracts`` false), no
      smaller than any step the meshes took once ``r <= 2``.

Changes below ``noise`` (round-off and the solver's tolerance: the values agree) have no contraction to
take: the estimate is ``SAFETY`` times the largest change.

The epsilon study (:mod:`ngcontact.drivers.study_epsilon`) applies it to each level's errors: with two meshes
to the change of the signed difference of the pair (:func:`~ngcontact.drivers.modelling_error.
discretization_errors`), with three to each solution's changes, summing the resolved and the homogenized
solution's estimates (``|e_2 - e| <= |R_2 - R| + |H_2 - H|`` for the finest pair's error ``e_2 = H_2 - R_2``).
Why each solution there, not the difference: the two converge each at its own rate, and their changes may
cancel in one step of the difference and not in the next, so the ratio of the difference's changes shows a
contraction neither solution has.  The resolved run's default estimate
(:mod:`ngcontact.drivers.resolved_accuracy`) applies it to its headline quantities on its mesh and that mesh
refined uniformly once, and so does the study to the resolved contact fraction of each level.
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ngcontact.macro.discretization_error import SAFETY

#: the slowest rate in ``h`` of the quantities' discretization error (module docstring)
RATE = 1.0


@dataclass(frozen=True)
class Tail:
    """The estimate of a value's discretization error from its changes (module docstring).

    ``ratio``: the observed ``d_n / d_(n-1)`` (``None`` with one change, or where ``d_(n-1) = 0 < d_n``; ``0``
    where nothing moved); ``contracts``: whether the unseen sum is a geometric tail (else the largest change
    continued at the presumed contraction).
    """

    estimate: float
    ratio: float | None
    contracts: bool


def presumed_ratio(refinement: float) -> float:
    """The contraction of an error at the slowest rate :data:`RATE` per refinement of ``h`` by ``refinement``."""
    if not refinement > 1:
        raise ValueError(f"refinement {refinement!r}: the meshes are refined by a factor above 1")
    return float(refinement) ** -RATE


def tail(changes: Sequence[float], refinement: float, member: int = -1, noise: float = 0.0) -> Tail:
    """:class:`Tail` of the value ``member`` (``0`` the coarsest, ``-1`` the finest) of a sequence of values on
    meshes refined by ``refinement`` each, from the norms ``changes`` of its successive changes, coarsest
    first (module docstring); changes at most ``noise`` are round-off."""
    d = [float(c) for c in changes]
    if not d:
        raise ValueError("no change: a discretization estimate needs values on two meshes at least")
    if any(c < 0 for c in d):
        raise ValueError(f"changes are norms: got {d!r}")
    start = member % (len(d) + 1)
    seen = sum(d[start:])
    q0 = presumed_ratio(refinement)
    ratio: float | None = None
    if len(d) >= 2:
        ratio = d[-1] / d[-2] if d[-2] > 0 else (0.0 if d[-1] == 0 else None)
    if max(d) <= noise:
        return Tail(estimate=SAFETY * max(d), ratio=ratio, contracts=True)
    if len(d) == 1:
        q, contracts = q0, True
    elif ratio is not None and ratio < 1:
        q, contracts = max(ratio, q0), True
    else:
        return Tail(estimate=SAFETY * (seen + max(d) * q0 / (1.0 - q0)), ratio=ratio, contracts=False)
    return Tail(estimate=SAFETY * (seen + d[-1] * q / (1.0 - q)), ratio=ratio, contracts=contracts)


def of_values(values: Sequence[float], refinement: float, member: int = -1, noise: float = 0.0) -> Tail:
    """:func:`tail` of a scalar's ``values`` on the meshes (coarsest first), its changes their differences."""
    return tail([abs(b - a) for a, b in zip(values, values[1:])], refinement, member, noise)
