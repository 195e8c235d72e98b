"""Round-off levels of a Newton iteration: where the residual and the energy can no longer be evaluated.

A Newton iteration (:mod:`ngcontact.solvers.newton`) stops when its residual
(free dofs) has fallen below its round-off floor
``ROUNDOFF eps || |K| |u| ||``: the size at which the residual, a sum of terms
as large as ``|K_ij| |u_j|``, can no longer be evaluated. Stiff terms (a Huber
width of 1e-12, a penalty touching with zero force) put that floor above
``rtol`` times the first residual; without it Newton would wander in the
round-off until ``max_iter``. The floor grows with ``|u|``: a runaway iterate
(a body that floats off under an unbalanced load, a singular system) drags it
up to its own, unchanged residual. So the floor counts only after real
progress: the residual has fallen below ``FLOOR_PROGRESS`` times the first
one, or the first one was itself at the round-off of the start value (within
``FLOOR_GROWTH`` times its floor: a start that already was the solution).
(Equilibrium checks of the results catch what a residual at its floor cannot
show, e.g. :func:`ngcontact.cell.fe.measures.equilibrium_error`.)

The energy itself is known only to its round-off, ``ROUNDOFF eps (|Pi| + |u| |K| |u| / 2)`` (its stiff terms
cancel: on the femur scene ``|Pi|`` is 4e-3 and ``|u| |K| |u| / 2`` 2.6e3).
Near the solution a Newton step lowers the energy by about ``r . du / 2``,
which falls below that round-off long before the residual reaches its own
floor: the energy then cannot tell the step from no step, and Armijo's test
rejects it at random.  A step whose energy is within the energy's round-off
of the current one is therefore judged by the residual instead, and accepted
when ``|r(u - alpha du)| <= (1 - c alpha) |r(u)|``.  When no step length
lowers either, the step's whole predicted decrease ``du . r`` is below the
energy's round-off and the residual is within ``STAGNATION`` times its floor,
the iterate is at round-off: converged (:func:`at_roundoff`).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

ROUNDOFF = 10.0
FLOOR_PROGRESS = 1e-3
FLOOR_GROWTH = 1e3
#: a residual within this factor of its round-off floor estimate, with no decrease measurable along the Newton step,
#: is at round-off (module docstring; the estimate can be a few times low, e.g. on a smooth field with a large offset)
STAGNATION = 100.0


def roundoff_floors(mat, vec, fixed, energy: float = 0.0) -> tuple[float, float]:
    """The round-off levels of the residual and of the energy at ``u = vec``.

    Residual: ``ROUNDOFF eps || |K| |u| ||`` over the free dofs.  Energy:
    ``ROUNDOFF eps (|energy| + |u| . |K| |u| / 2)``, the size of the terms
    whose sum it is.  ``K`` may be stored as its lower triangle (symmetric
    storage).  A matrix and vector distributed over MPI ranks (NGSolve's
    ``ParallelMatrix``) give each rank's local part ``K_r``: ``|K_r| |u|``
    summed over the ranks is the product with ``sum_r |K_r|`` (``|K|`` where
    no two ranks' elements add to one entry, as on 2 ranks: one part), its
    norm taken with each dof once (:func:`summed_norm`), so that every rank
    stops where the others do, and where one process does.
    """
    u = np.abs(vec.FV().NumPy())
    m = abs_product(local_matrix(mat), u)
    eps = ROUNDOFF * np.finfo(float).eps
    um = ranks_sum(vec, float(np.dot(u, m)))
    energy_floor = eps * (abs(energy) + 0.5 * um)
    m[fixed] = 0.0
    return eps * summed_norm(vec, m), energy_floor


def free_norm(vec, fixed) -> float:
    """``|vec|`` on the free dofs, with the entries that are not free zeroed in ``vec``.

    ``Norm()``, not ``sqrt(InnerProduct(vec, vec))``: on MPI ranks a residual is distributed (each rank holds
    its elements' part of a shared dof's entry), and NGSolve's inner product of a distributed vector with
    itself cumulates it in place first, so that it multiplies the cumulated vector by itself and counts
    every dof shared by k ranks k times; the norm counts each once."""
    vec.FV().NumPy()[fixed] = 0.0
    return float(vec.Norm())


def summed_norm(vec, local: np.ndarray) -> float:
    """``|sum_r local_r|``: the norm of the vector whose entries are ``local`` summed over the MPI ranks
    ``vec`` is distributed on, each dof counted once (``|local|`` in one process)."""
    comm = getattr(vec, "comm", None)
    if comm is None or comm.size == 1:
        return float(np.linalg.norm(local))
    import ngsolve as ng
    parts = vec.CreateVector()
    parts.FV().NumPy()[:] = local
    parts.SetParallelStatus(ng.la.PARALLEL_STATUS.DISTRIBUTED)
    return float(parts.Norm())


#: stored entries of a matrix taken at a time by :func:`abs_product`
CHUNK = 1 << 19


def abs_product(mat, u: np.ndarray) -> np.ndarray:
    """``|K| u`` for NGSolve's sparse ``mat`` (full or its lower triangle), taken ``CHUNK`` stored entries
    at a time, so that the absolute values never need a copy of the whole matrix."""
    vals, cols, ptr = (np.asarray(a) for a in mat.CSR())
    n = len(u)
    lower = type(mat).__name__.startswith("SparseMatrixSymmetric")   # the upper triangle is the lower's transpose
    m = np.zeros(n)
    r0 = 0
    while r0 < n:
        r1 = max(int(np.searchsorted(ptr, ptr[r0] + CHUNK, side="right")) - 1, r0 + 1)
        s0, s1 = int(ptr[r0]), int(ptr[r1])
        block = sp.csr_matrix((np.abs(vals[s0:s1]), cols[s0:s1], ptr[r0:r1 + 1] - s0), shape=(r1 - r0, n))
        m[r0:r1] += block @ u
        if lower:
            m += block.T @ u[r0:r1]
            m[r0:r1] -= block.diagonal(r0) * u[r0:r1]
        r0 = r1
    return m


def local_matrix(mat):
    """A rank's own sparse matrix of a matrix distributed over MPI ranks; ``mat`` itself in one process."""
    return getattr(mat, "local_mat", mat)


def ranks_sum(vec, value: float) -> float:
    """``value`` summed over the MPI ranks ``vec`` is distributed on (``value`` in one process)."""
    comm = getattr(vec, "comm", None)
    return float(comm.Sum(value)) if comm is not None and comm.size > 1 else value


def at_floor(rnorm: float, floor: float, r0: float, floor0: float) -> bool:
    """The residual is at its round-off ``floor`` after real progress, or the start was (module docstring)."""
    return rnorm <= floor and (rnorm <= FLOOR_PROGRESS * r0 or r0 <= FLOOR_GROWTH * floor0)


def within_roundoff(energy: float, e_new: float, efloor: float) -> bool:
    """``Pi_new`` finite and within the energy's round-off ``efloor`` above ``Pi``: the energy cannot tell the
    step from no step, and the residual decides (module docstring)."""
    return math.isfinite(e_new) and e_new <= energy + efloor


def at_roundoff(slope: float, efloor: float, rnorm: float, floor: float, r0: float) -> bool:
    """No step length lowered the energy or the residual, the step's predicted decrease ``slope`` is below the
    energy's round-off, and the residual is within ``STAGNATION`` times its floor after real progress."""
    return slope <= efloor and rnorm <= STAGNATION * floor and rnorm <= FLOOR_PROGRESS * r0
