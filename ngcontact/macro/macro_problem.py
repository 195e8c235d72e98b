"""The macro problem: two elastic bodies joined by a homogenized interface law.

Minimizes (paper eqs. 44 and 46-48; the Winkler form 69-71)

    Pi(u) = sum_B int_B 1/2 sigma(u_B) : eps(u_B) w dx
            + int_S0 W(J) w ds  -  int_GammaN t . u w ds,

with ``u_B`` the displacement of body ``B`` (each body its own ``VectorH1``
on its region, so ``u`` jumps across ``S_0``), the jump
``J = u_rough - u_counter`` on ``S_0``, the interface energy ``W`` of
:mod:`ngcontact.laws.homogenized` in the local frame ``(n0, t0)`` / ``(n0, t1,
t2)`` and the measure weight ``w`` (``2 pi r`` in axisymmetry).  Dirichlet
data fix chosen displacement components on labelled boundaries; tractions or
pressures load others.

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
  the tangential jump bonded by a spring as stiff as the normal law (so no
  body floats at the first Newton step);
* Coulomb friction ``G = mu0 [p]_+ + G0``: a fixed point on the pressure.
  It starts from that bonded state, then repeats Newton solves
  with ``G`` evaluated at the previous solution's pressure
  (:func:`ngcontact.solvers.coulomb.coulomb_fixed_point`, whose stopping
  rule is that of every scale); each pass stops at ``rtol`` times the first residual of the
  bonded start.  The fixed point converges to a solution of the regularized
  Coulomb problem; no energy of the coupled problem exists, so no coupled
  Newton is attempted.

Post-processing: stress fields (radial / axial / hoop in axisymmetry), von
Mises stress and strain, their extrema with locations, the profile along the
interface (arc length, pressure, shear, jumps, status open / stick / slip),
the force transmitted through the interface and the detachment points.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace
from typing import Any

import ngsolve as ng
import numpy as np

from ngcontact.fem import elasticity
from ngcontact.fem import two_body
from ngcontact.fem.elasticity import COMPONENTS
from ngcontact.fem.two_body import Load, Support, boundary_labels, interface_normal  # noqa: F401  (public names of the macro problem)
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.laws.local_frame import local_frame
from ngcontact.fem.materials import ElasticLaw, von_mises
from ngcontact.fem.quadrature import energy_order, sampling_order
from ngcontact.fem.sampling import boundary_values
from ngcontact.solvers.coulomb import coulomb_fixed_point
from ngcontact.solvers.newton import minimize
from ngcontact.errors import ModelError

log = logging.getLogger(__name__)



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
    order
        Polynomial order of the displacement.
    interface
        Label of the interface boundary ``S_0``.
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
    order: int = 2
    interface: str = "interface"


@dataclass
class MacroSolution:
    """Result of :func:`solve` (NGSolve objects unwrapped)."""

    problem: MacroProblem
    gfu: ng.GridFunction
    u_rough: ng.GridFunction
    u_counter: ng.GridFunction
    frame: list
    local_jump: list
    threshold: ng.CoefficientFunction | None
    history: dict[str, Any] = field(default_factory=dict)
    previous: ng.GridFunction | None = None  # the solution the friction threshold was evaluated at

    @property
    def ndof(self) -> int:
        return int(sum(self.gfu.space.FreeDofs()))


# ------------------------------------------------------------- checks
def check_problem(problem: MacroProblem) -> None:
    """Reject labels, regions and components that do not exist (ValueError naming them)."""
    two_body.check_labels(problem.mesh, problem.setting, problem.interface, problem.supports, problem.loads,
                          regions=(("rough", problem.rough), ("counter", problem.counter)))


# ------------------------------------------------------------- model
def _local(frame, J) -> list:
    return [ng.InnerProduct(J, e) for e in frame]


def _gap_cf(gap):
    return ng.CF(float(gap)) if isinstance(gap, (int, float)) else gap


def _form(problem: MacroProblem, fes, frame, *, G=None, start_stiffness: float | None = None):
    """Energy of the macro problem as a symmetric ``BilinearForm`` of ``Variation`` terms.

    With ``start_stiffness`` the interface energy is the quadratic start
    surrogate: the normal law with everything closed plus, when the law has
    friction, a tangential spring of that stiffness (tangentially bonded).
    """
    mesh, setting = problem.mesh, problem.setting
    w = elasticity.weight(setting)
    ur, uc = fes.TrialFunction()
    form = ng.BilinearForm(fes, symmetric=True)
    elasticity.add_elastic_energy(form, mesh, {problem.rough: problem.materials[problem.rough],
                                               problem.counter: problem.materials[problem.counter]},
                                  {problem.rough: ur, problem.counter: uc}, setting)
    a = _local(frame, ur.Trace() - uc.Trace())
    g0 = _gap_cf(problem.gap)
    law = problem.law
    if start_stiffness is not None:
        W = ie.normal_energy(law.normal, a, g0, closed=True)
        if law.friction is not None:
            W = W + 0.5 * start_stiffness * sum(t * t for t in a[1:])
    else:
        W = ie.energy(law, a, g0, G)
    form += ng.Variation(W * w * ng.ds(definedon=mesh.Boundaries(problem.interface)))
    return two_body.add_load_potential(form, mesh, problem.loads, (ur, uc), w)


def solve(problem: MacroProblem, *, rtol: float = 1e-10, atol: float = 0.0, max_iter: int = 40,
          inverse: str = "sparsecholesky", coulomb_rtol: float = 1e-8,
          coulomb_max_iter: int = 40) -> MacroSolution:
    """Solve the macro problem.

    Parameters
    ----------
    problem
        The description.
    rtol, atol, max_iter, inverse
        Newton settings (:func:`ngcontact.solvers.newton.minimize`).
    coulomb_rtol, coulomb_max_iter
        Stopping rule of the Coulomb fixed point
        (:func:`ngcontact.solvers.coulomb.coulomb_fixed_point`).

    Raises
    ------
    ValueError
        Unknown labels, regions or components.
    ConvergenceError
        Newton or the fixed point failed.
    """

    check_problem(problem)
    mesh = problem.mesh
    fes = two_body.spaces(mesh, problem.setting, (problem.rough, problem.counter), problem.supports,
                          problem.order)
    gfu = ng.GridFunction(fes)
    two_body.set_dirichlet(mesh, problem.setting, problem.supports, gfu)
    n0 = two_body.interface_normal(mesh, problem.rough, problem.interface)
    frame = local_frame(n0, mesh.dim)
    law = problem.law
    newton: dict[str, Any] = dict(rtol=rtol, atol=atol, max_iter=max_iter, inverse=inverse)
    history: dict[str, Any] = {"newton": [], "coulomb_changes": [], "coulomb_iterations": 0}
    g0 = _gap_cf(problem.gap)
    old = ng.GridFunction(fes)
    a_old = _local(frame, old.components[0] - old.components[1])
    G = None
    if not law.quadratic:
        # quadratic start: all closed (and tangentially bonded under friction),
        # so that no body floats at the first Newton step; later solves stop at
        # rtol times the first residual of the whole problem, not of their own
        start = _form(problem, fes, frame, start_stiffness=law.normal.stiffness)
        history["newton"].append(minimize(start, gfu, quadratic=True, **newton).as_dict())
        newton["atol"] = max(atol, rtol * history["newton"][0]["residuals"][0])
    if law.friction is not None and law.friction.coulomb:
        G = ie.threshold(law.friction, ie.pressure(law.normal, a_old, g0))
        form = _form(problem, fes, frame, G=G)
        p_now = ie.pressure(law.normal, _local(frame, gfu.components[0] - gfu.components[1]), g0)

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
            G = ng.CF(law.friction.threshold)
        form = _form(problem, fes, frame, G=G)
        history["newton"].append(minimize(form, gfu, quadratic=law.quadratic, **newton).as_dict())
    history["newton_iterations"] = int(sum(h["iterations"] for h in history["newton"]))
    history["converged"] = all(h["converged"] for h in history["newton"])
    history["quadratic"] = law.quadratic
    ur, uc = gfu.components
    sol = MacroSolution(problem=problem, gfu=gfu, u_rough=ur, u_counter=uc, frame=frame,
                        local_jump=_local(frame, ur - uc), threshold=G, history=history, previous=old)
    return sol


# ----------------------------------------------------- post-processing
def _by_region(sol: MacroSolution, fn):
    p = sol.problem
    return p.mesh.MaterialCF({p.rough: fn(sol.u_rough, p.materials[p.rough]),
                              p.counter: fn(sol.u_counter, p.materials[p.counter])})


def stress(sol: MacroSolution):
    """3x3 stress tensor field (both bodies)."""
    s = sol.problem.setting
    return _by_region(sol, lambda u, law: elasticity.stress(law, u, s))


def strain(sol: MacroSolution):
    """3x3 strain tensor field (both bodies)."""
    s = sol.problem.setting
    return _by_region(sol, lambda u, law: elasticity.strain(u, s))


def von_mises_strain(eps):
    """Equivalent strain ``sqrt(2/3 e:e)``, ``e`` the deviatoric strain."""
    e = eps - ng.Trace(eps) / 3.0 * ng.Id(3)
    return ng.sqrt(2.0 / 3.0 * ng.InnerProduct(e, e))


def stress_fields(sol: MacroSolution) -> dict:
    """Named scalar fields: stress components, von Mises stress and strain.

    Axisymmetric: ``sigma_r``, ``sigma_z``, ``sigma_hoop``, ``sigma_rz``;
    plane strain: ``sigma_xx``, ``sigma_yy``, ``sigma_zz``, ``sigma_xy``;
    3D: the six Cartesian components.  Always ``von_mises`` (stress) and
    ``von_mises_strain``.
    """
    sig = stress(sol)
    setting = sol.problem.setting
    if setting == "axisymmetric":
        out = {"sigma_r": sig[0, 0], "sigma_z": sig[1, 1], "sigma_hoop": sig[2, 2], "sigma_rz": sig[0, 1]}
    elif setting == "plane_strain":
        out = {"sigma_xx": sig[0, 0], "sigma_yy": sig[1, 1], "sigma_zz": sig[2, 2], "sigma_xy": sig[0, 1]}
    else:
        out = {f"sigma_{a}{b}": sig[i, j] for i, j, a, b in
               ((0, 0, "x", "x"), (1, 1, "y", "y"), (2, 2, "z", "z"), (1, 2, "y", "z"),
                (0, 2, "x", "z"), (0, 1, "x", "y"))}
    out["von_mises"] = von_mises(sig)
    out["von_mises_strain"] = von_mises_strain(strain(sol))
    return out


def _sample_rule(dim: int, inset: float = 1e-3):
    """Points at the vertices (moved ``inset`` inwards, off the axis ``r = 0``
    where the hoop strain ``u_r / r`` is 0/0), edge midpoints and centroid."""
    e = inset
    pts: list[tuple[float, ...]]
    if dim == 2:
        pts = [(e, e), (1 - 2 * e, e), (e, 1 - 2 * e), (0.5, e), (0.5 - e, 0.5 - e), (e, 0.5), (1 / 3, 1 / 3)]
    else:
        pts = [(e, e, e), (1 - 3 * e, e, e), (e, 1 - 3 * e, e), (e, e, 1 - 3 * e), (0.25, 0.25, 0.25)]
    return ng.IntegrationRule(pts, [0.0] * len(pts))


def field_extrema(sol: MacroSolution, fields: dict) -> dict:
    """Largest and smallest value of each field with its location and body.

    Sampled next to the vertices, at edge midpoints and centroids of every
    element, on each body's side separately (the fields jump across ``S_0``).
    """
    p = sol.problem
    mesh = p.mesh
    rule = _sample_rule(mesh.dim)
    coords = ng.CF((ng.x, ng.y, ng.z)[:mesh.dim])
    out: dict[str, dict[str, dict[str, Any]]] = {name: {} for name in fields}
    for region in (p.rough, p.counter):
        mips = mesh.MapToAllElements(rule, mesh.Materials(region))
        xyz = np.asarray(coords(mips)).reshape(-1, mesh.dim)
        for name, cf in fields.items():
            vals = np.asarray(cf(mips)).ravel()
            for key, k in (("max", int(np.argmax(vals))), ("min", int(np.argmin(vals)))):
                best = out[name].get(key)
                better = best is None or (vals[k] > best["value"] if key == "max" else vals[k] < best["value"])
                if better:
                    out[name][key] = {"value": float(vals[k]), "location": [float(c) for c in xyz[k]],
                                      "body": region}
    return out


def interface_tractions(sol: MacroSolution) -> list:
    """Local traction components ``dW/da`` on ``S_0`` at the solution."""
    p = sol.problem
    return ie.traction(p.law, sol.local_jump, _gap_cf(p.gap), sol.threshold)


def resultant(sol: MacroSolution) -> dict:
    """Force transmitted through ``S_0`` from the rough to the counter body.

    ``R = int_S0 tau w ds`` with the global traction ``tau = sum_k tau_k e_k``.
    Axisymmetric: only the axial component ``z`` (per full revolution; the
    radial tractions cancel around the circumference).  Plane strain: per unit
    thickness.  Integrated with the quadrature of the assembly (order ``2p``),
    so ``R`` is the discrete reaction and balances the applied loads to
    solver tolerance (the kinks of unilateral laws make other quadratures
    differ slightly).
    """
    p = sol.problem
    tau = interface_tractions(sol)
    glob = sum((t * e for t, e in zip(tau, sol.frame)), ng.CF((0,) * p.mesh.dim))
    w = elasticity.weight(p.setting)
    comps = COMPONENTS[p.setting]
    vals = [ng.Integrate(glob[i] * w, p.mesh, ng.BND, definedon=p.mesh.Boundaries(p.interface),
                         order=energy_order(p.order)) for i in range(p.mesh.dim)]
    if p.setting == "axisymmetric":
        return {"z": float(vals[1])}
    return {c: float(v) for c, v in zip(comps, vals)}


def interface_profile(sol: MacroSolution, points_per_element: int = 5) -> dict:
    """Values along the interface curve (2D and axisymmetric only).

    Returns arrays ``s`` (arc length from the end with the largest ``y``, or
    ``z``), the coordinates (``r, z`` or ``x, y``), ``pressure`` (compression
    positive), ``shear`` (traction along ``t0``), ``jump_n`` (``J . n0``,
    positive closes), ``jump_t`` (``J . t0``) and ``status``: ``open`` where
    ``p <= 0`` (for a bilateral linear law: tension), else ``stick`` / ``slip``
    (with friction: ``|J_t|`` within / beyond the Huber width; without: by
    whether the law has a tangential stiffness).  Element end points appear
    once per element, so values that jump at a kink of ``n0`` show both sides.
    """
    p = sol.problem
    mesh = p.mesh
    if mesh.dim != 2:
        raise ModelError("an interface profile needs a 2D or axisymmetric mesh")
    k = max(2, int(points_per_element))
    rule = ng.IntegrationRule([(t,) for t in np.linspace(0.0, 1.0, k)], [0.0] * k)
    mips = mesh.MapToAllElements(rule, mesh.Boundaries(p.interface))
    tau = interface_tractions(sol)
    a = sol.local_jump
    cf = ng.CF((ng.x, ng.y, tau[0], tau[1], a[0], a[1]))
    vals = np.asarray(cf(mips)).reshape(-1, k, 6)
    order = _chain(vals[:, 0, :2], vals[:, -1, :2])
    rows = np.concatenate([vals[e, ::-1] if flip else vals[e] for e, flip in order])
    steps = np.hypot(np.diff(rows[:, 0]), np.diff(rows[:, 1]))
    s = np.concatenate([[0.0], np.cumsum(steps)])
    press, shear, jn, jt = rows[:, 2], rows[:, 3], rows[:, 4], rows[:, 5]
    status = _status(sol, press, jt)
    names = COMPONENTS[p.setting]
    return {"s": s, names[0]: rows[:, 0], names[1]: rows[:, 1], "pressure": press, "shear": shear,
            "jump_n": jn, "jump_t": jt, "status": status}


def _status(sol: MacroSolution, press, jt) -> list:
    law = sol.problem.law
    if law.friction is not None:
        closed = np.where(np.abs(jt) <= law.friction.width, "stick", "slip")
    else:
        if isinstance(law.normal, il.FieldLaw):
            kt = 0.0
        elif isinstance(law.normal, il.TabulatedLaw):
            kt = law.normal.kt
        else:
            kt = law.normal.matrix(2)[1, 1]
        closed = np.full(len(press), "stick" if kt > 0 else "slip")
    return [("open" if pv <= 0 else str(c)) for pv, c in zip(press, closed)]


def _chain(starts, ends) -> list:
    """Order segments into chains: list of ``(element, reversed)``."""
    def key(p):
        return (round(float(p[0]), 12), round(float(p[1]), 12))

    at: dict[tuple[float, float], list[int]] = {}
    for e, (a, b) in enumerate(zip(starts, ends)):
        at.setdefault(key(a), []).append(e)
        at.setdefault(key(b), []).append(e)
    left = set(range(len(starts)))
    order = []
    while left:
        ends_ = [pt for pt, es in at.items() if len([e for e in es if e in left]) == 1]
        pool = ends_ or [key(starts[e]) for e in left]
        cur = max(pool, key=lambda q: (q[1], -q[0]))
        while True:
            nxt = [e for e in at.get(cur, []) if e in left]
            if not nxt:
                break
            e = nxt[0]
            left.discard(e)
            flip = key(starts[e]) != cur
            order.append((e, flip))
            cur = key(starts[e]) if flip else key(ends[e])
    return order


def detachments(profile: dict) -> list:
    """Points along the interface where the status changes between open and closed.

    The location is interpolated linearly where the pressure changes sign
    (or halfway between the two samples when it does not).
    """
    names = [k for k in profile if k not in ("s", "pressure", "shear", "jump_n", "jump_t", "status")]
    s, p, st = profile["s"], profile["pressure"], profile["status"]
    out = []
    for i in range(len(s) - 1):
        if (st[i] == "open") == (st[i + 1] == "open"):
            continue
        theta = p[i] / (p[i] - p[i + 1]) if p[i] * p[i + 1] < 0 else 0.5
        point = {"s": float(s[i] + theta * (s[i + 1] - s[i]))}
        for c in names:
            point[c] = float(profile[c][i] + theta * (profile[c][i + 1] - profile[c][i]))
        point["opens_towards_larger_s"] = st[i + 1] == "open"
        out.append(point)
    return out


def peak_pressure(profile: dict) -> dict:
    """Largest contact pressure along the interface with its location."""
    k = int(np.argmax(profile["pressure"]))
    return {key: (float(profile[key][k]) if key != "status" else profile[key][k]) for key in profile}


def replace_law(problem: MacroProblem, law: il.InterfaceLaw) -> MacroProblem:
    """The same problem with another interface law."""
    return replace(problem, law=law)


def piecewise_linear(coordinate, points):
    """CoefficientFunction interpolating ``points = [(x_i, y_i)]`` linearly in ``coordinate``.

    Constant ``y_0`` before ``x_0`` and ``y_last`` after the last point;
    written as ``y_0 + sum_i d_i [x - x_i]_+`` with the slope increments ``d_i``.
    """
    xs = np.array([q[0] for q in points], float)
    ys = np.array([q[1] for q in points], float)
    if len(xs) == 1:
        return ng.CF(float(ys[0]))
    if np.any(np.diff(xs) <= 0):
        raise ModelError("the abscissae of a piecewise linear table must increase strictly")
    slopes = np.diff(ys) / np.diff(xs)
    incr = np.diff(np.concatenate([[0.0], slopes, [0.0]]))
    f = ng.CF(float(ys[0]))
    for xi, d in zip(xs, incr):
        if d != 0:
            f = f + float(d) * ng.IfPos(coordinate - float(xi), coordinate - float(xi), 0.0)
    return f
