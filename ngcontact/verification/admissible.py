"""Admissible arguments of the closed-form solutions, and the form of their results.

Shared by :mod:`~ngcontact.verification.moduli`,
:mod:`~ngcontact.verification.westergaard`,
:mod:`~ngcontact.verification.hertz`, :mod:`~ngcontact.verification.lame`
and :mod:`~ngcontact.verification.laminate`; not part of their interface.

An inadmissible argument (a modulus <= 0, Poisson's ratio outside
``(-1, 0.5)``, a negative pressure) raises
:class:`ngcontact.errors.ModelError` naming the argument, its value and what
is allowed.  A result evaluated at a scalar position is a Python ``float``,
at an array of positions an array of the same shape.
"""
from __future__ import annotations

import numpy as np

from ngcontact.errors import ModelError


def _positive(name: str, value: float) -> None:
    if not value > 0:
        raise ModelError(f"{name} = {value!r}: must be > 0")


def _nonnegative(name: str, value: float) -> None:
    if not value >= 0:
        raise ModelError(f"{name} = {value!r}: must be >= 0")


def _poisson(name: str, value: float) -> None:
    if not -1.0 < value < 0.5:
        raise ModelError(f"{name} = {value!r}: must lie in (-1, 0.5)")


def _out(value):
    """A 0-d result as a Python float, arrays unchanged."""
    value = np.asarray(value, dtype=float)
    return float(value) if value.ndim == 0 else value
