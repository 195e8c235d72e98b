"""The error of the last of a sequence of FE discretizations, from the rate the sequence shows (Richardson).

A quantity ``q`` (a load's contact fraction, mean closure or normal stiffness) solved on discretizations
``0, 1, ..., n`` of one knob (the order on one mesh, or the interface element size halved each time) gives
values ``q_0 .. q_n`` and differences ``d_j = |q_j - q_(j-1)|``.  Where the errors ``e_j = q_j - q`` fall
geometrically, ``e_j = rho e_(j-1)``, the differences do too, with the same ratio, and the error of the last
value is the tail of the geometric series

    |e_n| = d_n rho / (1 - rho),        rho = d_n / d_(n-1)

(Richardson extrapolation with the observed order: for a knob that divides the element size by ``r``,
``rho = r^(-a)`` with ``a`` the observed order).  The value reported is ``q_n`` and the estimate is its
error, not the error of an earlier level.  How the observed ratio is used is the knob's
:class:`Convergence`:

* ``rho`` is the larger of the last :data:`WINDOW` successive ratios (four discretizations give two: where
  they disagree by more than :data:`DISAGREE`, the estimate says so and takes the larger);
* it is held to ``[floor, cap]``: ``floor`` is the slowest contraction the knob guarantees (halving the
  element size at least halves the error of a contact fraction, whose edges cut elements anywhere: first
  order), so an observed faster ratio (pre-asymptotic, or an edge that happened to fall on a vertex) is not
  trusted below it; a sequence contracting by less than ``cap`` is taken as contracting by ``cap``;
* the tail is multiplied by ``safety``: the observed ratio is that of the last step, and the next one may be
  slower (the contraction of ``p``-refinement grows slowly with ``p`` where the solution has a ``sqrt``
  edge; a halved mesh moves the contact edges within their elements);
* with two discretizations only (the third beyond the size bound), ``rho`` is the knob's ``assumed`` ratio.

The effectivity (estimate over the true error of the reported value) is measured against the oracles of
``scripts/fe_effectivity.py`` (``docs/benchmarks.md``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ngcontact.cell.cell_solution import COEFFICIENT, scale

#: successive ratios the estimate looks at
WINDOW = 2
#: two successive ratios further apart than this factor are said to disagree
DISAGREE = 2.0


def ratio_text(ratio: float) -> str:
    """A ratio of successive differences in a remark; one after a level without change has no finite value."""
    return f"{ratio:.2g}" if math.isfinite(ratio) else "unbounded (the level before changed nothing)"


@dataclass(frozen=True)
class Convergence:
    """How a knob's sequence of answers may be assumed to converge (module docstring)."""

    #: the slowest contraction per level the knob guarantees (an observed faster one is not trusted below it)
    floor: float
    #: the contraction assumed where none is observed (two discretizations), and at most ``cap``
    assumed: float
    #: a sequence contracting by less than this is taken as contracting by it
    cap: float
    #: the factor on the geometric tail
    safety: float

    def tail(self, values: list[float], relative: bool, scale: float | None = None) -> tuple[float, str]:
        """The estimated error of the last of ``values`` (absolute, or relative to the last value, or divided
        by ``scale`` where given) and a remark where the ratios disagree or a guard acted ("" otherwise).
        Needs two values at least."""
        d = [abs(b - a) for a, b in zip(values[:-1], values[1:])]
        if scale is None:
            scale = abs(values[-1]) if relative and values[-1] != 0 else 1.0
        if d[-1] == 0.0 and max(d) == 0.0:
            return 0.0, ""
        ratios = [d[j] / d[j - 1] if d[j - 1] > 0 else float("inf") for j in range(1, len(d))][-WINDOW:]
        remark = []
        if not ratios:
            rate = self.assumed
            remark.append(f"two discretizations: ratio {self.assumed:g} assumed")
        else:
            observed = max(ratios)
            if len(ratios) > 1 and max(ratios) > DISAGREE * min(ratios):
                remark.append("successive ratios disagree (" + ", ".join(ratio_text(r) for r in ratios)
                              + "): the larger taken")
            if observed > self.cap:
                remark.append(f"not contracting (ratio {ratio_text(observed)}): ratio {self.cap:g} taken")
            rate = min(max(observed, self.floor), self.cap)
        return self.safety * d[-1] * rate / (1.0 - rate) / scale, "; ".join(remark)

    def describe(self) -> str:
        """The rule in words, for the report's ``accuracy.how``."""
        floor = f", held to at least {self.floor:g}" if self.floor > 0 else ""
        return (f"{self.safety:g} x the geometric tail of the last difference at the larger observed ratio of "
                f"successive differences{floor} ({self.assumed:g} assumed with two discretizations)")


def sequence_estimates(levels: list[list[dict[str, float]]], rule: Convergence, measures: dict[str, bool],
                       whole: dict | None = None) -> tuple[list[dict[str, float]], list[str]]:
    """Per load the estimate of each quantity of the last level and the remarks.

    ``levels[i][k]`` holds load ``k``'s headline quantities on discretization ``i``; ``measures`` names the
    quantities estimated and whether relatively; with ``whole`` (the last level's whole-surface
    coefficients) the coefficients of eq. 34 among them are estimated too, relative to their group there
    (:func:`~ngcontact.cell.cell_solution.scale`), unless zero on every level.  A quantity missing on some
    level is not estimated."""
    estimates, remarks = [], []
    for k in range(len(levels[-1])):
        out: dict[str, float] = {}
        last = levels[-1][k]
        names = dict(measures)
        if whole is not None:
            names.update({n: False for n in last if n.startswith(COEFFICIENT)})
        for name, relative in names.items():
            values = [lv[k][name] for lv in levels if name in lv[k]]
            if len(values) != len(levels) or (name.startswith(COEFFICIENT) and not any(values)):
                continue
            size = scale(name, last, whole) if name.startswith(COEFFICIENT) else None
            out[name], note = rule.tail(values, relative, size)
            if note:
                remarks.append(f"load {k} {name}: {note}")
        estimates.append(out)
    return estimates, remarks


def exponent(ndofs: list[float], errors: list[float], assumed: tuple[float, float]) -> float | None:
    """The exponent ``a`` of errors falling like ``N^(-a)`` in the unknowns ``N``: observed
    on the last two ``(ndofs, errors)`` pairs, else from ``assumed = (ratio per level, growth of the unknowns
    per level)``; ``None`` where neither shows the errors falling as the unknowns grow
    (:mod:`ngcontact.cell.fe.default_refinement`)."""
    if len(ndofs) >= 2 and ndofs[-1] > ndofs[-2] and 0 < errors[-1] < errors[-2]:
        return math.log(errors[-2] / errors[-1]) / math.log(ndofs[-1] / ndofs[-2])
    if 0 < assumed[0] < 1 < assumed[1]:
        return math.log(1 / assumed[0]) / math.log(assumed[1])
    return None


def dofs_to_meet(ndof: float, estimate: float, tolerance: float, a: float | None) -> tuple[float, float] | None:
    """The unknowns ``N = N_n (e_n / tol)^(1/a)`` meeting ``tolerance`` from an estimate ``e_n`` on ``N_n``
    unknowns, and ``a``; ``None`` without a finite estimate or an exponent."""
    if a is None or a <= 0 or not math.isfinite(estimate):
        return None
    return ndof * max(estimate / tolerance, 1.0) ** (1 / a), a
