"""Manufactured solutions for the elasticity operator.

A chosen smooth displacement ``u*`` is made the exact solution of

    -div sigma(u*) = f        in every body B,    sigma = C_B : eps(u*)   (paper eq. 1)
               u   = u*       on the Dirichlet part,
        sigma(u*) n = t       on the Neumann part,
    [sigma(u*)] n  = j        on a bonded interface between two materials,

by computing the data from ``u*`` symbolically (NGSolve ``CoefficientFunction``
``.Diff``).  The weak form is the one of :mod:`ngcontact.fem.elasticity`
(paper eq. 46 without contact):

    sum_B int_B sigma(u) : eps(v) w dx
        = sum_B int_B f . v w dx + int_N t . v w ds + int_I j . v w ds,

with the weight ``w = 1`` (plane strain, 3D) or ``2 pi r`` (axisymmetric).
In the axisymmetric setting, coordinates ``(r, z)`` are the mesh ``(x, y)``
and

    f_r = -(d_r s_rr + d_z s_rz + (s_rr - s_tt) / r),
    f_z = -(d_r s_rz + d_z s_zz + s_rz / r);

the axis ``r = 0`` carries ``u_r = 0`` only (the weight makes every other
boundary term vanish there), and ``u*`` is regular at the axis (``u_r`` odd,
``u_z`` even in ``r``).

On the interface ``I`` with normal ``n`` pointing from ``rough`` (below) into
``counter`` (above), ``j = (sigma_rough(u*) - sigma_counter(u*)) n``: with
different materials the traction of a smooth ``u*`` jumps there.

The two bonded bodies of the periodic cell share one conforming, periodic
``VectorH1`` with a piecewise constant law: "bonded" means continuous
displacement, which a single H1 space imposes exactly, so the observed error
is the discretization error alone (a tie by penalty or multipliers would add
its own consistency error).

Errors: ``|u_h - u*|_L2`` and the H1 seminorm ``|grad(u_h - u*)|_L2``, both
with the measure weight; in axisymmetry the seminorm includes the hoop term
``(e_r / r)^2``.

Their estimates, made without ``u*`` (:func:`level_runner`): the same problem solved once more at order
``p + 1`` on the same mesh, and the norms of the difference over ``1 - beta`` (the saturation bound of
:mod:`ngcontact.cell.fe.saturation`, ``beta = 3/4``: where order ``p + 1`` keeps at most ``beta`` of the
error of order ``p``, ``|u_p - u*| <= |u_p - u_(p+1)| / (1 - beta)``).  The smooth ``u*`` makes order ``p + 1``
far closer than that, so the estimate is about ``4`` times the error (Galerkin orthogonality makes the
energy norm of the difference ``sqrt(|e_p|^2 - |e_(p+1)|^2)``, a hair below ``|e_p|``); the manufactured
kind reports both, and their ratio is the effectivity of the package's one-order-more estimate on this
oracle.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass

import ngsolve as ng
import numpy as np
from netgen.csg import unit_cube
from netgen.geom2d import SplineGeometry, unit_square

from ngcontact.cell.fe.saturation import SATURATION
from ngcontact.fem import elasticity
from ngcontact.errors import ConvergenceError
from ngcontact.geometry.cell2d import Segment, interface_cell
from ngcontact.fem.materials import ElasticLaw
from ngcontact.solvers.linear_solver import fixed_mask
from ngcontact.fem import two_body
from ngcontact.verification.exact_fields import (CELL_PERIOD, SETTINGS, SOLUTIONS, body_force, gradient,
                                                  polynomial_field, smooth_field, traction)

log = logging.getLogger(__name__)

CELL_DEPTH = 0.5
INTERFACE = "contact"


@dataclass(frozen=True)
class Problem:
    """A manufactured boundary value problem on a mesh (no discretization yet).

    Attributes
    ----------
    setting
        ``"plane_strain"``, ``"axisymmetric"`` or ``"3d"`` (the elasticity
        setting; the periodic cell is plane strain).
    mesh
        The mesh.
    laws
        ``region name -> ElasticLaw``.
    exact
        ``u*`` as a vector ``CoefficientFunction``.
    dirichlet
        Boundaries where every component of ``u*`` is imposed (``|``-joined).
    dirichlet_x
        Boundaries where only the first component is imposed (the axis).
    neumann
        Boundaries loaded by the traction ``sigma(u*) n``.
    interface
        Internal boundary loaded by the traction jump, or ``""``.
    periodic
        The space is periodic (identified boundaries of the mesh).
    """

    setting: str
    mesh: ng.Mesh
    laws: dict[str, ElasticLaw]
    exact: ng.CoefficientFunction
    dirichlet: str
    dirichlet_x: str = ""
    neumann: str = ""
    interface: str = ""
    periodic: bool = False


@dataclass
class Solution:
    """A discrete solution and what it cost."""

    gfu: ng.GridFunction
    ndof: int
    relative_residual: float
    seconds: float


def bump_segments(period: float = CELL_PERIOD) -> list:
    """Flat - circular arc bump - flat interface chain (arc of 90 degrees)."""
    a, b, m = 0.25 * period, 0.75 * period, 0.5 * period
    return [Segment("line", ((0.0, 0.0), (a, 0.0))),
            Segment("spline3", ((a, 0.0), (m, 0.25 * period), (b, 0.0))),
            Segment("line", ((b, 0.0), (period, 0.0)))]


def _axis_rectangle(maxh: float) -> ng.Mesh:
    geo = SplineGeometry()
    geo.AddRectangle((0.0, 0.0), (1.0, 1.0), bcs=("bottom", "outer", "top", "axis"))
    return ng.Mesh(geo.GenerateMesh(maxh=maxh))


def _refine(mesh: ng.Mesh, times: int) -> ng.Mesh:
    """Refine ``mesh`` uniformly ``times`` times (new boundary points lie on the geometry)."""
    if times < 0:
        raise ValueError(f"refinements = {times!r}: must be >= 0")
    for _ in range(times):
        mesh.Refine()
    return mesh


def problem(setting: str, laws: dict, maxh: float, *, refinements: int = 0, order: int = 1,
            solution: str = "smooth", degree: int | None = None) -> Problem:
    """The manufactured problem of ``setting`` on a mesh of size ``maxh``.

    The mesh is generated with ``maxh`` and then refined uniformly
    ``refinements`` times (each halving ``h``), so that a sequence of levels
    is nested and its mesh sizes have exactly the ratio 2.

    Parameters
    ----------
    setting
        ``plane_strain`` (unit square, Dirichlet on left and bottom, traction
        on right and top), ``axisymmetric`` (``(r, z)`` in the unit square,
        axis ``r = 0`` with ``u_r = 0``, Dirichlet at ``z = 0, 1``, traction
        at ``r = 1``), ``3d`` (unit cube, Dirichlet on three faces, traction
        on the others) or ``periodic_cell`` (two bodies bonded along a
        circular-arc bump, periodic in ``x``, Dirichlet on bottom and top).
    laws
        ``{"body": law}``; the periodic cell needs ``{"rough": law,
        "counter": law}``.
    maxh
        Mesh size of the generated (coarsest) mesh.
    refinements
        Number of uniform refinements of that mesh.
    order
        Geometry order of curved boundaries (periodic cell).
    solution
        ``"smooth"`` or ``"polynomial"`` (then ``degree`` is required).
    """
    if solution not in SOLUTIONS:
        raise ValueError(f"solution = {solution!r}: must be one of {', '.join(SOLUTIONS)}")
    if solution == "polynomial":
        if degree is None:
            raise ValueError("solution = 'polynomial' needs a degree")
        exact = polynomial_field(setting, degree)
    else:
        exact = smooth_field(setting)
    if setting == "periodic_cell":
        missing = {"rough", "counter"} - set(laws)
        if missing:
            raise ValueError(f"laws lacks {sorted(missing)}: the periodic cell needs 'rough' and 'counter'")
        cell = interface_cell(bump_segments(), CELL_PERIOD, CELL_DEPTH, CELL_DEPTH, maxh=maxh)
        _refine(cell.mesh, refinements)
        if order > 1:
            cell.mesh.Curve(order)
        return Problem("plane_strain", cell.mesh, {k: laws[k] for k in ("rough", "counter")}, exact,
                       dirichlet="bottom|top", interface=INTERFACE, periodic=True)
    law = laws["body"]
    if setting == "plane_strain":
        mesh = _refine(ng.Mesh(unit_square.GenerateMesh(maxh=maxh)), refinements)
        return Problem(setting, mesh, {mesh.GetMaterials()[0]: law}, exact,
                       dirichlet="left|bottom", neumann="right|top")
    if setting == "axisymmetric":
        mesh = _refine(_axis_rectangle(maxh), refinements)
        return Problem(setting, mesh, {mesh.GetMaterials()[0]: law}, exact,
                       dirichlet="bottom|top", dirichlet_x="axis", neumann="outer")
    if setting == "3d":
        mesh = _refine(ng.Mesh(unit_cube.GenerateMesh(maxh=maxh)), refinements)
        return Problem(setting, mesh, {mesh.GetMaterials()[0]: law}, exact,
                       dirichlet="left|bottom|back", neumann="right|top|front")
    raise ValueError(f"setting = {setting!r}: must be one of {', '.join(SETTINGS)}")


# ------------------------------------------------------------ solve
def space(prob: Problem, order: int):
    """Order-``order`` ``VectorH1`` over the whole mesh, periodic if asked."""
    if order < 1:
        raise ValueError(f"order = {order!r}: must be >= 1")
    V = ng.VectorH1(prob.mesh, order=order, dirichlet=prob.dirichlet, dirichletx=prob.dirichlet_x)
    return ng.Periodic(V) if prob.periodic else V


def interface_normal(prob: Problem) -> ng.CoefficientFunction:
    """Unit normal on ``prob.interface`` pointing from ``rough`` into ``counter``
    (:func:`ngcontact.fem.two_body.interface_normal`)."""
    return two_body.interface_normal(prob.mesh, "rough", prob.interface)


def solve(prob: Problem, order: int, *, inverse: str = "sparsecholesky",
          bonus_intorder: int = 2) -> Solution:
    """Assemble and solve the linear problem of ``prob`` with elements of order ``order``.

    The load integrals use ``bonus_intorder`` extra quadrature orders, so that
    quadrature does not pollute the rates (and is exact for polynomial data).

    Raises
    ------
    ConvergenceError
        The sparse direct solver ``inverse`` failed (e.g. is not installed).
    """
    t0 = time.perf_counter()
    mesh, setting = prob.mesh, prob.setting
    V = space(prob, order)
    u, v = V.TnT()
    w = elasticity.weight(setting)
    # only the Cholesky factorization reads a matrix stored as one triangle
    a = ng.BilinearForm(V, symmetric=True, symmetric_storage=(inverse == "sparsecholesky"))
    f = ng.LinearForm(V)
    for region, law in prob.laws.items():
        on = mesh.Materials(region)
        a += elasticity.bilinear_integrand(law, u, v, setting) * ng.dx(definedon=on, bonus_intorder=2)
        f += ng.InnerProduct(body_force(law, prob.exact, setting), v) * w * ng.dx(
            definedon=on, bonus_intorder=bonus_intorder)
    if prob.neumann:
        (law,) = prob.laws.values()
        t = traction(law, prob.exact, setting, ng.specialcf.normal(mesh.dim))
        f += ng.InnerProduct(t, v) * w * ng.ds(prob.neumann, bonus_intorder=bonus_intorder)
    if prob.interface:
        n = interface_normal(prob)
        jump = (traction(prob.laws["rough"], prob.exact, setting, n)
                - traction(prob.laws["counter"], prob.exact, setting, n))
        f += ng.InnerProduct(jump, v) * w * ng.ds(prob.interface, bonus_intorder=bonus_intorder)
    a.Assemble()
    f.Assemble()
    gfu = ng.GridFunction(V)
    boundaries = "|".join(b for b in (prob.dirichlet, prob.dirichlet_x) if b)
    gfu.Set(prob.exact, ng.BND, definedon=mesh.Boundaries(boundaries))
    free = V.FreeDofs()
    res = f.vec.CreateVector()
    res.data = f.vec - a.mat * gfu.vec
    try:
        inv = a.mat.Inverse(free, inverse=inverse)
    except RuntimeError as exc:
        raise ConvergenceError(f"linear solver {inverse!r} failed: {exc}",
                               {"linear_solve_only": True, "converged": False}) from exc
    gfu.vec.data += inv * res
    res.data = f.vec - a.mat * gfu.vec
    fixed = fixed_mask(free)
    r = res.FV().NumPy().copy()
    load = f.vec.FV().NumPy().copy()
    r[fixed] = 0.0
    load[fixed] = 0.0
    scale = max(float(np.linalg.norm(load)), np.finfo(float).tiny)
    rel = float(np.linalg.norm(r)) / scale
    seconds = time.perf_counter() - t0
    log.debug("%s order %d: %d dofs, relative residual %.2e, %.3f s", setting, order, V.ndof, rel, seconds)
    return Solution(gfu=gfu, ndof=int(sum(free)), relative_residual=rel, seconds=seconds)


def errors(prob: Problem, gfu: ng.GridFunction, bonus_intorder: int = 4,
           reference: ng.GridFunction | None = None) -> tuple[float, float]:
    """``(L2 error, H1-seminorm error)`` of ``gfu`` against ``prob.exact`` (weighted), or against ``reference``
    (a solution of the same problem of higher order) where given."""
    mesh, setting = prob.mesh, prob.setting
    dim = mesh.dim
    w = elasticity.weight(setting)
    e = gfu - (prob.exact if reference is None else reference)
    de = ng.Grad(gfu) - (gradient(prob.exact, dim) if reference is None else ng.Grad(reference))
    grad2 = ng.InnerProduct(de, de)
    if setting == "axisymmetric":
        grad2 = grad2 + (e[0] / ng.x) ** 2
    order = 2 * max(gfu.space.globalorder, 0 if reference is None else reference.space.globalorder) + bonus_intorder
    l2 = ng.Integrate(ng.InnerProduct(e, e) * w, mesh, order=order)
    h1 = ng.Integrate(grad2 * w, mesh, order=order)
    return math.sqrt(max(l2, 0.0)), math.sqrt(max(h1, 0.0))


def exact_norms(prob: Problem, intorder: int = 10) -> tuple[float, float]:
    """``(L2 norm, H1 seminorm)`` of ``prob.exact`` itself, weighted as in :func:`errors`.

    The scale against which an error is round-off: a discrete solution
    cannot come closer to ``u*`` than a small multiple of the machine
    precision times these norms.
    """
    mesh, setting = prob.mesh, prob.setting
    w = elasticity.weight(setting)
    u = prob.exact
    du = gradient(u, mesh.dim)
    grad2 = ng.InnerProduct(du, du)
    if setting == "axisymmetric":
        grad2 = grad2 + (u[0] / ng.x) ** 2
    l2 = ng.Integrate(ng.InnerProduct(u, u) * w, mesh, order=intorder)
    h1 = ng.Integrate(grad2 * w, mesh, order=intorder)
    return math.sqrt(max(l2, 0.0)), math.sqrt(max(h1, 0.0))


def level_runner(setting: str, laws: dict, maxh: float, *, inverse: str = "sparsecholesky",
                 keep: dict | None = None):
    """A ``level(order, refinements) -> dict`` for :mod:`ngcontact.verification.rates`.

    Each call builds the problem on the mesh refined ``refinements`` times,
    solves it with order ``order`` and returns ``ndof``, ``l2``, ``h1``, the
    solve's ``relative_residual`` and ``solve_seconds`` (wall time of mesh,
    assembly and solve, without the error evaluation), and the estimates of the two errors from one order
    more on the same mesh, ``l2_estimate`` and ``h1_estimate`` (module docstring; that solve not timed).
    When ``keep`` is a dict, the last problem and solution are stored in it under ``"problem"`` and
    ``"solution"`` (e.g. to write the finest one).
    """
    def level(order: int, refinements: int) -> dict:
        t0 = time.perf_counter()
        prob = problem(setting, laws, maxh, refinements=refinements, order=order)
        sol = solve(prob, order, inverse=inverse)
        solve_seconds = time.perf_counter() - t0
        l2, h1 = errors(prob, sol.gfu)
        higher = solve(prob, order + 1, inverse=inverse)
        d2, d1 = errors(prob, sol.gfu, reference=higher.gfu)
        if keep is not None:
            keep["problem"], keep["solution"] = prob, sol
        return {"ndof": sol.ndof, "l2": l2, "h1": h1, "relative_residual": sol.relative_residual,
                "solve_seconds": solve_seconds, "l2_estimate": d2 / (1.0 - SATURATION),
                "h1_estimate": d1 / (1.0 - SATURATION)}
    return level
