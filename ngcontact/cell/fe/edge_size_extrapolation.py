"""Richardson extrapolation of a 3D cell's contact fraction in the element size at its contact edge.

On the mesh refined along the contact edge
(:mod:`ngcontact.cell.fe.contact_edge_mesh`), with order-2 bodies on a
linear trace on ``S_C`` (:mod:`ngcontact.cell.fe.linear_trace`), the bodies'
error is of higher order and what is left of the contact fraction's error
is the node-to-node contact set's: the contact edge is placed from the
nodes around it (:mod:`ngcontact.cell.fe.exact_contact_set`) within a part
of the element size ``h`` at the edge, so that

    f(h) = f + C h + o(h),

the first-order term of one sign (the nodal contact set reaches beyond
the edge).  Two solves at ``h`` and ``r h`` (``r > 1``) then give

    f ~ (r f(h) - f(r h)) / (r - 1),

and a third size the observed rate ``q`` of the two successive differences
(``f(h) - f(r1 h)`` against ``f(r1 h) - f(r2 h)``), with which the
extrapolation is repeated.  Where the observed rate is outside
:data:`RATE_RANGE` the sizes are not in the asymptotic range: the
extrapolation keeps the first order and says so.  The range ends at 1:
the expansion's leading term is of first order, so a faster observed rate
(the last difference shrunk by more than the size's ratio) is the ``o(h)``
terms or the mesh's own scatter (where the edge falls among the nodes
differs from mesh to mesh by a part of ``h``) shortening the last step,
not a faster convergence, and taking it would correct by less than the
first-order term ``(f(rh) - f(h)) / (r - 1)`` that remains; a slower one
(down to ``1/2``) says the ``o(h)`` terms still add to the first-order
one, and extrapolates further.

The estimate of the extrapolated value's error.  With two sizes: the
correction itself, ``|f - f(h)|`` (nothing smaller is known from two
points).  With three, the finest value's error is split as

    f(h) - f_conv = E_0 + C h^q + o(h^q),

``C h^q`` the part the edge size carries (what the differences see) and
``E_0`` the part of the knobs the sequence keeps fixed (the element size
away from the edge and in the bodies, the linear trace's consistency on
``S_C``): constant along the sequence, it cancels in every difference and
Richardson keeps it, ``f - f_conv = E_0 + o(h^q)``.  No combination of the
three values can see ``E_0``; the disagreement of two extrapolations (the
finer and the coarser pair, the first order and the observed rate) measures
the ``o(h^q)`` remainder only, and alone it under-bounds the error wherever
``E_0`` is the larger part.  The estimate is therefore Roache's grid
convergence index of the finest value (P. J. Roache, J. Fluids Eng. 116
(1994) 405-413),

    GCI = F_s |f(h) - f(r h)| / (r^q - 1) = F_s |c|,    c = f(h) - f,

the correction ``c`` Richardson made, times the safety factor ``F_s``
(:data:`SAFETY`: 1.25 where three sizes show a rate in range, Roache's
three-grid factor; 3 where the first order is assumed for want of a rate,
his two-grid one; 2 where the rate shows faster than first order and the
first order is taken, in between: the differences' sign and ratio are
observed, but the correction is not the one they fit), and at least the last difference and the
extrapolations' disagreement.  It bounds the extrapolated value's error
``|E_0 + o(h^q)|`` as long as the part the sequence keeps fixed is at most
``F_s`` times the part it removed at the finest size: the premise of
refining the edge alone (the contact fraction's error is made at the edge,
:mod:`ngcontact.cell.fe.contact_edge_mesh`).  Its effectivity against the
converged bisinusoid is measured by ``scripts/bisinusoid_accuracy.py``
(docs/benchmarks.md, section ``scaling_3d``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

#: observed rates outside this range are not taken (the sizes are not asymptotic)
RATE_RANGE = (0.5, 1.0)
#: the grid convergence index's safety factor: with a rate observed in range, with one observed faster than the
#: range and the first order taken, with the first order assumed (no rate: the differences change sign or
#: the rate is slower than the range)
SAFETY = {"observed": 1.25, "faster": 2.0, "assumed": 3.0}


@dataclass(frozen=True)
class EdgeSizeExtrapolation:
    """The extrapolated value, its estimated error, the rate used and how it was found."""

    value: float
    estimate: float
    rate: float
    how: str


def extrapolate(sizes: list[float], values: list[float]) -> EdgeSizeExtrapolation:
    """Richardson extrapolation of ``values`` at edge ``sizes`` to size 0 (module docstring).

    ``sizes`` are at least two distinct positive element sizes, any order; the finest two extrapolate, a
    third gives the observed rate; the estimate is the module docstring's (two sizes: the correction; three:
    the grid convergence index).
    """
    if len(sizes) != len(values) or len(sizes) < 2:
        raise ValueError(f"{len(sizes)} sizes and {len(values)} values: two or more of each are needed")
    pairs = sorted(zip(sizes, values))
    h = [float(s) for s, _ in pairs]
    f = [float(v) for _, v in pairs]
    if not (h[0] > 0 and all(b > a for a, b in zip(h, h[1:]))):
        raise ValueError(f"sizes = {sizes}: must be distinct and > 0")
    r = h[1] / h[0]
    first = _richardson(f[0], f[1], r, 1.0)
    if len(h) == 2:
        return EdgeSizeExtrapolation(value=first, estimate=abs(first - f[0]), rate=1.0,
                                     how="first order in the edge size (two sizes), the correction its estimate")
    q = _observed_rate(h[:3], f[:3])
    if q is not None and RATE_RANGE[0] <= q <= RATE_RANGE[1]:
        rate, safety = q, SAFETY["observed"]
        how = f"observed rate {q:.2f} of three edge sizes"
    else:
        rate, safety = 1.0, SAFETY["faster" if q is not None and q > RATE_RANGE[1] else "assumed"]
        how = (f"first order in the edge size: the observed rate {q if q is None else round(q, 2)} "
               f"of three sizes is outside {RATE_RANGE}")
    value = _richardson(f[0], f[1], r, rate)
    coarser = _richardson(f[1], f[2], h[2] / h[1], rate)
    estimate = max(safety * abs(f[0] - value), abs(f[0] - f[1]), abs(value - coarser), abs(value - first))
    return EdgeSizeExtrapolation(value=value, estimate=estimate, rate=rate,
                                 how=f"{how}; estimate {safety:g} x the correction (grid convergence index)")


def _richardson(fine: float, coarse: float, r: float, q: float) -> float:
    """``(r^q f(h) - f(r h)) / (r^q - 1)``."""
    w = r ** q
    return (w * fine - coarse) / (w - 1.0)


def _observed_rate(h: list[float], f: list[float]) -> float | None:
    """The rate ``q`` of ``f(h_k) = f + C h_k^q`` through three sizes (bisection on the ratio of the
    differences), ``None`` where the differences change sign or vanish."""
    d1, d2 = f[1] - f[0], f[2] - f[1]
    if d1 == 0.0 or d2 == 0.0 or (d1 > 0) != (d2 > 0):
        return None
    target = d2 / d1

    def ratio(q: float) -> float:
        return (h[2] ** q - h[1] ** q) / (h[1] ** q - h[0] ** q)

    lo, hi = 1e-3, 8.0
    if not (ratio(lo) - target) * (ratio(hi) - target) < 0:
        return None
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if (ratio(lo) - target) * (ratio(mid) - target) <= 0:
            hi = mid
        else:
            lo = mid
    q = 0.5 * (lo + hi)
    return q if math.isfinite(q) else None
