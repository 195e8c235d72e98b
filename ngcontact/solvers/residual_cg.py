"""Conjugate gradients stopped on the residual that Newton's test measures.

NGSolve's preconditioned CG (``ngsolve.krylovspace.CGSolver``) stops when
the preconditioned residual ``sqrt(r_k . C r_k)`` has fallen to ``tol``
times its first value.  A linear solve of Newton's iteration
(:func:`ngcontact.solvers.newton.minimize` with a quadratic energy) is
judged afterwards by the Euclidean norm of the residual on the free dofs,
``|r| <= target``.  The two norms' reductions differ by a factor of order
one that depends on the mesh and on round-off (the preconditioner's sums
are made in another order on MPI ranks than in one process), so a solve to
``tol = target / |r_0|`` in the preconditioned norm lands at the target:
whether the test passes, or a second, whole solve follows, is decided by
round-off, and one process and N ranks may decide differently.

:class:`ResidualCG` runs the same iteration (the recursion of the residual
``r_k+1 = r_k - alpha_k K s_k``, the preconditioned direction update) but
stops when the Euclidean norm of that recursive residual is at most
``reach``, an absolute level that the caller sets below Newton's target
(:data:`ngcontact.solvers.newton.LINEAR_MARGIN`): the test that follows
then passes with that margin, in one process as on N ranks, and the
number of iterations differs only where round-off moves the recursive
residual across ``reach`` (by a few iterations: CG's iterates in one
process and on the ranks drift apart with round-off).  Without ``reach``
it is NGSolve's CG.
"""
from __future__ import annotations

import ngsolve as ng
from ngsolve.krylovspace import CGSolver

from ngcontact.solvers.roundoff import free_norm


class ResidualCG(CGSolver):
    """Preconditioned CG that stops on ``|r_k| <= reach`` when ``reach`` is set (module docstring), the norm
    taken on the free dofs (``fixed``: the mask of the others, whose rows hold the supports' reactions, not a
    residual).

    ``reach``: the absolute Euclidean norm of the residual ``rhs - K x`` to
    reach (``None``: NGSolve's stopping rule, ``tol`` times the first
    preconditioned residual).  ``iterations`` counts the residuals checked,
    the first one included, as NGSolve's does.
    """

    def __init__(self, *args, fixed, **kwargs):
        super().__init__(*args, **kwargs)
        self.reach: float | None = None
        self.fixed = fixed

    def _SolveImpl(self, rhs, sol):
        if self.reach is None:
            return super()._SolveImpl(rhs, sol)
        r, z, s, ks, rf = (sol.CreateVector() for _ in range(5))
        r.data = rhs - self.mat * sol
        z.data = self.pre * r
        s.data = z
        rz = ng.InnerProduct(z, r)
        self.iterations = 1
        while _norm(r, rf, self.fixed) > self.reach:
            if self.iterations >= self.maxiter:
                return
            ks.data = self.mat * s
            curvature = ng.InnerProduct(s, ks)
            if curvature == 0.0 or rz == 0.0:
                return
            alpha = rz / curvature
            sol.data += alpha * s
            r.data -= alpha * ks
            z.data = self.pre * r
            rz, rz_old = ng.InnerProduct(z, r), rz
            self.iterations += 1
            s.data = (rz / rz_old) * s + z


def _norm(vec, work, fixed) -> float:
    """The Euclidean norm of ``vec`` on the free dofs (``fixed``: the mask of the others; ``work``: a vector
    to hold the masked copy, ``vec`` left as it is), over the ranks for a vector distributed by NGSolve."""
    work.data = vec
    return free_norm(work, fixed)
