"""The rigid predictor: start values of the cell problem from a Winkler model of rigid motions (first and
frictionless shear loads).

The Newton solve of the cell problem (paper eqs. 49-51 in the penalized
variational form of eq. 65, :mod:`ngcontact.cell.fe.cell_problem`) needs a
start for every load.  Newton's active-set updates are slow when the
contact set of the start is far from the solution's: from the open side the
tangent of a few penalty springs is soft, the step overshoots and the line
search cuts it to a few per cent; from the closed side each step moves a
contact edge only part of the way.  Two predictors put the start near the
solution's contact set without any linear solve of the cell problem.  A
small-slope cell under the penalty has a third, run after the rigid one on
a first load: its spectral twin's contact set
(:mod:`ngcontact.cell.spectral_start`).

*First load* under a prescribed pressure ``p``: the rigid predictor.  The
fluctuations are zero and the counter is translated by the normal approach
``d`` that carries ``p`` on a Winkler foundation of stiffness ``k_L``, the
root of

    R(d) = int_{S_C} k_L [d n.n0 - g]_+ (n.n0) ds - p |T| = 0

(the normal part of the penalty force ``k_n [J.n - g]_+ n`` of eq. 65 for
the rigid jump ``J = -U = d n0``, with ``k_n`` softened by the bodies).
Only the predicted contact set matters to Newton, and the start is best
when that set is a little smaller than the solution's: from far on the open
side the tangent of a few stiff springs is soft, the steps overshoot and the
line search cuts them to a few per cent (the penalty alone, ``k_L = k_n``,
predicts far too small a contact set on the small-slope bisinusoid, and
Newton crawls from it in short steps); from the closed
side each step moves an edge only part of the way.  The stiffness that sets
the contact set is that of the pressure's variation over the cell, not of
its mean (the mean compression moves all points alike and is absorbed in
``d``): a pressure varying over a patch of width ``l`` deforms the two
bodies by about ``l/(pi E*)`` per unit pressure (a cosine of wavelength
``l`` on two half-spaces, ``1/E* = sum_B (1 - nu_B^2)/E_B``), and no more
than the bodies as columns in uniaxial strain, ``sum_B h_B/M_B``, so

    1/k_L(l) = 1/k_n + min(l/(pi E*), sum_B h_B/M_B).

With ``l = P`` (the period) this is exact at Westergaard's full contact,
``p* = pi E* h``; partial contact concentrates the pressure on a narrower
patch, so ``l`` is taken as the predicted patch itself, ``l = P f^(1/(dim-1))``
for the predicted contact fraction ``f``, iterated to consistency
(:func:`rigid_approach`): fewer Newton steps than the penalty alone on the
bisinusoid and the tabulated gap, as many on Westergaard.  ``start="closed"`` of
:class:`~ngcontact.cell.fe.cell_problem.CellProblem` restores the oldest start
instead: the counter pushed down by the largest gap plus ``p/k_n``
(:func:`max_gap`).

*Later frictionless loads whose tangential load changed*: the rigid
predictor again, for the whole traction ``tbar`` (:func:`rigid_translation`).
Fluctuations zero, the counter translated by the minimizer of the Winkler
energy

    W(U) = int_{S_C} (k_L/2) [-U.n - g]_+^2 ds - |T| tbar . U

over the translations the load leaves free (a few unknowns, Newton on a
surface integral; no solve of the cell problem), ``k_L`` made consistent
with the predicted patch as above.  The frictionless energy is convex with
one minimizer, so the start may forget the previous state; a start from it
is no better where the contact set moves across the cell (the shear turns
the pressed flank): on the sinusoid sweep the Newton steps after the start
are as many as after the rigid continuation
(:func:`ngcontact.cell.fe.load_start.rigid_continuation`), without the
continuation's own steps, and on
the 3D bisinusoid surface fewer in all.  The gain is the continuation's
steps, each an assembly of the cell's tangent; the predictor's own
iterations, on ``dim`` unknowns with surface integrals only, are no
Newton steps of the cell problem, like the first load's root.  With friction the Winkler model,
which has none, would slide the counter over the flat parts of ``S_C``
that friction holds (and Coulomb's law, without an energy, need not have
one solution: the previous one is the start to keep): the rigid
continuation (:mod:`ngcontact.cell.fe.load_start`), which chooses among these
starts for every load.
"""
from __future__ import annotations

import logging
import math

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.fe.measures import contact_integral, sample_surface
from ngcontact.errors import ConvergenceError
from ngcontact.laws import penalty as _contact
from ngcontact.solvers.line_search import armijo, illinois_root

log = logging.getLogger(__name__)


def layer_stiffness(problem, width: float) -> float:
    """``k_L(l)``: the penalty in series with the bodies' compliance for a contact patch of width ``l``.

    ``1/k_L = 1/k_n + min(l/(pi E*), sum_B h_B/M_B)`` (module docstring),
    ``1/E* = sum_B 1/E*_B`` with the plane-strain modulus ``E*_B = 4 G (M -
    G)/M`` from the body's Voigt stiffness (``M = C_nnnn``, ``G = C_ntnt``
    for the normal axis ``n0``, the last mesh axis, and the first tangent;
    ``E/(1 - nu^2)`` for an isotropic body).
    """
    d, cell, m = problem.dim, problem.cell, problem.model
    shear = 5 if d == 2 else 4           # Voigt index of (x, n0)
    columns = wave = 0.0
    for law, h in ((m.rough, cell.h_rough), (m.counter, cell.h_counter)):
        C = law.matrix
        M, G = float(C[d - 1, d - 1]), float(C[shear, shear])
        columns += h / M
        wave += M / (4.0 * G * (M - G))
    return 1.0 / (1.0 / m.k_n + min(width * wave / math.pi, columns))


def rigid_approach(problem, p: float, stiffness: float | None = None) -> float:
    """Normal approach ``d`` of the rigid predictor: root of ``R(d)`` (module docstring).

    ``stiffness`` is the Winkler stiffness ``k_L``; by default the patch
    width ``l`` and ``k_L(l)`` (:func:`layer_stiffness`) are made
    consistent: from ``l = P``, ``l <- P f^(1/(dim-1))`` with ``f`` the
    predicted contact fraction, which increases ``k_L`` monotonically to
    the smallest consistent value (within 5 %, at most 10 rounds).  ``R`` is
    nondecreasing and piecewise linear in ``d`` at the quadrature points of
    the contact energy; the root is bracketed by doubling and found by the
    Illinois variant of regula falsi.  The predicted state has at least one
    quadrature point in contact, so the first tangent is regular in ``U_n``.
    """
    if stiffness is not None:
        return _winkler_root(problem, p, stiffness)
    period = max(problem.cell.period)
    k_L = layer_stiffness(problem, period)
    d = _winkler_root(problem, p, k_L)
    for _ in range(10):
        width = period * _fraction(problem, d) ** (1.0 / (problem.dim - 1))
        k_new = layer_stiffness(problem, width)
        if k_new <= 1.05 * k_L:
            break
        k_L = k_new
        d = _winkler_root(problem, p, k_L)
    log.debug("rigid predictor: Winkler stiffness %.6e", k_L)
    return d


def _penetration(problem, dpar):
    """Penetration ``d n.n0 - g`` of the rigid jump ``J = d n0``."""
    n0 = problem.n[problem.dim - 1]
    return dpar * n0 if problem.gap is None else dpar * n0 - problem.gap


def _fraction(problem, d: float) -> float:
    """Projected fraction of ``S_C`` the rigid jump ``d n0`` closes."""
    n0 = problem.n[problem.dim - 1]
    dpar = ng.Parameter(d)
    closed = ng.IfPos(_penetration(problem, dpar), ng.IfPos(n0, n0, 0.0), 0.0)
    return float(contact_integral(problem, closed, order=problem.contact_order)) / problem.area


def _winkler_root(problem, p: float, k_L: float) -> float:
    """Root ``d`` of ``R(d)`` for the Winkler stiffness ``k_L``."""
    area = problem.area
    n0 = problem.n[problem.dim - 1]
    dpar = ng.Parameter(0.0)
    force = k_L * _contact.positive_part(_penetration(problem, dpar)) * n0
    order = problem.contact_order

    def R(dv):
        dpar.Set(dv)
        return float(contact_integral(problem, force, order=order)) - p * area

    lo, flo = 0.0, R(0.0)
    if flo == 0.0:            # d = 0 carries the load (a zero load, or one below what R resolves, at touch)
        return 0.0
    # the first step: the gap's and the load's scale, at least the smallest normal number (a subnormal
    # p / k_L, or 0, would never grow by doubling)
    step = max(problem.largest_gap() + p / k_L, np.finfo(float).tiny)
    if flo > 0.0:             # interference: already pressed at d = 0
        hi, fhi = lo, flo
        lo, flo, _, _ = _bracket(R, -step, lambda f: f > 0.0, p, (lo, flo))
        if flo == 0.0:
            return lo
    else:
        hi, fhi, lo, flo = _bracket(R, step, lambda f: f < 0.0, p, (lo, flo))
        if fhi == 0.0:
            return hi
    d = illinois_root(R, lo, flo, hi, fhi, ftol=1e-12 * p * area, xtol=1e-14 * abs(hi),
                      max_iter=200)
    log.debug("rigid predictor: approach %.6e for pressure %.6e", d, p)
    return d


#: doublings of the bracket: from the smallest normal number to the largest, the whole exponent range
MAX_DOUBLINGS = 2 * 1024


def _bracket(R, d: float, same_side, p: float, start: tuple[float, float]) -> tuple[float, float, float, float]:
    """``(d, R(d), e, R(e))``: ``d`` the first of ``d, 2d, 4d, ...`` where ``R`` has left the side of ``start``
    (``same_side(R(d))`` false) or reached 0, a root; ``e`` the last point on the start's side (``start``
    itself if none).  Bounded by :data:`MAX_DOUBLINGS`."""
    last = start
    for _ in range(MAX_DOUBLINGS):
        f = R(d)
        if not math.isfinite(f):
            break
        if not same_side(f):
            return d, f, last[0], last[1]
        last = (d, f)
        d *= 2.0
    raise ConvergenceError(f"rigid predictor: no approach carries the pressure {p!r} (R = {f!r} at d = {d!r} "
                           f"after doubling the bracket); the contact surface may not face the load", {})


def max_gap(problem) -> float:
    """Largest initial gap at the quadrature points of ``S_C`` (0 without gap)."""
    if problem.gap is None:
        return 0.0
    return float(max(sample_surface(problem, {"g": problem.gap})["g"].max(), 0.0))


def set_start(problem, load: CellLoad) -> None:
    """Put the start of a first load under a prescribed pressure into ``problem.gfu``.

    ``problem.start == "rigid"``: fluctuations zero, prescribed jumps kept,
    the counter translated by :func:`rigid_approach`; ``"closed"``: only
    ``U_n`` is set, to the largest gap plus ``p/k_n``.

    Raises
    ------
    ValueError
        The normal pressure is not positive (a free layer has no unique
        rigid position).
    """
    d = problem.dim
    vec, u_dofs = problem.gfu.vec, problem.u_dofs
    p = -load.traction[d - 1]
    if not p > 0:
        raise ValueError(f"normal pressure {p!r}: must be > 0 (a free layer has no unique "
                         "rigid position); prescribe a normal jump instead")
    if problem.start == "closed":
        vec[u_dofs[d - 1]] = -(problem.largest_gap() + p / problem.model.k_n)
    else:
        vec[:] = 0.0
        for i in range(d):
            jump = load.jump[i]
            if jump is not None:
                vec[u_dofs[i]] = -jump
        vec[u_dofs[d - 1]] = -rigid_approach(problem, p)


def rigid_translation(problem, load: CellLoad, free) -> bool:
    """Frictionless later load with a changed tangential load: the rigid predictor for the whole traction.

    Fluctuations zero, the counter translated by the minimizer ``U`` of the
    Winkler energy (module docstring) over the far-face translations the
    load leaves free (``free`` is the load's BitArray; prescribed jumps are
    kept), with ``k_L`` made consistent with the predicted patch as in
    :func:`rigid_approach`.  Returns ``False`` (state unchanged) with
    friction, a prescribed normal jump, or where the Winkler problem has no
    regular minimizer (no predicted contact, a translation without
    stiffness); the caller then continues rigidly.
    """
    d = problem.dim
    comps = [i for i, dof in enumerate(problem.u_dofs) if free[dof]]
    if problem.model.friction is not None or load.jump[d - 1] is not None or (d - 1) not in comps:
        return False
    vec = problem.gfu.vec
    U = np.array([vec[dof] for dof in problem.u_dofs])
    t = np.array([0.0 if x is None else float(x) for x in load.traction])
    period = max(problem.cell.period)
    k_L = layer_stiffness(problem, period)
    for _ in range(10):
        found = _winkler_translation(problem, U, t, comps, k_L)
        if found is None:
            return False
        U = found
        width = period * _translation_fraction(problem, U) ** (1.0 / (d - 1))
        k_new = layer_stiffness(problem, width)
        if k_new <= 1.05 * k_L:
            break
        k_L = k_new
    vec[:] = 0.0
    for i, dof in enumerate(problem.u_dofs):
        vec[dof] = U[i]
    log.debug("rigid translation: U = %s, Winkler stiffness %.6e", U, k_L)
    return True


def _rigid_pen(problem, params):
    """Penetration ``-U.n - g`` of the rigid jump ``J = -U`` for ``U`` given as Parameters."""
    pen = -ng.InnerProduct(ng.CF(tuple(params)), problem.n)
    return pen if problem.gap is None else pen - problem.gap


def _translation_fraction(problem, U) -> float:
    """Projected fraction of ``S_C`` the rigid jump ``-U`` closes."""
    n0 = problem.n[problem.dim - 1]
    closed = ng.IfPos(_rigid_pen(problem, [ng.Parameter(float(u)) for u in U]), ng.IfPos(n0, n0, 0.0), 0.0)
    return float(contact_integral(problem, closed, order=problem.contact_order)) / problem.area


def _winkler_translation(problem, U0, t, comps, k_L, max_iter: int = 50):
    """Minimizer over ``U[comps]`` of ``int (k_L/2) [-U.n - g]_+^2 ds - |T| t.U``, or ``None``.

    Newton with backtracking on the energy (convex, piecewise quadratic in
    ``U``); the gradient and the Hessian in one surface integral per step.
    """
    d, area, order = problem.dim, problem.area, problem.contact_order
    params = [ng.Parameter(float(u)) for u in U0]
    pen = _rigid_pen(problem, params)
    ramp = ng.IfPos(pen, pen, 0.0)
    on = ng.IfPos(pen, 1.0, 0.0)
    n = problem.n
    parts = [-k_L * ramp * n[i] for i in comps] + [k_L * on * n[i] * n[j] for i in comps for j in comps]
    m = len(comps)
    U = np.array(U0, dtype=float)

    def put(v) -> None:
        for i in range(d):
            params[i].Set(float(v[i]))

    def energy(v) -> float:
        put(v)
        return float(contact_integral(problem, 0.5 * k_L * ramp * ramp, order=order)) - area * float(t @ v)

    e = energy(U)
    for _ in range(max_iter):
        put(U)
        vals = np.asarray(contact_integral(problem, ng.CF(tuple(parts)), order=order), dtype=float).ravel()
        g = vals[:m] - area * t[comps]
        H = vals[m:].reshape(m, m)
        scale = np.trace(H)
        if not scale > 0 or np.linalg.cond(H) > 1e12:
            return None
        step = np.zeros(d)
        step[comps] = np.linalg.solve(H, g)
        slope = float(step[comps] @ g)
        alpha = 1.0
        while True:
            e_new = energy(U - alpha * step)
            if armijo(e, e_new, alpha * slope):
                break
            alpha *= 0.5
            if alpha < 1e-10:
                return None
        U, e = U - alpha * step, e_new
        if np.max(np.abs(alpha * step)) <= 1e-12 * max(np.max(np.abs(U)), 1e-300):
            return U
    return None
