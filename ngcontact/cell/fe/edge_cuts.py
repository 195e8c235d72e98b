"""The contact edges inside the boundary elements of a 2D FE cell's ``S_C``, and integrals cut at them.

The real contact set ``{J_n - g_h >= 0}`` of a penalty cell ends inside boundary elements; on each element the
penetration is a polynomial of the reference coordinate ``t`` (straight elements with the interpolated gap,
:func:`ngcontact.cell.fe.discrete_cell.discrete_gap`), whose real roots in ``(0, 1)`` cut the element into
pieces in and out of contact (:func:`element_cuts`; exact enforcement: the closed nodes and the edges between
them, :func:`ngcontact.cell.fe.exact_contact_set.contact_cuts`).  An integral over the real contact set
(:func:`contact_set_integral`) takes a Gauss rule on each piece in contact, so that the edge is where the
contact fraction (:func:`ngcontact.cell.fe.measures.contact_fraction`) puts it: an indicator integrated by
quadrature would put it at the nearest quadrature point, an error of up to half their spacing that changes
with the rule and not with the solution.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.cell.fe.exact_contact_set import contact_cuts
from ngcontact.fem.quadrature import kink_order


def element_cuts(problem) -> list[tuple[np.ndarray, list[bool]]]:
    """Per boundary element of ``S_C`` (2D, in the order of ``MapToAllElements``): ``(cuts, on)``, the
    reference coordinates ``0 = c_0 < ... < c_m = 1`` at which the penetration ``J_n - g_h`` changes sign
    and whether it is nonnegative on ``[c_i, c_(i+1)]``.  The penetration is interpolated at ``order + 3``
    Gauss points of each element (exact for the polynomial it is on straight elements with the interpolated
    gap) and its real roots in ``(0, 1)`` cut the element.  Exact enforcement: the cuts and states of
    :func:`ngcontact.cell.fe.exact_contact_set.contact_cuts` instead."""
    return cut_elements(problem)[1]


def cut_elements(problem):
    """:func:`element_cuts` and the monomial coefficients in ``t`` of the penetration, ``x`` and ``y`` per
    element (``[order + 3, elements, 3]``)."""
    P = np.polynomial.polynomial
    m = problem.model.order + 3
    ir = ng.IntegrationRule(ng.SEGM, 2 * m - 1)
    t = np.array([q[0] for q in ir.points])
    mesh = problem.mesh
    pts = mesh.MapToAllElements(ir, mesh.Boundaries("contact"))
    vals = np.asarray(ng.CF((problem.penetration, ng.x, ng.y))(pts)).reshape(-1, m, 3)
    coef = np.linalg.solve(P.polyvander(t, m - 1), vals.transpose(1, 0, 2).reshape(m, -1))
    coef = coef.reshape(m, -1, 3)
    if problem.multiplier is not None:
        return coef, contact_cuts(problem)
    # elements on which the penetration keeps one strict sign (all Bernstein coefficients on [0, 1] of
    # that sign: the polynomial lies in their convex hull) are one piece: no roots to seek there
    bern = _bernstein(m - 1) @ coef[:, :, 0]
    whole = np.all(bern > 0.0, axis=0) | np.all(bern < 0.0, axis=0)
    out: list[tuple[np.ndarray, list[bool]]] = []
    for e in range(vals.shape[0]):
        c_pen = coef[:, e, 0]
        if whole[e]:
            out.append((np.array([0.0, 1.0]), [bool(bern[0, e] > 0.0)]))
            continue
        r = P.polyroots(c_pen) if np.any(c_pen[1:]) else np.empty(0)
        r = np.sort(r[(np.abs(r.imag) <= 1e-10) & (r.real > 0.0) & (r.real < 1.0)].real)
        cuts = np.concatenate(([0.0], r, [1.0]))
        out.append((cuts, [bool(P.polyval(0.5 * (a + b), c_pen) >= 0.0) for a, b in zip(cuts[:-1], cuts[1:])]))
    return coef, out


def contact_set_integral(problem, cf, order: int | None = None) -> np.ndarray:
    """``int_{S_C_real} cf ds`` (2D) of a vector CF: over the boundary elements wholly in contact by the rule
    of ``order`` (default :func:`~ngcontact.fem.quadrature.kink_order`), over an element a contact edge cuts
    by the same rule on each of its pieces in contact (:func:`element_cuts`), so that the edge is where the
    contact fraction puts it, not at the nearest quadrature point."""
    o = order if order is not None else kink_order(problem.model.order)
    mesh, region = problem.mesh, problem.mesh.Boundaries("contact")
    ir = ng.IntegrationRule(ng.SEGM, o)
    t, w = np.array([q[0] for q in ir.points]), np.array(ir.weights)
    cuts = element_cuts(problem)
    full = np.array([len(on) == 1 and on[0] for _, on in cuts])
    total = np.zeros(cf.dim)
    if full.any():
        total += _weighted(mesh, region, cf, t, w)[full].sum(axis=0)
    parts = [(e, a, b) for e, (ts, on) in enumerate(cuts) if len(on) > 1
             for a, b, s in zip(ts[:-1], ts[1:], on) if s and b > a]
    if parts:   # all pieces' points in one rule, each piece's share taken from its own element
        tp = np.concatenate([a + (b - a) * t for _, a, b in parts])
        wp = np.concatenate([(b - a) * w for _, a, b in parts])
        vals = _weighted(mesh, region, cf, tp, wp, sum_points=False)
        n = len(t)
        total += sum(vals[e, k * n:(k + 1) * n].sum(axis=0) for k, (e, _, _) in enumerate(parts))
    return total


def _weighted(mesh, region, cf, t, w, sum_points: bool = True) -> np.ndarray:
    """``cf |dx/dt| w`` at the reference points ``t`` (weights ``w``) of every segment of ``region``:
    ``[elements, points, components]``, summed over the points where ``sum_points``."""
    rule = ng.IntegrationRule(points=[(float(x),) for x in t], weights=[float(x) for x in w])
    mips = mesh.MapToAllElements(rule, region)
    jac = np.asarray(ng.specialcf.JacobianMatrix(2, 1)(mips)).reshape(-1, len(t), 2)
    vals = np.asarray(cf(mips)).reshape(-1, len(t), cf.dim) * (np.linalg.norm(jac, axis=2) * w)[:, :, None]
    return vals.sum(axis=1) if sum_points else vals


def _bernstein(n: int) -> np.ndarray:
    """``B`` with ``B @ a`` the Bernstein coefficients on ``[0, 1]`` of the degree-``n`` polynomial of
    monomial coefficients ``a``: ``b_k = sum_{j <= k} C(k, j) / C(n, j) a_j``."""
    from math import comb
    return np.array([[comb(k, j) / comb(n, j) if j <= k else 0.0 for j in range(n + 1)] for k in range(n + 1)])


def piece_rule(cuts: np.ndarray, on: list[bool], order: int) -> ng.IntegrationRule:
    """A rule on the reference segment ``[0, 1]`` over its pieces in contact (``cuts`` and ``on`` of
    :func:`element_cuts`): the Gauss rule of ``order`` on each."""
    ir = ng.IntegrationRule(ng.SEGM, order)
    t, w = np.array([q[0] for q in ir.points]), np.array(ir.weights)
    pieces = [(a, b) for a, b, s in zip(cuts[:-1], cuts[1:], on) if s and b > a]
    points = [(float(a + (b - a) * x),) for a, b in pieces for x in t]
    weights = [float((b - a) * x) for a, b in pieces for x in w]
    return ng.IntegrationRule(points=points, weights=weights)
