"""Micro friction laws on ``S_C``: one class per law (paper eqs. 9, 16-17).

A friction law is the threshold ``G`` of the tangential traction (paper
eq. 17: stick while ``|tau| < G``, slip at ``|tau| = G``) together with
the Huber-regularized energy that enforces it (paper eqs. 9, 16)::

    psi_t(J) = G huber(|J_t|, w),      tau = G J_t / max(|J_t|, w),

``J_t`` the tangential jump and ``w`` the Huber width (the largest slip of
a sticking point; :mod:`ngcontact.laws.huber`, :mod:`ngcontact.laws.penalty`).

* :class:`Tresca`: a given threshold ``G``;
* :class:`Coulomb`: ``G = mu p``, ``p`` the contact pressure.

A law whose threshold depends on the pressure (``couples_to_pressure``)
has no potential: the solvers take its threshold from a frozen previous
pressure (a fixed point of problems with a given threshold) or from the
pressure of the unknown state itself (the coupled Newton of
:mod:`ngcontact.solvers.coulomb_newton`).  With exact enforcement the FE
cell takes the pressure from the contact multiplier and the spectral cell
takes the law's threshold without the Huber width (exact friction).

The homogenized (macro) friction of paper eqs. 42-43 is its own object,
:class:`ngcontact.laws.homogenized.Friction`.

A new law is one subclass (its ``name``, the scene keys of its numbers in
``parameters``, ``couples_to_pressure`` and :meth:`FrictionLaw.threshold`)
entered in :data:`FRICTION_LAWS`, plus its numbers in the cell scene's
``[contact]`` section; the registry is the one map from a scene's name to
a class (the scene's choice list, :func:`ngcontact.drivers.build.micro_friction`).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

from ngcontact.errors import ModelError
from ngcontact.laws import penalty as _contact


@dataclass(frozen=True, kw_only=True)
class FrictionLaw(ABC):
    """A micro friction law with Huber width ``w > 0``: its threshold and its energy (module docstring).

    ``w = None`` is exact (unregularized) friction, which only the spectral cell with exact enforcement
    solves; every regularized use needs ``w > 0``.
    """

    w: float | None
    #: the law's name in scenes and reports
    name: ClassVar[str]
    #: the keys of the law's numbers (fields of the class and of the cell scene's ``[contact]``)
    parameters: ClassVar[tuple[str, ...]]
    #: whether the threshold depends on the contact pressure (no potential: a fixed point or coupled Newton)
    couples_to_pressure: ClassVar[bool] = False

    def __post_init__(self) -> None:
        if self.w is not None and not self.w > 0:
            raise ModelError(f"friction width w = {self.w!r}: must be > 0")

    @abstractmethod
    def threshold(self, p):
        """The threshold ``G`` at the contact pressure ``p``.

        ``p`` is a CoefficientFunction (the FE problems), a NumPy array
        (the spectral cell) or a number; a law that does not couple to the
        pressure ignores it (``None`` is then accepted).
        """

    def affine_parts(self) -> tuple[float, float]:
        """``(G_0, mu)`` of a threshold affine in the pressure, ``G(p) = G_0 + mu p``.

        The homogenized threshold ``mu0 p + G0`` (paper eq. 43) is affine;
        :func:`ngcontact.coupling.cell_law.friction_from_bundle` reduces
        each part over the cell's contact surface.
        """
        g0 = self.threshold(0.0)
        return float(g0), float(self.threshold(1.0) - g0)

    def energy(self, J, n, G):
        """Energy density ``G huber(|J_t|, w)`` of the threshold ``G`` (paper eqs. 9, 16)."""
        return _contact.tresca_energy(J, n, G, self.w)

    def traction(self, J, n, G):
        """Tangential traction on the counter body, ``G J_t / max(|J_t|, w)`` (paper eq. 17)."""
        return _contact.friction_traction(J, n, G, self.w)

    def stiffness(self, J, n, dJ, dJv, G):
        """Second variation of :meth:`energy` at ``J`` (``G`` held fixed), bilinear in ``dJ`` and ``dJv``."""
        return _contact.friction_stiffness(J, n, dJ, dJv, G, self.w)


@dataclass(frozen=True, kw_only=True)
class Tresca(FrictionLaw):
    """Tresca friction: the given threshold ``G >= 0`` (paper eqs. 16-17)."""

    G: float
    name: ClassVar[str] = "tresca"
    parameters: ClassVar[tuple[str, ...]] = ("G", "w")

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.G is None or self.G < 0:
            raise ModelError(f"Tresca threshold G = {self.G!r}: must be >= 0")

    def threshold(self, p=None):
        """``G``, whatever the pressure."""
        return self.G


@dataclass(frozen=True, kw_only=True)
class Coulomb(FrictionLaw):
    """Coulomb friction: the threshold ``G = mu p`` of the contact pressure, ``mu >= 0``."""

    mu: float
    name: ClassVar[str] = "coulomb"
    parameters: ClassVar[tuple[str, ...]] = ("mu", "w")
    couples_to_pressure: ClassVar[bool] = True

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.mu is None or self.mu < 0:
            raise ModelError(f"Coulomb coefficient mu = {self.mu!r}: must be >= 0")

    def threshold(self, p):
        """``mu p``."""
        return self.mu * p


#: name -> class: the friction laws a scene can name
FRICTION_LAWS: dict[str, type[FrictionLaw]] = {law.name: law for law in (Tresca, Coulomb)}
