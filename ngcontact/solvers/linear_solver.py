"""The linear solve of a Newton step: sparse direct or preconditioned CG, by size.

Each Newton step of :func:`ngcontact.solvers.newton.minimize` solves

    K(u) du = r(u)

with the tangent ``K = Pi''(u)`` of the energy: the bodies' elasticity plus
the contact (and friction) terms on the interface, symmetric and positive
definite on the free dofs.  Two ways:

* ``"direct"``: a sparse Cholesky (or UMFPACK) factorization of ``K``.  Exact,
  but its cost grows like ``N^1.8`` in 3D (measured on the bisinusoid cell:
  8 s at 8k dofs, 508 s at 83k dofs for a solve of 11 Newton steps).
* ``"iterative"``: conjugate gradients preconditioned by NGSolve's BDDC
  (balancing domain decomposition by constraints, one subdomain per element)
  with a vertex-only wirebasket: the spaces are built with
  ``wb_withedges=False``, so the coarse problem holds the vertex dofs only
  (and the far-face translations, ``NumberSpace`` dofs, which BDDC keeps on
  the wirebasket).  Its setup costs about one assembly, its iterations grow
  like ``log(p)^2`` and mildly with the mesh; measured on a 3D box of order
  2: 58 iterations at 64k dofs, 87 at 120k, setup and solve together 2x
  cheaper than the factorization at 120k and cheaper beyond.  The
  preconditioner is registered with the energy form and rebuilt from each
  step's tangent by the assembly itself.  CG stops at
  ``|r_k| <= rtol |r_0|`` in the preconditioned norm (``rtol = 1e-10``
  by default: Newton's own tolerance, so the steps are as exact as the
  factorization's for the stopping rules downstream).
* ``"auto"``: iterative from ``threshold`` free dofs on (default
  ``AUTO_THRESHOLD``, about the crossover measured above), direct below.

BDDC reads the free dofs from the space; a solve whose free dofs differ
from the space's (prescribed far-face translations of a cell) sets the
space's free dofs to them first (:func:`match_free_dofs`).

The solver keeps what it did for the report (:meth:`LinearSolver.summary`):
the method chosen, the number of solves and CG iterations per solve.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import ngsolve as ng

from ngcontact.errors import ConvergenceError

POLICIES = ("direct", "iterative", "auto")
#: free dofs from which "auto" solves iteratively (BDDC-CG against sparse Cholesky, 3D order 2)
AUTO_THRESHOLD = 60_000


@dataclass
class LinearSolver:
    """Policy and record of the tangent solves (module docstring).

    Parameters
    ----------
    policy
        ``"direct"``, ``"iterative"`` or ``"auto"``.
    inverse
        Sparse direct solver of the direct path.
    threshold
        Free dofs from which ``"auto"`` goes iterative.
    rtol, max_iter
        CG stopping rule (relative, preconditioned residual) and step limit.
    """

    policy: str = "direct"
    inverse: str = "sparsecholesky"
    threshold: int = AUTO_THRESHOLD
    rtol: float = 1e-10
    max_iter: int = 2000
    iterations: list[int] = field(default_factory=list)
    solves: int = 0
    _pre: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        if self.policy not in POLICIES:
            raise ValueError(f"policy = {self.policy!r}: must be one of {POLICIES}")

    def method(self, freedofs) -> str:
        """``"direct"`` or ``"iterative"`` for a system with these free dofs."""
        if self.policy == "auto":
            return "iterative" if freedofs.NumSet() >= self.threshold else "direct"
        return self.policy

    def register(self, form: ng.BilinearForm, freedofs) -> None:
        """Before assembling ``form`` for a solve on ``freedofs``: register BDDC with it when iterative.

        NGSolve builds a registered preconditioner at every assembly of the
        form (``AssembleLinearization`` included), on the space's free dofs,
        which are set to ``freedofs`` here.
        """
        if self.method(freedofs) != "iterative":
            return
        match_free_dofs(form.space, freedofs)
        if id(form) not in self._pre:
            self._pre[id(form)] = ng.Preconditioner(form, "bddc")

    def prepare(self, form: ng.BilinearForm, freedofs) -> "TangentSolve":
        """The solve with the current (assembled) ``form.mat`` on ``freedofs``: ``apply(rhs, out)``."""
        if self.method(freedofs) == "direct":
            return TangentSolve(self, form.mat.Inverse(freedofs, inverse=self.inverse), counted=False)
        pre = self._pre.get(id(form))
        if pre is None:
            raise RuntimeError("LinearSolver.register(form) must come before the form's first assembly")
        from ngsolve.krylovspace import CGSolver
        return TangentSolve(self, CGSolver(form.mat, pre.mat, tol=self.rtol, maxiter=self.max_iter,
                                           printrates=False), counted=True)

    def summary(self) -> dict:
        """What was done, JSON-ready."""
        out: dict = {"policy": self.policy, "solves": self.solves}
        if self.policy == "auto":
            out["threshold"] = self.threshold
        if self.iterations:
            out.update(method="cg+bddc", cg_iterations=list(self.iterations), cg_rtol=self.rtol)
        else:
            out["method"] = f"direct ({self.inverse})"
        return out


class TangentSolve:
    """``out = K^-1 rhs`` by one factorization or by CG; CG's iterations go to the owner's record."""

    def __init__(self, owner: LinearSolver, inverse, counted: bool):
        self.owner, self.inverse, self.counted = owner, inverse, counted

    def apply(self, rhs, out) -> None:
        self.owner.solves += 1
        out.data = self.inverse * rhs
        if not self.counted:
            return
        its = int(self.inverse.iterations)
        self.owner.iterations.append(its)
        if its >= self.owner.max_iter:
            raise ConvergenceError(f"preconditioned CG did not reach rtol {self.owner.rtol:g} in "
                                   f"{self.owner.max_iter} iterations (solver.linear = 'iterative'); "
                                   "use solver.linear = 'direct'", {"cg_iterations": list(self.owner.iterations)})


def match_free_dofs(space, freedofs) -> None:
    """Make the space's own free dofs (what BDDC reads) equal ``freedofs``."""
    own = space.FreeDofs()
    for i in range(len(freedofs)):
        if own[i] != freedofs[i]:
            if freedofs[i]:
                own.Set(i)
            else:
                own.Clear(i)
