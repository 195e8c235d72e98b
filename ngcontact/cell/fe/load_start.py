"""The start of each load of the cell problem: which predictor starts it, and the rigid continuation.

The Newton solve of the cell problem (paper eqs. 49-51 in the penalized
variational form of eq. 65, :mod:`ngcontact.cell.fe.cell_problem`) starts
every load from a state :func:`start_load` puts in place:

* a first load under a prescribed pressure: the rigid predictor's state
  (:mod:`ngcontact.cell.fe.predictor`: the counter translated to carry the
  pressure on a Winkler layer), or every point closed (``"closed"``), moved
  on by the problem's :class:`Predictor` where it has one (``"predictor"``:
  e.g. onto the spectral twin's contact set,
  :class:`ngcontact.cell.spectral_start.SpectralStart`); with exact
  enforcement the multiplier starts afresh (:func:`start_multiplier` under
  friction);
* a later frictionless load whose tangential load changed: the rigid
  predictor for the whole traction
  (:func:`ngcontact.cell.fe.predictor.rigid_translation`);
* a later load with friction, or where that has no regular minimizer: the
  rigid continuation below.

A frictionless cell with a predictor solves every load of a sweep, and
every mesh of a graded solve, as a first load (:func:`starts_afresh`).

*Later loads with a tangential change under friction*, or where the
restart finds no regular minimizer (continuation from the previous load's
solution): the rigid continuation.  Before the Newton solve, the energy is minimized over the
far-face translations ``U_i`` that the load leaves free (a traction is
prescribed), the fluctuations frozen at the previous solution:

    U = argmin_U Pi(u_r, u_c, U)    (u_r, u_c fixed),

a problem in ``dim`` unknowns (Newton on the same energy with only those
dofs free; its tangent is the ``dim x dim`` block of ``Pi''`` in ``U``).  A
load increment then first moves the counter as a rigid body on the deformed
rough surface, which is where a shear load near the frictionless limit
goes: on the sinusoid a shear step with ``tau/p`` near the largest
slope slides the counter a quarter period and lifts it, which Newton
from the previous state reaches only after many steps, each moving the
contact set a little, and from the rigid continuation in a few.  The continuation's steps
are reported as a Newton history of their own (``"stage":
"rigid_continuation"``) and count towards the load.  Where the frozen
problem has no minimizer (the translation is free of energy, e.g. no
contact) its Newton raises; the previous state is restored and the
continuation is skipped.

Secant or tangent extrapolation of the whole state from earlier loads
gains little: the state is not
smooth in the load where the contact set changes, and the tangent predictor
is the first Newton step itself.
"""
from __future__ import annotations

import logging
from typing import Protocol

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.fe.predictor import rigid_translation, set_start
from ngcontact.errors import ConvergenceError
from ngcontact.solvers.newton import minimize

log = logging.getLogger(__name__)


#: the starts of a first load under a prescribed pressure (:func:`start_load`)
STARTS = ("rigid", "closed", "predictor")


class Predictor(Protocol):
    """A start of a first load under a prescribed pressure, better than the rigid predictor's.

    Passed to the cell problem by its builder; the cell problem calls it after putting the rigid (or
    closed) start in place.  :class:`ngcontact.cell.spectral_start.SpectralStart` is one: the contact set of
    the cell's spectral twin.
    """

    def check(self, mesh) -> None:
        """Raise ``ValueError`` where the predictor cannot serve a cell meshed so."""

    def start(self, problem, load: CellLoad) -> dict:
        """Move ``problem``'s state on from the rigid start; return the start's record for the report
        (``{"kind": ...}``)."""

    def edges(self, load: CellLoad) -> tuple[np.ndarray, float] | None:
        """The contact edges of ``load`` as far as the predictor knows them (a 2D cell), and their accuracy,
        or ``None``."""


def check_start(start: str | None, predictor: Predictor | None, enforcement: str) -> str:
    """The start of a cell problem's first loads: ``start``, by default ``"predictor"`` with a
    ``predictor`` and ``"rigid"`` without.

    Raises
    ------
    ValueError
        ``start`` is none of :data:`STARTS`, or ``"predictor"`` without a predictor.
    """
    if start is None:
        start = "rigid" if predictor is None else "predictor"
    if start not in STARTS:
        raise ValueError(f"start = {start!r}: must be 'rigid', 'closed' or 'predictor'")
    if start == "predictor" and predictor is None:
        raise ValueError("start = 'predictor' needs a predictor (the cell's spectral twin), none given "
                         f"(enforcement {enforcement!r})")
    return start


def starts_afresh(problem, load: CellLoad) -> bool:
    """Whether a sweep solves ``load`` as a first load: a frictionless cell with a predictor, under a
    prescribed pressure (its energy has one minimizer, and the predicted contact set is nearer the
    solution's than the previous load's: :meth:`~ngcontact.cell.fe.cell_problem.CellProblem.sweep`)."""
    return problem.model.friction is None and _predicted(problem, load)


def _predicted(problem, load: CellLoad) -> bool:
    """Whether a first ``load`` starts from the problem's predictor (a pressure prescribed)."""
    return problem.start == "predictor" and problem.predictor is not None and load.jump[problem.dim - 1] is None


def start_load(problem, load: CellLoad, free, first: bool, before: tuple[float, ...]) -> tuple[dict | None,
                                                                                             dict | None]:
    """Put the start of ``load`` (its values applied) into ``problem.gfu`` (module docstring).

    A first load under a prescribed pressure: the rigid or closed start (:func:`set_start`), moved onto the
    spectral twin's contact set where the problem starts so
    (:func:`ngcontact.cell.spectral_start.spectral_start`); with exact enforcement the multiplier starts
    afresh (:func:`start_multiplier` under friction).  A later load whose tangential load changed
    (``before``: :func:`tangential_load` of the previous one): frictionless, the rigid predictor for the
    whole traction (:func:`rigid_translation`); with friction, or where that has no minimizer, the rigid
    continuation, whose steps count.  ``free``: the load's free dofs.

    Returns the spectral start's record and the rigid continuation's history (either ``None``).
    """
    if not first:
        if tangential_load(problem) != before and rigid_translation(problem, load, free):
            return None, None
        return None, rigid_continuation(problem, free, before)
    if load.jump[problem.dim - 1] is None:
        set_start(problem, load)
    if problem.multiplier is not None:
        # a first load starts afresh: a multiplier left by an earlier load (a table of independent cell
        # solves) held against the rigid predictor's state could leave no point in contact, the bodies
        # afloat and the tangent singular
        problem.multiplier.set_point_values(np.zeros(len(problem.multiplier.point_values())))
        problem.augmentation.Set(problem.model.k_n)      # as the scene gave it (Uzawa may have raised it)
        if problem.model.friction is not None:
            start_multiplier(problem, load)
    return (problem.predictor.start(problem, load) if _predicted(problem, load) else None), None


def start_multiplier(problem, load: CellLoad) -> None:
    """Uzawa's start under friction: the start state's contact pattern carrying the load's pressure.

    With ``lambda = 0`` the Coulomb threshold ``mu lambda`` would leave the
    tangential translation without stiffness.  The start state's augmented
    pressure ``k_n [J_n - g]_+`` gives where the contact is; it is scaled to
    the prescribed mean pressure, since the start state (the rigid predictor)
    penetrates by what the bodies would yield, far more than ``p / k_n``, and
    a multiplier that large opens the whole surface in the first solve.
    """
    m = problem.multiplier
    assert m is not None  # exact enforcement
    lam = np.maximum(m.at_points(problem.augmented_pressure), 0.0)
    tn = load.traction[problem.dim - 1]
    if tn is not None and lam.any():
        m.set_point_values(lam)
        carried = m.integrate(m.value)
        lam *= -tn * problem.area / carried
    m.set_point_values(lam)


def tangential_load(problem) -> tuple[float, ...]:
    """The applied tangential far-face tractions and translations: compare before and after a load change."""
    t = problem.dim - 1
    return (tuple(problem.traction[i].Get() for i in range(t))
            + tuple(problem.gfu.vec[problem.u_dofs[i]] for i in range(t)))


def rigid_continuation(problem, free, before: tuple[float, ...] | None = None) -> dict | None:
    """Minimize the energy over the free far-face translations, fluctuations frozen (module docstring).

    ``free`` is the BitArray of the load's free dofs; the translations
    ``U_i`` among them are the unknowns.  With ``before``
    (:func:`tangential_load` of the previous load), only a load whose
    tangential traction or prescribed tangential jump changed is continued
    (a normal increment is carried by the bodies' compliance, which the
    rigid translation does not see).  Runs Newton
    (:func:`ngcontact.solvers.newton.minimize`) on ``problem.energy`` with
    only those dofs free and the problem's tolerance and line search, and
    returns its history with ``"stage": "rigid_continuation"``, or ``None``
    (state unchanged) when the load was not continued or the frozen
    problem has no minimizer.
    """
    if before is not None and tangential_load(problem) == before:
        return None
    ndof = len(free)
    rigid = ng.BitArray(ndof)
    rigid.Clear()
    dofs = [i for i in problem.u_dofs if free[i]]
    if not dofs:
        return None
    for i in dofs:
        rigid.Set(i)
    saved = problem.gfu.vec.CreateVector()
    saved.data = problem.gfu.vec
    try:
        h = minimize(problem.energy(), problem.gfu, freedofs=rigid, rtol=problem.rtol, atol=problem.atol,
                     max_iter=problem.max_iter, inverse=problem.inverse,
                     line_search=problem.line_search).as_dict()
    except ConvergenceError as err:
        problem.gfu.vec.data = saved
        log.info("rigid continuation skipped: %s", err)
        return None
    h["stage"] = "rigid_continuation"
    log.debug("rigid continuation: %d steps, U = %s", h["iterations"],
              [problem.gfu.vec[i] for i in problem.u_dofs])
    return h
