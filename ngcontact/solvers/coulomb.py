"""Coulomb friction as a fixed point of Tresca problems, written once for every scale.

Coulomb's law ``G = mu p`` makes the friction threshold depend on the
contact pressure, so no energy of the coupled problem exists (paper Sec.
2, eqs. 16-17, and the homogenized ``G0 = mu0 [p]_+ + G0`` of eqs. 42-43).
Each pass freezes the pressure of the previous iterate, ``G_k = mu
p_{k-1}``, and minimizes the convex Tresca energy with that threshold:

    for k = 1, 2, ...:  u_k = argmin Pi_Tresca(u; G = mu p(u_{k-1}))

stopped at the first ``k`` with

    max |p_k - p_{k-1}|  <=  coulomb_rtol * max |p_k|

over the quadrature points of the contact surface (``coulomb_rtol`` of
the scene's ``[solver]``), or failing with :class:`ConvergenceError` after
``coulomb_max_iter`` passes.  The history has one format everywhere:
``{"coulomb_changes": [...], "coulomb_iterations": k}`` plus the Newton
histories of the passes.

Acceleration (opt-in, ``depth > 0`` and access to the state): once the
stick, slip and contact sets settle, each pass is one Newton step and the
map ``x -> u(G = mu p(x))`` from the frozen state to the Tresca solution is
affine, so the plain iteration converges linearly (by a constant factor
per pass, set by how strongly the pressure feeds back into the threshold).
Anderson mixing (Walker and Ni, SIAM J. Numer. Anal. 49, 2011) takes the
next frozen state as the combination of the last ``depth + 1`` Tresca
solutions ``g_j`` whose pressure residuals ``f_j = p(g_j) - p(x_j)``
combine to the least-squares smallest one:

    x_{k+1} = g_k - sum_j gamma_j (g_{j+1} - g_j),
    gamma = argmin || f_k - sum_j gamma_j (f_{j+1} - f_j) ||_2,

which on an affine map is GMRES and ends in a few passes.  The map is
only piecewise affine (points cross the Huber kink between stick and slip),
and on the rectangular valley it saves only a few passes per load (a
larger depth does no better).  The stopping
rule is unchanged and still honest: pass ``k`` freezes ``x_k``, and the
test compares the pressure of its Tresca solution with the pressure
``p(x_k)`` the threshold was taken from; the returned state is that Tresca
solution (never a mixed state).  A pass whose change grew restarts the
mixing from the last pair.
"""
from __future__ import annotations

import logging
from typing import Any, Callable

import numpy as np

from ngcontact.errors import ConvergenceError

log = logging.getLogger(__name__)

#: Earlier passes Anderson mixing combines where a caller opts in (module docstring)
MIXING_DEPTH = 3


def coulomb_fixed_point(freeze: Callable[[], None], tresca_solve: Callable[[], dict],
                        pressure: Callable[[], np.ndarray], *, rtol: float, max_iter: int,
                        state: tuple[Callable[[], np.ndarray], Callable[[np.ndarray], None]] | None = None,
                        depth: int = 0) -> dict[str, Any]:
    """Iterate Tresca solves with the threshold of the previous pressure until it stops changing.

    Parameters
    ----------
    freeze
        Copies the current state into the one the threshold ``mu p`` is
        evaluated at (the previous iterate).
    tresca_solve
        Solves the Tresca problem with the frozen threshold from the
        current state; returns its Newton history (a dict).
    pressure
        The contact pressure of the current state at the quadrature points
        of the contact surface.
    rtol, max_iter
        The stopping rule of the module docstring.
    state, depth
        ``(get, set)`` of the current state as a NumPy array and the number
        of earlier passes Anderson mixing combines (module docstring);
        without ``state`` or with ``depth = 0`` the plain fixed point.

    Returns
    -------
    dict
        ``newton`` (the passes' histories), ``coulomb_changes``,
        ``coulomb_iterations``.

    Raises
    ------
    ConvergenceError
        After ``max_iter`` passes, with the history.
    """
    history: dict[str, Any] = {"newton": [], "coulomb_changes": [], "coulomb_iterations": 0}
    mixing = Anderson(depth) if state is not None and depth > 0 else None
    p_old = pressure()
    change = scale = 0.0
    for k in range(1, max_iter + 1):
        freeze()
        history["newton"].append(tresca_solve())
        p_new = pressure()
        change = float(np.max(np.abs(p_new - p_old))) if p_new.size else 0.0
        scale = float(np.max(np.abs(p_new))) if p_new.size else 0.0
        history["coulomb_changes"].append(change)
        history["coulomb_iterations"] = k
        log.info("Coulomb fixed point %d: max |dp| = %.3e (max p %.3e)", k, change, scale)
        if change <= rtol * max(scale, 1e-300):
            return history
        if mixing is None or p_new.size == 0:
            p_old = p_new
            continue
        get, put = state  # type: ignore[misc]
        put(mixing.next(get(), p_new - p_old, change))
        p_old = pressure()
    raise ConvergenceError(f"Coulomb fixed point did not converge in {max_iter} passes: max pressure change "
                           f"{change:.3e} > coulomb_rtol {rtol:g} x max pressure {scale:.3e}; raise "
                           "solver.coulomb_max_iter or solver.coulomb_rtol, or widen the Huber width", history)


class Anderson:
    """Anderson mixing of the fixed point ``x -> g(x)`` with residuals ``f`` (module docstring).

    :meth:`next` takes the latest ``g_k``, its residual ``f_k`` and the size
    of the change it showed, and returns the next ``x_{k+1}``.
    """

    def __init__(self, depth: int):
        self.depth = depth
        self.g: list[np.ndarray] = []
        self.f: list[np.ndarray] = []
        self.change = np.inf

    def next(self, g: np.ndarray, f: np.ndarray, change: float) -> np.ndarray:
        if change > self.change:       # the mixing made it worse: restart from this pass
            self.g, self.f = [], []
        self.change = change
        self.g.append(np.array(g, copy=True))
        self.f.append(np.array(f, dtype=float, copy=True))
        del self.g[:-(self.depth + 1)], self.f[:-(self.depth + 1)]
        if len(self.f) < 2:
            return g
        dF = np.stack([b - a for a, b in zip(self.f[:-1], self.f[1:])], axis=1)
        dG = np.stack([b - a for a, b in zip(self.g[:-1], self.g[1:])], axis=1)
        gamma = np.linalg.lstsq(dF, f, rcond=1e-12)[0]
        return g - dG @ gamma
