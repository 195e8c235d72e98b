"""The forms of the spectral refinement's estimate, and the estimates that may be loose by much.

:mod:`~ngcontact.cell.spectral.refinement` estimates the error of each headline quantity of a load on the
reported grid ``k`` in one of four forms, which the report names: Richardson's tail with the observed rate
(:data:`RICHARDSON`), the guarded geometric tail (:data:`GUARDED`), the estimate of a deferred grid plus the
last difference (:data:`CARRIED`), or the share of contact islands too narrow for the grid
(:data:`~ngcontact.cell.spectral.contact_edges.ISLAND`).  Each is a bound on its own argument; none is sharp
where the error of grid ``k`` is far below the differences that bound it.

The last two differences ``d_(k-1)``, ``d_k`` (``d_k = q_k - q_(k-1)``) say how large that error is in the
model every form rests on: where the levels beyond ``k`` contract as the last one did, by ``rho = |d_k| /
|d_(k-1)|`` (held to at most first order in the grid step, ``rho <= 1/2``: a slower last step is taken at
first order), the error ``e_k = sum_(j > k) d_j`` is the tail left by the last difference,
``|d_k| rho / (1 - rho)`` (:func:`tail_left`).  An estimate above :data:`LOOSE` times that tail (in the
quantity's measure, :func:`~ngcontact.cell.cell_solution.measure`) therefore rests on something else than
the last step: an earlier, larger difference (the guarded envelope: a first-order stretch before a faster
regime, such as the 2D edges' quartic once it locates them, or an error that crossed zero), the deferred
grid's estimate carried over, or an unresolved island's share.  The error may then lie below the estimate
by more than :data:`LOOSE` times, and the estimate is flagged with its reason (:func:`loose_flags`), listed
in the report (:func:`loose_remarks`).  The flag never lowers an estimate: a fast last step is often followed
by a first-order one (on Westergaard's sinusoid at a twentieth of its closing pressure the quartic's errors
fall by about 16 per doubling twice, then by 2), and an earlier difference bounds the error where the last
one vanished by coincidence (a stall, a symmetric cell).  Richardson's form states its rate and holds it to
first order on purpose (the same sinusoid) and is not flagged.  An estimate within :data:`LOOSE` times the
tail may still exceed an error that is small by chance (one that crosses zero on the reported grid), which
no difference shows.
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
#: the slowest contraction per level the error left by the last difference is taken at (first order)
FIRST_ORDER = 0.5
#: why, per form of the estimate (module docstring)
WHY_LOOSE = {GUARDED: "an earlier difference bounds it", CARRIED: "carried from the deferred grid",
             ISLAND: "an unresolved island's share bounds it"}


def loose_flags(history: list[dict[str, Any]], estimates: list[dict[str, float]], forms: list[dict[str, str]]
                ) -> list[dict[str, str]]:
    """Per load, the estimates of the last level of ``history`` above :data:`LOOSE` times the error that the
    last contraction would leave (:func:`tail_left`, in the quantity's measure), with the reason (module
    docstring)."""
    last = history[-1]
    flags = []
    for k, per_load in enumerate(estimates):
        now, out = last["headline"][k], {}
        for name, e in per_load.items():
            size = scale(name, now, last["whole_surface"])
            left, rate = tail_left([h["headline"][k][name] / size for h in history[-3:]])
            if forms[k][name] != RICHARDSON and e > LOOSE * left:
                ratio = f"{e / left:.3g} times" if left > 0 else "far above"
                out[name] = (f"{ratio} the tail the last difference leaves at its rate {rate:.2g}: "
                             f"{WHY_LOOSE.get(forms[k][name], WHY_LOOSE[GUARDED])}")
        flags.append(out)
    return flags


def tail_left(values: list[float]) -> tuple[float, float]:
    """The error of the last of ``values`` (two or three levels of a quantity in its measure) that the last
    difference ``d_k`` leaves where the next differences contract as the last one did, ``|d_k| rho / (1 -
    rho)``, with ``rho = |d_k| / |d_(k-1)|`` held to at most first order (:data:`FIRST_ORDER`: then
    ``|d_k|``, as with two levels only), and that rate."""
    d = [abs(b - a) for a, b in zip(values[:-1], values[1:])]
    rate = min(d[-1] / d[-2], FIRST_ORDER) if len(d) > 1 and d[-2] > 0 else FIRST_ORDER
    return d[-1] * rate / (1.0 - rate), rate


def loose_remarks(flags: list[dict[str, str]]) -> list[str]:
    """The report's remark listing the flags of :func:`loose_flags`, none without flags."""
    listed = [f"load {k} {name} ({why})" for k, per_load in enumerate(flags) for name, why in per_load.items()]
    return [f"may exceed the error by more than {LOOSE:g} times: " + ", ".join(listed)] if listed else []
