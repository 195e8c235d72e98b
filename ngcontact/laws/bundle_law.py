"""The bundle law: the unilateral interface law of paper eqs. 31-33 before linearization.

``W(a) = sum_q w_q / 2 [n_q . a - g_q - beta1_q g0]_+^2``: a bundle of micro directions ``n_q`` with
weights ``w_q = k_n |ds_q| / |T|`` and micro gaps ``g_q``, taken from the cell's quadrature; with every
direction closed its Hessian is eq. 34's ``K0`` (:func:`linearized`).  Conventions:
:mod:`ngcontact.laws.homogenized`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.laws.law_evaluation import dot, ramp
from ngcontact.laws.law_protocol import ExportRows, NormalLaw
from ngcontact.laws.linear_law import LinearLaw


#: Directions whose normal component is below this never close under a normal closure.
CLOSING = 1e-12


@dataclass(frozen=True, kw_only=True)
class BundleLaw(NormalLaw):
    """Unilateral bundle of weighted micro directions (paper eqs. 31-33)::

        W(a) = sum_q w_q/2 [n_q . a - g_q - beta1_q g0]_+^2,    beta1_q = n_q . e_n
        tau  = sum_q w_q   [n_q . a - g_q - beta1_q g0]_+ n_q

    (``tau_n`` and ``tau_t`` are the homogenized stresses of eqs. 32 and 33
    with the integral over ``S_C`` replaced by the weighted directions).

    Attributes
    ----------
    weights
        ``w_q`` [stress / length], > 0.
    directions
        Unit micro normals ``n_q`` in the local frame ``(n0, t0)`` or
        ``(n0, t1, t2)``; a 3D cell's normals under a 2D macro frame are
        their projections on ``(n0, t1)`` (the hoop jump is zero).
    gaps
        Micro gaps ``g_q`` [length] (default zeros).
    """

    weights: tuple[float, ...]
    directions: tuple[tuple[float, ...], ...]
    gaps: tuple[float, ...] = ()

    def __post_init__(self):
        w = np.asarray(self.weights, float)
        d = np.asarray(self.directions, float)
        if w.ndim != 1 or len(w) == 0 or np.any(w <= 0):
            raise ModelError("weights must be a non-empty list of numbers > 0")
        if d.shape[0] != len(w) or d.ndim != 2 or d.shape[1] not in (2, 3):
            raise ModelError(f"directions must be {len(w)} vectors of 2 or 3 components")
        norms = np.linalg.norm(d, axis=1)
        if np.any(norms <= 0) or np.any(norms > 1 + 1e-9):
            raise ModelError("directions must be unit vectors (or their projections on a 2D frame)")
        if self.gaps and len(self.gaps) != len(w):
            raise ModelError(f"gaps must have {len(w)} entries (one per direction)")

    @property
    def g(self) -> np.ndarray:
        return np.asarray(self.gaps, float) if self.gaps else np.zeros(len(self.weights))

    def matrix(self, dim: int | None = None) -> np.ndarray:
        """``K0 = sum_q w_q n_q n_q^T``, the tangent in full contact (eq. 34)."""
        d = np.asarray(self.directions, float)
        return np.einsum("q,qi,qj->ij", np.asarray(self.weights, float), d, d)

    @property
    def stiffness(self) -> float:
        return float(self.matrix()[0, 0])

    def energy(self, a, g0=0.0, closed: bool = False):
        """``W(a)`` of the class docstring; with ``closed`` every direction active (``[x]_+`` replaced by ``x``)."""
        self._check_dim(len(a))
        on = (lambda x: x) if closed else ramp
        W = 0
        for w, n, g in zip(self.weights, self.directions, self.g):
            W = W + 0.5 * w * on(dot(n, a) - g - n[0] * g0) ** 2
        return W

    def traction(self, a, g0=0.0) -> list:
        """``tau = sum_q w_q [n_q . a - g_q - beta1_q g0]_+ n_q``."""
        dim = len(a)
        self._check_dim(dim)
        tau = [0] * dim
        for w, n, g in zip(self.weights, self.directions, self.g):
            f = w * ramp(dot(n, a) - g - n[0] * g0)
            tau = [tau[i] + f * n[i] for i in range(dim)]
        return tau

    def full_contact_K0(self, dim: int) -> np.ndarray:
        return self.matrix(dim)

    def closing_ramps(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``c_q`` and slope increments ``s_q`` of the pressure under a purely normal closure ``c``::

            p(c) = sum_q w_q beta_q [beta_q c - g_q]_+ = sum_q s_q [c - c_q]_+,
            beta_q = n_q . n0,   s_q = w_q beta_q^2,   c_q = g_q / beta_q,

        a convex polyline whose last slope is ``k_n0 = sum_q s_q``, the normal
        entry of ``K0`` (eq. 34); directions with ``beta_q <= CLOSING`` never
        close under a normal closure and carry no pressure.
        """
        w = np.asarray(self.weights, float)
        beta = np.asarray(self.directions, float)[:, 0]
        g = np.asarray(self.g, float)
        closing = beta > CLOSING
        if not np.any(closing):
            raise ModelError("no direction of the bundle closes under a normal closure (all n_q . n0 <= 0)")
        return g[closing] / beta[closing], w[closing] * beta[closing] ** 2

    def export_rows(self) -> ExportRows:
        """:meth:`closing_ramps`, ``K0 = sum_q w_q n_q n_q^T`` and the gap forces ``sum_q w_q g_q n_q`` (eq. 34),
        stick slope the mean tangential entry of ``K0``, the bundle itself."""
        w, n, g = np.asarray(self.weights, float), np.asarray(self.directions, float), self.g
        kinks, slopes = self.closing_ramps()
        K0 = self.matrix()
        return ExportRows(kinks=kinks, slopes=slopes, stick_slope=float(np.mean(np.diag(K0)[1:])), K0=K0,
                          gap_force=np.einsum("q,q,qi->i", w, g, n),
                          bundle={"weights": w, "directions": n, "gaps": g})

    def _check_dim(self, dim: int) -> None:
        if len(self.directions[0]) != dim:
            raise ModelError(f"the bundle's directions have {len(self.directions[0])} components, "
                             f"the interface frame {dim}")

    def merged(self, decimals: int = 12) -> "BundleLaw":
        """The same law with equal ``(n_q, g_q)`` merged (weights added)."""
        acc: dict = {}
        for w, n, g in zip(self.weights, self.directions, self.g):
            key = tuple(np.round(n, decimals)) + (round(float(g), decimals + 6),)
            acc[key] = acc.get(key, 0.0) + float(w)
        keys = list(acc)
        return BundleLaw(weights=tuple(acc[k] for k in keys),
                         directions=tuple(tuple(float(c) for c in k[:-1]) for k in keys),
                         gaps=tuple(float(k[-1]) for k in keys))


#: how a :class:`TabulatedLaw` joins its nodes


def linearized(law: BundleLaw) -> LinearLaw:
    """The linear law a bundle equals when every direction is closed.

    ``K0 = sum w_q n_q n_q^T`` and gap forces ``sum w_q g_q n_q`` (eq. 34);
    a 3D bundle must have no ``t2`` coupling for a :class:`LinearLaw`.
    """
    K = law.matrix()
    gf = np.einsum("q,q,qi->i", np.asarray(law.weights, float), law.g, np.asarray(law.directions, float))
    if K.shape[0] == 3 and (abs(K[1, 1] - K[2, 2]) > 1e-12 * K[0, 0] or abs(K[0, 2]) > 1e-12 * K[0, 0]
                            or abs(K[1, 2]) > 1e-12 * K[0, 0]):
        raise ModelError("a 3D bundle is linearized to a LinearLaw only if transversely isotropic")
    return LinearLaw(kn=float(K[0, 0]), kt=float(K[1, 1]), knt=float(K[0, 1]),
                     gap_force=(float(gf[0]), float(gf[1])))
