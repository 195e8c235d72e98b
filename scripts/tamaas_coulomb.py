"""Tamaas' frictional solvers on the spectral cell's exact Coulomb problem: posed alike, run, judged alike.

The like-for-like problem.  Tamaas (``PolonskyKeerTan``, ``Kato``, ``Condat``, ``BeckTeboulle``, on a
``surface_2d`` model) solves one elastic half-space (``E``, ``nu``) pressed by a rigid rough surface with
Coulomb friction ``|q| <= mu p``, under a prescribed mean traction ``(q_x, q_y, p)``, in one loading step.  The
spectral cell (:class:`~ngcontact.cell.spectral.layered_cell.SpectralCell`) poses the same problem when its
rough layer is that half-space and its counter layer is rigid: a layer of ``HALF_SPACE`` periods is a
half-space to round-off at every wave vector but the uniform one (its compliance differs by ``e^{-2 |k| h}``,
below 1e-21 at ``|k| h >= 8 pi``), and the uniform mode drops out under prescribed means; the counter is
``RIGID`` times stiffer.  Only the gap enters a small-slope problem, so the rough surface may sit on either
body: ``g0 = max(z) - z`` on ours, the heights ``z`` on Tamaas' rigid surface.  The two codes' layouts:
ours ``[y, x]`` with ``t = (q_x, q_y, p)`` the traction the lower (elastic) body exerts on the upper one,
Tamaas ``[x, y, component]`` with the traction on the half-space surface, so the tangential components change
sign (:func:`to_tamaas`, :func:`from_tamaas`); the mean shear ``S`` along ``x`` is ``shear = (S, 0)`` of a
:func:`~ngcontact.cell.cell_load.cell_load` and ``[S, 0, p]`` for Tamaas.

The discretizations agree except on the Nyquist modes (``k = -k`` on the grid): ours zeroes the
normal/tangential coupling there (a real symmetric operator cannot couple a mode to itself through an
imaginary entry), Tamaas takes the wave number ``-N/2`` (and on an odd grid it takes the wave number of the
even grid's Nyquist index, so an odd grid does not help).  On a rough map the solutions therefore differ by
about a percent in the tangential traction and on a few points of the stick set; on the same operator
(:func:`tamaas_operator`) the solvers agree to their tolerance (``tests/cell/test_tamaas_coulomb.py``).

The judge.  Tamaas stops on its own error measure, which for ``PolonskyKeerTan`` does not vanish at the
classical Coulomb solution (on 64^2 it levels off at 3.8e-8 while the traction has converged to round-off),
so its tolerance cannot be matched to ours.  Every solution is judged instead by the spectral cell's own
stopping measure (:mod:`ngcontact.solvers.active_set_newton`): the residual of the proximal fixed point
``|t - prox(t - (K t + b) / L)|_max L / ptp(g0)`` with Coulomb's threshold ``mu p`` of the proximal step and
the prescribed means, ``K t`` taken from each code's own operator (:func:`fixed_point_residual`), and each Tamaas
solver is run for a fixed number of steps (its tolerance out of reach) chosen by :func:`next_steps` until
that residual meets ours.
"""
from __future__ import annotations

import math
import time

import numpy as np

#: thickness of the layer standing for a half-space, in periods
HALF_SPACE = 4.0
#: stiffness of the rigid counter body relative to the half-space
RIGID = 1e12
SOLVERS = ("PolonskyKeerTan", "Condat", "Kato", "BeckTeboulle")
#: a Tamaas tolerance no solver meets: the runs stop at their step count
UNREACHABLE = 1e-300
#: a solver whose residual falls by less than this factor when its steps double stalls
STALL_FACTOR = 0.5


def halfspace_cell(z: np.ndarray, E: float, nu: float, mu: float, tol: float, max_iter: int = 100000):
    """The spectral cell of an elastic half-space (``E``, ``nu``) and a rigid counter on the map ``z`` (``[y, x]``),
    exact Coulomb friction ``mu``."""
    from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
    from ngcontact.laws.friction import Coulomb
    n = z.shape[0]
    return SpectralCell(dim=3, period=1.0, grid=n, rough=Layer(E, nu, HALF_SPACE),
                        counter=Layer(RIGID * E, nu, HALF_SPACE), gap=z.max() - z, k_n=1.0, enforcement="exact",
                        tol=tol, max_iter=max_iter, friction=Coulomb(w=None, mu=mu))


def to_tamaas(t: np.ndarray) -> np.ndarray:
    """Our stacked tractions ``(3, ny, nx)`` in Tamaas' layout ``(nx, ny, 3)`` and sign (module docstring)."""
    return np.ascontiguousarray(np.stack([-t[0].T, -t[1].T, t[2].T], axis=-1))


def from_tamaas(T: np.ndarray) -> np.ndarray:
    """Tamaas' tractions (or displacements) ``(nx, ny, 3)`` in our layout and sign."""
    return np.stack([-T[..., 0].T, -T[..., 1].T, T[..., 2].T])


def gradient_from_tamaas(U: np.ndarray, g0: np.ndarray) -> np.ndarray:
    """``K t + b`` of our problem from Tamaas' surface displacement ``U = K_T T`` (its mean dropped, as the prescribed
    means drop the uniform mode of ``K``), ``b = (0, 0, g0)``."""
    g = from_tamaas(U - U.reshape(-1, 3).mean(axis=0))
    g[2] += g0
    return g


def fixed_point_residual(t: np.ndarray, grad: np.ndarray, L: float, scale: float, mu: float, pressure: float,
                         shear: float) -> float:
    """``|t - prox(t - grad / L)|_max L / scale``: the spectral cell's stopping measure of exact Coulomb friction
    (threshold ``mu p`` of the proximal step, mean pressure ``pressure``, mean shear ``(shear, 0)``)."""
    from ngcontact.cell.spectral.traction_constraints import TractionConstraints
    h = TractionConstraints(t.shape[1:], lambda p: mu * p, L, None, None, pressure, np.array([-shear, 0.0]),
                            slope=mu)
    t_hat, _ = h.prox(t - grad / L, ())
    return float(np.max(np.abs(t - t_hat))) * L / scale


def fractions(t: np.ndarray, mu: float) -> tuple[float, float]:
    """``(contact, stick)``: the shares of grid points pressed (``p > 0``) and pressed and sticking
    (``|q| < mu p (1 - 1e-6)``, the same rule for both codes)."""
    p = t[2]
    pressed = p > 0
    stick = pressed & (np.sqrt(t[0] ** 2 + t[1] ** 2) < mu * p * (1 - 1e-6))
    return float(np.mean(pressed)), float(np.mean(stick))


def traction_difference(t: np.ndarray, ref: np.ndarray) -> float:
    """``|t - ref|_2 / |ref|_2`` over all components and points."""
    return float(np.linalg.norm(t - ref) / np.linalg.norm(ref))


def _model(n: int, E: float, nu: float):
    import tamaas as tm
    tm.set_log_level(tm.LogLevel.error)
    model = tm.ModelFactory.createModel(tm.model_type.surface_2d, [1.0, 1.0], [n, n])
    model.E, model.nu = E, nu
    return model


def run_tamaas(name: str, z: np.ndarray, E: float, nu: float, mu: float, pressure: float, shear: float,
               steps: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Tamaas' solver ``name`` for ``steps`` steps on the map ``z`` (``[y, x]``): ``(t, grad, seconds)`` in our
    layout, ``grad = K t + b`` from Tamaas' own operator applied to its final traction, ``seconds`` from the model's
    creation to the solver's return."""
    import tamaas as tm
    if name not in SOLVERS:
        raise ValueError(f"Tamaas solver {name!r}: one of {SOLVERS}")
    t0 = time.perf_counter()
    model = _model(z.shape[0], E, nu)
    solver = getattr(tm, name)(model, np.ascontiguousarray(z.T), UNREACHABLE, mu)
    solver.max_iter = int(steps)
    solver.dump_freq = 10 ** 9
    solver.solve([shear, 0.0, pressure])
    seconds = time.perf_counter() - t0
    T = np.array(model.traction)
    U = np.zeros_like(T)
    model.operators["Westergaard::neumann"](T, U)
    return from_tamaas(T), gradient_from_tamaas(U, z.max() - z), seconds


def tamaas_operator(n: int, E: float, nu: float):
    """``t -> K_T t``: Tamaas' half-space operator on our stacked tractions ``(3, n, n)`` (its mean dropped)."""
    import tamaas as tm
    model = _model(n, E, nu)
    tm.PolonskyKeerTan(model, np.zeros((n, n)), 1e-12, 0.5)      # registers the operator on the model
    op = model.operators["Westergaard::neumann"]

    def apply(t: np.ndarray) -> np.ndarray:
        U = np.zeros((n, n, 3))
        op(to_tamaas(t), U)
        return from_tamaas(U - U.reshape(-1, 3).mean(axis=0))
    return apply


def next_steps(attempts: list[tuple[int, float]], tol: float, first: int) -> int | None:
    """The step count of the next run of a Tamaas solver, from its runs so far ``(steps, residual)``; ``None``: stop.

    First ``first`` steps, then twice as many; then the count at which the residual, falling geometrically as between
    the last two runs, meets ``tol`` (10 % added, at least 10 % more than the last run, at most twice as many).  Stops
    when the last run met ``tol``, when a run did not lower the residual, or when doubling the first run's steps cut
    it by less than ``STALL_FACTOR`` (the solver stalls).
    """
    if not attempts:
        return first
    n1, r1 = attempts[-1]
    if r1 <= tol:
        return None
    if len(attempts) == 1:
        return 2 * n1
    n0, r0 = attempts[-2]
    if not 0 < r1 < (STALL_FACTOR * r0 if len(attempts) == 2 else r0):
        return None
    rate = (math.log(r0) - math.log(r1)) / (n1 - n0)
    guess = n1 + math.log(r1 / tol) / rate
    return int(min(2 * n1, max(1.1 * n1, 1.1 * guess)))
