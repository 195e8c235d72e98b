"""The energy of the cell problem (paper eqs. 49-51 and 63 in the penalized form of eq. 65).

    Pi(u_r, u_c, U) = sum_B int_B 1/2 (eps(u_B) + E) : C_B : (eps(u_B) + E) dx
                      + int_{S_C} psi(J) ds  -  |T| tbar . U,      J = u_r - u_c - U,

as NGSolve ``Variation`` terms of one symmetric form, whose derivative is
the residual and whose second derivative the tangent of Newton's method
(:mod:`ngcontact.cell.fe.cell_problem` names the unknowns).  The interface
density ``psi`` (:func:`ngcontact.laws.penalty.interface_energy`):

* penalty: ``k_n/2 [J.n - g]_+^2`` (eq. 65), integrated with the contact
  bonus order (the penalty has a kink); where the penetration is a
  polynomial per element, Newton integrates it with that order on the
  contact edge's elements only, to the same numbers
  (:mod:`ngcontact.cell.fe.contact_quadrature`);
* exact: the augmented Lagrangian with the multiplier held fixed, at the
  Gauss-Lobatto nodes of :mod:`ngcontact.cell.fe.contact_multiplier`;
* friction ``G huber(|J_t|, w)`` (eqs. 57, 65) with the threshold of the
  law (:mod:`ngcontact.laws.friction`): Tresca ``G``; Coulomb
  ``G = mu p`` of a frozen previous state (penalty: a copy of the state,
  returned for the fixed point to fill) or ``mu lambda`` of the multiplier
  (exact).

Coulomb with the penalty, solved by the coupled Newton of
:mod:`ngcontact.solvers.coulomb_newton` (:func:`coulomb_residual`): no
energy exists, so the form is the residual itself, the same terms with the
friction written as its traction ``mu p(J) J_t / max(|J_t|, w)`` tested
with the jump of the test function, the threshold ``mu p(J)`` of the
unknown state (``mu k_n [J.n - g]_+``), so that the linearization is the
consistent, non-symmetric tangent.
"""
from __future__ import annotations

import ngsolve as ng

from ngcontact.cell.fe.discrete_cell import DiscreteCell
from ngcontact.fem import elasticity as _el
from ngcontact.solvers.split_energy import StateForm
from ngcontact.laws import penalty as _contact


def cell_energy(cell: DiscreteCell) -> tuple[ng.BilinearForm, ng.GridFunction | None, tuple]:
    """The form of ``Pi`` for the trial functions ``(u_r, u_c, U)`` of ``cell``'s space.

    Returns the form, for Coulomb friction with the penalty the
    GridFunction of the frozen previous state whose pressure sets the
    threshold (``None`` otherwise), and the forms of its two parts ``(Q,
    Psi)``: the bodies with the load potential (quadratic) and the interface
    energy, with the same terms (for :class:`ngcontact.solvers.split_energy.SplitEnergy`).
    """
    trial = cell.X.TrialFunction()
    form, quadratic, interface = _new_form(cell), _new_form(cell), _new_form(cell)
    for term in _bodies(cell, trial[0], trial[1]) + [_load(cell, trial)]:
        form += term
        quadratic += term
    parameters, previous = _interface_parameters(cell)
    psi = _contact.interface_energy(jump(trial), cell.n, **parameters)
    term = ng.Variation(psi * _contact_measure(cell))
    form += term
    interface += term
    return form, previous, (quadratic, interface)


def interface_tangent(cell: DiscreteCell, state: ng.GridFunction, previous: ng.GridFunction | None = None
                      ) -> StateForm:
    """The interface's second variation ``Psi''`` at ``state``, written out as a bilinear form of the state
    (:func:`ngcontact.laws.penalty.interface_stiffness` of the energy's own parameters and quadrature):
    the same matrix as linearizing the energy's ``Variation`` term, assembled by ``Assemble`` in about
    half its time (:class:`ngcontact.solvers.split_energy.StateForm`; the split energy's tangent)."""
    form = _new_form(cell)
    form += _interface_stiffness(cell, state, previous)
    return StateForm(form, state)


def preconditioning_form(cell: DiscreteCell, state: ng.GridFunction, quadrature=None,
                         previous: ng.GridFunction | None = None) -> StateForm | None:
    """The form a BDDC preconditioner of the cell's tangent is built from: the tangent itself, written as a
    bilinear form of ``state`` (the bodies' elasticity and :func:`interface_tangent`'s term), plus each
    body's bubble term on ``S_C`` (:func:`ngcontact.fem.elasticity.bubble_term`, with the body's
    longitudinal modulus and the contact stiffness: ``k_n``, or the augmentation of exact enforcement), so
    that BDDC's coarse cell needs only the vertex dofs of the contact surface.  Never assembled as the
    tangent.  ``quadrature``: the split contact quadrature
    (:class:`ngcontact.cell.fe.contact_quadrature.ContactQuadrature`) whose measures the interface term uses.

    ``None`` where the whole form serves: at order 1 (every dof is a vertex's, no bubbles), and for
    Coulomb friction with the penalty, whose coupled residual is not an energy's and keeps the contact
    surface on BDDC's wirebasket (set here, on ``cell.X``).
    """
    m = cell.model
    if previous is not None:
        _el.surface_wirebasket(cell.X, cell.mesh, "contact")
        return None
    if m.order < 2:
        return None
    pre = _new_form(cell)
    trial, test = cell.X.TnT()
    for i, (name, law) in enumerate((("rough", m.rough), ("counter", m.counter))):
        pre += _el.bilinear_integrand(law, trial[i], test[i], cell.setting) * ng.dx(
            definedon=cell.mesh.Materials(name))
    if quadrature is None:
        pre += _interface_stiffness(cell, state, previous)
    else:
        for term in quadrature.stiffness_terms(trial, test):
            pre += term
    for i, law in enumerate((m.rough, m.counter)):
        pre += _el.bubble_term(trial[i], test[i], law.longitudinal_modulus, _contact_stiffness(cell), "contact")
    # the load's potential is linear in U, its second variation zero; its face's elements couple U with the
    # face's dofs all the same, so that this form's sparsity is the whole form's (SplitEnergy.rebuild)
    pre += 0.0 * ng.InnerProduct(ng.CF(tuple(trial[2:])), ng.CF(tuple(test[2:]))) * ng.ds("top")
    return StateForm(pre, state)


def _interface_stiffness(cell: DiscreteCell, state, previous):
    """The integrand of ``Psi''(state)`` on ``S_C`` with its measure."""
    trial, test = cell.X.TnT()
    parameters, _ = _interface_parameters(cell, previous)
    return (_contact.interface_stiffness(jump(state.components), cell.n, jump(trial), jump(test), **parameters)
            * _contact_measure(cell))


def jump(u):
    """``J = u_r - u_c - U`` of the components ``(u_r, u_c, U...)`` of trial or test functions or of a state."""
    return u[0] - u[1] - ng.CF(tuple(u[2:]))


def _contact_stiffness(cell: DiscreteCell):
    """The contact stiffness of the interface energy: ``k_n``, or the augmentation of exact enforcement."""
    return cell.model.k_n if cell.multiplier is None else cell.augmentation


def _new_form(cell: DiscreteCell) -> ng.BilinearForm:
    # UMFPACK reads only one triangle of a symmetric-storage matrix: full storage for it
    return ng.BilinearForm(cell.X, symmetric=True, symmetric_storage=cell.inverse == "sparsecholesky")


def coulomb_residual(cell: DiscreteCell) -> ng.BilinearForm:
    """The non-symmetric residual form of Coulomb friction with the penalty (module docstring).

    Its ``Apply`` is the gradient of ``Pi`` with the threshold set to
    ``mu p`` of the state itself, its linearization the consistent tangent.
    """
    m = cell.model
    fr = m.friction
    if fr is None or not fr.couples_to_pressure or cell.multiplier is not None:
        raise ValueError("the coupled Coulomb residual needs friction coupled to the pressure with the penalty")
    trial, test = cell.X.TrialFunction(), cell.X.TestFunction()
    form = ng.BilinearForm(cell.X, symmetric=False)
    for term in _bodies(cell, trial[0], trial[1]):
        form += term
    J, dJ = jump(trial), jump(test)
    ds = _contact_measure(cell)
    form += ng.Variation(_contact.normal_energy(J, cell.n, m.k_n, cell.gap) * ds)
    G = fr.threshold(_contact.pressure(J, cell.n, m.k_n, cell.gap))
    form += ng.InnerProduct(fr.traction(J, cell.n, G), dJ) * ds
    form += _load(cell, trial)
    return form


def _interface_parameters(cell: DiscreteCell, previous=None) -> tuple[dict, ng.GridFunction | None]:
    """The keywords of the interface energy (:func:`ngcontact.laws.penalty.interface_energy`) and, for
    Coulomb friction with the penalty, the frozen previous state whose pressure sets the threshold
    (``previous``, or a new GridFunction)."""
    m = cell.model
    lam = None if cell.multiplier is None else cell.multiplier.value
    friction, threshold = m.friction, None
    if friction is not None:
        if not friction.couples_to_pressure:
            threshold = friction.threshold(None)
        elif lam is not None:
            # exact: the threshold of the multiplier Uzawa holds fixed in this Newton solve (mu lambda), so
            # Uzawa's iteration is the Coulomb fixed point as well (cell_problem's docstring)
            threshold = friction.threshold(lam)
        else:
            previous = ng.GridFunction(cell.X) if previous is None else previous
            threshold = friction.threshold(_contact.pressure(jump(previous.components), cell.n, m.k_n,
                                                             cell.gap))
    parameters = dict(k_n=_contact_stiffness(cell), gap=cell.gap, friction=friction,
                      threshold=threshold, multiplier=lam)
    return parameters, previous


def _contact_measure(cell: DiscreteCell):
    """``ds`` on ``S_C``: with the contact bonus order (the penalty's kink), or exact enforcement's
    Gauss-Lobatto nodes."""
    if cell.multiplier is None:
        return ng.ds("contact", bonus_intorder=cell.model.contact_bonus_order)
    return cell.multiplier.ds


def _bodies(cell: DiscreteCell, ur, uc) -> list:
    """The bodies' elastic energies (with the macro strain when assembled), one term per body."""
    m, mesh = cell.model, cell.mesh
    terms = []
    for name, law, u in (("rough", m.rough, ur), ("counter", m.counter, uc)):
        eps = cell.body_strain(u)
        terms.append(ng.Variation(0.5 * ng.InnerProduct(law.stress(eps), eps)
                                  * ng.dx(definedon=mesh.Materials(name))))
    return terms


def _load(cell: DiscreteCell, trial):
    """The potential ``-|T| tbar . U`` of the far-face tractions (``U``: the trial functions' last components)."""
    t = ng.CF(tuple(cell.traction))
    return ng.Variation(-ng.InnerProduct(t, ng.CF(tuple(trial[2:]))) * ng.ds("top"))
