"""The real contact set of exact enforcement: closed nodes and the contact edges between them.

The cell problem with ``contact.enforcement = "exact"`` holds the
multiplier ``lambda`` at the nodes of ``S_C``
(:mod:`ngcontact.cell.fe.contact_multiplier`); the contact fraction of its
results (paper Sec. 3.2.2, the real contact set of eq. 34) is read in this module
from the nodes, not from the sign of the penetration, which is zero to
round-off at the closed nodes and only the interpolation error of the
closure between them.

The real contact set (:func:`contact_cuts`): a node is closed where its
multiplier carries load, ``lambda > 0``.  A node that only touches (its
opening ``g - J_n`` zero, its multiplier zero) transmits nothing and is
not in contact: at zero load the contact set is empty, and a patch
narrower than an element is one loaded node and its edges, not the
elements around a touching node.  Between two closed nodes the surfaces are in
contact, between two open ones they are not; between a closed node ``x_c``
and an open one ``x_o`` lies a contact edge.  Beyond a smooth edge ``a``
the opening grows like ``(x - a)^(3/2)`` (the Westergaard and Hertz edge,
:mod:`ngcontact.verification.westergaard`), so ``opening^(2/3)`` is nearly linear there: the edge is the
root of the line through ``opening^(2/3)`` at ``x_o`` and the next open
node beyond it, kept between ``x_c`` and ``x_o``.  A closed node whose
neighbours are both open holds a patch narrower than the node spacing:
the opening at the next nodes is the initial gap, not the edge's
``3/2``-power, and the edge is placed by the pressure at the node and the
opening beyond it instead (:func:`edge_fraction`, as in 3D).  This needs the nodes in
order along ``S_C``: on a contact surface that is a graph over ``x``
(``n_y > 0``), sorted by ``x``; elsewhere, or without a falling line, the
edge is the midpoint of ``[x_c, x_o]``.

In 3D (:func:`contact_area`) no open node beyond a crossing lies on the
line through it on an unstructured surface mesh, so the edge is placed on
each element edge from a closed vertex ``c`` to an open vertex ``o`` by the
edge's asymptotics instead (:func:`edge_fraction`): the pressure
``lambda_c`` inside and the opening at ``o`` outside fix where a
square-root pressure and a ``3/2``-power gap of the same edge vanish.
Each triangle contributes the part of it on the closed side of the
straight lines through its crossings; the area of each triangle is its
own (exact for the flat triangles of a small-slope cell).
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.cell.fe.contact_multiplier import ContactMultiplier


def closed_nodes(problem) -> tuple[np.ndarray, np.ndarray]:
    """Per point of the multiplier: closed (it carries load, ``lambda > 0``; module docstring), and the
    opening ``g - J_n``."""
    m = problem.multiplier
    opening = -m.at_points(problem.penetration)
    return m.point_values() > 0.0, opening


def contact_area(problem) -> float:
    """Area of the real contact set on ``S_C`` (3D): closed nodes and the edges between them (module docstring)."""
    closed, opening = closed_nodes(problem)
    return vertex_area(problem.multiplier, closed, opening, contact_modulus(problem.model))


def contact_modulus(model) -> float | None:
    """``E*`` of the two bodies, ``1/E* = (1 - nu_r)/(2 mu_r) + (1 - nu_c)/(2 mu_c)`` (isotropic), else ``None``."""
    inverse = 0.0
    for law in (model.rough, model.counter):
        if law.lame is None:
            return None
        lam, mu = law.lame
        nu = lam / (2.0 * (lam + mu))
        inverse += (1.0 - nu) / (2.0 * mu)
    return 1.0 / inverse


def edge_fraction(lam_c, opening_o, length, estar) -> np.ndarray:
    """Where a contact edge crosses a segment of ``length`` from a closed to an open node, as a fraction from the
    closed one.

    At a smooth edge the pressure grows like ``A sqrt(d)`` inside and the
    gap like ``(4 A / (3 E*)) d^(3/2)`` outside (the 2D Hertz edge of
    :mod:`ngcontact.verification.hertz`; with ``E*`` of the two bodies).  With ``lambda_c`` at distance
    ``t L`` inside and the opening ``g_o`` at ``(1 - t) L`` outside, ``A``
    cancels: ``(1 - t)^(3/2) / t^(1/2) = 3 E* g_o / (4 lambda_c L)``, whose
    left side falls from infinity to 0 on ``(0, 1)``: one root, found by
    bisection.  A closed node that carries no load (closed by its opening
    alone) puts the edge on it; without ``E*`` (anisotropic bodies) the
    edge is at the midpoint.
    """
    lam_c, g_o, L = (np.asarray(v, float) for v in (lam_c, opening_o, length))
    if estar is None:
        return np.full(lam_c.shape, 0.5)
    with np.errstate(divide="ignore", invalid="ignore"):
        R = np.where(lam_c > 0.0, 3.0 * estar * np.maximum(g_o, 0.0) / (4.0 * lam_c * L), np.inf)
    lo, hi = np.zeros(R.shape), np.ones(R.shape)
    for _ in range(60):
        t = 0.5 * (lo + hi)
        above = (1.0 - t) ** 1.5 > R * np.sqrt(t)
        lo, hi = np.where(above, t, lo), np.where(above, hi, t)
    return np.where(np.isinf(R), 0.0, 0.5 * (lo + hi))


def vertex_area(m: ContactMultiplier, closed: np.ndarray, opening: np.ndarray, estar: float | None) -> float:
    """Area of the closed part of ``S_C`` (3D, order-1 triangles) from the state of the vertices.

    ``closed`` and ``opening`` are given per point of ``m`` (three per
    triangle).  A contact edge crosses each element edge from a closed to
    an open vertex at :func:`edge_fraction` of it; a triangle with one
    closed vertex contributes the triangle cut off by the two crossings
    from it, one with two closed vertices all but the triangle cut off
    towards the open one, one with three all of it.
    """
    closed = np.asarray(closed, bool).reshape(-1, 3)
    opening = np.asarray(opening, float).reshape(-1, 3)
    lam = m.point_values().reshape(-1, 3)
    xyz = np.stack([m.at_points(c).reshape(-1, 3) for c in (ng.x, ng.y, ng.z)], axis=-1)
    areas = m.element_areas
    count = closed.sum(axis=1)
    share = (count == 3).astype(float)
    rows = np.arange(len(count))

    def crossing(e, c, o) -> np.ndarray:
        """Fraction of the element edge from closed vertex ``c`` to open ``o`` on the closed side (per row ``e``)."""
        return edge_fraction(lam[e, c], opening[e, o], np.linalg.norm(xyz[e, o] - xyz[e, c], axis=1), estar)

    for k in (1, 2):
        e = rows[count == k]
        if e.size == 0:
            continue
        # the odd vertex out, closed (k = 1) or open (k = 2), and the other two
        v = np.argmax(closed[e], axis=1) if k == 1 else np.argmin(closed[e], axis=1)
        w1, w2 = (v + 1) % 3, (v + 2) % 3
        if k == 1:      # the triangle cut off by the two crossings from the closed vertex
            share[e] = crossing(e, v, w1) * crossing(e, v, w2)
        else:           # all but the triangle cut off towards the open vertex
            share[e] = 1.0 - (1.0 - crossing(e, w1, v)) * (1.0 - crossing(e, w2, v))
    return float(np.dot(share, areas))


def contact_cuts(problem, edges: list | None = None) -> list[tuple[np.ndarray, list[bool]]]:
    """Per segment of ``S_C`` (in the order of :attr:`ContactMultiplier.points`): ``(cuts, on)``; each contact
    edge also appended to ``edges`` where given, as ``(closed point, open point, fraction)``: the indices of
    the points on either side and the edge's place between them as a fraction from the closed one.

    ``cuts`` are reference coordinates ``0 = c_0 < ... < c_m = 1`` and
    ``on[i]`` says whether ``[c_i, c_(i+1)]`` is in contact: the nodes and
    the edges between them of the module docstring.  Within a segment the
    abscissa is taken as affine in the reference coordinate (straight
    segments) to place an edge.
    """
    m = problem.multiplier
    npt = len(m.rule.points)
    t = np.array([q[0] for q in m.rule.points])
    closed, opening = closed_nodes(problem)
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
    node_lam = np.zeros(len(X))
    np.maximum.at(node_lam, node, m.point_values())
    r = node_opening ** (2.0 / 3.0)
    estar = contact_modulus(problem.model)
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
                isolated = not any(node_closed[j] for j in (nc - 1, nc + 1) if 0 <= j < len(X))
                if isolated and estar is not None and abs(no - nc) == 1:
                    f = float(edge_fraction(node_lam[nc], node_opening[no], abs(X[no] - X[nc]), estar))
                elif abs(no - nc) == 1 and 0 <= n2 < len(X) and not node_closed[n2] and r[n2] > r[no]:
                    root = X[no] - r[no] * (X[n2] - X[no]) / (r[n2] - r[no])
                    f = float(np.clip((root - X[nc]) / (X[no] - X[nc]), 0.0, 1.0))
            tc = t[c] + f * (t[o] - t[c])
            if edges is not None:
                edges.append((e * npt + c, e * npt + o, f))
            cuts.append(tc)
            on.append(bool(a))
            cuts.append(t[q + 1])
            on.append(bool(b))
        keep = [i for i in range(len(on)) if cuts[i + 1] > cuts[i]]
        out.append((np.array([cuts[0]] + [cuts[i + 1] for i in keep]), [on[i] for i in keep]))
    return out
