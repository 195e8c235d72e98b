"""The Huber function that regularizes friction at both scales.

    huber(s, w) = s^2 / (2 w)   for 0 <= s <= w,
                  s - w / 2     for s > w,

a convex, once differentiable stand-in for ``|s|`` whose quadratic zone of
width ``w`` is the largest slip of a sticking point.  The friction energy is
``G huber(|J_t|, w)`` (paper eqs. 9 and 16 for the micro law; eqs. 42-43 for
the homogenized threshold ``G0``), its derivative the traction
``G J_t / max(|J_t|, w)`` (eq. 17).

Both forms are written in ``s^2`` so that no square root is taken near
``s = 0`` (its derivative would be singular there).  They accept plain
numbers and NumPy arrays (reports, checks) as well as NGSolve coefficient
functions (the energy forms), dispatching with :func:`if_positive` and
:func:`square_root`.
"""
from __future__ import annotations

import numpy as np


def is_numeric(*xs) -> bool:
    """True when every argument is a plain number or a NumPy array (not a CoefficientFunction)."""
    return all(isinstance(x, (int, float, np.ndarray, np.floating, np.integer)) for x in xs)


def if_positive(c, a, b):
    """``a`` where ``c > 0``, else ``b``: ``numpy.where`` for numbers, ``IfPos`` for coefficient functions."""
    if is_numeric(c, a, b):
        return np.where(np.asarray(c) > 0, a, b)
    import ngsolve as ng
    return ng.IfPos(c, a, b)


def square_root(x):
    """``sqrt(x)`` for numbers or coefficient functions."""
    if is_numeric(x):
        return np.sqrt(x)
    import ngsolve as ng
    return ng.sqrt(x)


def huber_of_square(s2, w):
    """``huber(s, w)`` of ``s = sqrt(s2)``, for ``s2 >= 0`` and width ``w > 0``."""
    return if_positive(s2 - w * w, square_root(if_positive(s2 - w * w, s2, w * w)) - w / 2, s2 / (2 * w))


def huber_slope(s2, w):
    """``huber'(s) / s = 1 / max(s, w)``: the friction traction per unit slip vector."""
    return if_positive(s2 - w * w, 1.0 / square_root(if_positive(s2 - w * w, s2, w * w)), 1.0 / w)


def huber(s, w):
    """``huber(s, w)`` of a nonnegative ``s`` (plots and checks)."""
    return huber_of_square(s * s, w)
