"""The error of the whole-surface coefficients of an FE cell, from one geometry order more.

The coefficients of the whole contact surface (paper eq. 34 with ``w = 1``, and eqs. 42-43),

    K0_pq = (1/|T|) int_S_C k_n beta_p beta_q ds,   ...     (:mod:`ngcontact.cell.coefficients`)

need no solve: their only discretization error is that of the surface itself, the mesh's order-``p``
interpolant of ``S_C`` (its normals ``beta`` and its arc length ``ds``), integrated by a quadrature exact
far beyond it.  On a polygonal profile (Example 27's rectangular and triangular valleys, Example 26's square
hills) the interpolant is the surface and the coefficients are exact to round-off; on a curved one
(Example 27's semicircular valley) the order-``p`` arcs miss it by ``O(h^(p+1))`` pointwise.

The estimate is the saturation bound of :mod:`ngcontact.cell.fe.saturation` on the same mesh one geometry
order higher: with ``d = |c_(p+1) - c_p|`` and the higher order keeping at most a fraction ``beta`` of the
lower order's error, ``|c_p - c| <= d / (1 - beta)``, at ``beta =``
:data:`~ngcontact.cell.fe.saturation.SATURATION` (``3/4``).  Here the higher order divides the error many
times over (a smooth arc interpolated one order higher), so the estimate is about ``1 / (1 - beta) = 4``
times the error, between the bounds 1 and 10 of an honest estimate; ``c_p`` is reported, the scene's own
numbers.  The cost is a second mesh and a surface integral, no solve.

The report's verdict on them: :mod:`ngcontact.cell.whole_surface`.
"""
from __future__ import annotations

from typing import Any

from ngcontact.cell.fe.saturation import SATURATION
from ngcontact.cell.whole_surface import flat

#: how the estimate is made, for the report's ``accuracy.how``
HOW = (f"d / (1 - {SATURATION:g}), d the change of each whole-surface coefficient one geometry order more on "
       "the same mesh makes (the saturation assumption)")


def estimates(lower: dict[str, Any], higher: dict[str, Any]) -> dict[str, float]:
    """The absolute error of each scalar coefficient of ``lower`` (the scene's geometry order) from
    ``higher`` (one order more): ``|higher - lower| / (1 - SATURATION)``."""
    low, high = flat(lower), flat(higher)
    return {name: abs(high[name] - value) / (1.0 - SATURATION) for name, value in low.items() if name in high}
