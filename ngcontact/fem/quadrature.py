"""The integration-order policy: how many quadrature orders each kind of integrand gets.

With displacements of polynomial order ``p`` the integrands of the package
fall into five kinds, and every integral names its kind instead of a bare
number:

* :func:`energy_order` ``2p``: the rule NGSolve assembles an energy form
  with; an integral that must equal the assembled residual (a discrete
  reaction) uses it too;
* :func:`sampling_order` ``2p + 2``: quadrature points at which fields are
  sampled for reports, plots and the Coulomb fixed point (a product of two
  degree-``p`` fields plus one order for curved elements);
* :func:`smooth_order` ``2p + 4``: smooth integrands over the contact
  surface (mean jumps, projected areas; two orders of reserve);
* :func:`resultant_order` ``2p + 6``: pressure and traction resultants
  weighted by ``2 pi r`` in axisymmetry (one more factor of degree one);
* :func:`kink_order` ``4p + 24``: integrands with a kink or a jump inside
  an element (the positive part ``[J_n - g]_+``, the indicator of the
  contact set): no rule is exact, so many points resolve where the contact
  edge cuts the element.

The contact energy itself is integrated at ``2p + bonus`` with the cell's
``contact_bonus_order`` (the energy's own term, chosen by the cell model).
"""
from __future__ import annotations


def energy_order(order: int) -> int:
    """``2p``: the assembly rule of the energy forms; discrete reactions that must balance the residual."""
    return 2 * order


def sampling_order(order: int) -> int:
    """``2p + 2``: sampling points of fields on a boundary."""
    return 2 * order + 2


def smooth_order(order: int) -> int:
    """``2p + 4``: smooth integrands over the contact surface."""
    return 2 * order + 4


def resultant_order(order: int) -> int:
    """``2p + 6``: resultants of the traction, with the axisymmetric weight ``2 pi r``."""
    return 2 * order + 6


def kink_order(order: int) -> int:
    """``4p + 24``: integrands with a kink or jump inside an element (contact sets, positive parts)."""
    return 4 * order + 24
