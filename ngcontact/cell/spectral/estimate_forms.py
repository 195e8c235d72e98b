"""The forms of the spectral refinement's estimate, and the estimates that may be loose by much.

:mod:`~ngcontact.cell.spectral.refinement` estimates the error of each headline quantity of a load on the
reported grid ``k`` in one of four forms, which the report names: Richardson's tail with the observed rate
(:data:`RICHARDSON`), the guarded geometric tail (:data:`GUARDED`), the estimate of a deferred grid plus the
last difference (:data:`CARRIED`), or the share of contact islands too narrow for the grid
(:data:`~ngcontact.cell.spectral.contact_edges.ISLAND`).  Each is a bound on its own argument; none is sharp
where the error of grid ``k`` is far below the differences that bound it.

The last difference ``d_k = q_k - q_(k-1)`` says how large that error may be at least in the model every
form rests on: where the levels beyond ``k`` contract at least at first order in the grid step (each next
difference at most half the one before), the error ``e_k = sum_(j > k) d_j`` is of the size of ``|d_k|`` or
below.  An estimate above :data:`LOOSE` times ``|d_k|`` (in the quantity's measure,
:func:`~ngcontact.cell.cell_solution.measure`) therefore rests on something else than the last step: an
earlier, larger difference (the guarded envelope: a first-order stretch before a faster regime, such as the
2D edges' quartic once it locates them, or an error that crossed zero), the deferred grid's estimate
carried over, or an unresolved island's share.  The error may then lie below the estimate by more than
:data:`LOOSE` times, and the estimate is flagged with its reason (:func:`loose_flags`), listed in the
report (:func:`loose_remarks`).  The flag never lowers an estimate: an earlier difference bounds the error
where the last one vanished by coincidence (a stall, a symmetric cell).  Richardson's form is at most
``SPREAD rho / (1 - rho)`` times ``|d_k|`` (the rate ``rho`` held to the guarded cap) and is not flagged; an
estimate within :data:`LOOSE` times ``|d_k|`` may still exceed an error that is small by chance (one that
crosses zero on the reported grid), which no difference shows.
"""
from __future__ import annotations

from typing import Any

from ngcontact.cell.cell_solution import scale
from ngcontact.cell.spectral.contact_edges import ISLAND

#: the forms of the estimate, as the report names them (:data:`CARRIED`: after a deferred stop, module
#: docstring of :mod:`~ngcontact.cell.spectral.refinement`)
RICHARDSON, GUARDED, CARRIED = "Richardson", "guarded", "carried"
#: an estimate above this many times the last difference of its quantity is flagged (module docstring)
LOOSE = 10.0
#: why, per form of the estimate (module docstring)
WHY_LOOSE = {GUARDED: "an earlier difference bounds it, and the error may have fallen as fast as the last one",
             CARRIED: "carried from the deferred grid, whose error may have fallen as fast as the last difference",
             ISLAND: "an unresolved island's share bounds it, whatever the island's true width below it"}


def loose_flags(history: list[dict[str, Any]], estimates: list[dict[str, float]], forms: list[dict[str, str]]
                ) -> list[dict[str, str]]:
    """Per load, the estimates of the last level of ``history`` above :data:`LOOSE` times the last difference
    of their quantity (in its measure), with the reason (module docstring)."""
    last, before = history[-1], history[-2]
    flags = []
    for k, per_load in enumerate(estimates):
        now, then, out = last["headline"][k], before["headline"][k], {}
        for name, e in per_load.items():
            d = abs(now[name] - then[name]) / scale(name, now, last["whole_surface"])
            if e > LOOSE * d:
                ratio = f"{e / d:.3g} times the last difference" if d > 0 else "the last difference vanished"
                out[name] = f"{ratio}: {WHY_LOOSE.get(forms[k][name], WHY_LOOSE[GUARDED])}"
        flags.append(out)
    return flags


def loose_remarks(flags: list[dict[str, str]]) -> list[str]:
    """The report's remark listing the flags of :func:`loose_flags`, none without flags."""
    listed = [f"load {k} {name} ({why})" for k, per_load in enumerate(flags) for name, why in per_load.items()]
    return [f"may exceed the error by more than {LOOSE:g} times: " + ", ".join(listed)] if listed else []
