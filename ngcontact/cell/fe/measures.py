"""Measurements of a solved cell problem: contact set, mean tractions and jumps, stresses.

Functions of a :class:`~ngcontact.cell.fe.cell_problem.CellProblem` in its
current state (the cell problem of paper eqs. 49-51, 57, 65, with the jump
``J = u_r - u_c - U`` across ``S_C``, the micro normal ``n``, the gap ``g``
and the penalty pressure ``p = k_n [J.n - g]_+`` of eq. 65).  ``|T|`` is the
area of the cell's period.

* Real contact set ``S_C_real = {J.n - g >= 0}`` (the set of paper Sec. 3.2.2
  over which eq. 34 integrates) and its measure per period,
  ``contact_fraction = |S_C_real| / |T|`` (:func:`contact_fraction`; in 2D
  the contact edges are located between quadrature points by the roots of
  the penetration polynomial on each boundary element);
* ``mean_pressure = (1/|T|) int_{S_C} p ds`` (:func:`mean_pressure`);
* the mean traction on the counter's far face, prescribed or the reaction
  (the residual of the energy on ``U``), :func:`mean_traction`;
* equilibrium of the counter body, :func:`equilibrium_error`: the force the
  interface transmits, ``F = (1/|T|) int_{S_C} (p n + tau_f) ds`` (pressure
  along the micro normal plus the friction traction of eq. 17), must balance
  the far-face traction ``t``: ``|F + t| <= EQUILIBRIUM_RTOL max(|t|, A)``
  with ``A = (1/|T|) int |p n + tau_f| ds``, both integrated with the rule
  the contact energy is assembled with, so that ``F`` is the discrete
  interface force and the balance holds to the solver's tolerance (1e-11
  and below on every shipped cell, 1.5e-6 for a Huber width of 1e-12 whose
  stick stiffness puts the residual's round-off floor there); a solve that
  violates it is not a solution, whatever its residual said (:func:`measure`
  raises);
* the projected mean jump ``Jbar = (1/|T|) int_{S_C} J |n.n0| ds``
  (:func:`mean_jump`);
* the homogenized coefficients of eqs. 34, 42-43 on ``S_C_real``
  (:func:`real_contact_coefficients`, computed by
  :mod:`ngcontact.cell.coefficients`; in 2D over the pieces the contact
  fraction measures, :func:`~ngcontact.cell.fe.edge_cuts.contact_set_integral`);
* the stress ``sigma_B = C_B : (eps(u_B) + E)`` of each body at element
  points and its largest von Mises and Tresca values (the equivalent
  stresses of eq. 77, :mod:`ngcontact.fem.materials`), :func:`body_stresses`,
  :func:`stress_maxima`;
* the effective stiffness of the interface (beyond the paper,
  :mod:`ngcontact.cell.fe.stiffness`).

Exact enforcement (:mod:`ngcontact.cell.fe.contact_multiplier`): the
pressure is the multiplier ``lambda``, given at the nodal points of the
contact energy (Gauss-Lobatto in 2D, the vertices of the triangles in 3D), so its
integrals use that rule (the discrete interface force) and its samples
are taken at those points; the real contact set is
built from the closed nodes and the edges between them
(:func:`ngcontact.cell.fe.exact_contact_set.contact_cuts`, in 3D
:func:`~ngcontact.cell.fe.exact_contact_set.contact_area`), not from the sign
of the penetration, which is zero to round-off at the nodes and the
interpolation error of the closure between them.

:func:`measure` collects them into the results of one load.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import CellLoad
from ngcontact.errors import ConvergenceError
from ngcontact.cell.coefficients import coefficients
from ngcontact.cell.fe.edge_cuts import contact_set_integral, cut_elements
from ngcontact.cell.fe.exact_contact_set import contact_area
from ngcontact.cell.fe.stiffness import effective_stiffness
from ngcontact.fem import materials as _mat
from ngcontact.fem.quadrature import kink_order, sampling_order, smooth_order
from ngcontact.fem.sampling import boundary_samples
from ngcontact.laws import penalty as _contact


# ------------------------------------------------------------ the contact surface
def contact_integral(problem, cf, order=None):
    """``int_{S_C} cf ds`` at integration order ``order`` (default :func:`~ngcontact.fem.quadrature.kink_order`)."""
    o = order if order is not None else kink_order(problem.model.order)
    return ng.Integrate(cf, problem.mesh, definedon=problem.mesh.Boundaries("contact"), order=o)


def contact_fraction(problem, method: str = "auto") -> float:
    """Measure of the real contact set ``{J_n - g >= 0}`` on ``S_C`` divided by ``|T|``.

    Parameters
    ----------
    method
        ``"roots"`` (2D): on each boundary element the penetration
        ``J_n - g_h`` is a polynomial of the reference coordinate ``t``
        (degree ``order`` on straight elements with the interpolated
        gap); it is interpolated at ``order + 3`` Gauss points, its real
        roots in ``[0, 1]`` split the element, and the length
        ``int |dx/dt| dt`` of the pieces where it is nonnegative is
        summed.  The contact edge is thus located inside the element
        instead of at the nearest quadrature point.
        ``"quadrature"``: integral of the indicator at high order (3D,
        where the zero set is a curve on each face).  ``"auto"``: roots
        in 2D, quadrature in 3D.  With exact enforcement the pieces of
        :func:`contact_pieces` are those of the closed nodes (module
        docstring; in 3D :func:`~ngcontact.cell.fe.exact_contact_set.contact_area`),
        whatever the method.
    """
    if problem.multiplier is not None:
        closed = _contact_length_by_roots(problem) if problem.dim == 2 else contact_area(problem)
        return closed / problem.area
    if method == "auto":
        method = "roots" if problem.dim == 2 else "quadrature"
    if method == "quadrature":
        ind = ng.IfPos(-problem.penetration, 0.0, 1.0)
        return float(contact_integral(problem, ind)) / problem.area
    if method != "roots" or problem.dim != 2:
        raise ValueError(f"method = {method!r}: must be 'auto', 'quadrature' or (2D) 'roots'")
    return _contact_length_by_roots(problem) / problem.area


def _contact_length_by_roots(problem) -> float:
    return float(sum(length for _, _, on, length in contact_pieces(problem) if on))


def contact_pieces(problem) -> list[tuple[float, float, bool, float]]:
    """The boundary elements of ``S_C`` (2D) cut at the roots of the penetration polynomial.

    Returns ``(x_start, x_end, in_contact, length)`` per piece: the
    abscissae of its ends (in the element's direction), whether the
    penetration ``J_n - g_h`` is nonnegative on it, and its arc length
    (the cuts of :func:`~ngcontact.cell.fe.edge_cuts.element_cuts`).
    """
    P = np.polynomial.polynomial
    coef, cuts = cut_elements(problem)
    tg, wg = np.polynomial.legendre.leggauss(coef.shape[0] + 2)
    out: list[tuple[float, float, bool, float]] = []
    for e, (ts, states) in enumerate(cuts):
        c_x, c_y = coef[:, e, 1], coef[:, e, 2]
        for a, b, on in zip(ts[:-1], ts[1:], states):
            if b > a:
                out.append((float(P.polyval(a, c_x)), float(P.polyval(b, c_x)), on, _arc(c_x, c_y, a, b, tg, wg)))
    return out


def _arc(c_x, c_y, a, b, tg, wg) -> float:
    """Length of the curve ``(x(t), y(t))`` (monomial coefficients) for ``t`` in ``[a, b]``."""
    P = np.polynomial.polynomial
    s = 0.5 * (b - a) * tg + 0.5 * (a + b)
    dx, dy = P.polyval(s, P.polyder(c_x)), P.polyval(s, P.polyder(c_y))
    return float(0.5 * (b - a) * np.sum(wg * np.hypot(dx, dy)))


def mean_pressure(problem) -> float:
    """``(1/|T|) int_{S_C} p ds`` with the penalty pressure ``p = k_n [J.n - g]_+`` (exact: the multiplier)."""
    if problem.multiplier is not None:
        return float(problem.multiplier.integrate(problem.pressure)) / problem.area
    return float(contact_integral(problem, problem.pressure)) / problem.area


# ------------------------------------------------------------ means over the period
def mean_traction(problem, load: CellLoad) -> np.ndarray:
    """Mean traction on the counter's far face per axis (prescribed or reaction)."""
    res = problem.gfu.vec.CreateVector()
    problem.form.Apply(problem.gfu.vec, res)
    out = np.empty(problem.dim)
    for i, d in enumerate(problem.u_dofs):
        if load.traction[i] is not None and (i == problem.dim - 1 or problem.tangential_free):
            out[i] = load.traction[i]
        else:  # the load term of a controlled component is zero: residual = reaction
            out[i] = res[d] / problem.area
    return out


#: Largest relative imbalance between the interface force and the far-face traction.
EQUILIBRIUM_RTOL = 1e-4


def interface_traction(problem):
    """The traction the rough body exerts on the counter across ``S_C``: ``p n + tau_f``."""
    t = problem.pressure * problem.n
    f = problem.model.friction
    if f is not None:
        t = t + f.traction(problem.J, problem.n, friction_threshold(problem))
    return t


def equilibrium_error(problem, far_face_traction: np.ndarray) -> float:
    """``|F + t| / max(|t|, A)`` of the module docstring (0 when nothing is transmitted)."""
    tr = interface_traction(problem)
    def energy_rule(cf):          # the rule the energy is assembled with: F is then the discrete force
        if problem.multiplier is not None:
            return problem.multiplier.integrate(cf)
        return contact_integral(problem, cf, order=problem.contact_order)
    F = np.array(energy_rule(tr), float).ravel() / problem.area
    A = float(energy_rule(ng.sqrt(ng.InnerProduct(tr, tr)))) / problem.area
    t = np.asarray(far_face_traction, float)
    scale = max(float(np.linalg.norm(t)), A)
    return float(np.linalg.norm(F + t)) / scale if scale > 0 else 0.0


def pressure_balance(problem, far_face_traction: np.ndarray) -> float:
    """``|F_h + t| / max(|t|, A_h)``: the interface force integrated accurately (the kink rule, not the
    energy's) against the far-face traction.

    The energy's quadrature sees the penalty's pressure at its points only: a contact patch narrower than
    those points' spacing penetrates between them unseen, the discrete force balances the load
    (:func:`equilibrium_error`) and the pressure field does not.  Its accurate integral then misses the load
    by the share of the pressure the energy did not see, which is what this measures (exact enforcement: the
    multiplier's rule is the force's own, and the two coincide).
    """
    if problem.multiplier is not None:
        return equilibrium_error(problem, far_face_traction)
    tr = interface_traction(problem)
    F = np.array(contact_integral(problem, tr), float).ravel() / problem.area
    A = float(contact_integral(problem, ng.sqrt(ng.InnerProduct(tr, tr)))) / problem.area
    t = np.asarray(far_face_traction, float)
    scale = max(float(np.linalg.norm(t)), A)
    return float(np.linalg.norm(F + t)) / scale if scale > 0 else 0.0


def mean_jump(problem) -> np.ndarray:
    """Projected mean of the jump on ``S_C``: ``(1/|T|) int J |n.n0| ds``."""
    n, d = problem.n, problem.dim
    w = ng.IfPos(n[d - 1], n[d - 1], -n[d - 1])
    return np.array(contact_integral(problem, problem.J * w, order=smooth_order(problem.model.order))) / problem.area


def friction_threshold(problem):
    """``G`` on ``S_C`` of the current state (``mu p`` for Coulomb), or ``None``."""
    f = problem.model.friction
    if f is None:
        return None
    return f.threshold(problem.pressure)


def real_contact_coefficients(problem) -> dict:
    """Paper eqs. 34, 42-43 on the real contact set ``{J_n - g >= 0}`` of the current state.

    2D: over the pieces in contact (:func:`~ngcontact.cell.fe.edge_cuts.contact_set_integral`), the set whose
    measure is the contact fraction, so that ``k_n`` of a flat cell is ``k_n`` times it.  An indicator
    integrated by quadrature would put each edge at its nearest quadrature point, an error of up to half
    their spacing (a tenth of an element at ``kink_order``) that changes with the order's rule and not with
    the solution: on the stem grooves at order 1 it exceeded the discretization's error of the fraction
    and made one order more's change (the default estimate, :mod:`ngcontact.cell.fe.saturation`) 36 times
    the error of ``k_n``.  The gap is the scene's ``g`` of eq. 34, not the penalty's interpolant of it
    (:func:`~ngcontact.cell.fe.discrete_cell.discrete_gap`, which makes the penetration a polynomial): its
    interpolation error is no part of ``g_n`` (at order 1 it cancelled the edges' error by chance).  3D: the
    indicator at :func:`~ngcontact.fem.quadrature.kink_order`; exact
    enforcement: where the multiplier's interpolant is positive (``k_n`` only scales ``K0`` and ``g``; in
    the rigid limit they diverge).
    """
    gap = problem.model.gap       # the scene's gap, not the penalty's interpolant of it (docstring)
    if problem.dim == 2:          # the pieces of the contact fraction: the edges cut the elements
        c = coefficients(problem.cell, kn=problem.model.k_n, gap=gap, G=friction_threshold(problem),
                         normal=problem.n, integrate=lambda cf: contact_set_integral(problem, cf))
        return c.as_dict()
    ind = ng.IfPos(-problem.penetration, 0.0, 1.0) if problem.multiplier is None else \
        ng.IfPos(problem.pressure, 1.0, 0.0)
    c = coefficients(problem.cell, kn=problem.model.k_n, gap=gap, G=friction_threshold(problem),
                     weight=ind, normal=problem.n, intorder=kink_order(problem.model.order))
    return c.as_dict()


# ------------------------------------------------------------ samples
def sample_surface(problem, fields: dict, order: int | None = None) -> dict:
    """Values of CoefficientFunctions at the quadrature points of ``S_C``.

    Evaluated on the boundary elements of ``contact`` themselves, so the
    traces of each body are unambiguous.  Returns arrays, with the
    coordinates under ``"x"``, ``"y"`` (and ``"z"``).  The default points:
    :func:`~ngcontact.fem.quadrature.sampling_order`, with exact
    enforcement the multiplier's Lobatto points (a shared vertex once).
    """
    coords = {name: c for name, c in zip(("x", "y", "z")[: problem.dim], (ng.x, ng.y, ng.z))}
    if order is None and problem.multiplier is not None:
        return problem.multiplier.samples({**coords, **fields})
    o = order if order is not None else sampling_order(problem.model.order)
    return boundary_samples(problem.mesh, "contact", {**coords, **fields}, o)


def surface_distribution(problem) -> dict:
    """Pressure and slip at the quadrature points of ``S_C`` (2D: sorted by ``x``)."""
    s = sample_surface(problem, {"pressure": problem.pressure,
                                 "slip": _contact.slip_magnitude(problem.J, problem.n),
                                 "closure": _contact.normal_closure(problem.J, problem.n)})
    if problem.dim == 2:
        idx = np.argsort(s["x"], kind="stable")
        s = {k: v[..., idx] for k, v in s.items()}
    return s


def body_stresses(problem) -> dict:
    """Stress tensors of the current state at the element integration points of each body.

    Returns ``{body: {"stress": (n, 3, 3), "points": (n, dim)}}``.  The
    points are those of the order-``2p`` rule mapped to every element of
    the body, so none lies on the interface (where point evaluation could
    pick the other body's element).
    """
    out = {}
    mesh, m = problem.mesh, problem.model
    comps = problem.gfu.components
    shape = ng.TET if problem.dim == 3 else ng.TRIG
    rule = ng.IntegrationRule(shape, 2 * max(m.order, 1))
    for name, law, u in (("rough", m.rough, comps[0]), ("counter", m.counter, comps[1])):
        sig = law.stress(problem.body_strain(u))
        coords = (ng.x, ng.y, ng.z)[: problem.dim]
        cf = ng.CF(tuple(sig[i, j] for i in range(3) for j in range(3)) + coords)
        vals = np.asarray(cf(mesh.MapToAllElements(rule, mesh.Materials(name))))
        out[name] = {"stress": vals[:, :9].reshape(-1, 3, 3).copy(), "points": vals[:, 9:].copy()}
    return out


def stress_maxima(problem) -> dict:
    """Largest von Mises and Tresca stress in each body and where (element points)."""
    out = {}
    for name, sample in body_stresses(problem).items():
        S, X = sample["stress"], sample["points"]
        vm = _mat.von_mises(S)
        tr = _mat.tresca(S)
        i, j = int(np.argmax(vm)), int(np.argmax(tr))
        out[f"max_von_mises_{name}"] = {"value": float(vm[i]), "location": X[i].tolist()}
        out[f"max_tresca_{name}"] = {"value": float(tr[j]), "location": X[j].tolist()}
    return out


# ------------------------------------------------------------ results of a load
def measure(problem, load: CellLoad) -> dict:
    """Scalar results of the current state (module docstring)."""
    d = problem.dim
    t = mean_traction(problem, load)
    imbalance = equilibrium_error(problem, t)
    if not imbalance <= EQUILIBRIUM_RTOL:
        raise ConvergenceError(
            f"the cell solution is not in equilibrium: the interface force differs from the far-face "
            f"traction {t.tolist()} by {imbalance:.3g} of it (allowed {EQUILIBRIUM_RTOL:g}); the penalty "
            f"k_n = {problem.model.k_n:g} is likely too stiff for this mesh and its material: lower it, "
            "or refine the mesh at the interface", {})
    jbar = mean_jump(problem)
    Uv = np.array([problem.gfu.vec[k] for k in problem.u_dofs])
    res = {
        "contact_fraction": contact_fraction(problem),
        "mean_pressure": mean_pressure(problem),
        "mean_traction": t.tolist(),
        "transmitted_pressure": float(-t[d - 1]),
        "equilibrium_error": imbalance,
        "pressure_balance": pressure_balance(problem, t),
        "mean_jump": jbar.tolist(),
        "mean_closure": float(jbar[d - 1]),
        "far_face_jump": (-Uv).tolist(),
        "max_penetration": float(sample_surface(problem, {"pen": problem.penetration})["pen"].max()),
    }
    if problem.multiplier is not None:   # between the multiplier's points (module docstring)
        o = sampling_order(problem.model.order)
        res["max_penetration_between_points"] = float(
            sample_surface(problem, {"pen": problem.penetration}, order=o)["pen"].max())
    res.update(stress_maxima(problem))
    res["effective_stiffness"] = effective_stiffness(problem)
    res["coefficients"] = real_contact_coefficients(problem)
    return res
