"""The linear homogenized law: the anisotropic Winkler law of paper eqs. 34 and 69-71.

``W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a`` with ``K0`` in the local frame ``(n0, t0)``
(3D ``(n0, t1, t2)``) and the gap terms of eq. 34; quadratic and bilateral (the overview of the laws and
their conventions: :mod:`ngcontact.laws.homogenized`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.laws.law_protocol import ExportRows, NormalLaw


@dataclass(frozen=True, kw_only=True)
class LinearLaw(NormalLaw):
    """Linear anisotropic Winkler law (paper eqs. 34, 69-71)::

        W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a
        tau  = K0 (a - g0 e_n) - g0_vec

    Attributes
    ----------
    kn, kt, knt
        ``k_n0``, ``k_t0``, ``k_nt0`` [stress / length].
    gap_force
        ``(g_n0, g_t0)`` of eq. 34 [stress]: traction offset of the micro gaps.
    """

    kn: float
    kt: float = 0.0
    knt: float = 0.0
    gap_force: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self):
        if not self.kn > 0 or self.kt < 0 or self.kn * self.kt < self.knt ** 2:
            raise ModelError(f"K0 = [[{self.kn}, {self.knt}], [{self.knt}, {self.kt}]]: "
                             "must be positive semidefinite with k_n0 > 0")

    def matrix(self, dim: int) -> np.ndarray:
        """``K0`` in the local frame (``dim`` = 2 or 3)."""
        K = np.diag([self.kn] + [self.kt] * (dim - 1))
        K[0, 1] = K[1, 0] = self.knt
        return K

    @property
    def stiffness(self) -> float:
        return self.kn

    def energy(self, a, g0=0.0, closed: bool = False):
        """``W(a) = 1/2 (a - g0 e_n) . K0 (a - g0 e_n) - g0_vec . a`` (eq. 34); quadratic, so ``closed`` is ``W``."""
        dim = len(a)
        K = self.matrix(dim)
        e = [a[0] - g0] + list(a[1:])
        W = 0.5 * sum(K[i, j] * e[i] * e[j] for i in range(dim) for j in range(dim) if K[i, j] != 0)
        return W - self.gap_force[0] * a[0] - self.gap_force[1] * a[1]

    def traction(self, a, g0=0.0) -> list:
        """``tau = K0 (a - g0 e_n) - g0_vec``."""
        dim = len(a)
        K = self.matrix(dim)
        e = [a[0] - g0] + list(a[1:])
        tau = [sum(K[i, j] * e[j] for j in range(dim) if K[i, j] != 0) for i in range(dim)]
        tau[0] = tau[0] - self.gap_force[0]
        tau[1] = tau[1] - self.gap_force[1]
        return tau

    def full_contact_K0(self, dim: int) -> np.ndarray:
        return self.matrix(dim)

    @property
    def quadratic(self) -> bool:
        return True

    def export_rows(self) -> ExportRows:
        """The line ``p(c) = k_n0 c - g_n0 = k_n0 [c - g_n0 / k_n0]_+`` (bilateral: it goes on below its kink,
        which a table does not carry), ``K0`` in 2D, stick slope ``k_t0``."""
        K0 = self.matrix(2)
        return ExportRows(kinks=np.array([self.gap_force[0] / self.kn]), slopes=np.array([self.kn]),
                          stick_slope=float(np.mean(np.diag(K0)[1:])), K0=K0,
                          gap_force=np.asarray(self.gap_force, float), bilateral=True)
