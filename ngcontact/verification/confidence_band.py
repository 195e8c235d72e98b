"""The mean of an ensemble of cells and its 95 % confidence band.

``M`` realizations ``x_1 .. x_M`` of a random surface class give, per load,
independent samples of a cell result (contact fraction, ``k_n0``, effective
stiffness, mean closure).  The class's law is their expectation, estimated
by the sample mean ``m = (1/M) sum x_i``, with the standard error
``s / sqrt(M)`` (``s`` the sample standard deviation, ``ddof = 1``) and the
95 % confidence band of Student's t,

    m -+ t_{0.975, M-1} s / sqrt(M).

The band narrows like ``M^(-1/2)``: :func:`shrinkage` evaluates the standard
error of the mean of ``m = M, M/2, M/4, ...`` members on disjoint
sub-ensembles and fits its rate in ``m`` (least squares in log-log).  An ensemble whose members are
identical has ``s = 0`` and a band of zero width.
"""
from __future__ import annotations

import math

import numpy as np

#: Confidence level of the band.
LEVEL = 0.95


def band(samples) -> dict[str, np.ndarray]:
    """Mean, standard deviation, standard error, half-width and band ``(low, high)`` along axis 0.

    ``samples``: shape ``(M, ...)`` with ``M >= 2`` members.
    """
    x = np.asarray(samples, dtype=float)
    M = x.shape[0]
    if M < 2:
        raise ValueError(f"a confidence band needs at least 2 members, not {M}")
    mean = x.mean(axis=0)
    # members equal to the last bit have no spread: exactly zero, not a rounding residue of the mean
    same = np.all(x == x[0], axis=0)
    std = np.where(same, 0.0, x.std(axis=0, ddof=1))
    se = std / math.sqrt(M)
    from scipy import stats     # imported here: a second of a worker's start that solves ensemble members
    half = stats.t.ppf(0.5 + LEVEL / 2, M - 1) * se
    return {"mean": mean, "std": std, "standard_error": se, "half_width": half,
            "low": mean - half, "high": mean + half}


def nested_sizes(M: int, smallest: int = 4) -> list[int]:
    """Ensemble sizes ``M, M/2, M/4, ...`` (rounded down) not below ``smallest``, increasing."""
    sizes, m = [], M
    while m >= smallest:
        sizes.append(m)
        m //= 2
    return sorted(set(sizes))


def shrinkage(samples, sizes=None) -> dict:
    """Standard error of the mean of ``m`` members for each size ``m``, and its fitted rate in ``m``.

    ``samples`` shape ``(M, n)`` (``n`` loads).  The members are split into
    ``M // m`` disjoint sub-ensembles of ``m``; the variance of the mean of
    ``m`` is estimated by the sub-ensembles' mean sample variance over
    ``m`` (unbiased, and using every member at every size), and its square
    root is taken relative to the magnitude of the whole ensemble's mean,
    then averaged over the loads (loads with a zero mean are left out).
    ``rate`` is the least-squares slope of its logarithm against ``log m``:
    ``-1/2`` for independent members; ``None`` with fewer than two sizes or
    a zero error (identical members).
    """
    x = np.asarray(samples, dtype=float).reshape(len(samples), -1)
    M = x.shape[0]
    sizes = nested_sizes(M) if sizes is None else list(sizes)
    scale = np.abs(x.mean(axis=0))
    keep = scale > 0
    errors = []
    for m in sizes:
        groups = x[:(M // m) * m].reshape(M // m, m, -1)
        variance = np.mean([band(g)["std"] ** 2 for g in groups], axis=0)
        se = np.sqrt(variance / m)
        errors.append(float(np.mean(se[keep] / scale[keep])) if keep.any() else 0.0)
    rate = None
    if len(sizes) >= 2 and min(errors) > 0:
        rate = float(np.polyfit(np.log(sizes), np.log(errors), 1)[0])
    return {"members": sizes, "relative_standard_error": errors, "rate": rate}
