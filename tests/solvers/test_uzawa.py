"""Uzawa's iteration on a problem whose solution is known: one spring pressed against a stop.

A spring of stiffness ``s`` loaded by ``f`` and held by the constraint
``u <= g`` (``f > s g``): the multiplier is ``lambda = f - s g`` and
``u = g``.  With the augmentation ``k`` the primal solve of a pass is
``u = (f - lambda + k g) / (s + k)`` when the augmented pressure is positive,
so the error in ``lambda`` contracts by ``s / (s + k)`` per pass: slowly for a
soft augmentation.  Requirements, one sentence each:

* the iteration reaches the known multiplier and position for any ``k``;
* without ``stiffen`` a soft augmentation does not converge within the pass
  limit and the failure carries its history;
* with ``stiffen`` the slow passes raise ``k`` until the passes contract,
  the passes that raised it are recorded, and a refusing ``stiffen`` changes
  nothing.
"""
import pytest

from ngcontact.errors import ConvergenceError
from ngcontact.solvers.uzawa import uzawa

S, F, G = 1.0, 3.0, 1.0          # lambda = F - S G = 2, u = G


def spring(k: float):
    """The state, a primal solve and a multiplier update of the spring with augmentation ``state["k"] = k``."""
    state = {"k": k, "lam": 0.0, "u": 0.0}

    def solve(j):
        lam, k = state["lam"], state["k"]
        u = (F - lam + k * G) / (S + k)
        state["u"] = u if lam + k * (u - G) > 0 else F / S
        return {"iterations": 1}

    def update():
        lam, k = state["lam"], state["k"]
        new = max(lam + k * (state["u"] - G), 0.0)
        state["lam"] = new
        return {"penetration": max(state["u"] - G, 0.0) / G, "change": abs(new - lam) / (k * G)}

    return state, solve, update


@pytest.mark.parametrize("k", [1e-2, 1e3])
def test_uzawa_reaches_the_stop_for_any_augmentation(k):
    state, solve, update = spring(k)

    def stiffen():
        state["k"] *= 10.0
        return True
    hist = uzawa(solve, update, rtol=1e-12, max_iter=200, stiffen=stiffen)
    assert state["lam"] == pytest.approx(F - S * G, rel=1e-10) and state["u"] == pytest.approx(G, rel=1e-10)
    assert hist["uzawa_iterations"] <= 20
    assert bool(hist["stiffened"]) == (k < 1.0)     # at k = 1e3 the passes contract by 1e-3


def test_a_soft_augmentation_without_stiffening_fails_with_its_history():
    _, solve, update = spring(1e-2)
    with pytest.raises(ConvergenceError, match="did not converge in 200 passes") as err:
        uzawa(solve, update, rtol=1e-12, max_iter=200)
    assert len(err.value.history["penetrations"]) == 200


def test_a_refusing_stiffen_changes_nothing():
    state, solve, update = spring(1e-2)
    calls = []
    with pytest.raises(ConvergenceError):
        uzawa(solve, update, rtol=1e-12, max_iter=50, stiffen=lambda: calls.append(1) is not None)
    assert state["k"] == 1e-2 and len(calls) == 49


def quantized_spring(k: float, step: float):
    """The spring whose primal solve resolves ``u`` only to ``step`` (the round-off of a real solve): a
    multiplier update that moves the exact ``u`` by less leaves the state as it was, in no Newton step."""
    state, solve, update = spring(k)

    def coarse_solve(j):
        before = state["u"]
        solve(j)
        rounded = round(state["u"] / step) * step
        if abs(rounded - before) < 0.5 * step:
            state["u"] = before
            return {"iterations": 0}
        state["u"] = rounded
        return {"iterations": 1}
    return state, coarse_solve, update


def test_passes_that_no_longer_move_the_state_stop_at_the_round_off_floor():
    """A solve resolving u to 3e-13 G: the measures stall near it; the iteration stops there, converged at the
    floor, within FLOOR_GROWTH times rtol, instead of cycling to the pass limit."""
    state, solve, update = quantized_spring(1e3, 3e-13 * G)
    hist = uzawa(solve, update, rtol=1e-13, max_iter=200)
    assert hist["at_floor"] and hist["uzawa_iterations"] < 20
    assert max(hist["penetrations"][-1], hist["changes"][-1]) <= 1e3 * 1e-13
    assert state["u"] == pytest.approx(G, rel=1e-11)


def test_a_stalled_pass_far_from_the_tolerance_is_no_convergence():
    """A solve that cannot resolve u below 7e-7 G leaves measures far above FLOOR_GROWTH * rtol: failure."""
    _, solve, update = quantized_spring(1e3, 7e-7 * G)
    with pytest.raises(ConvergenceError, match="did not converge in 30 passes") as err:
        uzawa(solve, update, rtol=1e-13, max_iter=30)
    assert not err.value.history["at_floor"]
