"""The penalty's quadrature on S_C: many points only where the contact edge cuts an element.

The penalty energy of eq. 65 (frictionless),

    Psi(u) = int_{S_C} k_n/2 [s]_+^2 ds,      s = J.n - g_h,

is integrated with ``contact_bonus_order`` extra orders because ``[.]_+``
has a kink where the contact set ends.  On a straight surface element with
the gap interpolated in the displacements' polynomials
(:func:`ngcontact.cell.fe.discrete_cell.discrete_gap`), ``s`` is a polynomial
of degree ``p`` (the order), so wherever an element's points are all in
contact the integrand is the polynomial ``k_n/2 s^2`` of degree ``2p``, and
wherever they are all open it is zero.  On such an element the order ``2p``
rule and the high rule give the same number (both are exact for the
polynomial; residual and tangent likewise), and only elements whose points
disagree in the sign of ``s`` (the contact edge's elements) need the high
rule.  :class:`ContactQuadrature` holds the set ``C`` of those elements and
integrates

    Psi(u) = int_{S_C in C} (high rule) + int_{S_C not in C} (order 2p rule),

which is the energy of the high rule everywhere to round-off wherever ``C``
holds every element whose points disagree.  Each tangent sets ``C`` to the
elements its state cuts, and ``C`` stays through that Newton step's line
search, which thus sees one energy (exact at the step's start, exact to
within the few elements the contact edge crosses during the step along
it).  After a solve the caller checks the final state (:meth:`covers`)
and continues Newton from there when it cuts an element outside ``C``: the
solution returned is that of the high rule everywhere.

The quadrature is what the issue asks by "exact contact quadrature only where
the active set changes": on the 3D bisinusoid cell a few per cent of S_C's
elements carry the high rule.  Energy, residual and tangent are written out
(:func:`ngcontact.laws.penalty.normal_energy`, :func:`~ngcontact.laws.penalty.pressure`,
:func:`~ngcontact.laws.penalty.interface_stiffness`), because NGSolve's
``Variation`` integrates every element whatever its ``definedonelements``.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.cell.fe.cell_energy import jump as _jump
from ngcontact.laws import penalty as _contact

#: relative tolerance of "every point in contact" and "every point open" on an element
UNIFORM_TOL = 1e-10


def applies(problem) -> bool:
    """Whether the penetration is a polynomial on each contact element (straight elements, the gap
    interpolated or absent) and the energy the frictionless penalty: the cases the split is exact for."""
    m = problem.model
    return (problem.multiplier is None and m.friction is None and m.contact_bonus_order > 0
            and problem.mesh.GetCurveOrder() <= 1 and (m.gap is None or m.interpolate_gap))


class ContactQuadrature:
    """The frictionless penalty energy on ``S_C`` with the high rule on the cut elements (module
    docstring): ``Energy``, ``Apply``, ``AssembleLinearization`` and ``mat`` of an interface form."""

    def __init__(self, problem, state: ng.GridFunction):
        m, mesh = problem.model, problem.mesh
        self.state = state
        self.contact = np.array([el.nr for el in mesh.Boundaries("contact").Elements()], dtype=int)
        nbnd = mesh.GetNE(ng.BND)
        #: the elements integrated with the high rule (``C``) and the other contact elements
        self.cut, self.smooth = ng.BitArray(nbnd), ng.BitArray(nbnd)
        self.smooth.Clear()
        self._uncut()
        self._high = 2 * m.order + m.contact_bonus_order
        self._low = 2 * m.order
        self.measures = (ng.ds("contact", definedonelements=self.cut, bonus_intorder=m.contact_bonus_order),
                         ng.ds("contact", definedonelements=self.smooth))
        trial, test = problem.X.TnT()
        J, n, gap, k = _jump(state.components), problem.n, problem.gap, m.k_n
        self._n, self._gap, self._k = n, gap, k
        self._energy = _contact.normal_energy(J, n, k, gap)
        traction = _contact.pressure(J, n, k, gap) * ng.InnerProduct(_jump(test), n)
        self.residual = ng.LinearForm(problem.X)
        self.tangent = ng.BilinearForm(problem.X, symmetric=True,
                                       symmetric_storage=problem.inverse == "sparsecholesky")
        for ds in self.measures:
            self.residual += traction * ds
        for term in self.stiffness_terms(trial, test):
            self.tangent += term
        self._closed = ng.IfPos(-_contact.penetration(J, n, gap), 0.0, 1.0)   # s >= 0, as positive_part
        self._area = {order: self._per_element(ng.CF(1.0), order) for order in (self._high, self._low)}

    @property
    def mat(self):
        return self.tangent.mat

    def stiffness_terms(self, trial, test) -> list:
        """The tangent's integrand at the state with the two measures (also a preconditioning form's
        interface part)."""
        stiffness = _contact.interface_stiffness(_jump(self.state.components), self._n, _jump(trial),
                                                 _jump(test), k_n=self._k, gap=self._gap)
        return [stiffness * ds for ds in self.measures]

    def _per_element(self, cf, order: int) -> np.ndarray:
        mesh = self.state.space.mesh
        values = ng.Integrate(cf, mesh, ng.BND, order=order, element_wise=True, definedon=mesh.Boundaries("contact"))
        return np.asarray(values)[self.contact]

    def cut_elements(self, vec) -> np.ndarray:
        """The contact elements whose points (of either rule) disagree in the sign of ``s`` at ``vec``."""
        self.state.vec.data = vec
        cut = np.zeros(len(self.contact), dtype=bool)
        for order, area in self._area.items():
            closed = self._per_element(self._closed, order)
            cut |= (closed > UNIFORM_TOL * area) & (closed < (1.0 - UNIFORM_TOL) * area)
        return self.contact[cut]

    def restart(self, vec) -> None:
        """``C``: the elements ``vec`` cuts (a new solve's start)."""
        self._uncut()
        self._add(vec)

    def _uncut(self) -> None:
        """``C`` empty: every contact element on the low rule."""
        self.cut.Clear()
        for e in self.contact:
            self.smooth.Set(int(e))

    def covers(self, vec) -> bool:
        """Add the elements ``vec`` cuts to ``C``; whether ``C`` held them all already."""
        return not self._add(vec)

    def _add(self, vec) -> list[int]:
        """Add the elements ``vec`` cuts to ``C``; those that were not in it."""
        new = [int(e) for e in self.cut_elements(vec) if not self.cut[int(e)]]
        for e in new:
            self.cut.Set(e)
            self.smooth.Clear(e)
        return new

    def summary(self) -> dict:
        """JSON-ready: how many of the contact elements carry the high rule now (``C``), and the rules' orders."""
        return {"high_rule_elements": sum(1 for e in self.contact if self.cut[int(e)]),
                "contact_elements": len(self.contact), "high_order": self._high, "low_order": self._low}

    def Energy(self, vec) -> float:  # noqa: N802 (NGSolve's name)
        """``Psi(vec)`` by the residual's rules: order ``2p + contact_bonus_order`` on ``C``, ``2p`` on the
        other contact elements, integrated element by element at those orders, so that :meth:`Apply` is its
        derivative (``Integrate`` of a ``ds`` term would take its own default order, below ``2p`` from
        order 3 on, an energy whose slope along a Newton step differs from the residual's)."""
        self.state.vec.data = vec
        cut = np.array([self.cut[int(e)] for e in self.contact], dtype=bool)
        high = self._per_element(self._energy, self._high)
        low = self._per_element(self._energy, self._low)
        return float(high[cut].sum() + low[~cut].sum())

    def Apply(self, vec, out) -> None:  # noqa: N802
        self.state.vec.data = vec
        self.residual.Assemble()
        out.data = self.residual.vec

    def AssembleLinearization(self, vec) -> None:  # noqa: N802
        """The tangent at ``vec``, with ``C`` the elements ``vec`` cuts."""
        self.restart(vec)                # leaves the state at ``vec``
        self.tangent.Assemble()

    def newton(self, vec, run, rtol: float, atol: float) -> dict:
        """A Newton solve from ``vec`` (updated in place by ``run(rtol, atol)``, which returns the history of
        :func:`ngcontact.solvers.newton.minimize`) whose final state ``C`` covers: while it cuts an element
        outside ``C``, Newton goes on from there to the first solve's residual target.  The history of all
        runs, with :meth:`summary` under ``"contact_quadrature"``."""
        self.restart(vec)
        h = run(rtol, atol)
        target = max(rtol * h["residuals"][0], atol)
        while not self.covers(vec):
            h = _continued(h, run(0.0, target))
        h["contact_quadrature"] = self.summary()
        return h


def _continued(first: dict, more: dict) -> dict:
    """The history of a Newton solve continued from its end by ``more``."""
    out = dict(more)
    out["iterations"] = first["iterations"] + more["iterations"]
    for key in ("residuals", "energies"):
        out[key] = first[key] + more[key][1:]
    for key in ("step_lengths", "active_set_sizes"):
        out[key] = first.get(key, []) + more.get(key, [])
    return out
