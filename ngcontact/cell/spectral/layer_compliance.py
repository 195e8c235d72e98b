"""Surface compliance of a periodic elastic layer bonded to a rigid face, per wave vector.

In the small-slope model both bodies of a cell are flat periodic layers: the
rough body ``-h_rough < z < 0`` clamped at its bottom, the counter body
``0 < z < h_counter`` whose top face is a rigid plate (its fluctuation
vanishes there).  Each layer is linear and invariant under in-plane
translations, so a surface traction ``t e^{i k.x}`` produces a surface
displacement ``C(k) t e^{i k.x}``: one 3 x 3 (2D: 2 x 2) Hermitian matrix per
wave vector.  This turns the cell problem of paper eqs. 49-51 (with the
penalized contact condition eq. 65, or its rigid limit) into an interface
problem on the grid of the height map (:mod:`ngcontact.cell.spectral.layered_cell`).

Derivation (plane strain in the plane of ``k``, ``t = |k| h``, shear modulus
``mu``, Poisson's ratio ``nu``, ``kappa = 3 - 4 nu``).  The Navier equations
with the dependence ``e^{ikx}`` have the general solution
``(A + B z) e^{kz} + (C + D z) e^{-kz}`` per component, two of the four
coefficient pairs tied by the equations; the rigid bottom ``u(-h) = 0`` and
the surface traction fix the rest.  Solved symbolically, the surface
displacement of a layer below its loaded face is, with
``D(t) = 2 kappa cosh 2t + 4 t^2 + 1 + kappa^2``,

    C_nn = 2 (1 - nu) (kappa sinh 2t - 2t) / (mu |k| D)        normal / normal
    C_ll = 2 (1 - nu) (kappa sinh 2t + 2t) / (mu |k| D)        along k / along k
    C_ln = i sgn 2 (t^2 - kappa (1 - 2 nu) sinh^2 t) / (mu |k| D)   along k / normal
    C_nl = -C_ln,
    C_aa = tanh t / (mu |k|)                                     antiplane (3D, across k)

(the antiplane one from ``u'' = k^2 u``).  Checks that hold: as ``t -> inf``
the half-space values ``C_nn = C_ll = 2 (1 - nu^2) / (E |k|)``,
``|C_ln| = (1 - 2 nu) / (2 mu |k|)`` (Johnson, Contact Mechanics, Sec. 2.8);
as ``t -> 0`` the uniaxial-strain layer ``C_nn -> h / (lambda + 2 mu)`` and
``C_ll, C_aa -> h / mu``, which are the zero mode's values used below; and
:mod:`ngcontact.verification.layer_fe` solves the same layer with high-order
finite elements through its thickness (the tests hold the two to 1e-10).
The formulas are evaluated with ``q = e^{-2t}`` (numerator and denominator
multiplied by ``q``), which neither overflows for thick layers nor cancels
for thin ones.

The counter body lies above its loaded face: mirroring ``z -> -z`` maps it
onto the layer below, which flips the sign of the normal/tangential
coupling and leaves the diagonal unchanged (:func:`layer_matrix` with
``above=True``).
"""
from __future__ import annotations

import numpy as np


def _checked(E: float, nu: float, h: float) -> tuple[float, float]:
    if not (E > 0 and -1 < nu < 0.5 and h > 0):
        raise ValueError(f"layer E = {E!r}, nu = {nu!r}, h = {h!r}: need E > 0, -1 < nu < 0.5, h > 0")
    return E / (2 * (1 + nu)), 3 - 4 * nu


def plane_compliances(k, E: float, nu: float, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(C_nn, C_ll, c_ln)`` of a layer of thickness ``h`` for wave numbers ``|k| = k >= 0``.

    ``c_ln`` is the real factor of the coupling: ``C_ln = i sgn(k) c_ln``.
    At ``k = 0`` the uniform limits ``h / (lambda + 2 mu)``, ``h / mu`` and 0.
    """
    mu, kap = _checked(E, nu, h)
    k = np.abs(np.asarray(k, dtype=float))
    t = k * h
    zero = t == 0.0
    ks = np.where(zero, 1.0, k)
    q = np.exp(-2.0 * t)
    den = kap * (1.0 + q * q) + q * (4.0 * t * t + 1.0 + kap * kap)
    # kappa sinh 2t -+ 2t, times q: kappa (1 - q^2)/2 -+ 2 t q; for small t the difference of
    # kappa (1 - q^2)/2 and 2 t q loses digits, so expm1 keeps (1 - q^2) exact
    s = -np.expm1(-4.0 * t)
    nn = 2 * (1 - nu) * (0.5 * kap * s - 2.0 * t * q) / (mu * ks * den)
    ll = 2 * (1 - nu) * (0.5 * kap * s + 2.0 * t * q) / (mu * ks * den)
    one_minus_q = -np.expm1(-2.0 * t)
    ln = 2 * (t * t * q - 0.25 * kap * (1 - 2 * nu) * one_minus_q ** 2) / (mu * ks * den)
    nn = np.where(zero, h * (1 - 2 * nu) / (2 * mu * (1 - nu)), nn)
    ll = np.where(zero, h / mu, ll)
    ln = np.where(zero, 0.0, ln)
    return nn, ll, ln


def antiplane_compliance(k, E: float, nu: float, h: float) -> np.ndarray:
    """``C_aa = tanh(|k| h) / (mu |k|)`` (``h / mu`` at ``k = 0``)."""
    mu, _ = _checked(E, nu, h)
    k = np.abs(np.asarray(k, dtype=float))
    zero = k == 0.0
    ks = np.where(zero, 1.0, k)
    return np.where(zero, h / mu, np.tanh(k * h) / (mu * ks))


def normal_compliance(k, E: float, nu: float, h: float) -> np.ndarray:
    """``C_nn(|k|)``: normal surface displacement per normal traction (the frictionless operator)."""
    return plane_compliances(k, E, nu, h)[0]


def layer_matrix(kvec, E: float, nu: float, h: float, *, above: bool = False) -> np.ndarray:
    """The Hermitian surface compliance ``C(k)`` in Cartesian components ``(x[, y], z)``.

    ``kvec``: wave vectors, shape ``(..., d-1)``.  Returns shape
    ``(..., d, d)``, complex.  ``above``: the layer lies above its loaded
    face (the counter body): the coupling changes sign.
    """
    return layers_matrix(kvec, [(E, nu, h, above)])


def layers_matrix(kvec, layers) -> np.ndarray:
    """The sum of the compliances :func:`layer_matrix` of ``layers``, ``(E, nu, h, above)`` each, assembled once
    from the sums of their plane and antiplane compliances (the matrix is linear in them)."""
    kvec = np.asarray(kvec, dtype=float)
    dt = kvec.shape[-1]
    kk = np.sqrt(np.sum(kvec * kvec, axis=-1))
    nn = ll = ln = aa = np.zeros(kk.shape)
    for E, nu, h, above in layers:
        n_, l_, c_ = plane_compliances(kk, E, nu, h)
        nn, ll, ln = nn + n_, ll + l_, ln + (-1.0 if above else 1.0) * c_
        if dt == 2:
            aa = aa + antiplane_compliance(kk, E, nu, h)
    safe = np.where(kk == 0.0, 1.0, kk)
    e = kvec / safe[..., None]                      # unit vector along k (0 at k = 0)
    C = np.zeros(kvec.shape[:-1] + (dt + 1, dt + 1), dtype=complex)
    C[..., dt, dt] = nn
    if dt == 1:
        C[..., 0, 0] = ll
    else:
        iso = kk == 0.0
        for a in range(2):
            for b in range(2):
                proj = e[..., a] * e[..., b]
                delta = 1.0 if a == b else 0.0
                C[..., a, b] = np.where(iso, delta * ll, ll * proj + aa * (delta - proj))
    for a in range(dt):
        C[..., a, dt] = 1j * e[..., a] * ln
        C[..., dt, a] = -C[..., a, dt]
    return C
