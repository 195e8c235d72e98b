"""What every homogenized interface law implements: the macro energy and the exporters ask nothing else.

A homogenized law (paper eqs. 31-34, 38-44) is one class.  The macro
problem (:mod:`ngcontact.macro.macro_energy`, through
:mod:`ngcontact.laws.interface_energy`) and the exporters
(:mod:`ngcontact.export.law_source`) call the methods below and never ask a
law for its type, so a new law is a new subclass and nothing else changes.
Every method works on NumPy arrays (tables, tests, reports) and on NGSolve
CoefficientFunctions (the energy forms) alike.

The local jump is ``a = (a_n, a_t)`` (2D, axisymmetry) or ``(a_n, a_t1,
a_t2)`` (3D) in the interface's frame (:mod:`ngcontact.laws.local_frame`,
``a_n > 0`` closes), ``g0`` the macro normal gap (``< 0``: interference).

:class:`NormalLaw`, the normal (and elastic tangential) law::

    energy(a, g0)       W(a), the interface energy density of eq. 44
    traction(a, g0)     tau = dW/da, what the rough body transmits; p = tau_n (compression positive)
    energy(a, g0, closed=True)
                        the quadratic "all closed" surrogate (a start value for Newton)
    full_contact_K0(d)  the tangent d^2W/da^2 in full contact, K0 of eq. 34 (None without one)
    stiffness, quadratic, holds_tangentially
                        what the solution strategy and the stick/slip status need
    export_rows()       the exact normal curve and the stiffness numbers the exporters write

:class:`TangentialLaw`, friction on top of a normal law (paper eqs. 38-44),
with a threshold field ``G`` held fixed in its energy::

    threshold_at(p)     G of the pressure p (G = mu0 [p]_+ + G0 for Huber friction, eqs. 42-43)
    energy(a, G)        W_f(a)
    traction(a, G)      tau_f = dW_f/da  (G frozen)
    coulomb, width      whether G follows the pressure; the largest slip of a sticking point
    huber_regularized, with_width(w)
                        the Huber width a continuation may change
"""
from __future__ import annotations

import abc
from dataclasses import dataclass

import numpy as np

from ngcontact.errors import ModelError


@dataclass(frozen=True)
class ExportRows:
    """What a normal law gives the exporters (:mod:`ngcontact.export.law_table`).

    Attributes
    ----------
    kinks, slopes
        The exact normal curve under a purely normal closure ``c``,
        ``p(c) = sum_i s_i [c - c_i]_+`` [length], [stress / length].
    stick_slope
        ``k_t0`` [stress / length], the tangential stiffness of a closed interface.
    K0
        The tangent in full contact (eq. 34), ``None`` for a law without ``k_nt0``.
    gap_force
        ``(g_n0, g_t0[, g_t1])`` of eq. 34 [stress] with ``K0``, else ``None``.
    bundle
        ``{"weights", "directions", "gaps"}`` of a direction bundle, else ``None``.
    bilateral
        True when the law transmits tension too.
    """

    kinks: np.ndarray
    slopes: np.ndarray
    stick_slope: float
    K0: np.ndarray | None = None
    gap_force: np.ndarray | None = None
    bundle: dict | None = None
    bilateral: bool = False


class NormalLaw(abc.ABC):
    """A homogenized normal (and elastic tangential) law ``W(a)`` (module docstring)."""

    @abc.abstractmethod
    def energy(self, a, g0=0.0, closed: bool = False):
        """Energy density ``W(a)`` at the local jump ``a`` with the macro gap ``g0``.

        With ``closed`` the quadratic "all closed" surrogate: a start value
        for Newton that holds every body in place.
        """

    @abc.abstractmethod
    def traction(self, a, g0=0.0) -> list:
        """``tau = dW/da`` of :meth:`energy`: the local traction components."""

    @property
    @abc.abstractmethod
    def stiffness(self) -> float:
        """The largest normal slope ``dp/dc`` [stress / length] (the quadratic start's tangential spring)."""

    def full_contact_K0(self, dim: int) -> np.ndarray | None:
        """The tangent ``d^2W/da^2`` with the interface closed everywhere, ``K0`` of eq. 34
        (``dim`` = 2 or 3); ``None`` for a law without ``k_nt0`` (a table)."""
        return None

    @property
    def quadratic(self) -> bool:
        """True when the energy is quadratic (one linear solve suffices)."""
        return False

    @property
    def holds_tangentially(self) -> bool:
        """True when a closed interface resists a tangential jump: ``k_t0 > 0``."""
        K0 = self.full_contact_K0(2)
        return K0 is not None and bool(K0[1, 1] > 0)

    def export_rows(self) -> ExportRows:
        """The exact normal curve and the stiffness numbers of :class:`ExportRows`."""
        raise ModelError(f"a {type(self).__name__} cannot be exported")


class TangentialLaw(abc.ABC):
    """Homogenized friction on top of a :class:`NormalLaw` (module docstring)."""

    @property
    @abc.abstractmethod
    def width(self) -> float:
        """The largest tangential jump of a sticking point [length] (the stick/slip status of the measures)."""

    @abc.abstractmethod
    def threshold_at(self, p):
        """The threshold field ``G`` of the pressure ``p``."""

    @abc.abstractmethod
    def energy(self, a, G):
        """Friction energy density ``W_f(a)`` with the threshold ``G`` given."""

    @abc.abstractmethod
    def traction(self, a, G) -> list:
        """``d/da`` of :meth:`energy` (``G`` frozen): local traction components."""

    @property
    @abc.abstractmethod
    def coulomb(self) -> bool:
        """True when ``G`` depends on the current pressure (solved by the coupled Newton or a fixed point)."""

    @property
    def huber_regularized(self) -> bool:
        """True when ``width`` is a Huber width that a continuation may widen and narrow again
        (:meth:`with_width`, :mod:`ngcontact.macro.macro_problem`)."""
        return False

    def with_width(self, width: float) -> TangentialLaw:
        """The same law with the Huber width ``width`` (a law that is :attr:`huber_regularized`)."""
        raise ModelError(f"a {type(self).__name__} has no Huber width to continue in")
