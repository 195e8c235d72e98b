"""The free directions of an active-set step in tractions, on the grid and in their own coordinates.

An active-set step of :mod:`ngcontact.solvers.active_set_newton` minimizes over the *free* unknowns of a
proximal point ``t_hat = (q, p)``: the pressure where it is positive, the whole shear at a sticking point, the
tangent ``n_perp`` of the friction disc at a slipping point of a 3D cell, and on each component group of
prescribed mean the sum zero.  :class:`FreeDirections` is the orthogonal projector onto them.

Every free direction lives on the *support* ``S``: the pressure at the pressed points and the shear at the
sticking and slipping points (a slipping point's shear turns in 3D and is held in 2D, where the Coulomb step's
lift still moves it), a few percent of the grid where the contact is sparse.  The Krylov vectors of a
step lie in the projector's range, so they are held in the coordinates of ``S`` alone (:meth:`gather`,
:meth:`scatter`; the order: the shear components at the points of the shear set, then the pressure at the
pressed points, each in the grid's order), and the projector acts there as :meth:`reduced`: the grid enters
only where the compliance is applied by FFTs.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np


class FreeDirections:
    """The orthogonal projector onto the free directions of a proximal point ``t_hat = (q, p)``.

    Free: the pressure where ``pressed``; the whole shear where ``stick``; at
    a slipping point (``rim``; held in 2D) of a 3D cell the shear along the tangent of
    the friction disc, ``n_perp`` (the slip direction's own update, the
    semismooth Newton step of ``q = G z / |z|`` without its curvature term);
    on each component group of prescribed mean, in addition, the sum zero
    (the projection ``y - Pi lambda`` with ``(sum_i Pi_i) lambda = sum_i y_i``).
    """

    def __init__(self, pressed: np.ndarray, stick: np.ndarray, rim: np.ndarray, t_hat: np.ndarray,
                 constrained: tuple[bool, ...]):
        d = self.d = t_hat.shape[0]
        self.grid_shape = stick.shape
        on = np.zeros(stick.shape, bool)
        self.turn = np.zeros((d - 1, 0))
        if d == 3:
            q = t_hat[:2]
            norm = np.sqrt(q[0] * q[0] + q[1] * q[1])
            on = rim & (norm > 0)
            self.turn = np.stack([-q[1][on], q[0][on]]) / norm[on]    # n_perp where turning (few)
        self.pressed = np.asarray(pressed, bool)
        # the points of the shear set: the free shear, and the rim's held shear, which a lift may move
        # (stick and rim disjoint)
        self.sheared = stick | rim
        self.on = np.flatnonzero(on[self.sheared])           # turning, among the points of the shear set
        self.held = np.flatnonzero((rim & ~on)[self.sheared])
        self.n_p = int(np.count_nonzero(pressed))
        self.n_q = int(np.count_nonzero(self.sheared))
        self.constrained = constrained
        self.M_inv = np.linalg.pinv(np.eye(d - 1) * float(max(np.count_nonzero(stick), d == 2))
                                    + self.turn @ self.turn.T) if constrained[0] else None
        points = int(np.prod(stick.shape))
        shear_at = np.flatnonzero(self.sheared)
        self.index = np.concatenate([shear_at + a * points for a in range(d - 1)]
                                    + [np.flatnonzero(self.pressed) + (d - 1) * points])

    @property
    def size(self) -> int:
        """The length of a vector in the coordinates of the support."""
        return self.index.size

    def gather(self, x: np.ndarray) -> np.ndarray:
        """The entries of a grid field ``x`` (shape ``(d, *grid)``) on the support (a new vector)."""
        return np.take(x.reshape(-1), self.index)

    def scatter(self, c: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """The grid field with the entries ``c`` on the support; ``out``: a field zero off the support (kept)."""
        if out is None:
            out = np.zeros((self.d,) + self.grid_shape)
        np.put(out.reshape(-1), self.index, c)
        return out

    def split(self, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Views of a support vector: its shear ``(d - 1, n_q)`` and its pressure ``(n_p,)``."""
        cut = (self.d - 1) * self.n_q
        return c[:cut].reshape(self.d - 1, self.n_q), c[cut:]

    def at_shear(self, mask: np.ndarray) -> np.ndarray:
        """A grid mask among the points of the shear set."""
        return mask[self.sheared]

    def at_pressure(self, mask: np.ndarray) -> np.ndarray:
        """A grid mask among the pressed points."""
        return mask[self.pressed]

    def _shear(self, qs: np.ndarray) -> None:
        """The shear's projection, in place: the tangent where turning, none where held."""
        if self.on.size:
            qs[:, self.on] = np.sum(qs[:, self.on] * self.turn, axis=0) * self.turn
        if self.held.size:
            qs[:, self.held] = 0.0

    def mean_free_reduced(self, total: np.ndarray) -> np.ndarray:
        """The free shear ``Pi lambda`` whose sum over the grid is ``total``, on the shear set."""
        assert self.M_inv is not None
        lam = self.M_inv @ total
        qs = np.repeat(lam.reshape(-1, 1), self.n_q, axis=1)
        self._shear(qs)
        return qs

    def mean_free(self, total: np.ndarray) -> np.ndarray:
        """The free shear ``Pi lambda`` whose sum over the grid is ``total`` (prescribed mean shear only)."""
        out = np.zeros((self.d - 1,) + self.grid_shape)
        out.reshape(self.d - 1, -1)[:, np.flatnonzero(self.sheared)] = self.mean_free_reduced(total)
        return out

    def reduced(self, c: np.ndarray) -> np.ndarray:
        """The projector in the coordinates of the support (a new vector)."""
        y = c.copy()
        qs, p = self.split(y)
        if self.constrained[self.d - 1] and self.n_p:
            p -= float(p.sum()) / self.n_p
        self._shear(qs)
        if self.constrained[0]:
            qs -= self.mean_free_reduced(qs.sum(axis=1))
        return y

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return self.scatter(self.reduced(self.gather(x)))


@dataclass
class SplitPreconditioner:
    """A preconditioner split for a pointwise curvature ``D``: ``base`` (``r -> M r`` on grid fields) on the
    entries off ``heavy``, the pointwise ``r * pointwise`` on those in it (``heavy`` ``None``: none), a
    block-Jacobi preconditioner
    (:meth:`~ngcontact.cell.spectral.frictional_contact.TractionPreconditioner.for_curvature`)."""

    base: Callable[[np.ndarray], np.ndarray]
    heavy: np.ndarray | None = None
    pointwise: np.ndarray | None = None

    def __call__(self, r: np.ndarray) -> np.ndarray:
        if self.heavy is None:
            return self.base(r)
        return np.where(self.heavy, r * self.pointwise, self.base(np.where(self.heavy, 0.0, r)))


class Lift(Protocol):
    """A linear map of free directions to tractions that stays on the support (e.g. the shear that follows the
    pressure at a slipping point, :mod:`ngcontact.cell.spectral.traction_constraints`)."""

    def __call__(self, u: np.ndarray) -> np.ndarray: ...

    def reduced(self, c: np.ndarray) -> np.ndarray: ...


class FreeOperator:
    """One active-set step's linear problem in the coordinates of the support of ``free``.

    ``operator(c) = P (A + D) c`` and ``precondition(c) = P M c`` (``P`` the projector, ``A`` applied by
    ``apply`` to grid fields, ``D`` a pointwise curvature, ``M`` the split preconditioner), ``residual(t)`` the
    projected gradient ``P ((A + D) t + b)`` of a grid field ``t``.  Each costs one application of ``A`` or
    ``M`` to a grid field that is zero off the support; the rest is on the support alone.
    """

    def __init__(self, apply: Callable[[np.ndarray], np.ndarray], D: np.ndarray, free: FreeDirections,
                 precondition: SplitPreconditioner):
        self.apply, self.free, self.M = apply, free, precondition.base
        self.D = free.gather(D)
        self.heavy = None if precondition.heavy is None else free.gather(precondition.heavy)
        self.pointwise = None if precondition.pointwise is None else free.gather(precondition.pointwise)
        self._field = np.zeros((free.d,) + free.grid_shape)       # zero off the support, always

    def operator(self, c: np.ndarray) -> np.ndarray:
        free = self.free
        return free.reduced(free.gather(self.apply(free.scatter(c, self._field))) + self.D * c)

    def residual(self, t: np.ndarray, b: np.ndarray) -> np.ndarray:
        free = self.free
        return free.reduced(free.gather(self.apply(t)) + free.gather(b) + self.D * free.gather(t))

    def precondition(self, c: np.ndarray) -> np.ndarray:
        free = self.free
        heavy, pointwise = self.heavy, self.pointwise
        if heavy is None or pointwise is None:
            return free.reduced(free.gather(self.M(free.scatter(c, self._field))))
        z = free.gather(self.M(free.scatter(np.where(heavy, 0.0, c), self._field)))
        z[heavy] = c[heavy] * pointwise[heavy]
        return free.reduced(z)

    def add(self, t: np.ndarray, c: np.ndarray) -> np.ndarray:
        """The grid field ``t`` plus the support vector ``c`` (a new field)."""
        out = t.copy()
        flat = out.reshape(-1)
        flat[self.free.index] += c
        return out
