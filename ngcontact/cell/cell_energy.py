"""The energy of the cell problem (paper eqs. 49-51 and 63 in the penalized form of eq. 65).

    Pi(u_r, u_c, U) = sum_B int_B 1/2 (eps(u_B) + E) : C_B : (eps(u_B) + E) dx
                      + int_{S_C} psi(J) ds  -  |T| tbar . U,      J = u_r - u_c - U,

as NGSolve ``Variation`` terms of one symmetric form, whose derivative is
the residual and whose second derivative the tangent of Newton's method
(:mod:`ngcontact.cell.cell_problem` names the unknowns).  The interface
density ``psi`` (:func:`ngcontact.laws.penalty.interface_energy`):

* penalty: ``k_n/2 [J.n - g]_+^2`` (eq. 65), integrated with the contact
  bonus order (the penalty has a kink);
* exact: the augmented Lagrangian with the multiplier held fixed, at the
  Gauss-Lobatto nodes of :mod:`ngcontact.cell.contact_multiplier`;
* friction ``G huber(|J_t|, w)`` (eqs. 57, 65): Tresca ``G``; Coulomb
  ``G = mu p`` of a frozen previous state (penalty: a copy of the state,
  returned for the fixed point to fill) or ``mu lambda`` of the multiplier
  (exact).
"""
from __future__ import annotations

import ngsolve as ng

from ngcontact.laws import penalty as _contact


def cell_energy(problem, ur, uc, U) -> tuple[ng.BilinearForm, ng.GridFunction | None]:
    """The form of ``Pi`` for the trial functions ``(ur, uc, U)`` of ``problem``'s space.

    Returns the form and, for Coulomb friction with the penalty, the
    GridFunction of the frozen previous state whose pressure sets the
    threshold (``None`` otherwise).
    """
    m, mesh = problem.model, problem.mesh
    previous = None
    # UMFPACK reads only one triangle of a symmetric-storage matrix: full storage for it
    form = ng.BilinearForm(problem.X, symmetric=True,
                           symmetric_storage=problem.inverse == "sparsecholesky")
    for name, law, u in (("rough", m.rough, ur), ("counter", m.counter, uc)):
        eps = problem.body_strain(u)
        form += ng.Variation(0.5 * ng.InnerProduct(law.stress(eps), eps)
                             * ng.dx(definedon=mesh.Materials(name)))
    J = ur - uc - U
    lam = None if problem.multiplier is None else problem.multiplier.value
    friction = threshold = w = None
    if m.friction is not None:
        friction, w = m.friction.law, m.friction.w
        if friction == "tresca":
            threshold = m.friction.G
        elif lam is not None:
            # exact: mu lambda of the multiplier Uzawa holds fixed in this Newton solve, so
            # Uzawa's iteration is the Coulomb fixed point as well (cell_problem's docstring)
            threshold = m.friction.mu * lam
        else:
            previous = ng.GridFunction(problem.X)
            pc = previous.components
            J_prev = pc[0] - pc[1] - ng.CF(tuple(pc[2:]))
            threshold = _contact.coulomb_threshold(J_prev, problem.n, m.k_n, m.friction.mu, problem.gap)
    k = m.k_n if lam is None else problem.augmentation
    psi = _contact.interface_energy(J, problem.n, k_n=k, gap=problem.gap, friction=friction,
                                    w=w, threshold=threshold, multiplier=lam)
    ds = (ng.ds("contact", bonus_intorder=m.contact_bonus_order) if problem.multiplier is None
          else problem.multiplier.ds)
    form += ng.Variation(psi * ds)
    t = ng.CF(tuple(problem.traction))
    form += ng.Variation(-ng.InnerProduct(t, U) * ng.ds("top"))
    return form, previous


def macro_strain_cf(params, dim: int):
    """The in-plane macro strain ``E`` of eq. 63 as a 3x3 CoefficientFunction.

    ``params``: 2D ``(e_xx,)``, 3D ``(e_xx, e_yy, e_xy)`` (``Parameter`` objects or numbers).
    """
    e = params
    if dim == 2:
        return ng.CF((e[0], 0, 0, 0, 0, 0, 0, 0, 0), dims=(3, 3))
    return ng.CF((e[0], e[2], 0, e[2], e[1], 0, 0, 0, 0), dims=(3, 3))
