"""Homogenized interface laws on the macro interface ``S_0``: one class per law, its formulas with it.

A law (paper eqs. 31-34, 38-44, 69-71) is an energy density ``W(a)`` of the
macro jump ``J = u_rough - u_counter`` written in the interface's local
frame, ``a = (a_n, a_t)`` with ``a_n = J . n0`` and ``a_t = J . t0`` in 2D
and axisymmetry, ``a = (J . n0, J . t1, J . t2)`` in 3D
(:mod:`ngcontact.laws.local_frame`; ``n0`` points from ``rough`` into
``counter``, so ``a_n > 0`` closes the interface).  The macro normal gap
``g0`` (length, ``g0 < 0`` is an initial interference, i.e. a press fit)
shifts the law along ``n0``.  The traction ``tau = dW/da`` is what the rough
body transmits to the counter body; its normal component is the contact
pressure ``p = tau_n`` (compression positive), its tangential part the shear.

Laws (frozen dataclasses), each a class of the protocol of
:mod:`ngcontact.laws.law_protocol` carrying its own energy ``W(a)``,
traction ``tau = dW/da`` and export rows (the normal laws: subclasses of
:class:`NormalLaw`; the friction laws: of :class:`TangentialLaw`);
:mod:`ngcontact.laws.interface_energy` adds them up:

:class:`LinearLaw`
    Anisotropic Winkler law of paper eqs. 34 and 69-71 with the matrix
    ``K0 = [[k_n0, k_nt0], [k_nt0, k_t0]]`` in ``(n0, t0)`` (3D:
    ``[[k_n0, 0, 0], [0, k_t0, 0], [0, 0, k_t0]]`` plus ``k_nt0`` coupling
    ``n0`` and ``t1``) and the gap terms ``g0_vec = (g_n0, g_t0)`` of eq. 34::

        W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a
        tau  = K0 (a - g0 e_n) - g0_vec

    Quadratic and bilateral: it transmits tension too.
:class:`BundleLaw`
    The unilateral law of paper eqs. 31-33 before linearization, a bundle of
    micro directions ``n_q`` (local frame) with weights ``w_q`` [stress /
    length, ``w_q = k_n |ds_q| / |T|``] and micro gaps ``g_q``::

        W(a) = sum_q w_q / 2 [n_q . a - g_q - beta1_q g0]_+^2,   beta1_q = n_q . e_n

    (a uniform macro offset ``g0`` along ``n0`` is a micro gap
    ``beta1_q g0`` along ``n_q``).  With every direction closed its Hessian
    is ``K0 = sum_q w_q n_q n_q^T`` (eq. 34) and it coincides with the
    :class:`LinearLaw` of :func:`linearized`; each direction opens on its own.
:class:`TabulatedLaw`
    Nonlinear normal law ``p(c)`` of the closure ``c = a_n - g0`` from a
    monotone table ``(c_i, p_i)``, ``p_0 = 0``, interpolated linearly, zero
    below ``c_0``, extrapolated with the last slope; written as a sum of
    ramps ``p(c) = sum_i s_i [c - c_i]_+`` (``s_i`` the slope increments), so
    its energy, the integral of the table, is ``sum_i s_i/2 [c - c_i]_+^2``.
    A linear tangential stiffness ``k_t`` may be added.  With
    ``interpolation = "monotone_cubic"`` the nodes are joined instead by the
    shape-preserving C1 cubic of :mod:`ngcontact.laws.monotone_cubic`
    (Fritsch and Carlson): nondecreasing like the table, with a continuous
    tangent at the nodes, zero below ``c_0``, continued with its last node
    slope beyond ``c_last``; the energy is again the integral.  The
    two-scale loop (paper Sec. 3.5, :mod:`ngcontact.coupling.two_scale`)
    hands the cell's own response over as such a cubic table: closure
    ``c(p)`` against pressure.
:class:`Friction`
    Homogenized friction on top of any of them (paper eqs. 38-44): threshold
    ``G = mu0 [p]_+ + G0`` and energy ``G huber(|a_t|, w)`` with
    ``huber(s, w) = s^2/(2w)`` for ``s <= w`` and ``s - w/2`` beyond, so a
    sticking interface slips at most ``w``.  Coulomb's ``G = mu0 p`` is not
    the derivative of an energy; :mod:`ngcontact.macro.macro_problem` treats it by a fixed
    point on the pressure (``G`` frozen at the previous solution's ``p``), see
    there.  The friction energy takes ``G`` as given.
:class:`CellShear`
    In place of :class:`Friction`: the cell's own tangential response, rows
    of shear against tangential jump tabulated at a set of pressures
    (:mod:`ngcontact.coupling.shear_table`), interpolated linearly in both;
    like Coulomb's threshold it depends on the current pressure, and its
    energy is that of the frozen pressure.
"""
from __future__ import annotations

from dataclasses import dataclass

from ngcontact.errors import ModelError
from ngcontact.laws.bundle_law import BundleLaw, linearized
from ngcontact.laws.law_protocol import ExportRows, NormalLaw, TangentialLaw
from ngcontact.laws.linear_law import LinearLaw
from ngcontact.laws.tabulated_law import TabulatedLaw
from ngcontact.laws.tangential_laws import CellShear, Friction

__all__ = ["BundleLaw", "CellShear", "ExportRows", "Friction", "InterfaceLaw", "LinearLaw", "NormalLaw",
           "TabulatedLaw", "Tangential", "TangentialLaw", "linearized", "normal_law"]

#: the friction laws (kept as the name the callers annotate with)
Tangential = TangentialLaw


@dataclass(frozen=True, kw_only=True)
class InterfaceLaw:
    """A normal (and elastic tangential) law, optionally with friction."""

    normal: NormalLaw
    friction: Tangential | None = None

    @property
    def quadratic(self) -> bool:
        """True when the energy is quadratic (one linear solve suffices)."""
        return self.normal.quadratic and self.friction is None

    @property
    def holds_tangentially(self) -> bool:
        """True when a closed interface resists a tangential jump.

        Friction does (the Huber-regularized stick, eq. 34's tangential
        slope), and so does an elastic tangential stiffness ``k_t0 > 0`` of a
        linear, bundle or tabulated law.
        """
        if self.friction is not None:
            return True
        return self.normal.holds_tangentially


def normal_law(law: str, *, kn=None, kt: float = 0.0, knt: float = 0.0, gap_force=(0.0, 0.0),
               weights=None, directions=None, gaps=None, closure=None, pressure=None) -> NormalLaw:
    """The normal law ``law`` ("linear", "bundle" or "tabulated") from its numbers.

    Raises ``ValueError`` (from the law's own checks) when the numbers are
    not admissible; unused numbers are ignored.
    """
    if law == "linear":
        return LinearLaw(kn=kn, kt=kt, knt=knt, gap_force=tuple(gap_force))
    if law == "bundle":
        return BundleLaw(weights=weights, directions=directions, gaps=gaps or ())
    if law == "tabulated":
        return TabulatedLaw(closure=closure, pressure=pressure, kt=kt)
    raise ModelError(f"law {law!r}: must be 'linear', 'bundle' or 'tabulated'")
