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
    * Two changes or more (three meshes): the larger of two tails, the observed ratio
      ``q = d_n / d_(n-1)``'s extrapolation with the factor of safety and the bound of the presumed ratio
      ``q0 = r^-RATE`` without one,

          E_n = max(SAFETY d_n q / (1 - q), d_n q0 / (1 - q0)).

      Where ``q >= q0`` the first is the larger.  Where the change fell faster than presumed the two disagree
      in rate (the study's rows carry ``q``), and the second holds the estimate: it is what the presumed rate
      alone bounds (every change beyond at most ``q0`` times the one before, the corners' argument above), and
      a fast observed fall may be pre-asymptotic: with the re-entrant corners of the resolved valleys
      (``lambda`` about 0.54) the L2 norms and the integrals converge like ``h^(2 lambda)``, about linearly,
      however fast they fall on coarse meshes.  The first takes over from ``q = 1 / (1 + SAFETY (1/q0 - 1))``
      (4/7 at ``r = 1.5``), so the estimate is continuous in ``q``, and at ``q = q0`` it is the two-mesh
      rule's ``SAFETY d_n q0 / (1 - q0)``.  Why not that rule wherever ``q < q0``: a third mesh that saw the
      change fall faster than presumed is the margin the safety was held for, and on the smallest block of the
      tests (order 2, ``r = 1.5``, each solution's changes on the meshes ``h, h/1.5, h/2.25``, the true error
      against the pair on ``h/9``) it put the estimates of the probes and the interior H1 norm at 11.6 and
      11.4 times their errors (the resolved solution's ratios 0.60 and 0.42), above the ten the estimates
      are held to; the rule here gives 9.2 and 7.6.  Why not the observed ratio alone: the resolved
      solution's L2 norm over the bodies showed 0.24 there, then 0.49 and 1.68 on the next meshes, and its
      estimate fell to 0.86 of the error against the pair on ``h/27``; the rule here gives 2.1.
      Where ``q >= 1``, or ``d_(n-1) = 0 < d_n``, the changes support no tail (the sequence is not yet
      asymptotic, or the quantity sits at its solver's tolerance): the unseen sum is then taken as the largest
      change continued at the presumed contraction, ``max_k d_k q0 / (1 - q0)`` (``contracts`` false), no
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
        return Tail(estimate=SAFETY * (seen + d[-1] * q0 / (1.0 - q0)), ratio=ratio, contracts=True)
    if ratio is None or ratio >= 1:
        return Tail(estimate=SAFETY * (seen + max(d) * q0 / (1.0 - q0)), ratio=ratio, contracts=False)
    observed = SAFETY * (seen + d[-1] * ratio / (1.0 - ratio))
    presumed = seen + d[-1] * q0 / (1.0 - q0)
    return Tail(estimate=max(observed, presumed), ratio=ratio, contracts=True)

def of_values(values: Sequence[float], refinement: float, member: int = -1, noise: float = 0.0) -> Tail:
    """:func:`tail` of a scalar's ``values`` on the meshes (coarsest first), its changes their differences."""
    return tail([abs(b - a) for a, b in zip(values, values[1:])], refinement, member, noise)
