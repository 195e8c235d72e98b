"""The exact fields of the manufactured solutions and the data they imply.

For a chosen displacement ``u*`` (:func:`smooth_field`, :func:`polynomial_field`) the body force
``f = -div sigma(u*)`` (paper eq. 1; axisymmetric: with the hoop terms, in the module docstring of
:mod:`ngcontact.verification.manufactured`), the stress and the traction ``sigma(u*) n``, computed
symbolically with NGSolve's ``CoefficientFunction.Diff``.
"""
from __future__ import annotations

import math

import ngsolve as ng
import numpy as np

from ngcontact.fem import elasticity
from ngcontact.fem.materials import ElasticLaw

#: the settings a manufactured solution is made for
SETTINGS = ("plane_strain", "axisymmetric", "3d", "periodic_cell")
#: the kinds of exact field: smooth (rates), polynomial (exactness)
SOLUTIONS = ("smooth", "polynomial")
#: the period of the periodic two-material cell
CELL_PERIOD = 1.0


def coordinates(dim: int) -> tuple:
    """The coordinate functions ``(x, y[, z])``."""
    return (ng.x, ng.y, ng.z)[:dim]


def gradient(u: ng.CoefficientFunction, dim: int) -> ng.CoefficientFunction:
    """``(du_i / dx_j)`` of a vector ``CoefficientFunction``, symbolically."""
    X = coordinates(dim)
    return ng.CF(tuple(u[i].Diff(X[j]) for i in range(dim) for j in range(dim)), dims=(dim, dim))


def exact_stress(law: ElasticLaw, u: ng.CoefficientFunction, setting: str) -> ng.CoefficientFunction:
    """3x3 stress ``C : eps(u)`` of a symbolic displacement ``u``."""
    dim = elasticity.dimension(setting)
    return law.stress(elasticity.strain_of_gradient(gradient(u, dim), u, setting))


def body_force(law: ElasticLaw, u: ng.CoefficientFunction, setting: str) -> ng.CoefficientFunction:
    """``f = -div sigma(u)`` (cylindrical divergence in the axisymmetric setting).

    For an isotropic law in plane strain or 3D the Navier form
    ``f = -(mu lap u + (lam + mu) grad div u)`` is used: the same field,
    with a several times smaller expression tree (faster quadrature).
    """
    if law.lame is not None and setting in ("plane_strain", "3d"):
        return navier_body_force(law, u, setting)
    return stress_divergence_body_force(law, u, setting)


def stress_divergence_body_force(law: ElasticLaw, u: ng.CoefficientFunction,
                                 setting: str) -> ng.CoefficientFunction:
    """``f = -div sigma(u)`` by differentiating the stress, for any law and setting."""
    dim = elasticity.dimension(setting)
    s = exact_stress(law, u, setting)
    X = coordinates(dim)
    div = [sum(s[i, j].Diff(X[j]) for j in range(dim)) for i in range(dim)]
    if setting == "axisymmetric":
        div[0] = div[0] + (s[0, 0] - s[2, 2]) / ng.x
        div[1] = div[1] + s[0, 1] / ng.x
    return ng.CF(tuple(-d for d in div)).Compile()


def navier_body_force(law: ElasticLaw, u: ng.CoefficientFunction, setting: str) -> ng.CoefficientFunction:
    """``f = -(mu lap u + (lam + mu) grad div u)`` for an isotropic law (plane strain, 3D)."""
    if law.lame is None or setting not in ("plane_strain", "3d"):
        raise ValueError("the Navier form needs an isotropic law in plane strain or 3D")
    lam, mu = law.lame
    dim = elasticity.dimension(setting)
    X = coordinates(dim)
    div_u = sum(u[j].Diff(X[j]) for j in range(dim))
    return ng.CF(tuple(-(mu * sum(u[i].Diff(X[j]).Diff(X[j]) for j in range(dim))
                         + (lam + mu) * div_u.Diff(X[i])) for i in range(dim))).Compile()


def traction(law: ElasticLaw, u: ng.CoefficientFunction, setting: str, normal) -> ng.CoefficientFunction:
    """``sigma(u) n`` for the in-plane (2D) or full (3D) normal ``n``."""
    dim = elasticity.dimension(setting)
    s = exact_stress(law, u, setting)
    return ng.CF(tuple(sum(s[i, j] * normal[j] for j in range(dim)) for i in range(dim))).Compile()


# ------------------------------------------------------------ exact fields
def smooth_field(setting: str) -> ng.CoefficientFunction:
    """A smooth, non-polynomial ``u*`` for rate studies.

    Axisymmetric: ``u_r`` odd and ``u_z`` even in ``r`` (regular at the axis).
    Periodic cell: ``1``-periodic in ``x``.
    """
    x, y, z = ng.x, ng.y, ng.z
    if setting == "plane_strain":
        return ng.CF((ng.sin(2 * x + y) * ng.cos(0.5 * y), ng.cos(x - 1.5 * y) * ng.exp(0.5 * x)))
    if setting == "axisymmetric":
        r = x
        return ng.CF((ng.sin(2 * r) * ng.cos(1.5 * y + 0.3), ng.cos(2 * r) * ng.sin(y) + r * r * y))
    if setting == "3d":
        return ng.CF((ng.sin(x + 2 * y) * ng.cos(z), ng.cos(2 * x - z) * ng.sin(y),
                      ng.exp(0.5 * x) * ng.sin(y + z)))
    if setting == "periodic_cell":
        k = 2 * math.pi / CELL_PERIOD
        return ng.CF((ng.sin(k * x) * ng.cos(2 * y) + 0.5 * y,
                      ng.cos(k * x) * ng.sin(3 * y) + 0.3 * ng.sin(k * x + y)))
    raise ValueError(f"setting = {setting!r}: must be one of {', '.join(SETTINGS)}")


def polynomial_field(setting: str, degree: int, seed: int = 1) -> ng.CoefficientFunction:
    """A generic polynomial ``u*`` of total degree ``degree`` (exactness tests).

    Coefficients are fixed pseudo-random numbers.  Axisymmetric:
    ``u_r = r q(r, z)`` with ``deg q = degree - 1`` and ``u_z`` without a term
    linear in ``r``, so that the weak form of ``u*`` has polynomial integrands.
    """
    if degree < 1:
        raise ValueError(f"degree = {degree!r}: must be >= 1")
    if setting == "periodic_cell":
        raise ValueError("a polynomial cannot be periodic; use setting 'plane_strain'")
    dim = elasticity.dimension(setting)
    rng = np.random.default_rng(seed)
    X = coordinates(dim)

    def poly(deg, skip=lambda powers: False):
        total = ng.CF(0.0)
        for powers in np.ndindex(*(deg + 1,) * dim):
            if sum(powers) > deg or skip(powers):
                continue
            term = ng.CF(float(rng.uniform(-1.0, 1.0)))
            for c, k in zip(X, powers):
                if k:
                    term = term * c ** int(k)
            total = total + term
        return total

    if setting == "axisymmetric":
        u_r = ng.x * poly(degree - 1) if degree > 1 else ng.x * float(rng.uniform(-1.0, 1.0))
        u_z = poly(degree, skip=lambda powers: powers[0] == 1)
        return ng.CF((u_r, u_z))
    return ng.CF(tuple(poly(degree) for _ in range(dim)))


# ------------------------------------------------------------ domains
