"""Interface energies of penalty contact with Huber-regularized friction.

All densities are NGSolve CoefficientFunctions of the displacement jump

    J = u_rough - u_counter        on S_C,

with the micro normal ``n`` pointing from ``rough`` into ``counter`` (so a
closure ``J_n = J.n > 0`` means the bodies move towards each other) and an
initial gap ``g >= 0``.  The total interface energy added to the elastic
energy of the bodies is the integral over ``S_C`` of

* normal penalty (paper eqs. 7 and 9, Winkler stiffness ``k_n = b/delta``)::

      psi_n(J) = (k_n / 2) [J_n - g]_+^2,       p = k_n [J_n - g]_+ >= 0,

  ``p`` is the contact pressure, compression positive;

* Tresca friction, regularized by the Huber function (paper eqs. 9 and 16)::

      psi_t(J) = G huber(|J_t|, w),   J_t = J - J_n n,
      huber(s, w) = s^2 / (2 w)  (s <= w),   s - w/2  (s > w),

  whose derivative is the friction traction ``G J_t / max(|J_t|, w)``
  (paper eq. 17): a tangential spring ``G/w`` while ``|J_t| <= w`` (stick),
  the threshold ``G`` beyond (slip).  The quadratic branch is written with
  ``J_t . J_t`` and the linear branch takes the root of
  ``max(J_t . J_t, w^2)``, so neither branch has a singular derivative, not
  even at ``J_t = 0``;

* Coulomb friction ``G = mu p``.  Coulomb friction has no potential, so it
  is solved as a fixed point of Tresca problems (see :mod:`ngcontact.cell.fe.cell_problem`):
  the threshold is ``mu`` times the pressure of the *previous* iterate,
  evaluated exactly at the quadrature points from a frozen copy of that
  iterate (:class:`ngcontact.laws.friction.Coulomb`), and the iteration
  stops when the pressure changes by less than a tolerance relative to its
  maximum.

* exact non-penetration by an augmented Lagrangian (the rigid limit
  ``k_n -> infinity`` of the Winkler layer; not in the paper):
  with a multiplier ``lambda >= 0`` held fixed, the normal energy is::

      psi_n(J; lambda) = (1 / (2 k)) ([lambda + k (J_n - g)]_+^2 - lambda^2),
      p = [lambda + k (J_n - g)]_+,

  ``k`` the augmentation parameter (the scene's ``k_n``).  At ``lambda = 0``
  it is the penalty above; its minimizer in ``J`` for fixed ``lambda`` is
  followed by the Uzawa update ``lambda <- p``, whose fixed points are the
  complementarity conditions ``J_n - g <= 0``, ``lambda >= 0``,
  ``lambda (J_n - g) = 0`` whatever ``k`` is (:func:`augmented_pressure`,
  :mod:`ngcontact.cell.fe.contact_multiplier`).  The constant ``-lambda^2/(2k)``
  only makes the energy vanish where the surfaces are open.

Only the terms a problem asks for are added: a frictionless problem
assembles no friction term, a problem without gap no gap.  The friction
laws themselves (threshold, coupling to the pressure, which of these
densities they use) are the classes of :mod:`ngcontact.laws.friction`.
"""
from __future__ import annotations

import ngsolve as ng

from ngcontact.laws.huber import huber, huber_of_square, huber_slope  # noqa: F401  (huber: the micro law's API)
from ngcontact.errors import ModelError


def positive_part(s):
    """``[s]_+ = max(s, 0)``.

    At the kink ``s = 0`` the generalized derivative is taken from the
    active side (slope 1), so that Newton sees the stiffness of surfaces that
    touch exactly without overlap (e.g. the flanks of a conforming valley).
    """
    return ng.IfPos(-s, 0.0, s)


def normal_closure(J, n):
    """``J_n = J . n``: closure of the interface (positive when closing)."""
    return ng.InnerProduct(J, n)


def penetration(J, n, gap=None):
    """``J_n - g``: positive where the bodies overlap (in contact)."""
    Jn = normal_closure(J, n)
    return Jn if gap is None else Jn - gap


def pressure(J, n, k_n, gap=None):
    """Contact pressure ``p = k_n [J_n - g]_+ >= 0`` (compression positive)."""
    return k_n * positive_part(penetration(J, n, gap))


def normal_energy(J, n, k_n, gap=None):
    """Penalty energy density ``(k_n/2) [J_n - g]_+^2`` (paper eq. 9)."""
    d = positive_part(penetration(J, n, gap))
    return 0.5 * k_n * d * d


def augmented_pressure(J, n, k, multiplier, gap=None):
    """Augmented-Lagrangian pressure ``p = [lambda + k (J_n - g)]_+ >= 0`` (module docstring)."""
    return positive_part(multiplier + k * penetration(J, n, gap))


def augmented_normal_energy(J, n, k, multiplier, gap=None):
    """``(1/(2k)) ([lambda + k (J_n - g)]_+^2 - lambda^2)`` for a fixed multiplier ``lambda``.

    Its derivative in ``J`` is ``p n`` with :func:`augmented_pressure`; with
    ``lambda = 0`` it is :func:`normal_energy`.
    """
    a = positive_part(multiplier + k * penetration(J, n, gap))
    return (0.5 / k) * (a * a - multiplier * multiplier)


def tangential_slip(J, n):
    """``J_t = J - (J.n) n``, the tangential part of the jump."""
    return J - normal_closure(J, n) * n


def tresca_energy(J, n, G, w):
    """Regularized Tresca energy density ``G huber(|J_t|, w)`` (paper eqs. 9, 16)."""
    Jt = tangential_slip(J, n)
    return G * huber_of_square(ng.InnerProduct(Jt, Jt), w)


def slip_magnitude(J, n):
    """``|J_t|``."""
    Jt = tangential_slip(J, n)
    return ng.sqrt(ng.InnerProduct(Jt, Jt))


def friction_traction(J, n, G, w):
    """Tangential traction on the counter body, ``G J_t / max(|J_t|, w)`` (paper eq. 17)."""
    Jt = tangential_slip(J, n)
    s2 = ng.InnerProduct(Jt, Jt)
    return G * Jt / ng.sqrt(ng.IfPos(s2 - w * w, s2, w * w))


def interface_energy(J, n, *, k_n, gap=None, friction=None, threshold=None, multiplier=None):
    """Total interface energy density of the terms asked for.

    Parameters
    ----------
    J
        Jump ``u_rough - u_counter`` (trial function expression).
    n
        Micro normal, from ``rough`` into ``counter``.
    k_n
        Penalty stiffness [stress/length].
    gap
        Initial gap ``g`` or ``None`` (no gap term).
    friction
        ``None`` (frictionless) or a friction law
        (:class:`ngcontact.laws.friction.FrictionLaw`), whose energy
        ``G huber(|J_t|, w)`` takes ``threshold`` as ``G`` (its
        ``threshold`` of a given pressure, e.g. ``mu p_previous``).
    multiplier
        ``None``: the penalty :func:`normal_energy`; a contact multiplier
        ``lambda`` (held fixed): the augmented energy
        :func:`augmented_normal_energy` with ``k = k_n``.
    """
    if multiplier is None:
        energy = normal_energy(J, n, k_n, gap)
    else:
        energy = augmented_normal_energy(J, n, k_n, multiplier, gap)
    if not _has_friction(friction, threshold):
        return energy
    return energy + friction.energy(J, n, threshold)


def _has_friction(friction, threshold) -> bool:
    """Whether the interface terms include friction; raises on a friction law without a threshold."""
    if friction is None:
        return False
    if threshold is None:
        raise ModelError(f"friction {friction.name!r} needs a threshold")
    return True


def interface_stiffness(J, n, dJ, dJv, *, k_n, gap=None, friction=None, threshold=None, multiplier=None):
    """The second variation of :func:`interface_energy` at the jump ``J``, bilinear in ``dJ`` and ``dJv``:

        d2 psi(J)[dJ, dJv] = k H(s) (dJ.n)(dJv.n)
                             + G ( P dJ . P dJv / m  -  [|J_t| > w] (J_t.dJ)(J_t.dJv) / |J_t|^3 ),

    ``s = J_n - g`` (penalty, ``k = k_n``, eq. 9) or ``s = lambda + k (J_n - g)``
    (augmented, the multiplier held fixed), ``H`` the derivative of ``[.]_+``
    taken as :func:`positive_part` takes it (1 at ``s = 0``), ``P = I - n n``,
    ``m = max(|J_t|, w)`` (the Huber function's two branches, eqs. 16-17, the
    threshold ``G`` fixed as in :func:`interface_energy`).

    The same numbers as NGSolve's linearization of the ``Variation`` of
    :func:`interface_energy` (tested to round-off), as a *bilinear* density
    of a state: a form built from it is assembled by ``Assemble``, which
    costs half of the automatic second derivative (a BDDC preconditioner
    rebuilt from it: :func:`ngcontact.cell.fe.cell_energy.preconditioning_form`).
    """
    s = penetration(J, n, gap)
    if multiplier is not None:
        s = multiplier + k_n * s
    stiffness = k_n * ng.IfPos(-s, 0.0, 1.0) * ng.InnerProduct(dJ, n) * ng.InnerProduct(dJv, n)
    if not _has_friction(friction, threshold):
        return stiffness
    return stiffness + friction.stiffness(J, n, dJ, dJv, threshold)


def friction_stiffness(J, n, dJ, dJv, G, w):
    """The second variation of :func:`tresca_energy` at ``J`` (``G`` fixed), bilinear in ``dJ`` and ``dJv``:

        G ( P dJ . P dJv / m  -  [|J_t| > w] (J_t.dJ)(J_t.dJv) / |J_t|^3 ),

    ``P = I - n n`` and ``m = max(|J_t|, w)`` (paper eqs. 16-17; the friction
    part of :func:`interface_stiffness`).
    """
    Jt = tangential_slip(J, n)
    s2 = ng.InnerProduct(Jt, Jt)
    slope = huber_slope(s2, w)
    sliding = ng.IfPos(s2 - w * w, slope * slope * slope, 0.0)
    tangential = (slope * ng.InnerProduct(tangential_slip(dJ, n), tangential_slip(dJv, n))
                  - sliding * ng.InnerProduct(Jt, dJ) * ng.InnerProduct(Jt, dJv))
    return G * tangential
