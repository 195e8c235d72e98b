"""Homogenized coefficients of the contact surface of a periodic cell.

With the micro normal ``n`` on ``S_C`` (from ``rough`` into ``counter``), its
components ``beta = (n.n0, n.t0[, n.t1])`` in the macro basis ``(n0, t0[, t1])``
(2D: ``n0 = e_y, t0 = e_x``; 3D: ``n0 = e_z, t0 = e_x, t1 = e_y``), the
penalty stiffness ``k_n``, the initial gap ``g``, the Tresca threshold ``G``
and a weight ``w`` (1 on the whole contact surface, or the indicator of the
real contact set ``S_C_real`` from a cell solution):

    K0_pq = (1/|T|) int_S_C  w k_n beta_p beta_q ds          (paper eq. 34)
    k_n = K0_00,  k_t_j = K0_jj,  k_nt_j = K0_0j,  mu_j = k_nt_j / k_n
    g_p   = (1/|T|) int_S_C  w k_n beta_p g ds               (eq. 34 with g inside)
    G_p   = (1/|T|) int_S_C  w G |(I - n n^T) e_p| ds        (eqs. 42-43)

Signs: the paper writes the stiffnesses with a minus sign (tension
positive); here compression is positive, so ``K0`` is positive semidefinite
and the linearized macro traction is ``p = K0 J - (g_n, g_t)``.  For eqs.
42-43 the paper bounds the friction ``G |J . tau|`` per macro component by
Hoelder's inequality; for isotropic friction ``G |(I - n n^T) J|`` the same
bound gives the weights ``|(I - n n^T) e_p|`` (in 2D ``|beta_2|`` for ``G_n``
and ``|beta_1|`` for ``G_t``, the paper's ``|alpha|``).

The same integrals, left unsummed over the quadrature points of ``S_C``, are
the *direction bundle* of the macro interface law (paper eqs. 31-33):
:func:`direction_bundle`.

Orientation of the normal: Netgen orients a boundary element's normal from
the domain on one side of its face to the other according to how the face
was generated (in ``geom2d`` from left to right domain, in CSG from the
face's inner to outer domain), so on an internal interface it is not the
same for every builder.  :func:`contact_normal` fixes it element by element:
the sign is chosen so that the normal points away from the centre of the
adjacent ``rough`` element.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import ngsolve as ng

from ngcontact.geometry.cell2d import Cell
from ngcontact.fem.two_body import interface_normal

log = logging.getLogger(__name__)


# ------------------------------------------------------------------ normal
def contact_normal(cell: Cell):
    """Unit normal on ``contact`` pointing from ``rough`` into ``counter``.

    The one oriented normal of the package,
    :func:`ngcontact.fem.two_body.interface_normal`, on the cell's contact
    surface; valid on the ``contact`` boundary only.
    """
    if "contact" not in cell.mesh.GetBoundaries():
        raise ValueError("the cell has no 'contact' boundary")
    return interface_normal(cell.mesh, "rough", "contact")


def macro_basis(dim: int) -> np.ndarray:
    """Rows ``n0, t0[, t1]`` in Cartesian components (2D: ``e_y, e_x``; 3D: ``e_z, e_x, e_y``)."""
    if dim == 2:
        return np.array([[0.0, 1.0], [1.0, 0.0]])
    if dim == 3:
        return np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    raise ValueError(f"dim = {dim!r}: must be 2 or 3")


def _beta(cell: Cell, normal):
    """Components ``(n.n0, n.t0[, n.t1])`` of the micro normal."""
    return [sum(float(B[i]) * normal[i] for i in range(cell.dim) if B[i] != 0.0)
            for B in macro_basis(cell.dim)]


def _cf(value, name):
    if value is None:
        return None
    if isinstance(value, (int, float)):
        if not math.isfinite(value):
            raise ValueError(f"{name} = {value!r}: must be finite")
        return ng.CF(float(value))
    return value


def _intorder(cell: Cell, intorder):
    if intorder is not None:
        return int(intorder)
    return 2 * max(1, cell.mesh.ngmesh.GetCurveOrder()) + 4


# ------------------------------------------------------------ coefficients
@dataclass(frozen=True)
class Coefficients:
    """Homogenized interface coefficients (compression positive).

    In 2D the tangential entries are numbers, in 3D tuples of two (``t0, t1``).
    ``K0`` is the full matrix in the basis ``(n0, t0[, t1])``;
    ``contact_fraction`` is ``(1/|T|) int_S_C w ds``.
    """

    k_n: float
    k_t: float | tuple
    k_nt: float | tuple
    g_n: float
    g_t: float | tuple
    mu: float | tuple
    G_n: float
    G_t: float | tuple
    K0: np.ndarray
    contact_fraction: float

    def as_dict(self) -> dict:
        """Plain numbers and lists, e.g. for ``report.json``."""
        out = {}
        for key in ("k_n", "k_t", "k_nt", "g_n", "g_t", "mu", "G_n", "G_t", "contact_fraction"):
            v = getattr(self, key)
            out[key] = list(v) if isinstance(v, tuple) else v
        out["K0"] = self.K0.tolist()
        return out


def coefficients(cell: Cell, kn=1.0, gap=None, G=None, weight=None, *,
                 intorder: int | None = None, normal=None, integrate=None) -> Coefficients:
    """The coefficients of paper eqs. 34 and 42-43 (see the module docstring).

    Parameters
    ----------
    cell
        A meshed cell with a ``contact`` boundary.
    kn
        Penalty stiffness ``k_n`` (number or CoefficientFunction on ``contact``).
    gap
        Initial gap ``g`` (number or CF); ``None`` means 0.
    G
        Tresca threshold on ``S_C`` (number or CF); ``None`` means 0.
    weight
        ``w``: ``None`` (1, the whole contact surface, purely geometric) or a
        CF such as the indicator of the real contact set.
    intorder
        Quadrature order on ``contact``; default ``2 * curve order + 4``.
    normal
        Micro normal CF; default :func:`contact_normal` of ``cell``.
    integrate
        ``integrate(cf)``: the integral over ``S_C`` of the vector CF ``cf`` as
        an array; default NGSolve's quadrature at ``intorder``.  A weight with
        a jump inside an element (the real contact set's indicator) is
        integrated exactly by a caller that cuts the elements at its edges and
        passes that integral, with ``weight`` left 1
        (:func:`ngcontact.cell.fe.measures.real_contact_coefficients`).

    Returns
    -------
    Coefficients
    """
    dim = cell.dim
    n = contact_normal(cell) if normal is None else normal
    beta = _beta(cell, n)
    w = _cf(weight, "weight") if weight is not None else ng.CF(1.0)
    k = _cf(kn, "kn") * w
    g = _cf(gap, "gap") if gap is not None else ng.CF(0.0)
    Gt = _cf(G, "G") * w if G is not None else ng.CF(0.0)
    basis = macro_basis(dim)
    entries = [k * beta[p] * beta[q] for p in range(dim) for q in range(dim)]
    entries += [k * beta[p] * g for p in range(dim)]
    for p in range(dim):
        e = [float(v) for v in basis[p]]
        proj = [e[i] - n[i] * sum(n[j] * e[j] for j in range(dim)) for i in range(dim)]
        sq = sum(c * c for c in proj)
        entries.append(Gt * ng.sqrt(ng.IfPos(sq, sq, 0.0)))
    entries.append(w)
    mesh = cell.mesh
    if integrate is None:
        vals = ng.Integrate(ng.CF(tuple(entries)), mesh, definedon=mesh.Boundaries("contact"),
                            order=_intorder(cell, intorder))
    else:
        vals = integrate(ng.CF(tuple(entries)))
    vals = np.asarray(vals, dtype=float).ravel() / cell.area
    K0 = vals[:dim * dim].reshape(dim, dim)
    K0 = 0.5 * (K0 + K0.T)
    gv = vals[dim * dim:dim * dim + dim]
    Gv = vals[dim * dim + dim:dim * dim + 2 * dim]
    frac = float(vals[-1])
    kn0 = float(K0[0, 0])
    mu = [float(K0[0, j]) / kn0 if kn0 != 0.0 else 0.0 for j in range(1, dim)]

    def tangential(values):
        values = tuple(float(v) for v in values)
        return values[0] if dim == 2 else values

    log.debug("coefficients: K0 = %s, gap terms %s, thresholds %s", K0.tolist(), gv, Gv)
    return Coefficients(k_n=kn0, k_t=tangential(np.diag(K0)[1:]), k_nt=tangential(K0[0, 1:]),
                        g_n=float(gv[0]), g_t=tangential(gv[1:]), mu=tangential(mu),
                        G_n=float(Gv[0]), G_t=tangential(Gv[1:]), K0=K0, contact_fraction=frac)


# ----------------------------------------------------------------- bundle
@dataclass(frozen=True)
class DirectionBundle:
    """Weighted micro directions of the contact surface (one row per quadrature point).

    ``w``: ``(1/|T|) w k_n ds_q`` (stiffness weights, ``sum w n n^T = K0`` in
    full contact); ``n``: micro normals in the basis ``(n0, t0[, t1])``;
    ``g``: initial gaps; ``G``: ``(1/|T|) w G ds_q`` (friction weights);
    ``x``: Cartesian points on ``S_C`` (for plots and checks).  The macro
    interface energy per unit area is

        W(J) = sum_q w_q/2 [n_q . J - g_q]_+^2 + sum_q G_q |(I - n_q n_q^T) J|

    with ``J`` in the same basis (the friction term Huber-regularized by the user).
    """

    w: np.ndarray
    n: np.ndarray
    g: np.ndarray
    G: np.ndarray
    x: np.ndarray

    def stiffness(self) -> np.ndarray:
        """``sum_q w_q n_q n_q^T``."""
        return (self.w[:, None, None] * self.n[:, :, None] * self.n[:, None, :]).sum(axis=0)


def direction_bundle(cell: Cell, kn=1.0, gap=None, G=None, weight=None, *,
                     intorder: int | None = None, normal=None) -> DirectionBundle:
    """Quadrature of the contact surface as a bundle of weighted directions.

    Parameters are those of :func:`coefficients`.  All surface elements of
    ``contact`` must be of one type (segments in 2D, triangles from CSG in 3D).

    Returns
    -------
    DirectionBundle
    """
    mesh, dim = cell.mesh, cell.dim
    n = contact_normal(cell) if normal is None else normal
    region = mesh.Boundaries("contact")
    types = {el.type for el in mesh.Elements(ng.BND) if el.mat == "contact"}
    if len(types) != 1:
        raise ValueError(f"contact elements of types {sorted(map(str, types))}: need one type")
    ir = ng.IntegrationRule(types.pop(), _intorder(cell, intorder))
    mips = mesh.MapToAllElements(ir, region)
    nq = len(ir.weights)
    jac = np.asarray(ng.specialcf.JacobianMatrix(dim, dim - 1)(mips)).reshape(-1, dim, dim - 1)
    if dim == 2:
        meas = np.linalg.norm(jac[:, :, 0], axis=1)
    else:
        meas = np.linalg.norm(np.cross(jac[:, :, 0], jac[:, :, 1]), axis=1)
    ds = np.tile(np.asarray(ir.weights, dtype=float), len(meas) // nq) * meas / cell.area
    w = _cf(weight, "weight") if weight is not None else ng.CF(1.0)

    def values(cf, comps=1):
        return np.asarray(cf(mips), dtype=float).reshape(-1, comps)

    normals = values(ng.CF(tuple(n[i] for i in range(dim))), dim) @ macro_basis(dim).T
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    wk = values(_cf(kn, "kn") * w)[:, 0] * ds
    gq = values(_cf(gap, "gap"))[:, 0] if gap is not None else np.zeros_like(ds)
    Gq = values(_cf(G, "G") * w)[:, 0] * ds if G is not None else np.zeros_like(ds)
    xq = values(ng.CF((ng.x, ng.y, ng.z)[:dim]), dim)
    return DirectionBundle(w=wk, n=normals, g=gq, G=Gq, x=xq)
