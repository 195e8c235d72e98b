"""The pointwise contact and friction terms of the spectral cell's traction problem, for a given threshold rule.

The frictional cell (:mod:`ngcontact.cell.spectral.frictional_contact`) is
``min 1/2 <t, K t> + <t, b> + sum_i h_i(t_i)`` under prescribed means, ``t = (q, p)``;
``h_i`` is ``p >= 0`` (plus ``p^2 / (2 k_n)`` with the penalty) and ``|q| <= G_i``
(plus ``w |q|^2 / (2 G_i)`` with the Huber width).  This object holds what is
local to a grid point: the proximal map of ``h`` in the step ``1/L``, the
projection onto the constraints, and the linearization used by
:mod:`ngcontact.solvers.active_set_newton`.  The threshold rule ``G(p)`` is
the law's own (Coulomb: ``mu p`` of the same proximal step) or a frozen
field (the Tresca problems of a Coulomb fixed point).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ngcontact.solvers.active_set_newton import traction_projector
from ngcontact.solvers.free_directions import FreeDirections
from ngcontact.solvers.projected_gradient import prox_friction, prox_pressure


@dataclass
class TractionConstraints:
    """The terms ``h_i`` of one load (module docstring).

    ``threshold``: ``p -> G`` (an array of the grid's shape); ``w`` and
    ``k_n``: ``None`` for exact laws; ``mean_p``, ``mean_q``: the prescribed
    means (``None`` where free); ``L``: the step's inverse.
    """

    shape: tuple[int, ...]
    threshold: Callable[[np.ndarray], np.ndarray]
    L: float
    w: float | None
    k_n: float | None
    mean_p: float | None
    mean_q: np.ndarray | None
    #: ``dG/dp`` of the threshold rule (Coulomb: ``mu``; 0 for a frozen or constant threshold)
    slope: float = 0.0

    @property
    def d(self) -> int:
        return len(self.shape) + 1

    def frozen(self, G: np.ndarray) -> TractionConstraints:
        """The same terms with the threshold field ``G`` held fixed (a Tresca problem)."""
        return TractionConstraints(self.shape, lambda p: G, self.L, self.w, self.k_n, self.mean_p, self.mean_q)

    def _G(self, p: np.ndarray) -> np.ndarray:
        return np.asarray(self.threshold(p) * np.ones(self.shape), float)

    def prox(self, v: np.ndarray, shifts: tuple) -> tuple[np.ndarray, tuple]:
        """The proximal map of ``h / L`` at ``v`` (warm-started shifts of the means in, the new ones out)."""
        d = self.d
        sp, sq = shifts if shifts else (0.0, None)
        damp_p = 1.0 if self.k_n is None else 1.0 + 1.0 / (self.L * self.k_n)
        p, sp = prox_pressure(v[d - 1], damp_p, self.mean_p, sp)
        G = self._G(p)          # Coulomb: mu times the pressure of this very step
        damp_q = 1.0 if self.w is None else 1.0 + self.w / (self.L * np.maximum(G, 1e-300))
        q, sq = prox_friction(v[:d - 1], G, damp_q, self.mean_q, sq)
        return np.concatenate([q, p[None]]), (sp, sq)

    def project(self, v: np.ndarray, shifts: tuple) -> np.ndarray:
        """The projection onto ``p >= 0``, ``|q| <= G(p)`` and the means."""
        d = self.d
        sp, sq = shifts if shifts else (0.0, None)
        p, _ = prox_pressure(v[d - 1], 1.0, self.mean_p, sp)
        q, _ = prox_friction(v[:d - 1], self._G(p), 1.0, self.mean_q, sq)
        return np.concatenate([q, p[None]])

    def linearize(self, t_hat: np.ndarray, v: np.ndarray, shifts: tuple):
        """``(projector, D, lift)`` at a proximal point ``t_hat = prox(v)``: the free directions, the curvature
        of ``h`` along them and, for a threshold of slope ``dG/dp > 0`` (Coulomb), the map from free directions
        to tractions (``None`` otherwise).

        ``D``: the penalty's ``1 / k_n`` on the pressure, the Huber term's ``w / G`` on a sticking shear, and on
        a slipping shear of a 3D cell the curvature of the friction disc's rim in the step ``1/L``,
        ``L (|v_q - s| / G - 1)`` (the derivative of ``q = G z / |z|`` across ``z``).
        """
        d = self.d
        G = self._G(t_hat[d - 1])
        stick = (np.sum(t_hat[:d - 1] ** 2, axis=0) < (G * (1 - 1e-12)) ** 2) & (G > 0)
        rim = ~stick & (G > 0)
        D = np.zeros((d,) + self.shape)
        safe = np.where(G > 0, G, 1.0)
        if self.w is not None:
            D[:d - 1] = np.where(stick, self.w / safe, 0.0)
        if self.k_n is not None:
            D[d - 1] = 1.0 / self.k_n
        if d == 3:
            sq = shifts[1]
            z = v[:2] - (0.0 if sq is None else np.asarray(sq).reshape(2, 1, 1))
            # every rim point turns: a large curvature (a point far outside the disc) is the split
            # preconditioner's diagonal block (:meth:`~.frictional_contact.TractionPreconditioner.for_curvature`)
            D[:2] += np.where(rim, self.L * np.maximum(np.sqrt(z[0] * z[0] + z[1] * z[1]) / safe - 1.0, 0.0), 0.0)
        constrained = (self.mean_q is not None,) * (d - 1) + (self.mean_p is not None,)
        free = traction_projector(t_hat[d - 1] > 0, stick, rim, t_hat, constrained)    # a 2D rim is held
        return free, D, (self._lift(t_hat, rim, free) if self.slope > 0 else None)

    def _lift(self, t_hat: np.ndarray, rim: np.ndarray, free: FreeDirections) -> ShearFollowsPressure:
        """The shear that follows the threshold ``G(p)`` at the slipping points (:class:`ShearFollowsPressure`)."""
        slipping = rim & (t_hat[self.d - 1] > 0)
        q = t_hat[:self.d - 1][:, slipping]
        return ShearFollowsPressure(free, slipping, q / np.sqrt(np.sum(q * q, axis=0)), self.slope,
                                    self.mean_q is not None)


class ShearFollowsPressure:
    """``u -> u + (dG/dp) u_p n`` at the slipping points (``n = q / |q|``, the shear on the rim follows the
    threshold ``G(p)``), the mean shear restored over the free shear (``free.mean_free``) where it is prescribed:
    on grid fields (call) and in the coordinates of the free directions' support (:meth:`reduced`), on which
    it stays (a slipping point is pressed and turns).
    """

    def __init__(self, free: FreeDirections, slipping: np.ndarray, n: np.ndarray, slope: float, constrained: bool):
        self.free, self.slipping, self.n, self.slope, self.constrained = free, slipping, n, slope, constrained
        self.at_q, self.at_p = free.at_shear(slipping), free.at_pressure(slipping)

    def __call__(self, u: np.ndarray) -> np.ndarray:
        d = self.free.d
        y = u.copy()
        added = self.slope * u[d - 1][self.slipping] * self.n
        y[:d - 1, self.slipping] += added
        if self.constrained:
            y[:d - 1] -= self.free.mean_free(added.sum(axis=1))
        return y

    def reduced(self, c: np.ndarray) -> np.ndarray:
        y = c.copy()
        qs, p = self.free.split(y)
        added = self.slope * p[self.at_p] * self.n
        qs[:, self.at_q] += added
        if self.constrained:
            qs -= self.free.mean_free_reduced(added.sum(axis=1))
        return y
