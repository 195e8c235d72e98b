"""The contact multiplier of exact non-penetration on ``S_C``: node-to-node constraints (2D).

With ``contact.enforcement = "exact"`` the cell problem (paper eqs. 49-51,
57 and 65, :mod:`ngcontact.cell.cell_problem`) keeps the bodies from
overlapping instead of resisting the overlap with the Winkler layer
``k_n [J_n - g]_+`` of eq. 65, the rigid limit ``k_n -> infinity``
(DESIGN 7a).  Its contact energy is the augmented Lagrangian of
:func:`ngcontact.laws.penalty.augmented_normal_energy`,

    psi_n(J; lambda) = (1/(2k)) ([lambda + k (J_n - g)]_+^2 - lambda^2),

with the multiplier ``lambda`` held fixed in each Newton solve and updated
by Uzawa's iteration (:mod:`ngcontact.solvers.uzawa`),
``lambda <- [lambda + k (J_n - g)]_+``, ``k`` the scene's ``k_n`` (the
augmentation: it sets the speed, not the answer).

Where the constraints sit.  The contact energy is integrated with the
Gauss-Lobatto rule of ``p + 1`` points on each boundary segment (order
``p`` displacements, :func:`lobatto_rule`): its points are the two
vertices of the segment and ``p - 1`` interior points, ``p`` new points per
element, as many as the trace of a continuous order-``p`` field has dofs.
Non-penetration is imposed at these nodes only, and the multiplier has one
value ``lambda_q`` per point.  A fixed point of Uzawa's iteration is the
discrete problem

    lambda_q >= 0,   J_n(x_q) - g(x_q) <= 0,   lambda_q (J_n(x_q) - g(x_q)) = 0,

    a(u, v) + sum_q w_q lambda_q n_q . [v](x_q) = load(v)   for all v,

with the Lobatto weights ``w_q``: ``k`` is not in it, so the solution does
not depend on ``k``.  Unlike Gauss points (more constraints than trace dofs
with ``p + 1`` points per element, and the multiplier alternating between
points with fewer), the nodes determine the trace: the discrete problem is
a well-posed node-to-node contact problem.

A vertex shared by two segments is a point of both rules: it carries two
copies of the multiplier, one per segment.  The closure ``J_n - g`` is
continuous there (``J`` and the interpolated gap are, and so is ``n`` on a
smooth ``S_C``, in particular the flat one), so both copies see the same
penetration, start at 0 and receive the same update: they stay equal, and
act as one nodal constraint with the weight ``w_left + w_right``.  Where
the normal jumps (a kinked ``S_C``) the two copies constrain the two
components of the jump along two different normals, still independent
constraints on the node's two dofs.

The multiplier as a field: the polynomial of degree ``p`` on each segment
through its ``p + 1`` point values (a ``SurfaceL2`` GridFunction; the
Lobatto values determine it), so the energy reads it at the points
exactly.  Between the points it is only an interpolant: integrals of the
pressure use the Lobatto rule (:meth:`ContactMultiplier.integrate`, the
discrete interface force) and samples are taken at the points
(:meth:`ContactMultiplier.samples`).

The real contact set (:func:`contact_cuts`): a node is closed where its
multiplier carries load or its opening ``g - J_n`` is at most the Uzawa
tolerance ``rtol L``.  Between two closed nodes the surfaces are in
contact, between two open ones they are not; between a closed node ``x_c``
and an open one ``x_o`` lies a contact edge.  Beyond a smooth edge ``a``
the opening grows like ``(x - a)^(3/2)`` (the Westergaard and Hertz edge,
DESIGN 8), so ``opening^(2/3)`` is nearly linear there: the edge is the
root of the line through ``opening^(2/3)`` at ``x_o`` and the next open
node beyond it, kept between ``x_c`` and ``x_o``.  This needs the nodes in
order along ``S_C``: on a contact surface that is a graph over ``x``
(``n_y > 0``), sorted by ``x``; elsewhere, or without a falling line, the
edge is the midpoint of ``[x_c, x_o]``.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

import ngsolve as ng
import numpy as np

from ngcontact.solvers.uzawa import uzawa

log = logging.getLogger(__name__)


def lobatto_rule(order: int) -> ng.IntegrationRule:
    """Gauss-Lobatto rule of ``order + 1`` points on the reference segment ``[0, 1]`` (both ends included).

    Exact for polynomials of degree ``2 order - 1``; its interior points are
    the roots of ``P'_order`` (Legendre), its weights
    ``2 / (n (n - 1) P_(n-1)(s)^2)`` on ``[-1, 1]`` with ``n = order + 1``,
    halved for ``[0, 1]``.
    """
    p = int(order)
    if p < 1:
        raise ValueError(f"order = {order!r}: a Gauss-Lobatto rule needs order >= 1")
    n = p + 1
    leg = np.polynomial.legendre
    P = np.zeros(n)
    P[-1] = 1.0                                   # P_(n-1) = P_p
    s = np.concatenate(([-1.0], np.sort(leg.legroots(leg.legder(P))), [1.0])) if p > 1 else np.array([-1.0, 1.0])
    w = 2.0 / (n * (n - 1) * leg.legval(s, P) ** 2)
    return ng.IntegrationRule([(0.5 * (si + 1.0),) for si in s], [0.5 * wi for wi in w])


class ContactMultiplier:
    """``lambda`` at the Gauss-Lobatto points of the boundary ``label`` (2D meshes).

    Parameters
    ----------
    mesh
        The cell's mesh (2D: the contact boundary is made of segments).
    order
        Displacement order ``p``: ``p + 1`` Lobatto points per segment.

    Attributes
    ----------
    rule, ds
        The Lobatto rule and the differential symbol of the contact energy
        with it.
    value
        The multiplier (module docstring), 0 at the start.
    """

    def __init__(self, mesh: ng.Mesh, order: int, label: str = "contact"):
        self.mesh, self.label, self.order = mesh, label, int(order)
        self.region = mesh.Boundaries(label)
        self.rule = lobatto_rule(order)
        self.ds = ng.ds(label, intrules={ng.SEGM: self.rule})
        self.space = ng.SurfaceL2(mesh, order=self.order, definedon=self.region)
        self.value = ng.GridFunction(self.space)
        self.points = mesh.MapToAllElements(self.rule, self.region)
        self._values = np.zeros(len(self.points))      # lambda_q exactly (the field reads them back to round-off)
        npt = len(self.rule.points)
        t = [q[0] for q in self.rule.points]
        elements = np.asarray(self.points["nr"]).reshape(-1, npt)[:, 0]
        # per segment: its dofs and the inverse of (shape_j(t_q)), point values -> coefficients
        self._dofs = np.empty((len(elements), npt), dtype=int)
        self._inverse = np.empty((len(elements), npt, npt))
        for e, nr in enumerate(elements):
            ei = ng.ElementId(ng.BND, int(nr))
            fe = self.space.GetFE(ei)
            V = np.array([np.asarray(fe.CalcShape(tq)) for tq in t])
            self._dofs[e] = np.asarray(self.space.GetDofNrs(ei))
            self._inverse[e] = np.linalg.inv(V)

    @property
    def weights(self) -> np.ndarray:
        """Reference Lobatto weights, one per point of a segment."""
        return np.array(self.rule.weights)

    def at_points(self, cf) -> np.ndarray:
        """Values of the scalar ``cf`` at the points (segment by segment, ``p + 1`` each)."""
        return np.asarray(cf(self.points)).ravel()

    def point_values(self) -> np.ndarray:
        """The multiplier's values ``lambda_q`` at the points (as set: an open point's 0 is exactly 0)."""
        return self._values.copy()

    def set_point_values(self, values: np.ndarray) -> None:
        """``lambda_q = values``; :attr:`value` the degree-``p`` polynomial through them on each segment."""
        self._values[:] = values
        v = np.asarray(values, float).reshape(self._dofs.shape)
        coef = np.einsum("eij,ej->ei", self._inverse, v)
        self.value.vec.FV().NumPy()[self._dofs.ravel()] = coef.ravel()

    def integrate(self, cf):
        """``sum_q w_q cf(x_q) |x'|`` over the segments: ``int_{S_C} cf ds`` with the energy's rule (per component)."""
        if cf.dim > 1:
            return [ng.Integrate(cf[i] * self.ds, self.mesh) for i in range(cf.dim)]
        return ng.Integrate(cf * self.ds, self.mesh)

    def samples(self, fields: dict) -> dict[str, np.ndarray]:
        """``{name: values}`` of each field at the points, a shared vertex once; vectors as ``(dim, points)``."""
        x, y = self.at_points(ng.x), self.at_points(ng.y)
        scale = max(float(np.ptp(x)), float(np.ptp(y)), 1.0)
        _, keep = np.unique(np.round(np.stack([x, y]) / scale, 10), axis=1, return_index=True)
        keep = np.sort(keep)
        out = {}
        for name, cf in fields.items():
            if cf.dim > 1:
                out[name] = np.stack([self.at_points(cf[i])[keep] for i in range(cf.dim)])
            else:
                out[name] = self.at_points(cf)[keep]
        return out

    def update(self, pressure, penetration, k: float, length: float) -> dict[str, float]:
        """``lambda <- pressure`` at the points; the relative measures of :func:`~ngcontact.solvers.uzawa.uzawa`.

        ``pressure`` is the augmented pressure ``[lambda + k (J_n - g)]_+``
        of the current state, ``penetration`` is ``J_n - g``, ``length`` the
        characteristic length ``L`` of the tests.  Returns the largest
        penetration and the largest change ``|d lambda| / k`` on the points
        that carry load after the update (there it equals ``|J_n - g|``:
        the gap left open under load), both divided by ``L``, and, for the
        history, the largest change relative to the largest multiplier.
        """
        new = np.maximum(self.at_points(pressure), 0.0)
        pen = self.at_points(penetration)
        old = self.point_values()
        loaded = new > 0.0
        step = np.abs(new - old)
        scale = float(max(new.max(initial=0.0), old.max(initial=0.0)))
        out = {"penetration": max(float(pen.max(initial=0.0)), 0.0) / length,
               "change": float(step[loaded].max(initial=0.0)) / (k * length),
               "relative_change": float(step.max(initial=0.0)) / scale if scale > 0 else 0.0}
        self.set_point_values(new)
        return out


def characteristic_length(problem) -> float:
    """``L`` of the Uzawa test: the largest initial gap on ``S_C`` or the far-face translation ``|U|``.

    Falls back to the largest ``|J|`` on ``S_C`` and then to 1 (nothing loaded).
    """
    m = problem.multiplier
    gap = 0.0 if problem.gap is None else float(m.at_points(problem.gap).max(initial=0.0))
    U = float(np.linalg.norm([problem.gfu.vec[d] for d in problem.u_dofs]))
    length = max(gap, U)
    if length > 0:
        return length
    J = float(m.at_points(ng.sqrt(ng.InnerProduct(problem.J, problem.J))).max(initial=0.0))
    return J if J > 0 else 1.0


def solve_exact(problem, newton: Callable[[float], dict], atol: float) -> dict[str, Any]:
    """Uzawa's iteration on ``problem`` (a cell problem built with ``enforcement = "exact"``).

    ``newton(atol)`` minimizes the augmented energy with the current
    multiplier and returns its history.  Returns one history in the format
    of :meth:`ngcontact.solvers.newton.NewtonHistory.as_dict`, the passes'
    lists concatenated, plus ``uzawa_iterations``, ``uzawa_penetrations``,
    ``uzawa_changes``, ``uzawa_relative_changes`` and ``newton_per_pass``.
    """
    m, model = problem.multiplier, problem.model

    def solve(j: int) -> dict:
        return newton(atol)

    def update() -> dict[str, float]:
        return m.update(problem.augmented_pressure, problem.penetration, problem.augmentation.Get(),
                        characteristic_length(problem))

    hist = uzawa(solve, update, rtol=model.uzawa_rtol, max_iter=model.uzawa_max_iter)
    passes = hist["newton"]
    out: dict[str, Any] = {"iterations": sum(h["iterations"] for h in passes),
                           "converged": all(h["converged"] for h in passes), "linear_solve_only": False}
    for key in ("residuals", "energies", "step_lengths", "active_set_sizes"):
        out[key] = [v for h in passes for v in h[key]]
    out["uzawa_iterations"] = hist["uzawa_iterations"]
    out["uzawa_penetrations"] = hist["penetrations"]
    out["uzawa_changes"] = hist["changes"]
    out["uzawa_relative_changes"] = hist["relative_changes"]
    out["newton_per_pass"] = [h["iterations"] for h in passes]
    log.info("exact contact: %d Uzawa passes, %d Newton steps", hist["uzawa_iterations"], out["iterations"])
    return out


def contact_cuts(problem) -> list[tuple[np.ndarray, list[bool]]]:
    """Per segment of ``S_C`` (in the order of :attr:`ContactMultiplier.points`): ``(cuts, on)``.

    ``cuts`` are reference coordinates ``0 = c_0 < ... < c_m = 1`` and
    ``on[i]`` says whether ``[c_i, c_(i+1)]`` is in contact: the nodes and
    the edges between them of the module docstring.  Within a segment the
    abscissa is taken as affine in the reference coordinate (straight
    segments) to place an edge.
    """
    m = problem.multiplier
    npt = len(m.rule.points)
    t = np.array([q[0] for q in m.rule.points])
    lam = m.point_values()
    opening = -m.at_points(problem.penetration)
    closed = (lam > 0.0) | (opening <= problem.model.uzawa_rtol * characteristic_length(problem))
    x = m.at_points(ng.x)
    graph = problem.dim == 2 and float(m.at_points(problem.n[1]).min(initial=1.0)) > 0.0
    # the nodes along S_C, a shared vertex once: sorted by x
    scale = max(float(np.ptp(x)), 1.0)
    X, node = np.unique(np.round(x / scale, 11), return_inverse=True)
    X = X * scale
    node_closed = np.zeros(len(X), bool)
    np.logical_or.at(node_closed, node, closed)
    node_opening = np.full(len(X), np.inf)
    np.minimum.at(node_opening, node, np.maximum(opening, 0.0))
    r = node_opening ** (2.0 / 3.0)
    out = []
    for e in range(len(x) // npt):
        idx = node[e * npt:(e + 1) * npt]
        cuts, on = [0.0], []
        for q in range(npt - 1):
            a, b = node_closed[idx[q]], node_closed[idx[q + 1]]
            if a == b:
                on.append(bool(a))
                cuts.append(t[q + 1])
                continue
            c, o = (q, q + 1) if a else (q + 1, q)
            f = 0.5                                   # the edge at this fraction from the closed node
            if graph:
                nc, no = idx[c], idx[o]
                n2 = no + (no - nc)
                if abs(no - nc) == 1 and 0 <= n2 < len(X) and not node_closed[n2] and r[n2] > r[no]:
                    root = X[no] - r[no] * (X[n2] - X[no]) / (r[n2] - r[no])
                    f = float(np.clip((root - X[nc]) / (X[no] - X[nc]), 0.0, 1.0))
            tc = t[c] + f * (t[o] - t[c])
            cuts.append(tc)
            on.append(bool(a))
            cuts.append(t[q + 1])
            on.append(bool(b))
        keep = [i for i in range(len(on)) if cuts[i + 1] > cuts[i]]
        out.append((np.array([cuts[0]] + [cuts[i + 1] for i in keep]), [on[i] for i in keep]))
    return out
