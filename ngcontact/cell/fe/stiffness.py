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
  than the factorization there, in a fraction of its memory);
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
stiffness ``k`` (the augmentation).  ``S(k)`` is smooth in ``1/k`` at a
fixed contact set, so it is extrapolated from ``k, 2k, 4k`` to ``1/k = 0``
(Richardson, error ``O(k^-3)``) instead of evaluated at a stiffness that
would spoil the factorization.
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.fem import materials as _mat
from ngcontact.solvers.linear_solver import LinearSolver, fixed_mask, mask_fixed, match_free_dofs


def schur_complement(form, X, dofs, state_vec, linear: LinearSolver) -> np.ndarray:
    """Schur complement of the tangent of the split energy ``form`` at ``state_vec`` on the dofs ``dofs``.

    ``K_II`` (the free dofs of ``X`` without ``dofs``) is inverted by the
    cell's linear-solver policy (:meth:`~ngcontact.solvers.linear_solver.LinearSolver.exact_inverse`:
    a factorization, or CG with BDDC for a large 3D cell); the result
    ``K_UU - K_UI K_II^-1 K_IU`` is symmetrized.  The space's own free
    dofs are restored afterwards.
    """
    own = ng.BitArray(X.FreeDofs())
    free = ng.BitArray(own)
    for d in dofs:
        free.Clear(d)
    linear.register(form, free)
    form.renew_preconditioner()              # its preconditioner is built anew on these free dofs
    try:
        form.AssembleLinearization(state_vec)
        K = form.mat
        inv = linear.exact_inverse(form, free)
        n = len(dofs)
        S = np.zeros((n, n))
        e, y, x, z = (state_vec.CreateVector() for _ in range(4))
        fixed = fixed_mask(free)
        for j, dj in enumerate(dofs):
            e[:] = 0.0
            e[dj] = 1.0
            y.data = K * e
            rhs = y.FV().NumPy().copy()
            x.data = y
            mask_fixed(x, fixed)                          # K_IU e_j
            z.data = inv * x
            x.data = z
            mask_fixed(x, fixed)
            z.data = K * x
            for i, di in enumerate(dofs):
                S[i, j] = rhs[di] - z[di]
    finally:
        match_free_dofs(X, own)
    return 0.5 * (S + S.T)


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


def tangent_stiffness(problem) -> np.ndarray:
    """``S``: tangent of the mean far-face traction w.r.t. the far-face jump (per ``|T|``).

    Exact enforcement: extrapolated to ``k -> infinity`` (module docstring).
    """
    def at_current_k() -> np.ndarray:
        return schur_complement(problem.energy(), problem.X, problem.u_dofs, problem.gfu.vec,
                                problem.linear) / problem.area
    try:
        if problem.multiplier is None:
            return at_current_k()
        k = problem.augmentation.Get()
        S = []
        try:
            for scale in (1.0, 2.0, 4.0):
                problem.augmentation.Set(scale * k)
                S.append(at_current_k())
        finally:
            problem.augmentation.Set(k)
        return (8.0 * S[2] - 6.0 * S[1] + S[0]) / 3.0
    finally:
        if problem.linear.preconditioned(problem.energy()):
            # the whole form was assembled here, on other free dofs: the preconditioner kept by the
            # Newton solve of the next load must be built anew
            problem.energy().renew_preconditioner()


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
    ``S (I - S_0^-1 S)^-1 = 0`` and ``compliance`` is ``None``.
    """
    dim = problem.dim
    keep = [i for i in range(dim) if i == dim - 1 or problem.tangential_free]
    names = (["t0"] if dim == 2 else ["t1", "t2"]) + ["n0"]
    S = tangent_stiffness(problem)[np.ix_(keep, keep)]
    S0 = reference_stiffness(problem)[np.ix_(keep, keep)]
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
    return {"components": [names[i] for i in keep], "matrix": K,
            "compliance": None if compliance is None else compliance.tolist(),
            "total": S.tolist(), "reference": S0.tolist()}


def _acoustic_tensor(law, normal_axis: int) -> np.ndarray:
    """``A_ik = C_ijkl n_j n_l`` for ``n = e_normal_axis`` (3x3, from the Voigt matrix)."""
    C = law.matrix
    voigt = {}
    for k, (i, j) in enumerate(_mat.VOIGT_PAIRS):
        voigt[i, j] = voigt[j, i] = k
    m = normal_axis
    return np.array([[C[voigt[i, m], voigt[k, m]] for k in range(3)] for i in range(3)])
