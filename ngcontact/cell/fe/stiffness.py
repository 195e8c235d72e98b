"""Far-face and effective stiffness of the interface layer (beyond the paper).

The paper homogenizes the contact layer into the stiffnesses of eq. 34,
integrals of the penalty ``k_n`` over the real contact set; they grow
without bound with ``k_n`` and leave out the compliance of the asperities
themselves.  This module measures the stiffness the solved cell problem
(paper eqs. 49-51, 57, 65; :mod:`ngcontact.cell.fe.cell_problem`) really has:

* ``S``: the tangent of the mean far-face traction with respect to the
  far-face jump, per ``|T|`` — the Schur complement of the tangent of the
  cell energy on the far-face translation ``U`` (:func:`schur_complement`,
  :func:`tangent_stiffness`), its inner solves by the cell's linear-solver
  policy: a factorization, or for a large 3D cell CG with BDDC (faster
  than the factorization there, in a fraction of its memory); a 2D penalty
  cell's tangent integrated exactly up to its contact edges
  (:func:`edge_correction`);
* ``S_0``: the same for the flat bonded laminate of the same thickness,
  analytic (:func:`reference_stiffness`): each layer in a uniform state
  ``eps = sym(a (x) n0)`` with ``t = A a`` and the acoustic tensor
  ``A_ik = C_ijkl n0_j n0_l``, so

      S_0 = (h_rough A_rough^-1 + h_counter A_counter^-1)^-1;

* the interface's compliance ``S^-1 - S_0^-1`` (penalty layer plus the
  constriction of the asperities, finite as ``k_n -> infinity``) and the
  effective stiffness, its inverse (:func:`effective_stiffness`).

Exact enforcement (:mod:`ngcontact.cell.fe.contact_multiplier`): ``S`` is the
tangent with the contact set held closed, the limit ``k -> infinity`` of
the augmented energy's tangent, in which the loaded points are springs of
stiffness ``k`` (the augmentation).  At a fixed contact set the tangent is
affine in ``k``, ``K(k) = K_0 + k P``, and ``S(k)`` is smooth in ``eps =
1/k``; with ``v_j = e_j - K_II^-1 K_IU e_j`` (the translation ``e_j`` and
the bodies' response to it) its derivatives are ``dS_ij/dk = v_i^T P v_j``
(the bodies' response is stationary) and ``d2S_ij/dk2 = -2 (P v_i)_I^T
K_II^-1 (P v_j)_I``, so that the Taylor polynomial of degree two in ``eps``,
taken from ``eps = 1/k`` to 0, is

    S(inf) = S(k) + 2 v^T Q v - (Q v)_I^T K_II^-1 (Q v)_I + O(k^-3),      Q = k P = Psi''(2k) - Psi''(k),

the same order as a Richardson extrapolation from ``k, 2k, 4k``, from the
one inverse of ``K_II`` at ``k`` and one solve more per component (where
three Schur complements took three factorizations or preconditioners).  It
is taken at ``k = RIGID_SCALE`` times the solve's augmentation (within the
ceiling of :func:`~ngcontact.cell.fe.contact_multiplier.max_augmentation`,
which keeps the tangent well conditioned), where the ``O(k^-3)`` remainder
is ``RIGID_SCALE^3`` times smaller: on the quarter bisinusoid cell
(``h = 0.01``, ``p/p* = 0.05``, ``k = 182``, ``S(k)`` 3 % below the limit)
the polynomial at ``k``, ``4k``, ``16k``, ``64k`` is off the limit (its
values converged to ten digits) by ``1e-4``, ``2e-6``, ``5e-8``, ``6e-10``
relative, the Richardson extrapolation from ``k, 2k, 4k`` by ``2e-5``.
``Q`` is the difference of the interface's tangents alone (no assembly of
the bodies).  Only the components the caller keeps are computed (a
frictionless flat interface: the normal one).

The set held closed is that of the closed nodes, which ends a node spacing
short of each contact edge; in 2D ``S`` is taken at the edges instead, by
interpolation between that set and the set with the next open node held
too (:func:`edge_interpolation`), and the change with the set is kept for
the estimate (:func:`edge_record`).

The inner solves.  Both terms are minima of an energy: ``S_ij = v_i^T K
v_j`` with ``v_j`` the minimizer of ``v^T K v`` among the ``v`` equal to
``e_j`` on the far-face dofs, and ``q^T K_II^-1 q = max_z 2 q^T z - z^T
K_II z``.  Taken in these forms (``v_i^T K v_j``, ``q_i^T z_j + z_i^T q_j -
z_i^T K z_j``) their error is the product of the two solves' errors in the
energy norm, not the error itself, as in ``e_i^T K v_j``.  Their CG solves
(:meth:`~ngcontact.solvers.linear_solver.LinearSolver.exact_inverse`) thus
stop at a relative residual of ``SCHUR_RTOL = 1e-7`` instead of ``1e-12``:
on the quarter bisinusoid scene at ``p/p* = 0.05`` the stiffness came out
the same to six digits at each of its six levels.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.cell.fe.cell_energy import jump
from ngcontact.cell.fe.contact_multiplier import max_augmentation
from ngcontact.cell.fe.edge_cuts import element_cuts, piece_rule
from ngcontact.cell.fe.exact_contact_set import closed_nodes, contact_cuts
from ngcontact.fem import materials as _mat
from ngcontact.laws import penalty as _contact
from ngcontact.solvers.linear_solver import LinearSolver, fixed_mask, mask_fixed, match_free_dofs
from ngcontact.solvers.split_energy import add_matrix


#: relative (preconditioned) residual of the inner solves of :func:`schur_complement` (module docstring, "The
#: inner solves"): the Schur complement and the rigid limit's term are taken in their variational forms, whose
#: error is the square of the solves' energy error, so 1e-7 leaves them at round-off
SCHUR_RTOL = 1e-7
#: the augmentation the rigid limit is taken from, in units of the solve's (module docstring), within
#: :func:`~ngcontact.cell.fe.contact_multiplier.max_augmentation`
RIGID_SCALE = 64.0
#: the most contact edges of a 2D exact cell whose stiffness takes one solve per edge (:func:`edge_interpolation`)
EDGE_SOLVES = 4


def schur_complement(form, X, dofs, state_vec, linear: LinearSolver, kept: list[int] | None = None,
                     stiff=None, correction=None) -> np.ndarray:
    """Schur complement of the tangent of the split energy ``form`` at ``state_vec`` on the dofs ``dofs``, its
    rows and columns ``kept`` (default all).

    ``K_II`` (the free dofs of ``X`` without ``dofs``) is inverted by the
    cell's linear-solver policy (:meth:`~ngcontact.solvers.linear_solver.LinearSolver.exact_inverse`:
    a factorization, or CG with BDDC for a large 3D cell); with ``v_j = e_j - K_II^-1 K_IU e_j`` the
    result ``S_ij = e_i^T K v_j = K_UU - K_UI K_II^-1 K_IU`` is symmetrized.  ``stiff = (set_k, k)``: the
    augmentation ``k`` of exact contact, which ``set_k`` sets; ``S`` is then taken to ``k -> infinity``
    (:func:`_rigid_limit`).  ``correction``: a matrix added to the assembled tangent before it is inverted
    (:func:`edge_correction`).  The space's own free dofs are restored afterwards.
    """
    kept = list(range(len(dofs))) if kept is None else list(kept)
    own = ng.BitArray(X.FreeDofs())
    free = ng.BitArray(own)
    for d in dofs:
        free.Clear(d)
    linear.register(form, free)
    form.renew_preconditioner()              # its preconditioner is built anew on these free dofs
    try:
        form.AssembleLinearization(state_vec)
        K = form.mat
        if correction is not None:
            add_matrix(K, correction)
        inv = linear.exact_inverse(form, free, SCHUR_RTOL)
        fixed = fixed_mask(free)
        cols = [dofs[j] for j in kept]
        v = []
        e, x = state_vec.CreateVector(), state_vec.CreateVector()
        for dj in cols:
            e[:] = 0.0
            e[dj] = 1.0
            x.data = K * e
            mask_fixed(x, fixed)                          # K_IU e_j
            z = state_vec.CreateVector()
            z.data = inv * x
            mask_fixed(z, fixed)
            vj = state_vec.CreateVector()
            vj.data = e - z
            v.append(vj)
        S = np.empty((len(cols), len(cols)))
        for j, vj in enumerate(v):
            x.data = K * vj
            for i, vi in enumerate(v):
                S[i, j] = ng.InnerProduct(vi, x)              # v_i^T K v_j: error quadratic in the solve's
        if stiff is not None:
            S = S + _rigid_limit(form, state_vec, inv, v, fixed, *stiff)
    finally:
        match_free_dofs(X, own)
    return 0.5 * (S + S.T)


def _rigid_limit(form, state_vec, inv, v, fixed, set_k, k: float) -> np.ndarray:
    """What takes ``S(k)`` to ``k -> infinity``: ``2 v^T Q v - (Q v)_I^T K_II^-1 (Q v)_I`` with
    ``Q = Psi''(2k) - Psi''(k)`` (module docstring), ``inv`` the inverse of ``K_II`` at ``k``; the interface is
    left assembled at ``k``."""
    qv = []
    for vj in v:
        a, b = vj.CreateVector(), vj.CreateVector()
        set_k(2.0 * k)
        form.interface_product(state_vec, vj, a)
        set_k(k)
        form.interface_product(state_vec, vj, b)
        a.data -= b
        qv.append(a)
    n = len(v)
    q, z, kz = [], [], []
    for j in range(n):
        qj, zj, kj = (v[0].CreateVector() for _ in range(3))
        qj.data = qv[j]
        mask_fixed(qj, fixed)
        zj.data = inv * qj
        mask_fixed(zj, fixed)
        kj.data = form.mat * zj
        q.append(qj)
        z.append(zj)
        kz.append(kj)
    out = np.empty((n, n))
    for j in range(n):
        for i in range(n):
            # (Q v_i)_I^T K_II^-1 (Q v_j)_I as q_i^T z_j + z_i^T q_j - z_i^T K z_j: its error quadratic in z's
            inverse = ng.InnerProduct(q[i], z[j]) + ng.InnerProduct(z[i], q[j]) - ng.InnerProduct(z[i], kz[j])
            out[i, j] = 2.0 * ng.InnerProduct(v[i], qv[j]) - inverse
    return out


def reference_stiffness(problem) -> np.ndarray:
    """``S_0``: far-face stiffness of the flat bonded laminate of the same thickness.

    Both bodies, each with its own law, stacked flat with the interface in
    the summit plane (``rough`` below it over ``h_rough``, ``counter``
    above over ``h_counter``) and bonded.  Under a mean traction each
    layer is in a uniform state ``eps = sym(a (x) n0)`` with
    ``t = A a``, ``A_ik = C_ijkl n0_j n0_l`` (the acoustic tensor), so
    the far-face jump is ``sum_L h_L A_L^-1 t`` and

        S_0 = (h_rough A_rough^-1 + h_counter A_counter^-1)^-1,

    in the components ``(t0[, t1], n0)`` (per ``|T|``).
    """
    d = problem.dim
    idx = list(range(d))  # mesh axes; n0 is the last one
    C = 0.0
    for law, h in ((problem.model.rough, problem.cell.h_rough),
                   (problem.model.counter, problem.cell.h_counter)):
        A = _acoustic_tensor(law, normal_axis=d - 1)[np.ix_(idx, idx)]
        C = C + h * np.linalg.inv(A)
    return np.linalg.inv(C)


def tangent_stiffness(problem, kept: list[int] | None = None, held: list[int] | None = None) -> np.ndarray:
    """``S``: tangent of the mean far-face traction w.r.t. the far-face jump (per ``|T|``), on the components
    ``kept`` (default all), the others held: ``S = C^-1`` (:func:`compliance`).

    Exact enforcement: at ``k -> infinity`` (module docstring), the closed points held closed and, with
    ``held`` (indices of points of the multiplier), those points and the other copies of their nodes too
    (:func:`held_closed`).
    """
    kept = list(range(problem.dim)) if kept is None else list(kept)
    stiff = None
    k = problem.augmentation.Get() if problem.multiplier is not None else None
    if k is not None:
        stiff = (problem.augmentation.Set, max(min(RIGID_SCALE * k, max_augmentation(problem)), k))
        problem.augmentation.Set(stiff[1])
    values = problem.multiplier.point_values() if held and stiff is not None else None
    try:
        if values is not None and stiff is not None and held:
            problem.multiplier.set_point_values(held_closed(problem, held, 4.0 * stiff[1]))
        return schur_complement(problem.energy(), problem.X, problem.u_dofs, problem.gfu.vec, problem.linear,
                                kept, stiff, edge_correction(problem)) / problem.area
    finally:
        if values is not None:
            problem.multiplier.set_point_values(values)
        if k is not None:
            problem.augmentation.Set(k)
        if problem.linear.preconditioned(problem.energy()):
            # the whole form was assembled here, on other free dofs: the preconditioner kept by the
            # Newton solve of the next load must be built anew
            problem.energy().renew_preconditioner()


def held_closed(problem, held: list[int], k: float) -> np.ndarray:
    """The multiplier's point values with the nodes of the points ``held`` (every copy of each) raised to
    ``k`` times their opening (and above 0), so that ``lambda + k' (J_n - g) > 0`` there for every
    augmentation ``k' < k``: the augmented energy's tangent then holds them closed as it holds the loaded
    points, and its value there does not enter it (its second derivative is ``k' H(lambda + k' (J_n - g))``)."""
    m = problem.multiplier
    values, (_, opening) = m.point_values(), closed_nodes(problem)
    x = m.at_points(ng.x)
    tiny = 1e-11 * max(float(np.ptp(x)), 1.0)
    for q in held:
        copies = np.abs(x - x[q]) <= tiny
        values[copies] = k * np.maximum(opening[copies], 0.0) + np.finfo(float).tiny
    return values


def edge_interpolation(problem, kept: list[int], S: np.ndarray) -> tuple[np.ndarray, dict | None]:
    """``S`` at the contact edges of exact enforcement (2D), from ``S`` (``S_c``) of the closed points and
    ``S_o`` with the next open node beyond each edge held closed too; and the record of :func:`edge_record`
    (``None`` where no edge lies between two nodes: nothing moves).

    The tangent of exact contact holds the contact set closed: the set of the closed nodes, which ends at
    the last closed node ``x_c`` while the edge ``a`` lies between it and the first open node ``x_o``
    (:func:`~ngcontact.cell.fe.exact_contact_set.contact_cuts`, the fraction ``t = (a - x_c) / (x_o -
    x_c)``).  The stiffness of a set held closed grows with its extent: the periodic flat punch of
    half-width ``a``, ``K = pi E* / (2 ln(1 / sin(pi a)))``, the tangent of Westergaard's contact
    (``docs/benchmarks.md``, "The graded FE cell at a stated tolerance"), has ``d ln K / da = pi cot(pi
    a) / ln(1 / sin(pi a))``, large where the contact is wide, so the closed nodes' set, short by ``a - x_c``
    at each edge, takes ``K`` low by ``(a - x_c) d ln K / da`` relative, which no refinement of the grading
    shows in time (``tests/cell/test_exact_stiffness_edges.py``).  Linear in the extent between the two sets,

        S(a) = S_c + t (S_o - S_c) + O((x_o - x_c)^2),

    for each edge with its own ``S_o`` while there are at most :data:`EDGE_SOLVES` (one solve more per
    edge); beyond, one ``S_o`` holds every edge's next node closed and ``t`` is their mean weighted by the
    node spacing, ``sum (a_e - x_c) / sum (x_o - x_c)`` (the set's measure added; :func:`edge_record` states
    what the edges' different ``t_e`` leave).
    """
    m = problem.multiplier
    if m is None or problem.dim != 2:
        return S, None
    edges: list = []
    contact_cuts(problem, edges)
    if not edges:
        return S, None
    x = m.at_points(ng.x)
    groups = [[e] for e in edges] if len(edges) <= EDGE_SOLVES else [edges]
    out, record = S.copy(), []
    for group in groups:
        S_o = tangent_stiffness(problem, kept, [o for _, o, _ in group])
        t = np.array([f for *_, f in group])
        length = np.array([abs(x[o] - x[c]) for c, o, _ in group])
        share = float(np.dot(t, length) / np.sum(length))
        out = out + share * (S_o - S)
        record.append((S_o, float(np.max(np.abs(t - share))), float(np.sum(length)) / float(np.sum(m.element_areas))))
    return out, {"S_c": S, "groups": record}


def edge_record(edge: dict, S0: np.ndarray) -> dict:
    """What the edges' interpolation (:func:`edge_interpolation`) leaves to the estimate, in the normal
    stiffness ``K`` (absolute): ``slope``, the largest ``|K_o - K_c| / df`` of the groups of edges (``df`` the
    contact fraction the group's next open nodes add), whose product with the fraction's error bounds the
    stiffness's share of the edges' error; and ``spread``, the sum over the groups of ``max_e |t_e - t_g|
    |K_o - K_c|``, what one ``t_g`` for a group leaves where its edges' ``t_e`` differ (each edge's share
    of the group's ``K_o - K_c``, all of the same sign, at most all of it): zero where each edge has its own
    solve."""
    K_c = _normal(edge["S_c"], S0)
    slope, spread = 0.0, 0.0
    for S_o, dt, added in edge["groups"]:
        K_o = _normal(S_o, S0)
        if K_c is None or K_o is None or added <= 0.0:
            return {}
        slope, spread = max(slope, abs(K_o - K_c) / added), spread + dt * abs(K_o - K_c)
    return {"slope": slope, "spread": spread}


def _normal(S: np.ndarray, S0: np.ndarray) -> float | None:
    """The normal entry of ``(S^-1 - S_0^-1)^-1``, or ``None`` where it is singular."""
    compliance = np.linalg.inv(S) - np.linalg.inv(S0)
    compliance = 0.5 * (compliance + compliance.T)
    if np.linalg.cond(compliance) > 1e12:
        return None
    return float(np.linalg.inv(compliance)[-1, -1])


def edge_correction(problem):
    """What takes the penalty's tangent to its exact value on the elements of ``S_C`` a contact edge cuts (2D,
    frictionless penalty), or ``None``: ``int k_n H(s) (dJ.n)(dJ'.n) ds`` over their pieces in contact
    (:func:`~ngcontact.cell.fe.edge_cuts.element_cuts`, a Gauss rule per piece) less the same integrand at
    the energy's rule, ``2p + contact_bonus_order``, which puts the jump of ``H`` at a quadrature point.

    The tangent is the derivative of the penalty's residual ``int k_n [s]_+ (dJ.n) ds``; ``[s]_+`` vanishes
    at the edge, so the edge's motion adds nothing to it and the exact tangent is ``H(s)`` integrated up
    to the edge.  The energy's rule changes it by up to half a quadrature spacing at each edge, which the
    difference of nearly equal compliances amplifies: on the Westergaard cell (interface_maxh 0.01, order
    2, load 1) the effective stiffness moved by 3e-3 between ``contact_bonus_order`` 12 and 40, more than
    its discretization error, and one order more's change (:mod:`ngcontact.cell.fe.saturation`) was 22
    times that error.
    """
    m = problem.model
    if problem.dim != 2 or problem.multiplier is not None or m.friction is not None:
        return None
    cuts = element_cuts(problem)
    elements = [el.nr for el in problem.mesh.Boundaries("contact").Elements()]
    cut = [(elements[e], ts, on) for e, (ts, on) in enumerate(cuts) if len(on) > 1 and any(on)]
    if not cut:
        return None
    trial, test = problem.X.TnT()
    dJ, dJv = jump(trial), jump(test)
    exact = m.k_n * ng.InnerProduct(dJ, problem.n) * ng.InnerProduct(dJv, problem.n)
    rule_energy = _contact.interface_stiffness(problem.J, problem.n, dJ, dJv, k_n=m.k_n, gap=problem.gap)
    form = ng.BilinearForm(problem.X, symmetric=True, symmetric_storage=problem.inverse == "sparsecholesky")
    every = ng.BitArray(problem.mesh.GetNE(ng.BND))
    every.Clear()
    order = 2 * m.order + m.contact_bonus_order
    for nr, ts, on in cut:
        one = ng.BitArray(problem.mesh.GetNE(ng.BND))
        one.Clear()
        one.Set(nr)
        every.Set(nr)
        form += exact * ng.ds("contact", definedonelements=one,
                              intrules={ng.SEGM: piece_rule(ts, on, order)})
    form += -rule_energy * ng.ds("contact", definedonelements=every, bonus_intorder=m.contact_bonus_order)
    form.Assemble()
    return form.mat

def effective_stiffness(problem) -> dict:
    """Interface stiffness with asperity compliance: ``(S^-1 - S_0^-1)^-1``.

    ``S`` is the tangent far-face stiffness of the cell, ``S_0`` that of
    the flat bonded laminate (:func:`reference_stiffness`); their
    compliance difference is the interface's share: penalty layer plus
    the compliance of the asperities (constriction), which stays finite
    as ``k_n -> infinity`` (module docstring).  Restricted to the components
    that are determinate (all but the tangential ones of a frictionless
    flat interface).  ``matrix`` is ``None`` when the interface
    compliance is singular (e.g. a component the interface does not
    resist beyond the bulk).  An open interface transmits nothing
    (``S`` singular): its stiffness is the limit
    ``S (I - S_0^-1 S)^-1 = 0`` and ``compliance`` is ``None``.  An
    interface closed at every node under exact enforcement (full contact)
    has no compliance beyond the bulk's: ``S = S_0`` in the rigid limit, the
    stiffness is infinite, ``matrix`` is ``None`` and ``compliance`` zero, as
    the spectral cell reports it (a difference ``S^-1 - S_0^-1`` of round-off
    size inverted would be a number of ``1e9`` to ``1e11`` that changes with
    the solver's start and the mesh, and its "estimate" with it).
    """
    dim = problem.dim
    keep = [i for i in range(dim) if i == dim - 1 or problem.tangential_free]
    names = (["t0"] if dim == 2 else ["t1", "t2"]) + ["n0"]
    S = tangent_stiffness(problem, keep)
    S0 = reference_stiffness(problem)[np.ix_(keep, keep)]
    if problem.multiplier is not None and bool(np.all(closed_nodes(problem)[0])):
        return {"components": [names[i] for i in keep], "matrix": None,
                "compliance": np.zeros((len(keep), len(keep))).tolist(), "total": S.tolist(), "reference": S0.tolist()}
    S, edge = edge_interpolation(problem, keep, S)
    if np.linalg.cond(S) > 1e12 * np.linalg.cond(S0):  # (partly) open: S^-1 does not exist
        compliance = None
        A = np.eye(len(keep)) - np.linalg.solve(S0, S)
        K = None if np.linalg.cond(A) > 1e12 else S @ np.linalg.inv(A)
    else:
        compliance = np.linalg.inv(S) - np.linalg.inv(S0)
        compliance = 0.5 * (compliance + compliance.T)
        K = None if np.linalg.cond(compliance) > 1e12 else np.linalg.inv(compliance)
    if K is not None:
        K = (0.5 * (K + K.T)).tolist()
    out = {"components": [names[i] for i in keep], "matrix": K,
           "compliance": None if compliance is None else compliance.tolist(),
           "total": S.tolist(), "reference": S0.tolist()}
    if edge is not None and K is not None:
        out["edges"] = edge_record(edge, S0)
    return out


def _acoustic_tensor(law, normal_axis: int) -> np.ndarray:
    """``A_ik = C_ijkl n_j n_l`` for ``n = e_normal_axis`` (3x3, from the Voigt matrix)."""
    C = law.matrix
    voigt = {}
    for k, (i, j) in enumerate(_mat.VOIGT_PAIRS):
        voigt[i, j] = voigt[j, i] = k
    m = normal_axis
    return np.array([[C[voigt[i, m], voigt[k, m]] for k in range(3)] for i in range(3)])
