"""The discretization error of a headline quantity from a sequence of locally refined meshes at one order.

Where raising the order no longer pays, the macro refinement (:mod:`ngcontact.drivers.macro_refinement`)
refines the mesh where :mod:`ngcontact.macro.error_indicator` is large and solves again at the same order.
Each mesh level ``k`` gives the quantity ``Q_k``; on every level the order ladder on that mesh
(:mod:`ngcontact.macro.discretization_error`) estimates the error as before.  The sequence adds what the
ladder cannot see: the share of the error that only a finer mesh removes (a corner, where the order
ladder finds a maximum growing with the order and gives no estimate).

The estimate of the finest level ``k`` from the last three levels, with ``d_lo = Q_{k-1} - Q_{k-2}``,
``d_hi = Q_k - Q_{k-1}`` and the observed ratio ``rho = |d_hi| / |d_lo|`` (with four levels or more the
larger of the last two ratios: where successive differences disagree in rate the slower one rules, and
``how`` says so):

* the same sign, ``rho < 1``: the differences fall geometrically (the refinement grades the mesh towards
  the corner by a fixed factor per level, and the error of a corner's quantity falls algebraically in
  the smallest element size, i.e. by a fixed factor per level), so the error left is the sum of the
  differences still to come, ``e_k = 1.5 |d_hi| rho / (1 - rho)``, with the factor of safety
  :data:`~ngcontact.macro.discretization_error.SAFETY` of the order ladder;
* opposite signs, ``rho < 1``: the values oscillate about their limit, which lies between ``Q_{k-1}``
  and ``Q_k``: ``e_k = 1.5 |d_hi|``;
* ``rho >= 1``: the difference does not shrink with the mesh: no limit can be extrapolated (a stress
  singularity grows without bound under refinement).

The reported error is the larger of the ladder's and the sequence's; a quantity without a ladder estimate
(a corner's maximum) takes the sequence's alone, so a corner whose maximum converges under refinement
is estimated, and one that does not stays without an estimate.  A sequence that does not converge while
the ladder has an estimate adds its last difference: ``max(e_ladder, 1.5 |d_hi|)``.

Whether levels grow without a limit (:func:`growing`: rises above round-off and sampling that do not
contract) is decided here once, for the refinement's stop, the corner check of
:mod:`ngcontact.macro.singular_maxima` and the levels at the singular points of
:mod:`ngcontact.macro.away_sequence`.
"""
from __future__ import annotations

import math
from dataclasses import replace

from ngcontact.macro import discretization_error as DE

#: a maximum growing at each level with the last difference at least this share of the first has no limit
#: (:func:`growing`): above the slowest contraction of a converging stress's differences (0.69), below the
#: logarithm's 1 by a margin for a log-singular maximum whose sample points still approach its point
GROWING = 0.75


def _ratio(values: list[float]) -> tuple[float, str]:
    """The observed ratio of the last differences of ``values`` (the larger of the last two) and its text."""
    d = [b - a for a, b in zip(values[:-1], values[1:])]
    ratios = [abs(hi) / abs(lo) if lo != 0 else (0.0 if hi == 0 else math.inf) for lo, hi in zip(d[:-1], d[1:])]
    last = ratios[-2:]
    if len(last) == 2 and max(last) > 2.0 * min(last) and min(last) > 0:
        return max(last), (f"the last ratios {last[0]:.2g} and {last[1]:.2g} disagree in rate: the larger is "
                           "taken")
    return max(last), f"ratio {max(last):.2g}"


def sequence_error(values: list[float], scale: float) -> tuple[float | None, str]:
    """The error of ``values[-1]`` from the mesh levels ``values`` (module docstring) and how; ``None``:
    fewer than three levels or not converging."""
    if len(values) < 3:
        return None, f"{len(values)} mesh level(s): no observed rate yet"
    q0, q1, q2 = values[-3:]
    d_lo, d_hi = q1 - q0, q2 - q1
    head = f"mesh levels {len(values) - 3}-{len(values) - 1} at one order: differences {d_lo:.3g}, {d_hi:.3g}"
    if max(abs(d_lo), abs(d_hi)) <= DE.NOISE * scale:
        return DE.SAFETY * max(abs(d_lo), abs(d_hi)), f"{head}: the levels agree to round-off"
    rho, said = _ratio(values)
    if rho >= DE.NOT_CONVERGING:
        return None, f"{head} ({said}): the difference does not shrink with the mesh (not converging)"
    if d_lo * d_hi < 0:
        return DE.SAFETY * abs(d_hi), f"{head} ({said}): they alternate in sign, {DE.SAFETY:g} x |d_hi|"
    return (DE.SAFETY * abs(d_hi) * rho / (1.0 - rho),
            f"{head} ({said}): {DE.SAFETY:g} x the geometric tail |d_hi| ratio / (1 - ratio)")


def combined(ladder: DE.Estimate, values: list[float]) -> DE.Estimate:
    """The estimate of a quantity on the finest mesh level: the larger of the order ladder's (``ladder``,
    on that mesh) and the mesh sequence's ``values`` (module docstring)."""
    seq, how = sequence_error(values, ladder.scale)
    if len(values) < 3:
        return replace(ladder, how=f"{ladder.how}; {how}")
    if seq is None:
        if ladder.error is None:
            return replace(ladder, how=f"{ladder.how}; {how}")
        last = DE.SAFETY * abs(values[-1] - values[-2])
        return replace(ladder, error=max(ladder.error, last),
                       how=f"{ladder.how}; {how}: at least {DE.SAFETY:g} x the last difference")
    if ladder.error is None:
        return replace(ladder, error=seq, singular_at=None,
                       how=f"{how}; the order ladder on the finest mesh has none ({ladder.how.split(': ')[-1]})")
    if seq > ladder.error:
        return replace(ladder, error=seq, how=f"{how}, larger than the order ladder's ({ladder.how})")
    return replace(ladder, how=f"{ladder.how}; larger than the mesh sequence's ({how})")


def growing(values: list[float], scale: float, sampling: list[float] | None = None, minimum: bool = False) -> bool:
    """Whether a maximum's levels ``values`` (the coarsest first) have no limit: its magnitude grows at each of
    the last three levels by differences that do not contract, ``d_2 >= GROWING d_1``, each resolved, that is
    above round-off (:data:`~ngcontact.macro.discretization_error.NOISE` of ``scale`` or of the values) and
    above the sampling error of the level it starts from (``sampling``, one per level; none: 0).  With
    ``minimum`` the values are a minimum (a safety factor): its reciprocal is the maximum tested for growth,
    and its own falls are the differences that must be resolved.

    A maximum converging at rate ``q`` on levels that halve the elements holding it has differences that
    contract by ``2^-q`` per level: at most ``2^-0.544 = 0.69`` for the pollution of the slowest singular
    point of :mod:`ngcontact.macro.away_maxima`.  One that is unbounded does not: ``log(1/r)`` sampled at
    ``r ~ h_k = 2^-k h_0`` gains a constant per level (ratio 1), ``r^(lambda - 1)`` a factor
    ``2^(1 - lambda) > 1``.  :data:`GROWING` lies between the two (the argument in full:
    :mod:`ngcontact.macro.away_sequence`).  No estimate of the scene's own mesh enters:
    a quantity without a limit has no error to compare its growth with."""
    if len(values) < 3:
        return False
    last = [abs(v) for v in values[-3:]]
    if minimum and not all(0.0 < v < math.inf for v in last):
        return False
    floor = [max(DE.NOISE * max(scale, max(last)), s) for s in (sampling or [0.0] * len(values))[-3:-1]]
    rises = [last[0] - last[1], last[1] - last[2]] if minimum else [last[1] - last[0], last[2] - last[1]]
    q0, q1, q2 = (1.0 / v for v in last) if minimum else last
    return rises[0] > floor[0] and rises[1] > floor[1] and q2 - q1 >= GROWING * (q1 - q0)
