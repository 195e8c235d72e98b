"""The resolved (direct) contact problem of two bodies with a rough interface.

The micro problem that the homogenized model approximates (paper Sec. 3.3,
the problem whose limit Prop. 29 identifies): the roughness of period
``eps`` is resolved in the mesh and the micro contact law of the cell acts
on the whole resolved surface ``S_C^eps``.  Minimizes

    Pi(u) = sum_B int_B 1/2 sigma(u_B) : eps(u_B) w dx
            + int_{S_C^eps} psi(J) w ds  -  int_GammaN t . u w ds

with each body ``B`` its own ``VectorH1`` on its region (``definedon``), the
jump ``J = u_rough - u_counter`` on ``S_C^eps``, the micro normal ``n``
pointing from ``rough`` into ``counter`` (sign fixed element by element by
:func:`ngcontact.fem.two_body.interface_normal`), the measure weight ``w`` (``2 pi r``
in axisymmetry) and the interface energy density of
:mod:`ngcontact.laws.penalty` (paper eqs. 7, 9, 16)::

    psi(J) = (k_n / 2) [J.n - g]_+^2  (+ G huber(|J_t|, w_h)  with friction).

Dirichlet data fix displacement components on labelled boundaries (the
values may vary linearly along the boundary: a tilt); pressures and
tractions load others.  The energy is convex: it is minimized by Newton's
method with the exact line search of :func:`ngcontact.solvers.newton.minimize`,
started from the solution of the quadratic surrogate with every point of
``S_C^eps`` closed (so that no body floats at the first step).  Coulomb
friction ``G = mu p`` is a fixed point on the pressure of the previous
solution, stopped when ``max |p_k - p_{k-1}| <= coulomb_rtol max p_k`` at
the quadrature points of ``S_C^eps``.

Measures on the resolved surface: :func:`contact_force` (the force the
counter body receives through a part of the interface) and
:func:`contact_fraction`.  Reactions and probes, which the resolved and the
homogenized solutions share, are in :mod:`ngcontact.fem.reaction` and
:mod:`ngcontact.fem.sampling`.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Any

import ngsolve as ng
import numpy as np

from ngcontact.laws import penalty as _contact
from ngcontact.fem import elasticity
from ngcontact.fem import two_body
from ngcontact.laws.friction import FrictionLaw
from ngcontact.fem.quadrature import kink_order, resultant_order, sampling_order
from ngcontact.fem.sampling import boundary_values
from ngcontact.fem.materials import ElasticLaw
from ngcontact.fem.two_body import Load, Support, interface_normal  # noqa: F401  (public names of the resolved problem)
from ngcontact.solvers.coulomb import coulomb_fixed_point
from ngcontact.solvers.newton import minimize
from ngcontact.errors import ModelError

log = logging.getLogger(__name__)

SETTINGS = ("plane_strain", "axisymmetric")


@dataclass(frozen=True, kw_only=True)
class DirectProblem:
    """A resolved contact problem (no solution inside).

    Attributes
    ----------
    mesh
        Mesh with regions ``rough`` and ``counter`` and the resolved surface ``contact``.
    setting
        ``plane_strain`` or ``axisymmetric``.
    materials
        ``{"rough": ElasticLaw, "counter": ElasticLaw}``.
    k_n
        Micro penalty stiffness [stress / length].
    gap
        Initial micro gap ``g >= 0`` (number or CoefficientFunction) or ``None``.
    friction
        :class:`~ngcontact.laws.friction.FrictionLaw` or ``None`` (frictionless).
    supports, loads
        Boundary conditions.
    order
        Polynomial order of the displacement.
    periodic
        The lateral faces are identified (``Periodic`` spaces).
    coulomb_rtol, coulomb_max_iter
        Stopping rule of the Coulomb fixed point.
    contact
        Label of the interface boundary.
    """

    mesh: ng.Mesh
    materials: dict[str, ElasticLaw]
    k_n: float
    setting: str = "plane_strain"
    gap: float | ng.CoefficientFunction | None = None
    friction: FrictionLaw | None = None
    supports: tuple[Support, ...] = ()
    loads: tuple[Load, ...] = ()
    order: int = 2
    periodic: bool = False
    contact: str = "contact"
    coulomb_rtol: float = 1e-8
    coulomb_max_iter: int = 40


@dataclass
class DirectSolution:
    """Result of :func:`solve`: the state as NGSolve objects, plus the solver history."""

    problem: DirectProblem
    gfu: ng.GridFunction
    u_rough: ng.GridFunction
    u_counter: ng.GridFunction
    normal: ng.CoefficientFunction
    jump: ng.CoefficientFunction
    pressure: ng.CoefficientFunction
    history: dict[str, Any] = field(default_factory=dict)

    @property
    def ndof(self) -> int:
        return int(sum(self.gfu.space.FreeDofs()))


# ------------------------------------------------------------------ model
def _form(problem: DirectProblem, fes, n, *, threshold=None, surrogate: bool = False):
    """The energy as a symmetric ``BilinearForm`` of ``Variation`` terms.

    ``surrogate``: the quadratic start energy, every point of ``S_C`` closed
    (no positive part) and, under friction, the slip held by a spring ``k_n``.
    """
    mesh, setting = problem.mesh, problem.setting
    w = elasticity.weight(setting)
    ur, uc = fes.TrialFunction()
    form = ng.BilinearForm(fes, symmetric=True)
    elasticity.add_elastic_energy(form, mesh, {"rough": problem.materials["rough"],
                                               "counter": problem.materials["counter"]},
                                  {"rough": ur, "counter": uc}, setting)
    J = ur.Trace() - uc.Trace()
    k_n = problem.k_n
    fr = problem.friction
    if surrogate:
        d = _contact.penetration(J, n, problem.gap)
        psi = 0.5 * k_n * d * d
        if fr is not None:
            Jt = _contact.tangential_slip(J, n)
            psi = psi + 0.5 * k_n * ng.InnerProduct(Jt, Jt)
    else:
        psi = _contact.interface_energy(J, n, k_n=k_n, gap=problem.gap, friction=fr, threshold=threshold)
    form += ng.Variation(psi * w * ng.ds(definedon=mesh.Boundaries(problem.contact)))
    return two_body.add_load_potential(form, mesh, problem.loads, (ur, uc), w)


def _check(problem: DirectProblem) -> None:
    mesh = problem.mesh
    labels = set(mesh.GetBoundaries())
    if problem.setting not in SETTINGS:
        raise ModelError(f"setting = {problem.setting!r}: must be one of {', '.join(SETTINGS)}")
    if problem.contact not in labels:
        raise ModelError(f"the mesh has no boundary {problem.contact!r}")
    for item in tuple(problem.supports) + tuple(problem.loads):
        if item.label not in labels:
            raise ModelError(f"boundary {item.label!r} does not exist; labels are "
                             + ", ".join(sorted(labels - {""})))
    if not problem.k_n > 0:
        raise ModelError(f"k_n = {problem.k_n!r}: must be > 0")


def solve(problem: DirectProblem, *, rtol: float = 1e-10, atol: float = 0.0, max_iter: int = 40,
          inverse: str = "sparsecholesky") -> DirectSolution:
    """Solve the resolved contact problem.

    Parameters
    ----------
    problem
        The description.
    rtol, atol, max_iter, inverse
        Newton settings (:func:`ngcontact.solvers.newton.minimize`); every Newton
        solve after the quadratic start stops at ``rtol`` times the first
        residual of that start.

    Raises
    ------
    ValueError
        Unknown boundary labels or an invalid setting.
    ConvergenceError
        Newton or the Coulomb fixed point failed.
    """
    _check(problem)
    mesh = problem.mesh
    fes = two_body.spaces(mesh, problem.setting, ("rough", "counter"), problem.supports, problem.order,
                          periodic=problem.periodic)
    gfu = ng.GridFunction(fes)
    two_body.set_dirichlet(mesh, problem.setting, problem.supports, gfu)
    n = two_body.interface_normal(mesh, "rough", problem.contact)
    newton: dict[str, Any] = dict(rtol=rtol, atol=atol, max_iter=max_iter, inverse=inverse)
    history: dict[str, Any] = {"newton": [], "coulomb_changes": [], "coulomb_iterations": 0}
    start = _form(problem, fes, n, surrogate=True)
    history["newton"].append(minimize(start, gfu, quadratic=True, **newton).as_dict())
    newton["atol"] = max(atol, rtol * history["newton"][0]["residuals"][0])
    ur, uc = gfu.components
    J = ur - uc
    fr = problem.friction
    if fr is not None and fr.couples_to_pressure:
        pressure = _contact.pressure(J, n, problem.k_n, problem.gap)
        _coulomb(problem, fes, gfu, n, pressure, newton, history)
    else:
        pressure = _contact.pressure(J, n, problem.k_n, problem.gap)
        G = ng.CF(fr.threshold(None)) if fr is not None else None
        form = _form(problem, fes, n, threshold=G)
        history["newton"].append(minimize(form, gfu, line_search="exact", **newton).as_dict())
    history["newton_iterations"] = int(sum(h["iterations"] for h in history["newton"]))
    history["converged"] = all(h["converged"] for h in history["newton"])
    return DirectSolution(problem=problem, gfu=gfu, u_rough=ur, u_counter=uc, normal=n, jump=J,
                          pressure=pressure, history=history)


def _coulomb(problem, fes, gfu, n, pressure, newton, history) -> None:
    """Friction coupled to the pressure (Coulomb): solves with the threshold (``G = mu p``) of the previous
    solution's pressure, to a fixed point."""
    mesh, fr = problem.mesh, problem.friction
    old = ng.GridFunction(fes)
    J_old = old.components[0] - old.components[1]
    G = fr.threshold(_contact.pressure(J_old, n, problem.k_n, problem.gap))
    form = _form(problem, fes, n, threshold=G)

    def freeze() -> None:
        old.vec.data = gfu.vec

    fixed = coulomb_fixed_point(
        freeze, lambda: minimize(form, gfu, line_search="exact", **newton).as_dict(),
        lambda: boundary_values(mesh, problem.contact, pressure, sampling_order(problem.order)),
        rtol=problem.coulomb_rtol, max_iter=problem.coulomb_max_iter)
    history["newton"].extend(fixed["newton"])
    history["coulomb_changes"] = fixed["coulomb_changes"]
    history["coulomb_iterations"] = fixed["coulomb_iterations"]


# -------------------------------------------------------- post-processing
def contact_force(sol: DirectSolution, x_range=None, part=None) -> np.ndarray:
    """Force the counter body receives through ``S_C^eps`` (or its part with ``x`` in ``x_range``).

    ``int p n w ds`` with the pressure ``p`` (compression positive) and the
    micro normal ``n`` from rough into counter (friction not included).
    ``part``: an indicator CoefficientFunction of the part instead of
    ``x_range``.
    """
    p = sol.problem
    mesh = p.mesh
    ind = ng.CF(1.0) if part is None else part
    if x_range is not None:
        ind = ng.IfPos(ng.x - x_range[0], 1.0, 0.0) * ng.IfPos(x_range[1] - ng.x, 1.0, 0.0)
    w = elasticity.weight(p.setting)
    vals = ng.Integrate(sol.pressure * sol.normal * ind * w, mesh, ng.BND,
                        definedon=mesh.Boundaries(p.contact), order=resultant_order(p.order))
    return np.asarray(vals, float).ravel()


def closed_indicator(sol: DirectSolution) -> ng.CoefficientFunction:
    """1 where ``J.n - g >= 0`` on ``S_C^eps`` (closed), else 0."""
    return ng.IfPos(-_contact.penetration(sol.jump, sol.normal, sol.problem.gap), 0.0, 1.0)


def contact_fraction(sol: DirectSolution, length: float) -> float:
    """Measure of ``{J.n - g >= 0}`` on ``S_C^eps`` (high-order quadrature) per unit macro length."""
    p = sol.problem
    return float(ng.Integrate(closed_indicator(sol), p.mesh, ng.BND, definedon=p.mesh.Boundaries(p.contact),
                              order=kink_order(p.order))) / length
