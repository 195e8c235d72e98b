"""The shape-preserving C1 cubic through monotone data (Fritsch and Carlson, SIAM J. Numer. Anal. 17, 1980).

Through nodes ``x_0 < x_1 < ... < x_n`` with values ``y_i`` and secants
``d_i = (y_i+1 - y_i) / h_i``, ``h_i = x_i+1 - x_i``, the piece on
``[x_i, x_i+1]`` is the cubic Hermite interpolant of the values and the node
slopes ``m_i``; with ``t = (x - x_i) / h_i``::

    y(x) = y_i H00(t) + h_i m_i H10(t) + y_i+1 H01(t) + h_i m_i+1 H11(t),
    H00 = 2t^3 - 3t^2 + 1,  H10 = t^3 - 2t^2 + t,  H01 = 3t^2 - 2t^3,  H11 = t^3 - t^2,

and its integral from ``x_0``::

    Y(x) = Y_i + h_i [y_i (t^4/2 - t^3 + t) + h_i m_i (t^4/4 - 2t^3/3 + t^2/2)
                      + y_i+1 (t^3 - t^4/2) + h_i m_i+1 (t^4/4 - t^3/3)],
    Y_i+1 - Y_i = h_i (y_i + y_i+1) / 2 + h_i^2 (m_i - m_i+1) / 12.

The slopes (:func:`slopes`) are Fritsch and Butland's choice: at an interior
node the weighted harmonic mean of the neighbouring secants,

    m_i = (w1 + w2) / (w1 / d_i-1 + w2 / d_i),   w1 = 2 h_i + h_i-1,  w2 = h_i + 2 h_i-1,

and 0 where the secants differ in sign or either is 0; at an end node the
one-sided three-point estimate, 0 if its sign is not the end secant's, and
at most three times the end secant where the data turn.  Monotone data
give a monotone interpolant, and there is no overshoot near a flat
stretch.  These are the slopes of SciPy's ``PchipInterpolator`` (tested
against it); written here because importing ``scipy.interpolate`` costs
a good share of a short two-scale run's time.

Used by the two-scale loop's cell table and its macro law (paper Sec. 3.5,
:class:`~ngcontact.laws.homogenized.TabulatedLaw` with ``interpolation =
"monotone_cubic"``).
"""
from __future__ import annotations

import numpy as np


def slopes(x, y) -> np.ndarray:
    """Node slopes ``m_i`` of the shape-preserving cubic through ``(x_i, y_i)`` (module docstring)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    h = np.diff(x)
    d = np.diff(y) / h
    m = np.zeros(len(x))
    if len(x) == 2:
        m[:] = d[0]
        return m
    w1, w2 = 2.0 * h[1:] + h[:-1], h[1:] + 2.0 * h[:-1]
    same = (np.sign(d[:-1]) * np.sign(d[1:])) > 0
    lo, hi = np.where(same, d[:-1], 1.0), np.where(same, d[1:], 1.0)
    m[1:-1] = np.where(same, (w1 + w2) / (w1 / lo + w2 / hi), 0.0)
    m[0] = _end(h[0], h[1], d[0], d[1])
    m[-1] = _end(h[-1], h[-2], d[-1], d[-2])
    return m


def _end(h0: float, h1: float, d0: float, d1: float) -> float:
    m = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)
    if np.sign(m) != np.sign(d0):
        return 0.0
    if np.sign(d0) != np.sign(d1) and abs(m) > 3.0 * abs(d0):
        return 3.0 * d0
    return float(m)


def _pieces(x, at):
    """Interval index and local coordinate ``t`` in ``[0, 1]`` of each point (clamped to the nodes' span)."""
    i = np.clip(np.searchsorted(x, at, side="right") - 1, 0, len(x) - 2)
    return i, np.clip((at - x[i]) / (x[i + 1] - x[i]), 0.0, 1.0)


def evaluate(x, y, m, at) -> np.ndarray:
    """The cubic at ``at``, held at the end values outside ``[x_0, x_n]``."""
    x, y, m = (np.asarray(v, float) for v in (x, y, m))
    i, t = _pieces(x, np.asarray(at, float))
    h = x[i + 1] - x[i]
    t2, t3 = t * t, t * t * t
    return (y[i] * (2.0 * t3 - 3.0 * t2 + 1.0) + h * m[i] * (t3 - 2.0 * t2 + t)
            + y[i + 1] * (3.0 * t2 - 2.0 * t3) + h * m[i + 1] * (t3 - t2))


def integral(x, y, m, at) -> np.ndarray:
    """``int_{x_0}^{at}`` of the cubic, for ``at`` in ``[x_0, x_n]`` (clamped to it)."""
    x, y, m = (np.asarray(v, float) for v in (x, y, m))
    h = np.diff(x)
    nodes = np.concatenate([[0.0], np.cumsum(0.5 * h * (y[:-1] + y[1:]) + h * h * (m[:-1] - m[1:]) / 12.0)])
    i, t = _pieces(x, np.asarray(at, float))
    hi = h[i]
    t2, t3, t4 = t * t, t * t * t, t * t * t * t
    return nodes[i] + hi * (y[i] * (0.5 * t4 - t3 + t) + hi * m[i] * (0.25 * t4 - 2.0 * t3 / 3.0 + 0.5 * t2)
                            + y[i + 1] * (t3 - 0.5 * t4) + hi * m[i + 1] * (0.25 * t4 - t3 / 3.0))


def largest_slope(x, y, m) -> float:
    """The largest derivative of the cubic on ``[x_0, x_n]``: at a node or at the vertex of a piece's
    quadratic derivative ``m_i + b t + a t^2``."""
    x, y, m = (np.asarray(v, float) for v in (x, y, m))
    d = np.diff(y) / np.diff(x)
    a = 3.0 * (m[:-1] + m[1:] - 2.0 * d)
    b = 6.0 * d - 4.0 * m[:-1] - 2.0 * m[1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.clip(np.where(a < 0, -b / (2.0 * a), 0.0), 0.0, 1.0)
    return float(max(np.max(m), np.max(m[:-1] + b * t + a * t * t)))
