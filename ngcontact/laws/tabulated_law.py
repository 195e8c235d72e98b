"""The tabulated law: a nonlinear normal law ``p(c)`` of the closure from a monotone table.

Interpolated linearly (a sum of ramps, its energy ``sum_i s_i/2 [c - c_i]_+^2``) or by the
shape-preserving C1 cubic of :mod:`ngcontact.laws.monotone_cubic`; the form in which the two-scale loop
(paper Sec. 3.5) hands the cell's response to the macro problem.  Conventions:
:mod:`ngcontact.laws.homogenized`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.laws import monotone_cubic
from ngcontact.laws.huber import is_numeric
from ngcontact.laws.law_evaluation import cubic_splines, ramp, table_splines
from ngcontact.laws.law_protocol import ExportRows, NormalLaw


INTERPOLATIONS = ("linear", "monotone_cubic")


@dataclass(frozen=True, kw_only=True)
class TabulatedLaw(NormalLaw):
    """Monotone tabulated normal law ``p(c)`` with optional tangential stiffness.

    Closure ``c = a_n - g0``, kinks ``c_i``, slope increments ``s_i``::

        W(a) = sum_i s_i/2 [c - c_i]_+^2 + k_t/2 |a_t|^2
        tau  = (sum_i s_i [c - c_i]_+,  k_t a_t)

    (on CoefficientFunctions the same functions are NGSolve B-splines, one
    table lookup per quadrature point instead of one ramp per kink, see
    :mod:`ngcontact.laws.law_evaluation`).  A ``"monotone_cubic"`` table:
    ``p(c)`` the C1 cubic Hermite interpolant and ``W(c) = int_{c_0}^c p``
    (the formulas of :mod:`ngcontact.laws.monotone_cubic`; on
    CoefficientFunctions a cubic B-spline with triple knots, the Bezier form
    of each piece).  The "all closed" surrogate is the table's first segment
    of nonzero slope, extended both ways.

    Attributes
    ----------
    closure
        ``c_i`` [length], strictly increasing.
    pressure
        ``p_i`` [stress], non-decreasing, ``p_0 = 0``.
    kt
        Linear tangential stiffness [stress / length].
    interpolation
        ``"linear"`` (the polyline) or ``"monotone_cubic"`` (module docstring).
    """

    closure: tuple[float, ...]
    pressure: tuple[float, ...]
    kt: float = 0.0
    interpolation: str = "linear"

    def __post_init__(self):
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        if c.ndim != 1 or len(c) < 2 or len(p) != len(c):
            raise ModelError("closure and pressure must be lists of the same length >= 2")
        if np.any(np.diff(c) <= 0):
            raise ModelError("closure must be strictly increasing")
        if np.any(np.diff(p) < 0):
            raise ModelError("pressure must be non-decreasing (a monotone law has a convex energy)")
        if p[0] != 0.0:
            raise ModelError("the first pressure must be 0 (contact starts there)")
        if np.all(p == 0):
            raise ModelError("the table carries no pressure")
        if self.kt < 0:
            raise ModelError("kt must be >= 0")
        if self.interpolation not in INTERPOLATIONS:
            raise ModelError(f"interpolation = {self.interpolation!r}: must be one of {', '.join(INTERPOLATIONS)}")

    def ramps(self) -> tuple[np.ndarray, np.ndarray]:
        """Kinks ``c_i`` and slope increments ``s_i`` of the polyline ``p(c) = sum s_i [c - c_i]_+`` through
        the table (the law itself when ``interpolation = "linear"``)."""
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        slopes = np.diff(p) / np.diff(c)
        return c[:-1], np.diff(np.concatenate([[0.0], slopes]))

    def node_slopes(self) -> np.ndarray:
        """``dp/dc`` at the nodes of the monotone cubic (:func:`ngcontact.laws.monotone_cubic.slopes`)."""
        return monotone_cubic.slopes(self.closure, self.pressure)

    @property
    def stiffness(self) -> float:
        """The largest slope ``dp/dc`` of the law."""
        c = np.asarray(self.closure, float)
        p = np.asarray(self.pressure, float)
        if self.interpolation == "monotone_cubic":
            return monotone_cubic.largest_slope(c, p, self.node_slopes())
        return float(np.max(np.diff(p) / np.diff(c)))

    def energy(self, a, g0=0.0, closed: bool = False):
        """``W(a)`` of the class docstring; with ``closed`` the first segment of nonzero slope, extended both ways."""
        c = a[0] - g0
        if not closed and (self.interpolation != "linear" or not is_numeric(c)):
            W = self._cubic_table(c, energy=True) if is_numeric(c) else self._splines()[1](c)
            return W + 0.5 * self.kt * sum(ai * ai for ai in a[1:]) if self.kt > 0 else W
        on = (lambda x: x) if closed else ramp
        kinks, slopes = self.ramps()
        if closed:
            first = next(k for k, s in enumerate(slopes) if s != 0)
            kinks, slopes = kinks[first:first + 1], slopes[first:first + 1]
        W = sum(0.5 * s * on(c - ci) ** 2 for ci, s in zip(kinks, slopes) if s != 0)
        if self.kt > 0:
            W = W + 0.5 * self.kt * sum(ai * ai for ai in a[1:])
        return W

    def traction(self, a, g0=0.0) -> list:
        """``tau = (p(c), k_t a_t)``."""
        c = a[0] - g0
        if not is_numeric(c):
            p = self._splines()[0](c)
        elif self.interpolation != "linear":
            p = self._cubic_table(c, energy=False)
        else:
            kinks, slopes = self.ramps()
            p = sum(s * ramp(c - ci) for ci, s in zip(kinks, slopes) if s != 0)
        return [p] + [self.kt * ai for ai in a[1:]]

    @property
    def holds_tangentially(self) -> bool:
        return self.kt > 0

    def export_rows(self) -> ExportRows:
        """The polyline itself, :meth:`ramps` (a ``"monotone_cubic"`` table has no exact polyline: it is the
        two-scale loop's own law and is not exported); stick slope ``k_t``, no ``K0``."""
        if self.interpolation != "linear":
            return super().export_rows()
        kinks, slopes = self.ramps()
        return ExportRows(kinks=kinks, slopes=slopes, stick_slope=float(self.kt))

    def _splines(self):
        """``(p, W)`` as B-splines, by the interpolation (:mod:`ngcontact.laws.law_evaluation`)."""
        if self.interpolation == "linear":
            return table_splines(self.closure, self.pressure)
        return cubic_splines(self.closure, self.pressure, tuple(self.node_slopes()))

    def _cubic_table(self, c, energy: bool):
        """``p(c)`` or ``W(c)`` of a monotone cubic table at closures ``c`` (NumPy;
        :mod:`ngcontact.laws.monotone_cubic`), 0 below ``c_0`` and continued with the last node slope beyond
        ``c_last``."""
        cn = np.asarray(self.closure, float)
        pn = np.asarray(self.pressure, float)
        m = self.node_slopes()
        x = np.asarray(c, float)
        d = x - cn[-1]
        if energy:
            inside = monotone_cubic.integral(cn, pn, m, x)
            beyond = float(monotone_cubic.integral(cn, pn, m, cn[-1])) + pn[-1] * d + 0.5 * m[-1] * d * d
        else:
            inside, beyond = monotone_cubic.evaluate(cn, pn, m, x), pn[-1] + m[-1] * d
        return np.where(x < cn[0], 0.0, np.where(x > cn[-1], beyond, inside))
