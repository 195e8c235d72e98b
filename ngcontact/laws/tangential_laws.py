"""The homogenized tangential laws: friction (paper eqs. 38-44) and the cell's own shear response.

:class:`Friction`: threshold ``G = mu0 [p]_+ + G0`` and energy ``G huber(|a_t|, w)``;
:class:`CellShear`: rows of shear against tangential jump tabulated at a set of pressures.  Conventions:
:mod:`ngcontact.laws.homogenized`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.laws.huber import huber_of_square, huber_slope, if_positive, is_numeric
from ngcontact.laws.law_evaluation import ramp, row_splines, tangential_norm2
from ngcontact.laws.law_protocol import TangentialLaw


@dataclass(frozen=True, kw_only=True)
class Friction(TangentialLaw):
    """Homogenized friction: ``G = mu [p]_+ + threshold``, Huber width ``width``.

    Paper eqs. 38-44 with the Huber function of eq. 16
    (:mod:`ngcontact.laws.huber`)::

        G      = mu0 [p]_+ + G0                          (eqs. 42-43)
        W_f(a) = G huber(|a_t|, w)
        tau_f  = (0,  G a_t / max(|a_t|, w))            (G held fixed)

    Attributes
    ----------
    mu
        Homogenized Coulomb coefficient ``mu0`` (paper ``k_nt0 / k_n0`` or given).
    threshold
        Tresca-type threshold ``G0`` [stress] (eqs. 42-43).
    width
        Huber regularization width ``w`` [length]: the largest slip of a
        sticking interface.
    """

    mu: float = 0.0
    threshold: float = 0.0
    width: float = 1e-6

    def __post_init__(self):
        if self.mu < 0 or self.threshold < 0 or not self.width > 0:
            raise ModelError("need mu >= 0, threshold >= 0, width > 0")

    @property
    def coulomb(self) -> bool:
        return self.mu > 0

    @property
    def huber_regularized(self) -> bool:
        return True

    def with_width(self, width: float) -> Friction:
        return replace(self, width=width)

    def threshold_at(self, p):
        """``G = mu0 [p]_+ + G0``."""
        return self.mu * ramp(p) + self.threshold

    def energy(self, a, G):
        """``W_f(a) = G huber(|a_t|, w)``."""
        return G * huber_of_square(tangential_norm2(a), self.width)

    def traction(self, a, G) -> list:
        """``tau_f = (0, G a_t / max(|a_t|, w))``."""
        f = G * huber_slope(tangential_norm2(a), self.width)
        return [0.0 * a[0]] + [f * ai for ai in a[1:]]


@dataclass(frozen=True, kw_only=True)
class CellShear(TangentialLaw):
    """The cell's own tangential response, tabulated over pressure and tangential jump.

    Rows ``i`` at pressures ``p_0 = 0 < p_1 < ...`` hold the cell's mean
    shear ``T_i(s)`` at mean tangential interface jumps ``0 = s_i0 < s_i1 <
    ...`` (a polyline, odd in ``s``, held constant beyond the last jump: the
    cell slides there or the macro interface never went further); row 0 is
    zero (an open interface carries no shear).  Between rows the shear is
    interpolated linearly in ``p`` along the rays ``s / p = const``, each
    row stretched by ``r_i = p / p_i`` (so that a response homogeneous in
    the load, as a Coulomb cell's nearly is, ``T(p, s) = p f(s / p)``, is
    reproduced exactly; above the last row the shear grows with ``p`` that way)::

        T(p, s)  = sum_i phi_i(p) r_i T_i(s / r_i),        phi_i the piecewise-linear hats of the p_i
        W_t(a; p) = sum_i phi_i(p) r_i^2 E_i(a_t / r_i),   E_i(s) = int_0^|s| T_i
        tau_t    = dW_t/da_t = T(p, a_t)                   (p frozen)

    Like Coulomb's threshold, the dependence on the pressure is not the
    derivative of an energy: energy, traction and tangent are consistent with
    ``p`` frozen, and the coupled Newton of the macro problem takes ``p`` at
    the current state (:mod:`ngcontact.solvers.coulomb_newton`).  2D (and
    axisymmetric) frames only: one tangential component.

    Attributes
    ----------
    pressure
        ``p_i`` [stress], strictly increasing, ``p_0 = 0``.
    jumps
        Per row the jumps ``s_ij`` [length], strictly increasing from 0.
    shears
        Per row the shears ``T_i(s_ij)`` [stress], 0 at ``s = 0``.
    """

    pressure: tuple[float, ...]
    jumps: tuple[tuple[float, ...], ...]
    shears: tuple[tuple[float, ...], ...]

    def __post_init__(self):
        p = np.asarray(self.pressure, float)
        if p.ndim != 1 or len(p) < 2 or p[0] != 0.0 or np.any(np.diff(p) <= 0):
            raise ModelError("pressure must be >= 2 strictly increasing values starting at 0")
        if len(self.jumps) != len(p) or len(self.shears) != len(p):
            raise ModelError(f"jumps and shears need one row per pressure ({len(p)})")
        for i, (row_s, row_t) in enumerate(zip(self.jumps, self.shears)):
            s, t = np.asarray(row_s, float), np.asarray(row_t, float)
            if s.ndim != 1 or len(s) < 2 or len(t) != len(s) or s[0] != 0.0 or np.any(np.diff(s) <= 0):
                raise ModelError(f"row {i}: jumps must be >= 2 strictly increasing values from 0, one shear each")
            if t[0] != 0.0 or not np.all(np.isfinite(t)):
                raise ModelError(f"row {i}: the shear must be finite and 0 at s = 0")

    @property
    def coulomb(self) -> bool:
        """True: the shear depends on the current pressure (solved like Coulomb friction)."""
        return True

    def threshold_at(self, p):
        """The pressure ``p`` itself: the rows are interpolated at it."""
        return p

    def energy(self, a, G):
        """``W_t(a; p)`` of the class docstring with the frozen pressure ``p = G``."""
        self._check_frame(a)
        return sum(phi * e for phi, e in self._rows(a[1], G, energy=True))

    def traction(self, a, G) -> list:
        """``tau_t = T(p, a_t)`` with the frozen pressure ``p = G``; no normal component."""
        self._check_frame(a)
        return [0.0 * a[0], sum(phi * t for phi, t in self._rows(a[1], G, energy=False))]

    @property
    def width(self) -> float:
        """The smallest tabulated nonzero jump: below it every row is in its first (sticking) segment."""
        return float(min(s[1] for s in self.jumps))

    def hats(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``p_k`` and, per row ``i``, slope increments of ``phi_i(p) = phi_i(0) + sum_k d_ik [p - p_k]_+``."""
        p = np.asarray(self.pressure, float)
        eye = np.eye(len(p))
        slopes = np.diff(eye, axis=1) / np.diff(p)                       # (rows, intervals)
        slopes = np.concatenate([slopes, np.zeros((len(p), 1))], axis=1)  # held constant beyond p_last
        return p, np.diff(np.concatenate([np.zeros((len(p), 1)), slopes], axis=1), axis=1)

    def ramps(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``s_k`` and slope increments ``e_k`` of ``T_i(s) = sum_k e_k [s - s_k]_+`` for ``s >= 0``."""
        s = np.asarray(self.jumps[i], float)
        t = np.asarray(self.shears[i], float)
        slopes = np.concatenate([np.diff(t) / np.diff(s), [0.0]])
        return s, np.diff(np.concatenate([[0.0], slopes]))

    def _rows(self, s, p, energy: bool):
        """``(phi_i(p) r_i^k, E_i(s / r_i) or T_i(s / r_i))`` of the rows ``i >= 1``.

        ``r_i = p / p_i`` (with ``p`` kept above ``1e-12 p_1``: for ``p <= 0``
        every ``phi_i``, ``i >= 1``, is zero and row 0 is zero), ``k = 2`` for the
        energy and 1 for the traction; ``T_i(x) = sum_k e_k ([x - s_k]_+ -
        [-x - s_k]_+)`` (odd), ``E_i(x) = sum_k e_k/2 ([x - s_k]_+^2 + [-x -
        s_k]_+^2)``; ``phi_i(p) = sum_k d_ik [p - p_k]_+``.  On
        CoefficientFunctions ``T_i`` and ``E_i`` are B-splines
        (:func:`ngcontact.laws.law_evaluation.row_splines`).
        """
        kinks, d = self.hats()
        floor = 1e-12 * float(kinks[1])
        q = if_positive(p - floor, p, floor)
        for i in range(1, len(kinks)):
            phi = sum(float(dk) * ramp(p - float(pk)) for pk, dk in zip(kinks, d[i]) if dk != 0)
            r = q / float(kinks[i])
            x = s / r
            if not is_numeric(x):
                T, E = row_splines(tuple(self.jumps[i]), tuple(self.shears[i]))
                yield (phi * r * r, E(x)) if energy else (phi * r, T(x))
                continue
            sk, ek = self.ramps(i)
            if energy:
                f = sum(0.5 * float(e) * (ramp(x - float(k)) ** 2 + ramp(-x - float(k)) ** 2)
                        for k, e in zip(sk, ek) if e != 0)
                yield phi * r * r, f
            else:
                f = sum(float(e) * (ramp(x - float(k)) - ramp(-x - float(k))) for k, e in zip(sk, ek) if e != 0)
                yield phi * r, f

    @staticmethod
    def _check_frame(a) -> None:
        if len(a) != 2:
            raise ModelError("a tabulated cell shear (CellShear) needs a 2D or axisymmetric interface frame "
                             f"(one tangent); this frame has {len(a) - 1}")
