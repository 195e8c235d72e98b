"""Linear elastic materials and stress measures.

Hooke's law ``sigma = C : eps`` (paper eq. 1, ``sigma_ij = a_ijkl du_k/dx_l``)
for isotropic materials (Young's modulus ``E``, Poisson's ratio ``nu``;
Lame ``lam = E nu / ((1 + nu)(1 - 2 nu))``, ``mu = E / (2 (1 + nu))``) and for
general anisotropic ones given by their 6x6 Voigt matrix, ordered
``(11, 22, 33, 23, 13, 12)`` with engineering shear strains
``gamma_ij = 2 eps_ij``.

Every setting (plane strain, axisymmetric, 3D) works with the full 3x3 strain
tensor, so a single 3D law serves all of them; see :mod:`ngcontact.fem.elasticity`.

Stress measures (paper eq. 77): principal stresses, the von Mises equivalent
``sqrt(3/2 s:s)`` with the deviator ``s = sigma - tr(sigma)/3 I`` and the
Tresca equivalent ``max_kl |sigma_k - sigma_l|``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ngcontact.errors import ModelError

VOIGT_PAIRS = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))


@dataclass(frozen=True)
class ElasticLaw:
    """A linear elastic law.

    Attributes
    ----------
    voigt
        6x6 symmetric positive definite stiffness matrix (tuple of tuples).
    lame
        ``(lam, mu)`` for an isotropic material, else ``None``; the isotropic
        path assembles a cheaper expression.
    """

    voigt: tuple[tuple[float, ...], ...]
    lame: tuple[float, float] | None = None

    @property
    def matrix(self) -> np.ndarray:
        return np.array(self.voigt, dtype=float)

    @property
    def longitudinal_modulus(self) -> float:
        """Mean of ``C_1111, C_2222, C_3333``: a stress per unit normal strain (``lam + 2 mu`` if isotropic)."""
        return float(np.trace(self.matrix[:3, :3])) / 3.0

    def stress(self, eps):
        """Stress tensor for a 3x3 strain tensor (NGSolve CoefficientFunction or array)."""
        if self.lame is not None:
            lam, mu = self.lame
            return _isotropic_stress(lam, mu, eps)
        return _voigt_stress(self.matrix, eps)


def isotropic(E: float, nu: float) -> ElasticLaw:
    """Isotropic law from Young's modulus ``E > 0`` and ``-1 < nu < 0.5``."""
    if not E > 0:
        raise ModelError(f"E = {E!r}: must be > 0")
    if not -1.0 < nu < 0.5:
        raise ModelError(f"nu = {nu!r}: must lie in (-1, 0.5)")
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    C = np.zeros((6, 6))
    C[:3, :3] = lam
    C[:3, :3] += 2 * mu * np.eye(3)
    C[3:, 3:] = mu * np.eye(3)
    return ElasticLaw(voigt=_freeze(C), lame=(lam, mu))


def anisotropic(C) -> ElasticLaw:
    """General law from a 6x6 Voigt matrix; must be symmetric positive definite."""
    C = np.asarray(C, dtype=float)
    if C.shape != (6, 6):
        raise ModelError(f"C has shape {C.shape}: must be 6x6")
    if not np.all(np.isfinite(C)):
        raise ModelError("C must hold finite numbers")
    if not np.allclose(C, C.T, rtol=1e-12, atol=1e-12 * np.abs(C).max()):
        raise ModelError("C must be symmetric")
    if np.linalg.eigvalsh(C).min() <= 0:
        raise ModelError("C must be positive definite")
    return ElasticLaw(voigt=_freeze(C))


def plane_strain_modulus(E: float, nu: float) -> float:
    """``E / (1 - nu^2)``, the modulus of a body in plane strain."""
    return E / (1.0 - nu * nu)


def _freeze(C: np.ndarray) -> tuple:
    return tuple(tuple(float(c) for c in row) for row in C)


def _isotropic_stress(lam, mu, eps):
    if isinstance(eps, np.ndarray):
        tr = np.trace(eps, axis1=-2, axis2=-1)[..., None, None]
        return lam * tr * np.eye(3) + 2 * mu * eps
    from ngsolve import Id, Trace
    return lam * Trace(eps) * Id(3) + 2 * mu * eps


def _voigt_stress(C: np.ndarray, eps):
    if isinstance(eps, np.ndarray):
        e = np.stack([eps[..., i, j] * (1 if i == j else 2) for i, j in VOIGT_PAIRS], axis=-1)
        s = e @ C.T
        out = np.empty(eps.shape)
        for k, (i, j) in enumerate(VOIGT_PAIRS):
            out[..., i, j] = s[..., k]
            out[..., j, i] = s[..., k]
        return out
    from ngsolve import CF
    e = CF(tuple(eps[i, j] * (1 if i == j else 2) for i, j in VOIGT_PAIRS))
    Ccf = CF(tuple(C.ravel()), dims=(6, 6))
    s = Ccf * e
    idx = {}
    for k, (i, j) in enumerate(VOIGT_PAIRS):
        idx[i, j] = idx[j, i] = k
    comps = [s[idx[i, j]] for i in range(3) for j in range(3)]
    return CF(tuple(comps), dims=(3, 3))


# ------------------------------------------------------------ stress measures
def principal_stresses(sigma: np.ndarray) -> np.ndarray:
    """Principal stresses, descending, of an array of 3x3 stress tensors."""
    sigma = np.asarray(sigma, dtype=float)
    return np.linalg.eigvalsh(0.5 * (sigma + np.swapaxes(sigma, -1, -2)))[..., ::-1]


def von_mises(sigma):
    """Von Mises equivalent ``sqrt(3/2 s:s)`` (paper eq. 77) of 3x3 stress tensors.

    Accepts an array ``(..., 3, 3)`` or an NGSolve 3x3 CoefficientFunction.
    """
    if isinstance(sigma, np.ndarray):
        tr = np.trace(sigma, axis1=-2, axis2=-1)[..., None, None]
        s = sigma - tr / 3.0 * np.eye(3)
        return np.sqrt(1.5 * np.sum(s * s, axis=(-2, -1)))
    from ngsolve import Id, InnerProduct, Trace, sqrt
    s = sigma - Trace(sigma) / 3.0 * Id(3)
    return sqrt(1.5 * InnerProduct(s, s))


def tresca(sigma: np.ndarray) -> np.ndarray:
    """Tresca equivalent ``max |sigma_k - sigma_l|`` (paper eq. 77) of 3x3 stress tensors."""
    p = principal_stresses(sigma)
    return p[..., 0] - p[..., -1]
