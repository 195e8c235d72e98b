"""The contact multiplier of exact non-penetration on ``S_C``: node-to-node constraints (2D and 3D).

With ``contact.enforcement = "exact"`` the cell problem (paper eqs. 49-51,
57 and 65, :mod:`ngcontact.cell.fe.cell_problem`) keeps the bodies from
overlapping instead of resisting the overlap with the Winkler layer
``k_n [J_n - g]_+`` of eq. 65, the rigid limit ``k_n -> infinity``.  Its contact energy is the augmented Lagrangian of
:func:`ngcontact.laws.penalty.augmented_normal_energy`,

    psi_n(J; lambda) = (1/(2k)) ([lambda + k (J_n - g)]_+^2 - lambda^2),

with the multiplier ``lambda`` held fixed in each Newton solve and updated
by Uzawa's iteration (:mod:`ngcontact.solvers.uzawa`),
``lambda <- [lambda + k (J_n - g)]_+``, ``k`` the scene's ``k_n`` (the
augmentation: it sets the speed, not the answer).

Where the constraints sit.  In 2D the contact energy is integrated with
the Gauss-Lobatto rule of ``p + 1`` points on each boundary segment (order
``p`` displacements, :func:`lobatto_rule`): its points are the two
vertices of the segment and ``p - 1`` interior points, ``p`` new points per
element, as many as the trace of a continuous order-``p`` field has dofs.
In 3D (triangles on ``S_C``) the nodes are the vertices, each carrying a
third of the area of every triangle around it (:func:`triangle_vertex_rule`:
positive weights, exact for linear functions, the consistent nodal forces
of linear elements), and the displacements are of order 1.  Higher orders
are refused (``TRIANGLE_MAX_ORDER``): no rule with positive weights has
the Lagrange nodes of a quadratic triangle as its points and the
consistent nodal forces (a uniform pressure puts none on the corners of a
quadratic triangle), and the lumped rule of the order-``p`` lattice (each
of the ``p^2`` sub-triangles giving a third of its area to each of its
vertices) leaves corner nodes hanging open inside the
contact patch: on Westergaard's waves in a 3D cell at order 2 a good part
of the nodes inside the patch stay open, the contact fraction comes out
low and worsens under refinement, and the bisinusoid's falls away from
the spectral cell's.  At order 1 no node inside the
patch stays open.  Either way,
non-penetration is imposed at these nodes only, and the multiplier has one
value ``lambda_q`` per point.  A fixed point of Uzawa's iteration is the
discrete problem

    lambda_q >= 0,   J_n(x_q) - g(x_q) <= 0,   lambda_q (J_n(x_q) - g(x_q)) = 0,

    a(u, v) + sum_q w_q lambda_q n_q . [v](x_q) = load(v)   for all v,

with the Lobatto weights ``w_q``: ``k`` is not in it, so the solution does
not depend on ``k``.  Unlike Gauss points (more constraints than trace dofs
with ``p + 1`` points per element, and the multiplier alternating between
points with fewer), the nodes determine the trace: the discrete problem is
a well-posed node-to-node contact problem.

A vertex shared by two segments (in 3D: by the triangles around it, and
likewise an edge's nodes) is a point of each of their rules: it carries one
copy of the multiplier per element.  The closure ``J_n - g`` is
continuous there (``J`` and the interpolated gap are, and so is ``n`` on a
smooth ``S_C``, in particular the flat one), so both copies see the same
penetration, start at 0 and receive the same update: they stay equal, and
act as one nodal constraint with the sum of the copies' weights.  Where
the normal jumps (a kinked ``S_C``) the two copies constrain the two
components of the jump along two different normals, still independent
constraints on the node's two dofs.

The multiplier as a field: the polynomial of degree ``p`` on each element
through its point values (a ``SurfaceL2`` GridFunction; the
Lobatto values determine it), so the energy reads it at the points
exactly.  Between the points it is only an interpolant: integrals of the
pressure use the Lobatto rule (:meth:`ContactMultiplier.integrate`, the
discrete interface force) and samples are taken at the points
(:meth:`ContactMultiplier.samples`).

The real contact set the multiplier and the openings give (closed nodes
and the contact edges between them) is measured in
:mod:`ngcontact.cell.fe.exact_contact_set`.
"""
from __future__ import annotations

import logging
import math
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


def triangle_vertex_rule() -> ng.IntegrationRule:
    """The vertices of the reference triangle, each with a third of its area (``1/6``).

    Positive weights summing to the reference area ``1/2``, exact for
    linear functions: on order-1 triangles the consistent nodal forces of
    a pressure linear on the element.
    """
    return ng.IntegrationRule([(1.0, 0.0), (0.0, 1.0), (0.0, 0.0)], [1.0 / 6.0] * 3)


#: Largest displacement order with exact contact on triangles (3D): the vertex rule (module docstring)
TRIANGLE_MAX_ORDER = 1


class ContactMultiplier:
    """``lambda`` at the nodes of the boundary ``label``: Gauss-Lobatto on segments (2D), vertices of triangles (3D).

    Parameters
    ----------
    mesh
        The cell's mesh (2D: the contact boundary is made of segments; 3D:
        of triangles).
    order
        Displacement order ``p``: ``p + 1`` Lobatto points per segment,
        the vertices of each triangle (order 1 only: ``TRIANGLE_MAX_ORDER``).

    Attributes
    ----------
    rule, ds
        The nodal rule (:func:`lobatto_rule`, :func:`triangle_vertex_rule`)
        and the differential symbol of the contact energy with it.
    value
        The multiplier (module docstring), 0 at the start.
    """

    def __init__(self, mesh: ng.Mesh, order: int, label: str = "contact"):
        self.mesh, self.label, self.order = mesh, label, int(order)
        self.dim = mesh.dim
        if self.dim not in (2, 3):
            raise ValueError(f"mesh.dim = {self.dim!r}: a contact multiplier needs a 2D or 3D mesh")
        if self.dim == 3 and self.order > TRIANGLE_MAX_ORDER:
            raise ValueError(f"order = {order!r}: exact contact on triangles (3D) is built for order "
                             f"<= {TRIANGLE_MAX_ORDER} (module docstring)")
        self.region = mesh.Boundaries(label)
        shape = ng.SEGM if self.dim == 2 else ng.TRIG
        self.rule = lobatto_rule(order) if self.dim == 2 else triangle_vertex_rule()
        self.ds = ng.ds(label, intrules={shape: self.rule})
        self.space = ng.SurfaceL2(mesh, order=self.order, definedon=self.region)
        self.value = ng.GridFunction(self.space)
        self.points = mesh.MapToAllElements(self.rule, self.region)
        self._values = np.zeros(len(self.points))      # lambda_q exactly (the field reads them back to round-off)
        npt = len(self.rule.points)
        ref = [q[: self.dim - 1] for q in self.rule.points]
        elements = np.asarray(self.points["nr"]).reshape(-1, npt)[:, 0]
        self.elements = elements
        self._areas: np.ndarray | None = None
        # per element: its dofs and the inverse of (shape_j(x_q)), point values -> coefficients
        self._dofs = np.empty((len(elements), npt), dtype=int)
        self._inverse = np.empty((len(elements), npt, npt))
        for e, nr in enumerate(elements):
            ei = ng.ElementId(ng.BND, int(nr))
            fe = self.space.GetFE(ei)
            V = np.array([np.asarray(fe.CalcShape(*xq)) for xq in ref])
            self._dofs[e] = np.asarray(self.space.GetDofNrs(ei))
            self._inverse[e] = np.linalg.inv(V)

    @property
    def element_areas(self) -> np.ndarray:
        """Measure of each element of ``S_C`` (length in 2D, area in 3D), in the order of :attr:`points`."""
        if self._areas is None:
            every = ng.Integrate(ng.CF(1.0), self.mesh, ng.BND, definedon=self.region, element_wise=True)
            self._areas = np.asarray(every)[self.elements]
        return self._areas

    @property
    def weights(self) -> np.ndarray:
        """Reference weights of the nodal rule, one per point of an element."""
        return np.array(self.rule.weights)

    def at_points(self, cf) -> np.ndarray:
        """Values of the scalar ``cf`` at the points (element by element, the rule's points each)."""
        return np.asarray(cf(self.points)).ravel()

    def point_values(self) -> np.ndarray:
        """The multiplier's values ``lambda_q`` at the points (as set: an open point's 0 is exactly 0)."""
        return self._values.copy()

    def set_point_values(self, values: np.ndarray) -> None:
        """``lambda_q = values``; :attr:`value` the degree-``p`` polynomial through them on each element."""
        self._values[:] = values
        v = np.asarray(values, float).reshape(self._dofs.shape)
        coef = np.einsum("eij,ej->ei", self._inverse, v)
        self.value.vec.FV().NumPy()[self._dofs.ravel()] = coef.ravel()

    def integrate(self, cf):
        """``sum_q w_q cf(x_q) |J_q|`` over the elements: ``int_{S_C} cf ds`` with the energy's rule (per component)."""
        if cf.dim > 1:
            return [ng.Integrate(cf[i] * self.ds, self.mesh) for i in range(cf.dim)]
        return ng.Integrate(cf * self.ds, self.mesh)

    def samples(self, fields: dict) -> dict[str, np.ndarray]:
        """``{name: values}`` of each field at the points, a shared vertex once; vectors as ``(dim, points)``."""
        xyz = np.stack([self.at_points(c) for c in (ng.x, ng.y, ng.z)[: self.dim]])
        scale = max(float(np.ptp(xyz, axis=1).max()), 1.0)
        _, keep = np.unique(np.round(xyz / scale, 10), axis=1, return_index=True)
        keep = np.sort(keep)
        out = {}
        for name, cf in fields.items():
            if cf is self.value:           # the multiplier itself: its point values as set, not read back
                out[name] = self._values[keep].copy()
            elif cf.dim > 1:
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


#: factor by which a slow Uzawa pass raises the augmentation (:func:`ngcontact.solvers.uzawa.uzawa`)
STIFFEN = 10.0
#: ceiling of a raised augmentation, as ``k h / E`` (``h`` the smallest element of ``S_C``, ``E`` the
#: softer body's modulus): high enough that Uzawa ends in a couple of passes, low enough that the stiff
#: term leaves the equilibrium at round-off (a far larger ratio costs it several digits)
MAX_AUGMENTATION_RATIO = 1e4
#: ``k h / E`` of the augmentation Uzawa's passes start from (:func:`solve_exact`)
START_AUGMENTATION_RATIO = 1e2


def max_augmentation(problem) -> float:
    """The ceiling of a raised augmentation: ``MAX_AUGMENTATION_RATIO E / h``; never below the scene's ``k_n``."""
    return max(MAX_AUGMENTATION_RATIO * softer_modulus(problem.model) / smallest_element(problem), problem.model.k_n)


def smallest_element(problem) -> float:
    """``h``, the smallest element of ``S_C``: its length in 2D, the leg of the right isosceles triangle of its
    area in 3D."""
    m = problem.multiplier
    smallest = float(m.element_areas.min())
    return smallest if m.dim == 2 else math.sqrt(2.0 * smallest)


def start_augmentation(problem) -> float:
    """The augmentation Uzawa's passes start from (:func:`solve_exact`): in 3D ``START_AUGMENTATION_RATIO E / h``
    with ``h`` the mesh's smallest element of ``S_C`` (:func:`smallest_element`), never below the scene's
    ``k_n``; in 2D the scene's ``k_n``."""
    if problem.multiplier.dim != 3:
        return problem.model.k_n
    return max(START_AUGMENTATION_RATIO * softer_modulus(problem.model) / smallest_element(problem),
               problem.model.k_n)


def softer_modulus(model) -> float:
    """Young's modulus of the softer body (isotropic), else the smallest eigenvalue of its stiffness matrix."""
    out = math.inf
    for law in (model.rough, model.counter):
        if law.lame is not None:
            lam, mu = law.lame
            out = min(out, mu * (3.0 * lam + 2.0 * mu) / (lam + mu))
        else:
            out = min(out, float(np.linalg.eigvalsh(law.matrix).min()))
    return out


def solve_exact(problem, newton: Callable[[float], dict], atol: float) -> dict[str, Any]:
    """Uzawa's iteration on ``problem`` (a cell problem built with ``enforcement = "exact"``).

    ``newton(atol)`` minimizes the augmented energy with the current
    multiplier and returns its history.  Returns one history in the format
    of :meth:`ngcontact.solvers.newton.NewtonHistory.as_dict`, the passes'
    lists concatenated, plus ``uzawa_iterations``, ``uzawa_penetrations``,
    ``uzawa_changes``, ``uzawa_relative_changes``, ``newton_per_pass`` and
    ``uzawa_at_floor`` (stopped at the round-off floor,
    :func:`~ngcontact.solvers.uzawa.uzawa`), ``uzawa_stiffened`` (the passes after which a slow pass raised the
    augmentation by ``STIFFEN``, up to :func:`max_augmentation`).

    The passes start from :func:`start_augmentation`.  A pass contracts the multiplier's error by about
    ``1 / (1 + k c)``, ``c`` the compliance of the slowest mode, a node's own, of the order of ``h / E`` at
    the smallest element ``h``; the scene's ``k_n`` (default ``10 E / interface_maxh``,
    :func:`ngcontact.scene.cell_scene.exact_scale`) is of that order on the scene's mesh, but a mesh
    refined along the contact edge has elements ten to a hundred times smaller, where it contracts by
    about a third per pass: on the quarter bisinusoid (``h = 0.01``, ``p/p* = 0.05``) the levels refined
    to ``l/20`` and ``l/40`` took 16 and 13 passes.  In 3D, where each pass is a 3D solve, the passes
    therefore start at ``k h / E = START_AUGMENTATION_RATIO``, a hundredth of the ceiling
    (:data:`MAX_AUGMENTATION_RATIO`): 4 and 3 passes, 10.7 -> 3.9 and 17.7 -> 7.9 CPU s, the contact
    fraction, closure and coefficients the same to nine digits (the fixed point does not depend on
    ``k``).  In 2D the meshes graded towards the contact edges have elements down to ``1e-5`` of the
    interface size, where ``E / h`` is a stiffness the equilibrium's round-off feels (the sweep over
    ``k_n`` of tests/verification/test_hard_cases.py), and a pass is cheap: the scene's ``k_n`` stays the
    start there, raised by ``stiffen`` where slow.
    """
    m, model = problem.multiplier, problem.model
    problem.augmentation.Set(max(problem.augmentation.Get(), start_augmentation(problem)))

    def solve(j: int) -> dict:
        return newton(atol)

    def update() -> dict[str, float]:
        return m.update(problem.augmented_pressure, problem.penetration, problem.augmentation.Get(),
                        characteristic_length(problem))

    def stiffen() -> bool:
        k, ceiling = problem.augmentation.Get(), max_augmentation(problem)
        if STIFFEN * k > ceiling:
            return False
        problem.augmentation.Set(STIFFEN * k)
        return True

    hist = uzawa(solve, update, rtol=model.uzawa_rtol, max_iter=model.uzawa_max_iter, stiffen=stiffen)
    passes = hist["newton"]
    out: dict[str, Any] = {"iterations": sum(h["iterations"] for h in passes),
                           "converged": all(h["converged"] for h in passes), "linear_solve_only": False}
    for key in ("residuals", "energies", "step_lengths", "active_set_sizes"):
        out[key] = [v for h in passes for v in h[key]]
    out["uzawa_iterations"] = hist["uzawa_iterations"]
    out["uzawa_stiffened"] = hist["stiffened"]
    out["uzawa_at_floor"] = hist["at_floor"]
    out["uzawa_penetrations"] = hist["penetrations"]
    out["uzawa_changes"] = hist["changes"]
    out["uzawa_relative_changes"] = hist["relative_changes"]
    out["newton_per_pass"] = [h["iterations"] for h in passes]
    log.info("exact contact: %d Uzawa passes, %d Newton steps", hist["uzawa_iterations"], out["iterations"])
    return out
