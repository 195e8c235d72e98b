"""The interface energy ``W(a)`` of a homogenized law and its gradient, the traction.

Adds up the laws of :mod:`ngcontact.laws.homogenized` at the local jump
``a = (a_n, a_t)`` (2D, axisymmetry) or ``(a_n, a_t1, a_t2)`` (3D) of
:mod:`ngcontact.laws.local_frame`, with the macro normal gap ``g0``.  The
traction ``tau = dW/da`` is what the rough body transmits to the counter
body, its normal component the contact pressure ``p = tau_n`` (compression
positive).  Each law carries its own formulas (the protocol of
:mod:`ngcontact.laws.law_protocol`); this module only calls them, so a new
law is one class and nothing here changes:

* the normal (and elastic tangential) law ``W_normal``, ``tau_normal``:
  :func:`normal_energy`, :func:`normal_traction`, :func:`pressure`
  (``LinearLaw``: paper eqs. 34 and 69-71; ``BundleLaw``: eqs. 31-33;
  ``TabulatedLaw``: a monotone table ``p(c)``).  With ``closed=True``
  :func:`normal_energy` is the quadratic "all closed" surrogate (a start
  value for Newton);
* the friction law (paper eqs. 38-44) with its threshold field ``G`` held
  fixed, :func:`threshold`, :func:`friction_energy`,
  :func:`friction_traction` (``Friction``: ``G = mu0 [p]_+ + G0`` and the
  Huber energy ``G huber(|a_t|, w)``; ``CellShear``: the cell's tabulated
  shear at the frozen pressure ``p = G``);
* the total, the interface integrand of eq. 44, :func:`energy` and
  :func:`traction`::

      W   = W_normal(a; g0) + W_f(a; G)
      tau = tau_normal(a; g0) + tau_f(a; G)

  with ``G = threshold(friction, 0)`` (``G0`` only) unless a threshold
  field is given.

All functions work on NumPy arrays (for tests and tables) and on NGSolve
CoefficientFunctions alike.
"""
from __future__ import annotations

from ngcontact.laws.homogenized import InterfaceLaw, NormalLaw, Tangential


def normal_energy(law: NormalLaw, a, g0=0.0, closed: bool = False):
    """Energy density of the normal (and elastic tangential) law at local jump ``a``.

    Parameters
    ----------
    law
        Any :class:`~ngcontact.laws.law_protocol.NormalLaw`.
    a
        Local jump components ``(a_n, a_t)`` or ``(a_n, a_t1, a_t2)``.
    g0
        Macro normal gap (number or CoefficientFunction); ``< 0`` interference.
    closed
        Replace the law by its quadratic "all closed" surrogate: every bundle
        direction active, the table's first segment extended both ways (a
        start value for Newton that holds every body in place).
    """
    return law.energy(a, g0, closed)


def normal_traction(law: NormalLaw, a, g0=0.0) -> list:
    """``dW/da`` of :func:`normal_energy`: local traction components."""
    return law.traction(a, g0)


def pressure(law: NormalLaw, a, g0=0.0):
    """Contact pressure ``p = tau_n`` (compression positive)."""
    return normal_traction(law, a, g0)[0]


def friction_energy(friction: Tangential, a, G):
    """``G huber(|a_t|, w)`` with the threshold field ``G`` given; for a ``CellShear``,
    ``W_t(a; p)`` with the frozen pressure ``p = G`` (:func:`threshold`)."""
    return friction.energy(a, G)


def friction_traction(friction: Tangential, a, G) -> list:
    """``d/da`` of :func:`friction_energy` (``G`` frozen)."""
    return friction.traction(a, G)


def threshold(friction: Tangential, p):
    """``G = mu [p]_+ + G0`` for a pressure ``p``; a ``CellShear`` depends on ``p`` itself."""
    return friction.threshold_at(p)


def energy(law: InterfaceLaw, a, g0=0.0, G=None):
    """Total interface energy density; ``G`` is the friction threshold field
    (default: ``threshold(friction, 0)``, i.e. ``G0`` only)."""
    W = normal_energy(law.normal, a, g0)
    if law.friction is not None:
        if G is None:
            G = threshold(law.friction, 0.0)
        W = W + friction_energy(law.friction, a, G)
    return W


def traction(law: InterfaceLaw, a, g0=0.0, G=None) -> list:
    """Local traction ``dW/da`` of :func:`energy` (same ``G``)."""
    tau = normal_traction(law.normal, a, g0)
    if law.friction is not None:
        if G is None:
            G = threshold(law.friction, 0.0)
        ft = friction_traction(law.friction, a, G)
        tau = [t + f for t, f in zip(tau, ft)]
    return tau
