"""The energy of the macro problem (paper eqs. 44, 46-48; the Winkler form 69-71) as NGSolve forms.

    Pi(u) = sum_B int_B 1/2 sigma(u_B) : eps(u_B) w dx
            + int_S0 W(J) w ds  -  int_GammaN t . u w ds  -  sum_B int_B f_B . u_B w dx,

the jump ``J = u_rough - u_counter`` in the interface's local frame, ``w``
the measure weight (``2 pi r`` in axisymmetry); the variants the solution
strategy of :mod:`ngcontact.macro.macro_problem` needs: the quadratic start
surrogate, the coupled Coulomb residual, the Tresca energy frozen at a state,
and, for the measures, the energy of a solution and the load potential alone.
Newton's steps use the split form (:class:`~ngcontact.solvers.split_energy.SplitEnergy`):
the bodies and loads assembled once, the interface at each state.  ``problem``
below is a :class:`~ngcontact.macro.macro_problem.MacroProblem`, ``sol`` a
:class:`~ngcontact.macro.macro_problem.MacroSolution` (not imported: that
module builds on this one).
"""
from __future__ import annotations

import ngsolve as ng

from ngcontact.fem import elasticity
from ngcontact.fem import two_body
from ngcontact.laws import interface_energy as ie
from ngcontact.solvers.coulomb_newton import FrozenTresca
from ngcontact.solvers.split_energy import SplitEnergy


def local_jump(frame, J) -> list:
    """Components of the jump ``J`` in the local frame ``(n0, t...)`` of the interface."""
    return [ng.InnerProduct(J, e) for e in frame]


def gap_cf(gap):
    """The initial gap as a CoefficientFunction (a number or already one)."""
    return ng.CF(float(gap)) if isinstance(gap, (int, float)) else gap


def macro_energy(problem, fes, frame, *, G=None, start_stiffness: float | None = None,
                 coupled: bool = False, split: bool = False):
    """Energy of the macro problem as a symmetric ``BilinearForm`` of ``Variation`` terms.

    With ``start_stiffness`` the interface energy is the quadratic start
    surrogate: the normal law with everything closed plus, when the law has
    friction, a tangential spring of that stiffness (tangentially bonded);
    ``start_stiffness = 0`` leaves the tangential jump free.

    With ``coupled`` (Coulomb friction) the form is the residual of the
    coupled equations instead (:mod:`ngcontact.solvers.coulomb_newton`):
    the energy without friction plus the virtual work of the friction
    traction whose threshold ``G = mu [p(u)]_+ + G0`` is the current
    pressure's; not symmetric.

    With ``split`` the form is a :class:`~ngcontact.solvers.split_energy.SplitEnergy`:
    the same terms, the bodies and loads (quadratic) assembled once and only
    the interface at each state (what Newton's steps use).
    """
    mesh, setting = problem.mesh, problem.setting
    w = elasticity.weight(setting)
    ur, uc = fes.TrialFunction()
    form = ng.BilinearForm(fes, symmetric=not coupled)
    # the split's parts (built only for it): the bodies and loads, assembled already when an earlier
    # solve of the problem (another law: the two-scale loop) built them on this space, and the interface
    quadratic, assembled = _bodies(problem, fes, symmetric=not coupled) if split else (None, False)
    interface = ng.BilinearForm(fes, symmetric=not coupled) if split else None
    for f in (form, quadratic) if split and not assembled else (form,):
        elasticity.add_elastic_energy(f, mesh, {problem.rough: problem.materials[problem.rough],
                                                problem.counter: problem.materials[problem.counter]},
                                      {problem.rough: ur, problem.counter: uc}, setting)
        two_body.add_load_potential(f, mesh, problem.loads, (ur, uc), w)
        two_body.add_body_force_potential(f, mesh, problem.body_forces, {problem.rough: ur, problem.counter: uc}, w)
    a = local_jump(frame, ur.Trace() - uc.Trace())
    g0 = gap_cf(problem.gap)
    law = problem.law
    ds = ng.ds(definedon=mesh.Boundaries(problem.interface))
    if start_stiffness is not None:
        W = ie.normal_energy(law.normal, a, g0, closed=True)
        if law.friction is not None and start_stiffness > 0:
            W = W + 0.5 * start_stiffness * sum(t * t for t in a[1:])
    elif coupled and law.friction is not None:
        W = ie.normal_energy(law.normal, a, g0)
        G = ie.threshold(law.friction, ie.pressure(law.normal, a, g0))
        vr, vc = fes.TestFunction()
        b = local_jump(frame, vr.Trace() - vc.Trace())
        work = sum(f * bi for f, bi in zip(ie.friction_traction(law.friction, a, G)[1:], b[1:]))
        form += work * w * ds
        if split:
            interface += work * w * ds
    else:
        W = ie.energy(law, a, g0, G)
    term = ng.Variation(W * w * ds)
    form += term
    if not split:
        return form
    interface += term
    split_form = SplitEnergy(form, quadratic, interface, key=lambda: None, assembled=assembled)
    problem.parts[("bodies", not coupled)] = (fes, quadratic)     # assembled now
    return split_form


def _bodies(problem, fes, symmetric: bool) -> tuple[ng.BilinearForm, bool]:
    """The form of the bodies and loads on ``fes`` in the given storage, and whether it is assembled.

    Kept in ``problem.parts`` (shared by the problem's copies with other
    laws, :func:`ngcontact.macro.macro_problem.replace_law`) for ``fes``, the
    space of those parts: the bodies are linear, so every solve of the
    problem, whatever its law, has the same stiffness ``K`` and load vector
    (a second assembly of ``K`` would add a good share to a macro solve
    with the cell's law, twice: symmetric and not).
    """
    held = problem.parts.get(("bodies", symmetric))
    if held is not None and held[0] is fes:
        return held[1], True
    return ng.BilinearForm(fes, symmetric=symmetric), False


def frozen_tresca(problem, fes, frame, gfu: ng.GridFunction, split: bool = False) -> FrozenTresca:
    """The Tresca energy whose threshold ``mu [p]_+ + G0`` is the pressure of a frozen copy of ``gfu``.

    The coupled Newton's line search minimizes it along its step, frozen at
    each iterate (:mod:`ngcontact.solvers.coulomb_newton`).
    """
    law = problem.law
    assert law.friction is not None
    old = ng.GridFunction(fes)
    a_old = local_jump(frame, old.components[0] - old.components[1])
    G = ie.threshold(law.friction, ie.pressure(law.normal, a_old, gap_cf(problem.gap)))

    def freeze() -> None:
        old.vec.data = gfu.vec

    return FrozenTresca(macro_energy(problem, fes, frame, G=G, split=split), freeze)


def energy_form(sol):
    """The energy whose minimizer ``sol`` is (the friction threshold frozen at ``sol.previous``)."""
    return macro_energy(sol.problem, sol.gfu.space, sol.frame, G=sol.threshold)


def load_form(sol):
    """The load potential ``-int t . u w ds - sum_B int_B f_B . u_B w dx`` alone: its gradient is ``-l``,
    the applied loads (surface loads and body forces)."""
    p = sol.problem
    fes = sol.gfu.space
    form = ng.BilinearForm(fes, symmetric=True)
    ur, uc = fes.TrialFunction()
    w = elasticity.weight(p.setting)
    two_body.add_load_potential(form, p.mesh, p.loads, (ur, uc), w)
    return two_body.add_body_force_potential(form, p.mesh, p.body_forces, {p.rough: ur, p.counter: uc}, w)
