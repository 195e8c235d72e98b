"""The linear solve of a Newton step: sparse direct or preconditioned CG, by size.

Each Newton step of :func:`ngcontact.solvers.newton.minimize` solves

    K(u) du = r(u)

with the tangent ``K = Pi''(u)`` of the energy: the bodies' elasticity plus
the contact (and friction) terms on the interface, symmetric and positive
definite on the free dofs.  Two ways:

* ``"direct"``: a sparse Cholesky (or UMFPACK) factorization of ``K``.  Exact,
  but in 3D its fill-in makes the cost grow much faster than ``N``
  (docs/benchmarks.md, section scaling_3d).  The
  tangent of every step has the sparsity of the first (the form's matrix
  is assembled in place), so while the free dofs stay the same the
  factorization is only refreshed (``Update``: the fill-reducing ordering
  and symbolic analysis are kept), cheaper than a fresh one and with the
  same solution to round-off;
  where the matrix holds the very values it was factorized with, the
  factorization is kept as it is.  The augmented Lagrangian's tangent of exact
  contact (:mod:`ngcontact.cell.fe.contact_multiplier`) is the bodies'
  stiffness plus ``k n n^T`` at the points whose augmented pressure is
  positive: the same matrix, to the bit, for as long as that set and ``k``
  stay, which is most of Uzawa's passes and their Newton steps once the
  contact set has settled (on the 3D bisinusoid cell most refreshes of a
  level were of an unchanged matrix).
* ``"iterative"``: conjugate gradients preconditioned by NGSolve's BDDC
  (balancing domain decomposition by constraints, one subdomain per element)
  with a vertex-only wirebasket: the body spaces mark their edge dofs as
  interface dofs (:func:`ngcontact.fem.elasticity.vector_h1`, what
  ``wb_withedges=False`` does for ``H1``), so the coarse problem holds the
  vertex dofs and the far-face translations (``NumberSpace`` dofs).  A
  contact boundary element's own matrix is singular on its edge dofs, and
  BDDC eliminates each element's interface dofs with it: a split energy
  with a preconditioning form (a cell: the tangent plus the bubble term,
  :func:`ngcontact.fem.elasticity.bubble_term`) has BDDC built from that
  form; any other form puts the contact surface's dofs on the wirebasket
  (:func:`ngcontact.fem.elasticity.surface_wirebasket`: a larger coarse
  problem, so dearer CG iterations).  Its setup costs about one
  assembly, its iterations grow
  like ``log(p)^2`` and mildly with the mesh.  The
  preconditioner is registered with the energy form and built by its
  assembly; a split energy (:mod:`ngcontact.solvers.split_energy`: the bodies
  assembled once, the interface at each step) keeps it across Newton steps
  while CG's iterations per decade stay within ``REBUILD_GROWTH`` times
  their rate after its build (a rebuild costs an assembly; a kept BDDC
  costs CG iterations as the tangent drifts from its own).  A step whose
  contact set moved far can find the kept BDDC far off at once (on the 3D
  bisinusoid cell after a Uzawa update: 270 iterations for two decades where
  the build took 26), so a solve with a kept BDDC is capped at
  ``REBUILD_GROWTH`` times the iterations its decades took after the build
  (at least ``KEPT_MIN_ITERATIONS``); past the cap BDDC is rebuilt at the
  step's state and the step solved again, its iterations counted together.  CG stops at
  ``|r_k| <= eta |r_0|`` in the preconditioned norm: an inexact Newton
  step, ``eta`` from the Newton residual's decrease (:func:`forcing_term`,
  Eisenstat-Walker), never below ``rtol = 1e-10``; ``forcing = False``
  solves every step to ``rtol``.  The forcing saves many more CG
  iterations than the Newton step it may add costs, and leaves the
  contact fraction the same to round-off.  The linear solve of a
  quadratic energy stops instead on the Euclidean residual that Newton's
  test measures (:class:`~ngcontact.solvers.residual_cg.ResidualCG`,
  ``TangentSolve.apply(reach=...)``).
* ``"auto"``: in 3D iterative from ``threshold`` free dofs on (default
  ``AUTO_THRESHOLD``), direct below; in 2D direct.  The threshold lies
  where BDDC-CG overtakes the factorization on the 3D bisinusoid cell and
  on a 3D press fit of two tubes, its time growing nearly like ``N``
  against the factorization's much steeper growth; in 2D the
  factorization stays far ahead (measured with ``scripts/scaling_3d.py``:
  docs/benchmarks.md, section scaling_3d).

BDDC's coarse problem (the wirebasket) is factorized by a sparse Cholesky
(``BDDC_FLAGS``: further flags of NGSolve's BDDC, none).  Under MPI NGSolve
gathers it on rank 0 and factorizes it there, so rank 0 applies the coarse
solve of every CG iteration while the ranks holding the mesh wait; the
coarse solves NGSolve offers are compared in docs/benchmarks.md, section
macro_mpi_scaling.

BDDC reads the free dofs from the space; a solve whose free dofs differ
from the space's (prescribed far-face translations of a cell) sets the
space's free dofs to them first (:func:`match_free_dofs`).  The same free
dofs as a NumPy mask (:func:`fixed_mask`, :func:`mask_fixed`) restrict the
vectors of Newton's iterations and their step lengths to them without
NGSolve's ``BitArray`` per entry.

The solver keeps what it did for the report (:meth:`LinearSolver.summary`):
the method chosen, the number of solves and CG iterations per solve.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import ngsolve as ng
import numpy as np

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.roundoff import local_matrix

POLICIES = ("direct", "iterative", "auto")
#: LU solvers NGSolve offers for a non-symmetric tangent; any other ``inverse`` (Cholesky) gives way to UMFPACK
LU_INVERSES = ("umfpack", "pardiso", "mumps")
#: factorizations whose ``Update()`` refactorizes a changed matrix of the same sparsity (tested)
UPDATABLE = ("sparsecholesky", "umfpack")
#: free dofs from which "auto" solves 3D problems iteratively (BDDC-CG against sparse Cholesky, order 2)
AUTO_THRESHOLD = 20_000
#: a kept BDDC is rebuilt once CG needs this many times the iterations per decade it needed after its build
REBUILD_GROWTH = 2.0
#: a CG solve with a kept BDDC stops at ``REBUILD_GROWTH`` times the iterations its decades took after the
#: build, at least this many, and is solved again with BDDC rebuilt (module docstring)
KEPT_MIN_ITERATIONS = 20
#: flags of NGSolve's BDDC beyond the space's coupling types (its coarse solve: module docstring); none
BDDC_FLAGS: dict = {}


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
    forcing: bool = True
    iterations: list[int] = field(default_factory=list)
    tolerances: list[float] = field(default_factory=list)
    solves: int = 0
    methods: set = field(default_factory=set)
    _pre: dict = field(default_factory=dict, repr=False)
    _factors: dict = field(default_factory=dict, repr=False)
    _reuse: dict = field(default_factory=dict, repr=False)
    #: iterative solves with the BDDC of an earlier step, and rebuilds forced by CG's growth
    reuses: int = 0
    rebuilds: int = 0
    #: direct solves whose matrix held the values of its last factorization (kept, not refreshed)
    kept: int = 0

    def __post_init__(self):
        if self.policy not in POLICIES:
            raise ValueError(f"policy = {self.policy!r}: must be one of {POLICIES}")

    def method(self, freedofs, dim: int = 3) -> str:
        """``"direct"`` or ``"iterative"`` for a system with these free dofs on a mesh of dimension ``dim``."""
        if self.policy == "auto":
            return "iterative" if dim == 3 and freedofs.NumSet() >= self.threshold else "direct"
        return self.policy

    def register(self, form: ng.BilinearForm, freedofs) -> None:
        """Before assembling ``form`` for a solve on ``freedofs``: register BDDC with it when iterative.

        NGSolve builds a registered preconditioner at every assembly of the
        form (``AssembleLinearization`` included), on the space's free dofs,
        which are set to ``freedofs`` here.
        """
        if self.method(freedofs, form.space.mesh.dim) != "iterative":
            return
        match_free_dofs(form.space, freedofs)
        # a split energy: BDDC is built by its preconditioning form, or its whole form
        target = form.preconditioner_form() if hasattr(form, "preconditioner_form") else form
        if id(target) not in self._pre:
            self._pre[id(target)] = ng.Preconditioner(target, "bddc", **BDDC_FLAGS)

    def prepare(self, form: ng.BilinearForm, freedofs, *, symmetric: bool = True,
                forcing: float | None = None) -> "TangentSolve":
        """The solve with the current (assembled) ``form.mat`` on ``freedofs``: ``apply(rhs, out)``.

        A non-symmetric tangent (``symmetric=False``: Coulomb friction's
        coupled equations) is factorized by the policy's ``inverse`` when it
        is an LU (``LU_INVERSES``), else by UMFPACK, or solved by GMRES with
        the same BDDC preconditioner.  ``forcing``: the relative tolerance
        of an inexact Newton step (:func:`forcing_term`) for CG, used when the
        solver's ``forcing`` is on; never tighter than ``rtol``.
        """
        if self.method(freedofs, form.space.mesh.dim) == "direct":
            inverse = self.inverse if symmetric or self.inverse in LU_INVERSES else "umfpack"
            self.methods.add(f"direct ({inverse})")
            return TangentSolve(self, self._factorization(form, freedofs, inverse), counted=False)
        pre = self._pre.get(_key(form))
        if pre is None:
            raise RuntimeError("LinearSolver.register(form) must come before the form's first assembly")
        record = self._kept_preconditioner(form)
        from ngsolve.krylovspace import GMResSolver

        from ngcontact.solvers.residual_cg import ResidualCG
        krylov = ResidualCG if symmetric else GMResSolver
        self.methods.add("cg+bddc" if symmetric else "gmres+bddc")
        tol = self.rtol
        if symmetric and self.forcing and forcing is not None:
            tol = max(self.rtol, forcing)
        extra = {"fixed": fixed_mask(freedofs)} if symmetric else {}
        retry = None
        if symmetric and record is not None and record[0] is not None and not form.assembled_whole:
            def retry() -> "TangentSolve":          # the kept BDDC's CG ran past its cap: rebuilt, solved again
                form.rebuild()
                self.rebuilds += 1
                return self.prepare(form, freedofs, symmetric=symmetric, forcing=forcing)
        return TangentSolve(self, krylov(form.mat, pre.mat, tol=tol, maxiter=self.max_iter, printrates=False,
                                         **extra), counted=True, record=record, tol=tol, retry=retry)

    def preconditioned(self, form: ng.BilinearForm) -> bool:
        """Whether a preconditioner is registered with ``form`` (rebuilt at each of its assemblies)."""
        return _key(form) in self._pre

    def exact_inverse(self, form: ng.BilinearForm, freedofs, rtol: float | None = None):
        """``K^-1`` on ``freedofs`` to ``rtol`` (default ``MEASURE_RTOL``), for measurements after a solve (a
        Schur complement).

        ``form`` has just been assembled with the space's free dofs equal to
        ``freedofs`` (:meth:`register` before the assembly).  Direct: a fresh
        factorization by the policy's ``inverse``; iterative: CG with the
        BDDC built by that assembly, so that a large 3D cell needs no
        factorization of its whole matrix (for a large 3D cell the factorization
        of the effective stiffness would cost as much time as the cell's whole
        Newton solve, and far more memory).
        """
        if self.method(freedofs, form.space.mesh.dim) == "direct":
            return form.mat.Inverse(freedofs, inverse=self.inverse)
        from ngsolve.krylovspace import CGSolver
        pre = self._pre[_key(form)]
        return CGSolver(form.mat, pre.mat, tol=MEASURE_RTOL if rtol is None else rtol, maxiter=self.max_iter,
                        printrates=False)

    def _kept_preconditioner(self, form) -> list | None:
        """A split energy (:class:`~ngcontact.solvers.split_energy.SplitEnergy`) keeps its BDDC across
        Newton steps while CG's iterations per decade of residual reduction stay below
        ``REBUILD_GROWTH`` times their rate right after the last build (per decade: an inexact Newton
        step asks fewer decades of CG far from the solution than near it); past that, the whole form
        is assembled again at this step's state, which rebuilds BDDC.  Returns the record ``[rate after
        the build, last rate]`` that the solve updates (``None`` for a whole form: BDDC rebuilt at
        every assembly)."""
        if not hasattr(form, "rebuild"):
            return None
        record = self._reuse.setdefault(id(form), [None, None])
        if not form.assembled_whole and record[0] is not None and record[1] > REBUILD_GROWTH * record[0]:
            form.rebuild()
            self.rebuilds += 1
        if form.assembled_whole:
            record[0] = None
        else:
            self.reuses += 1
        return record

    def _factorization(self, form: ng.BilinearForm, freedofs, inverse: str):
        """The factorization of ``form.mat`` on ``freedofs``: kept as it is when the same matrix holds the
        same values on the same free dofs as at its factorization (module docstring), refreshed in place
        (``Update``) when only its values changed, else a fresh one."""
        mat, free = form.mat, freedofs.__getstate__()
        key = (id(form), inverse)
        held = self._factors.get(key)
        values = local_matrix(mat).AsVector().FV().NumPy()
        if held is not None and held[0] is mat and held[1] == free and inverse in UPDATABLE:
            if np.array_equal(held[3], values):
                self.kept += 1
            else:
                held[2].Update()
                held[3][:] = values
            return held[2]
        inv = mat.Inverse(freedofs, inverse=inverse)
        self._factors[key] = (mat, free, inv, values.copy())
        return inv

    def summary(self) -> dict:
        """What was done, JSON-ready."""
        out: dict = {"policy": self.policy, "solves": self.solves}
        if self.policy == "auto":
            out["threshold"] = self.threshold
        out["method"] = ", ".join(sorted(self.methods)) or f"direct ({self.inverse})"
        if self.kept:
            out["factorizations_kept"] = self.kept
        if self.iterations:
            out.update(cg_iterations=list(self.iterations), cg_rtol=self.rtol,
                       krylov_tolerances=list(self.tolerances), inexact_newton=self.forcing,
                       bddc_kept=self.reuses, bddc_rebuilt_for_growth=self.rebuilds)
        return out


#: relative tolerance of the CG solves of :meth:`LinearSolver.exact_inverse` (measurements, not Newton steps)
MEASURE_RTOL = 1e-12

#: Eisenstat-Walker (choice 2) constants of :func:`forcing_term`: ``eta = GAMMA (|r_k| / |r_k-1|)^2``,
#: at most ``ETA_MAX``, at least ``ETA_MIN``
EW_GAMMA, ETA_MAX, ETA_MIN = 0.9, 1e-2, 1e-3


def forcing_term(rnorm: float, previous: float | None, eta_previous: float | None, target: float) -> float:
    """Relative tolerance of the Krylov solve of an inexact Newton step (Eisenstat and Walker, choice 2).

    A Newton step needs its linear system solved only as far as the
    nonlinear residual will fall: with ``|r_k|`` now and ``|r_k-1|`` before,

        eta_k = GAMMA (|r_k| / |r_k-1|)^2,

    kept above ``GAMMA eta_k-1^2`` when that is above 0.1 (no sudden
    tightening), at most ``ETA_MAX`` (the first step and slow phases: two
    digits), at least ``ETA_MIN`` and at least ``target / (2 |r_k|)``,
    since the Newton loop stops at ``|r| <= target`` (no over-solving of
    the last step).  ``ETA_MIN``: after the first step of a contact
    problem the residual has fallen by 1e-3 to 1e-4 (the bodies' linear
    part is solved), and the formula then asks the next step for 7 digits,
    while the step's own decrease is bounded by the moving contact set
    (the residual can rise after it).  On the 3D bisinusoid cell the floor
    saves CG iterations at every size with the same Newton steps and
    contact fraction.  Far
    from the solution most CG iterations of a fixed ``rtol = 1e-10`` buy
    digits the next Newton step discards; near it each step still gains at
    least three digits (``ETA_MIN``), and the last one stops at the target.
    """
    if previous is None or eta_previous is None or not previous > 0:
        eta = ETA_MAX
    else:
        eta = EW_GAMMA * (rnorm / previous) ** 2
        safeguard = EW_GAMMA * eta_previous ** 2
        if safeguard > 0.1:
            eta = max(eta, safeguard)
    eta = max(min(eta, ETA_MAX), ETA_MIN)
    return max(eta, 0.5 * target / rnorm) if rnorm > 0 else eta


class TangentSolve:
    """``out = K^-1 rhs`` by one factorization or by CG to the relative tolerance ``tol``; CG's iterations
    and tolerance go to the owner's record, one entry per solve (and to ``record``, the preconditioner's:
    ``[iterations per decade after its build, last ones]``)."""

    def __init__(self, owner: LinearSolver, inverse, counted: bool, record: list | None = None,
                 tol: float = 0.1, retry=None):
        self.owner, self.inverse, self.counted, self.record, self.tol = owner, inverse, counted, record, tol
        #: ``() -> TangentSolve`` with BDDC rebuilt, where this one keeps an earlier BDDC (its CG then capped)
        self.retry = retry

    def apply(self, rhs, out, reach: float | None = None) -> None:
        """``out = K^-1 rhs``; with ``reach``, CG stops once the Euclidean norm of ``rhs - K out`` is at most
        ``reach`` (:class:`~ngcontact.solvers.residual_cg.ResidualCG`: a linear solve of Newton's iteration,
        judged by that norm); a factorization ignores it."""
        self.owner.solves += 1
        tol = self.tol
        if self.counted and reach is not None and hasattr(self.inverse, "reach"):
            self.inverse.reach = reach
            size = rhs.Norm()
            tol = reach / size if size > 0 else 1.0
        if self.retry is not None:
            assert self.record is not None and self.record[0] is not None
            cap = math.ceil(REBUILD_GROWTH * self.record[0] * max(-math.log10(tol), 1.0))
            self.inverse.maxiter = min(self.owner.max_iter, max(cap, KEPT_MIN_ITERATIONS))
        out.data = self.inverse * rhs
        if not self.counted:
            return
        its = int(self.inverse.iterations)
        if self.retry is not None and its >= self.inverse.maxiter:
            # the kept BDDC no longer fits the tangent: the iterations spent stay counted in the fresh solve's
            self.owner.solves -= 1
            fresh = self.retry()
            fresh.apply(rhs, out, reach)
            self.owner.iterations[-1] += its
            return
        self.owner.iterations.append(its)
        self.owner.tolerances.append(tol)
        if self.record is not None:
            rate = max(its, 1) / max(-math.log10(tol), 1.0)
            if self.record[0] is None:
                self.record[0] = rate
            self.record[1] = rate
        if its >= self.owner.max_iter:
            raise ConvergenceError(f"preconditioned CG did not reach its relative tolerance {tol:g} in "
                                   f"{self.owner.max_iter} iterations (solver.linear = 'iterative'); "
                                   "use solver.linear = 'direct'", {"cg_iterations": list(self.owner.iterations)})


def _key(form) -> int:
    """Which registered preconditioner serves ``form``: that of its preconditioning form, of its whole form (a
    split energy), or of the form itself."""
    pre = getattr(form, "preconditioning", None)
    return id(pre.form if pre is not None else getattr(form, "whole", form))


def match_free_dofs(space, freedofs) -> None:
    """Make the space's own free dofs (what BDDC reads) equal ``freedofs``."""
    own = space.FreeDofs()
    for i in range(len(freedofs)):
        if own[i] != freedofs[i]:
            if freedofs[i]:
                own.Set(i)
            else:
                own.Clear(i)


def fixed_mask(freedofs):
    """Boolean NumPy array, True where a dof is not free."""
    return ~np.array([freedofs[i] for i in range(len(freedofs))], dtype=bool)


def mask_fixed(vec, fixed) -> None:
    """Zero the entries of ``vec`` that are not free."""
    vec.FV().NumPy()[fixed] = 0.0
