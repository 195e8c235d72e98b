"""Convergence studies: refinement runners and observed rates.

An a-priori estimate ``e(h) ~ C h^q`` makes ``log e`` affine in ``log h``;
the observed rate ``q`` is the least-squares slope of ``log e`` against
``log h`` over at least three levels (a two-point slope hides a level that
is not yet asymptotic).  For order-``p`` Lagrange elements and a smooth
solution the expected rates are ``p + 1`` in L2 and ``p`` in the H1
seminorm.

A *level* is any callable ``level(order, refinements) -> dict`` that returns
at least ``ndof``, ``l2`` and ``h1``; the runners add the setting, order,
mesh size and wall time and return one row (a dict) per level.  Rows are
plain data, ready for CSV tables, reports and plots.
"""
from __future__ import annotations

import logging
import time
from typing import Callable, Sequence

import numpy as np

log = logging.getLogger(__name__)

ROW_KEYS = ("setting", "order", "level", "h", "ndof", "l2", "h1", "seconds")


def fit_rate(h: Sequence[float], error: Sequence[float]) -> float:
    """Least-squares slope of ``log error`` against ``log h``.

    Parameters
    ----------
    h, error
        Mesh sizes and errors of at least three levels, all > 0.

    Raises
    ------
    ValueError
        Fewer than three levels, or a non-positive value.
    """
    hh = np.asarray(h, dtype=float)
    e = np.asarray(error, dtype=float)
    if hh.shape != e.shape or hh.ndim != 1:
        raise ValueError(f"h and error must be 1-d of equal length, got {hh.shape} and {e.shape}")
    if len(hh) < 3:
        raise ValueError(f"{len(hh)} levels: a rate needs at least 3")
    if not (np.all(hh > 0) and np.all(e > 0) and np.all(np.isfinite(e))):
        raise ValueError("mesh sizes and errors must be finite and > 0")
    return float(np.polyfit(np.log(hh), np.log(e), 1)[0])


def expected_rates(order: int) -> dict:
    """``{"l2": p + 1, "h1": p}`` for elements of order ``p``."""
    return {"l2": float(order + 1), "h1": float(order)}


def h_refinement(level: Callable[[int, int], dict], *, setting: str, orders: Sequence[int],
                 maxh: float, refinements: Sequence[int]) -> list[dict]:
    """Rows for every order and every refinement level (h-refinement).

    Parameters
    ----------
    level
        ``level(order, refinements) -> {"ndof", "l2", "h1", ...}``.
    setting
        Label copied into each row.
    orders
        Polynomial orders.
    maxh
        Size of the generated mesh; level ``k`` has ``h = maxh / 2**k``.
    refinements
        Numbers of uniform refinements, one per level.
    """
    rows = []
    for p in orders:
        for k in refinements:
            rows.append(_timed_row(level, setting, p, k, maxh))
    return rows


def p_refinement(level: Callable[[int, int], dict], *, setting: str, orders: Sequence[int],
                 maxh: float, refinement: int) -> list[dict]:
    """Rows for increasing order on one fixed mesh (p-refinement)."""
    return [_timed_row(level, setting, p, refinement, maxh) for p in orders]


def _timed_row(level, setting, order, k, maxh) -> dict:
    t0 = time.perf_counter()
    out = dict(level(order, k))
    seconds = time.perf_counter() - t0
    row = {"setting": setting, "order": int(order), "level": int(k), "h": maxh / 2 ** k,
           "ndof": int(out.pop("ndof")), "l2": float(out.pop("l2")), "h1": float(out.pop("h1")),
           "seconds": seconds}
    row.update(out)
    log.info("%s p=%d h=%.4g: ndof %d, L2 %.3e, H1 %.3e (%.2f s)", setting, order, row["h"],
             row["ndof"], row["l2"], row["h1"], seconds)
    return row


def rates_by_order(rows: Sequence[dict]) -> dict:
    """Observed ``{order: {"l2": rate, "h1": rate}}`` from h-refinement rows.

    Orders with fewer than three levels are left out.
    """
    out = {}
    for p in sorted({r["order"] for r in rows}):
        sel = sorted((r for r in rows if r["order"] == p), key=lambda r: -r["h"])
        if len(sel) < 3:
            continue
        h = [r["h"] for r in sel]
        out[p] = {"l2": fit_rate(h, [r["l2"] for r in sel]),
                  "h1": fit_rate(h, [r["h1"] for r in sel])}
    return out


#: Fewest levels a rate is fitted over (:func:`fit_rate`).
MIN_LEVELS = 3


def judge(rows: Sequence[dict], floor: dict, tolerance: float) -> dict:
    """Observed rates over the levels above the round-off ``floor`` and the study's verdict.

    A level whose ``l2`` or ``h1`` error is at or below ``floor[norm]`` is
    round-off: it carries no rate.  Each order then falls into one class:

    * no level above the floor: the order reproduces the solution to
      round-off (exact); no rate, and no failure;
    * one or two levels above it: too few for a rate (:data:`MIN_LEVELS`);
      the order is neither verified nor failed, and the verdict says so;
    * three or more: the least-squares rate over them, compared with the
      expected ``p + 1`` (L2) and ``p`` (H1).

    Returns ``rates`` and ``expected_rates`` (per rated order),
    ``max_rate_deviation``, ``orders_at_roundoff``, ``orders_without_rate``
    (order -> number of levels above the floor), ``verified`` (every fitted
    rate within ``tolerance`` and at least one order rated or exact) and
    ``verdict``, one sentence naming what was and was not judged.
    """
    orders = sorted({r["order"] for r in rows})
    resolved = [r for r in rows if r["l2"] > floor["l2"] and r["h1"] > floor["h1"]]
    rates = rates_by_order(resolved)
    expected = {p: expected_rates(p) for p in rates}
    levels = {p: sum(r["order"] == p for r in rows) for p in orders}
    above = {p: sum(r["order"] == p for r in resolved) for p in orders}
    at_roundoff = [p for p in orders if above[p] == 0]
    without = {p: above[p] for p in orders if 0 < above[p] < MIN_LEVELS}
    deviation = max((abs(rates[p][n] - expected[p][n]) for p in rates for n in ("l2", "h1")), default=0.0)
    judged = bool(rates) or bool(at_roundoff)
    notes = []
    if rates:
        notes.append(f"every fitted rate lies within {tolerance:g} of the expected one" if deviation <= tolerance
                     else f"observed rates deviate by up to {deviation:.2f} from the expected ones (tolerance "
                     f"{tolerance:g})")
    if at_roundoff:
        notes.append(f"order{'s' if len(at_roundoff) > 1 else ''} {', '.join(map(str, at_roundoff))} "
                     f"reproduce{'' if len(at_roundoff) > 1 else 's'} the solution to round-off on every level "
                     "(exact: no rate to fit)")
    notes += [f"order {p}: {n} of {levels[p]} levels lie above the round-off floor, too few for a rate "
              f"({MIN_LEVELS} needed): start from a coarser mesh or take more levels" for p, n in without.items()]
    verdict = "; ".join(notes)
    return {"rates": rates, "expected_rates": expected, "max_rate_deviation": deviation,
            "orders_at_roundoff": at_roundoff, "orders_without_rate": without,
            "verified": judged and deviation <= tolerance,
            "verdict": verdict if judged else "no order could be judged: " + verdict}


def table(rows: Sequence[dict], keys: Sequence[str] = ROW_KEYS) -> tuple[list, list]:
    """``(header, rows as lists)`` for a CSV file."""
    return list(keys), [[r[k] for k in keys] for r in rows]
