"""The macro problem: two elastic bodies joined by a homogenized interface law.

Minimizes (paper eqs. 44 and 46-48; the Winkler form 69-71)

    Pi(u) = sum_B int_B 1/2 sigma(u_B) : eps(u_B) w dx
            + int_S0 W(J) w ds  -  int_GammaN t . u w ds  -  sum_B int_B f_B . u_B w dx,

with ``u_B`` the displacement of body ``B`` (each body its own ``VectorH1``
on its region, so ``u`` jumps across ``S_0``), the jump
``J = u_rough - u_counter`` on ``S_0``, the interface energy ``W`` of
:mod:`ngcontact.laws.homogenized` in the local frame ``(n0, t0)`` / ``(n0, t1,
t2)`` and the measure weight ``w`` (``2 pi r`` in axisymmetry).  Dirichlet
data (constant, tilted or affine ``u0 + G x``) fix chosen displacement
components on labelled boundaries; tractions or pressures load others, and a
constant body force ``f_B`` may load each body.

``n0`` points from ``rough`` into ``counter``.  The mesh's normal on an
internal boundary has an orientation set by the mesher, so
:func:`interface_normal` fixes its sign element by element: ``n0`` must point
away from the centroid of the adjacent ``rough`` element.

Solution strategy:

* linear law, no friction: the energy is quadratic, one linear solve;
* bundle / tabulated laws, or a Tresca threshold ``G0`` only: Newton with
  line search (:func:`ngcontact.solvers.newton.minimize`);
* every nonlinear law starts from one linear solve of its quadratic
  surrogate: the normal law with every direction closed and, under friction,
  the tangential jump bonded by a spring as stiff as the normal law where
  the bodies would float without it (:func:`start_stiffness`), so that no
  body floats at the first Newton step;
* Coulomb friction ``G = mu0 [p]_+ + G0`` (``coulomb = "newton"``, the
  default): Newton on the coupled equations, whose friction threshold is
  the current pressure's (no energy exists; the residual is the gradient of
  the frictionless energy plus the friction's virtual work, and its
  Jacobian is not symmetric: :mod:`ngcontact.solvers.coulomb_newton`,
  the cell's Coulomb Newton too, with its line search on the Tresca energy
  frozen at the iterate, :func:`frozen_tresca`).  Where Newton fails from
  the start value, continuation in the Huber width
  (:mod:`ngcontact.solvers.continuation`) from the largest slip of the
  start value down to the scene's width.  On the femur / hip-stem scene
  and its variants (``scripts/femur_coulomb_variants.py``: loads,
  interferences, line-to-line, clearances, mu, widths, orders) Newton
  converges without the continuation (backtracking on the residual instead
  of the frozen-energy search needs it on some), where the fixed point
  below, from the same start, fails on several (a period-2 cycle, or a
  singular Tresca tangent): docs/benchmarks.md, section femur_coulomb_variants;
* ``coulomb = "fixed_point"`` (the paper's Sec. 2): repeated Newton solves
  with ``G`` evaluated at the previous solution's pressure
  (:func:`ngcontact.solvers.coulomb.coulomb_fixed_point`, whose stopping
  rule is that of every scale); each pass stops at ``rtol`` times the first
  residual of the start.  Same solution where both converge (1e-9 on the
  femur scene).

Post-processing (stress fields, extrema, the interface profile and
resultant, detachment points) is in :mod:`ngcontact.macro.macro_measures`.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace
from typing import Any

import ngsolve as ng
import numpy as np

from ngcontact.errors import ConvergenceError, ModelError
from ngcontact.fem import elasticity
from ngcontact.fem import two_body
from ngcontact.fem.two_body import Load, Support, boundary_labels, interface_normal  # noqa: F401  (public names of the macro problem)
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.laws.local_frame import local_frame
from ngcontact.fem.materials import ElasticLaw
from ngcontact.fem.quadrature import sampling_order
from ngcontact.fem.sampling import boundary_values
from ngcontact.solvers.coulomb import coulomb_fixed_point
from ngcontact.solvers.linear_solver import LinearSolver, fixed_mask
from ngcontact.solvers.roundoff import free_norm
from ngcontact.solvers.newton import minimize
from ngcontact.fem.rigid_modes import check_rigid_modes, free_rigid_modes
from ngcontact.solvers.continuation import INTERMEDIATE_RTOL, ladder
from ngcontact.solvers.coulomb_newton import coupled_newton
from ngcontact.macro.macro_energy import frozen_tresca, gap_cf, local_jump, macro_energy  # noqa: F401  (gap_cf: public)

log = logging.getLogger(__name__)

#: Newton's default relative tolerance of a macro solve
RTOL = 1e-10


@dataclass(frozen=True, kw_only=True)
class MacroProblem:
    """A macro problem description.

    Attributes
    ----------
    mesh
        Mesh with the two body regions and the interface boundary.
    setting
        ``plane_strain``, ``axisymmetric`` or ``3d``.
    rough, counter
        Region names of the rough body (paper ``D``) and the counter body.
    materials
        ``{rough: ElasticLaw, counter: ElasticLaw}``.
    law
        The interface law.
    gap
        Macro normal gap ``g0`` (number or CoefficientFunction), negative
        for an interference (press fit).
    supports, loads
        Boundary conditions.
    body_forces
        Constant force per unit volume of a body, region -> vector (global
        components; ``(f_r, f_z)`` in axisymmetry): the potential
        ``-int_B f . u w dx``.
    order
        Polynomial order of the displacement.
    interface
        Label of the interface boundary ``S_0``.
    parts
        What a solve builds that does not depend on the interface law: the
        space (with its wirebasket), the interface frame and the bodies'
        assembled stiffness (:func:`ngcontact.macro.macro_energy.macro_energy`).
        Built by the first solve; shared with the copies :func:`replace_law`
        makes (the two-scale loop solves one problem with several laws), a
        fresh one for any other copy.
    """

    mesh: ng.Mesh
    setting: str
    rough: str
    counter: str
    materials: dict[str, ElasticLaw]
    law: il.InterfaceLaw
    gap: float | ng.CoefficientFunction = 0.0
    supports: tuple[Support, ...] = ()
    loads: tuple[Load, ...] = ()
    body_forces: dict[str, tuple[float, ...]] = field(default_factory=dict)
    order: int = 2
    interface: str = "interface"
    parts: dict = field(default_factory=dict, init=False, repr=False, compare=False)


@dataclass
class MacroSolution:
    """Result of :func:`solve` (NGSolve objects unwrapped)."""

    problem: MacroProblem
    gfu: ng.GridFunction
    u_rough: ng.GridFunction
    u_counter: ng.GridFunction
    frame: list[ng.CoefficientFunction]
    local_jump: list[ng.CoefficientFunction]
    threshold: ng.CoefficientFunction | None
    history: dict[str, Any] = field(default_factory=dict)
    previous: ng.GridFunction | None = None  # the solution the friction threshold was evaluated at

    @property
    def ndof(self) -> int:
        return int(sum(self.gfu.space.FreeDofs()))


# ------------------------------------------------------------- checks
def check_problem(problem: MacroProblem) -> None:
    """Reject labels, regions and components that do not exist, and supports that leave a rigid motion.

    Raises :class:`ModelError` naming the label, the component or the free
    motion (:func:`ngcontact.fem.rigid_modes.check_rigid_modes`).  A problem on a mesh distributed over
    MPI ranks was checked on the whole mesh before (``parts["checked"]``): a rank's part says nothing.
    """
    if problem.parts.get("checked"):
        return
    two_body.check_labels(problem.mesh, problem.setting, problem.interface, problem.supports, problem.loads,
                          regions=(("rough", problem.rough), ("counter", problem.counter)))
    check_rigid_modes(problem.mesh, problem.setting, (problem.rough, problem.counter), problem.supports,
                      problem.interface, problem.law.holds_tangentially)


def solve(problem: MacroProblem, *, rtol: float = RTOL, atol: float = 0.0, max_iter: int = 40,
          inverse: str = "sparsecholesky", coulomb_rtol: float = 1e-8,
          coulomb_max_iter: int = 40, linear: LinearSolver | None = None,
          coulomb: str = "newton", start: ng.BaseVector | None = None) -> MacroSolution:
    """Solve the macro problem.

    Parameters
    ----------
    problem
        The description.
    rtol, atol, max_iter, inverse
        Newton settings (:func:`ngcontact.solvers.newton.minimize`).
    coulomb
        Coulomb friction: ``"newton"`` (the coupled equations,
        :func:`ngcontact.solvers.coulomb_newton.coupled_newton`) or
        ``"fixed_point"`` (Tresca passes, paper Sec. 2).
    coulomb_rtol, coulomb_max_iter
        Stopping rule of the Coulomb fixed point
        (:func:`ngcontact.solvers.coulomb.coulomb_fixed_point`).
    linear
        Tangent solves (:class:`~ngcontact.solvers.linear_solver.LinearSolver`);
        default: direct with ``inverse``.  Its record goes to the history.
    start
        Warm start: the solution vector of an earlier solve on the same mesh,
        order and supports (e.g. the previous iterate of the two-scale loop).
        Newton starts there instead of from the quadratic start and stops at
        the same absolute residual a cold start would (``rtol`` times the
        residual of the quadratic start at the undeformed state).

    Raises
    ------
    ValueError
        Unknown labels, regions or components.
    ConvergenceError
        Newton or the fixed point failed.
    """

    check_problem(problem)
    mesh = problem.mesh
    fes, frame = space_and_frame(problem)
    gfu = ng.GridFunction(fes)
    two_body.set_dirichlet(mesh, problem.setting, problem.supports, gfu)
    law = problem.law
    linear = linear if linear is not None else LinearSolver("direct", inverse=inverse)
    newton: dict[str, Any] = dict(rtol=rtol, atol=atol, max_iter=max_iter, linear=linear)
    history: dict[str, Any] = {"newton": [], "coulomb": None, "coulomb_changes": [], "coulomb_iterations": 0}
    g0 = gap_cf(problem.gap)
    old = ng.GridFunction(fes)
    a_old = local_jump(frame, old.components[0] - old.components[1])
    G = None
    if not law.quadratic:
        # quadratic start: all closed (and tangentially bonded under friction where needed),
        # so that no body floats at the first Newton step; later solves stop at
        # rtol times the first residual of the whole problem, not of their own
        surrogate = macro_energy(problem, fes, frame, start_stiffness=start_stiffness(problem))
        if start is None:
            history["newton"].append(minimize(surrogate, gfu, quadratic=True, **newton).as_dict())
            newton["atol"] = max(atol, rtol * history["newton"][0]["residuals"][0])
        else:
            newton["atol"] = max(atol, rtol * _residual_norm(surrogate, gfu))
            _warm(gfu, start)
            history["warm_start"] = True
    elif start is not None:
        _warm(gfu, start)
    if law.friction is not None and law.friction.coulomb and coulomb == "newton":
        coupled = _coupled_newton(problem, fes, frame, gfu, newton)
        history["newton"].extend(coupled["newton"])
        history["coulomb"] = {"method": "coupled Newton", "widths": coupled["widths"]}
        old.vec.data = gfu.vec
        G = ie.threshold(law.friction, ie.pressure(law.normal, a_old, g0))
    elif law.friction is not None and law.friction.coulomb:
        history["coulomb"] = {"method": "fixed point"}
        G = ie.threshold(law.friction, ie.pressure(law.normal, a_old, g0))
        form = macro_energy(problem, fes, frame, G=G, split=True)
        p_now = ie.pressure(law.normal, local_jump(frame, gfu.components[0] - gfu.components[1]), g0)

        def freeze() -> None:
            old.vec.data = gfu.vec

        fixed = coulomb_fixed_point(
            freeze, lambda: minimize(form, gfu, **newton).as_dict(),
            lambda: boundary_values(mesh, problem.interface, p_now, sampling_order(problem.order)),
            rtol=coulomb_rtol, max_iter=coulomb_max_iter)
        history["newton"].extend(fixed["newton"])
        history["coulomb_changes"] = fixed["coulomb_changes"]
        history["coulomb_iterations"] = fixed["coulomb_iterations"]
    else:
        if law.friction is not None:
            G = ng.CF(ie.threshold(law.friction, 0.0))
        form = macro_energy(problem, fes, frame, G=G, split=not law.quadratic)     # a linear solve: one assembly anyway
        history["newton"].append(minimize(form, gfu, quadratic=law.quadratic, **newton).as_dict())
    history["newton_iterations"] = int(sum(h["iterations"] for h in history["newton"]))
    history["converged"] = all(h["converged"] for h in history["newton"] if not h.get("failed"))
    history["quadratic"] = law.quadratic
    history["linear"] = linear.summary()
    ur, uc = gfu.components
    sol = MacroSolution(problem=problem, gfu=gfu, u_rough=ur, u_counter=uc, frame=frame,
                        local_jump=local_jump(frame, ur - uc), threshold=G, history=history, previous=old)
    return sol


def _coupled_newton(problem: MacroProblem, fes, frame, gfu, newton: dict) -> dict:
    """Coulomb friction by Newton on the coupled equations, with continuation in the Huber width on failure.

    First Newton from the start value at the scene's width ``w``; where it
    fails, from the same start value down the ladder of
    :func:`ngcontact.solvers.continuation.ladder`, which begins at the
    largest tangential jump of the start value (at least ``10 w``): there
    every point sticks in the Huber sense.  Returns ``newton`` (the
    histories, the failed first attempt's included and marked ``failed``:
    its steps count) and ``widths`` (the ladder's rungs; empty when none
    was needed).
    """
    law, mesh, friction = problem.law, problem.mesh, problem.law.friction
    assert friction is not None
    start = gfu.vec.CreateVector()
    start.data = gfu.vec
    try:
        return {"newton": [coupled_newton(macro_energy(problem, fes, frame, coupled=True, split=True), gfu,
                                          frozen=frozen_tresca(problem, fes, frame, gfu, split=True), **newton)],
                "widths": []}
    except ConvergenceError as err:
        if not friction.huber_regularized:   # a tabulated cell shear has no Huber width to continue in
            raise
        log.info("coupled Newton at the scene's Huber width failed (%s); continuation in the width", err)
        gfu.vec.data = start
        failed = [{**err.history, "failed": True}] if isinstance(err.history, dict) else []
    a = local_jump(frame, gfu.components[0] - gfu.components[1])
    slips = boundary_values(mesh, problem.interface, ng.sqrt(sum(t * t for t in a[1:])), sampling_order(problem.order))
    width = friction.width

    def solve_at(w: float, last: bool) -> dict:
        at = replace(problem, law=replace(law, friction=friction.with_width(w)))
        opts = newton if last else {**newton, "rtol": INTERMEDIATE_RTOL, "atol": 0.0}
        return coupled_newton(macro_energy(at, fes, frame, coupled=True, split=True), gfu,
                              frozen=frozen_tresca(at, fes, frame, gfu, split=True), **opts)

    def save():
        copy = gfu.vec.CreateVector()
        copy.data = gfu.vec
        return copy

    def restore(copy) -> None:
        gfu.vec.data = copy

    try:
        largest = float(mesh.comm.Max(float(slips.max(initial=0.0))))       # over the ranks of a distributed mesh
        rungs = ladder(solve_at, save, restore, start=max(largest, 10 * width), target=width)
    except ConvergenceError as err:
        raise ConvergenceError(f"Coulomb friction (solver.coulomb = 'newton'): {err}. A tangential load larger "
                               "than friction (mu times the pressure) can carry has no equilibrium: a body would "
                               "slide without bound; if the load can be carried, try solver.coulomb = "
                               "'fixed_point'", err.history) from err
    return {"newton": failed + [r["history"] for r in rungs], "widths": [r["width"] for r in rungs]}


def start_stiffness(problem: MacroProblem) -> float:
    """Tangential spring of the quadratic start: none where the normal law alone holds the bodies.

    Under friction the start bonds the tangential jump with a spring as
    stiff as the normal law only when the bodies would otherwise float
    (:func:`ngcontact.fem.rigid_modes.free_rigid_modes` with the normal tie
    only: a block sheared on a plane).  Where the normal law holds them (a
    tapered stem in its bore) the start leaves the tangential jump free:
    a bonded start would hold a stem with a clearance above its seat,
    every point open, and the first Newton step of the real law would
    find nothing that carries the load.
    """
    law = problem.law
    if law.friction is None:
        return 0.0
    if "start_stiffness" in problem.parts:      # found on the whole mesh before it was distributed
        return problem.parts["start_stiffness"]
    free = free_rigid_modes(problem.mesh, problem.setting, (problem.rough, problem.counter), problem.supports,
                            problem.interface, holds_tangentially=False)
    return law.normal.stiffness if free else 0.0


def _residual_norm(form, gfu: ng.GridFunction) -> float:
    """Norm of the free part of the residual of ``form`` at ``gfu`` (as Newton measures it)."""
    r = gfu.vec.CreateVector()
    form.Apply(gfu.vec, r)
    return free_norm(r, fixed_mask(gfu.space.FreeDofs()))


def _warm(gfu: ng.GridFunction, start: ng.BaseVector) -> None:
    """Copy the free values of ``start`` into ``gfu`` (its Dirichlet values stay)."""
    if len(start) != len(gfu.vec):
        raise ModelError(f"warm start: a vector of {len(start)} values for a space of {len(gfu.vec)} dofs "
                         "(the start must come from the same mesh, order and supports)")
    free = np.array(list(gfu.space.FreeDofs()), dtype=bool)
    gfu.vec.FV().NumPy()[free] = np.asarray(start.FV().NumPy())[free]


def replace_law(problem: MacroProblem, law: il.InterfaceLaw) -> MacroProblem:
    """The same problem with another interface law, sharing the law-independent ``parts`` of its solves."""
    new = replace(problem, law=law)
    object.__setattr__(new, "parts", problem.parts)
    return new


def space_and_frame(problem: MacroProblem):
    """The displacement space of both bodies (the interface's dofs on BDDC's wirebasket) and the interface's
    local frame ``(n0, t...)``: built once per problem and kept in its ``parts``."""
    parts = problem.parts
    if "space" not in parts:
        mesh = problem.mesh
        fes = two_body.spaces(mesh, problem.setting, (problem.rough, problem.counter), problem.supports,
                              problem.order)
        elasticity.surface_wirebasket(fes, mesh, problem.interface)
        n0 = two_body.interface_normal(mesh, problem.rough, problem.interface)
        parts["space"], parts["frame"] = fes, local_frame(n0, mesh.dim)
    return parts["space"], parts["frame"]
