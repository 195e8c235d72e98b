"""This package's macro solution against CalculiX's on the same model: the numbers compared, and how far apart.

The harness of the client check of an exported law
(:mod:`ngcontact.export.calculix_check`): ccx solves a model of
:mod:`ngcontact.verification.calculix_model` with the exported
``*SURFACE INTERACTION``, this package solves the same geometry as a macro
problem whose interface reads the exported JSON table back.  This module
measures the macro solution, reads the same quantities off ccx's results and
tabulates them as rows ``(quantity, unit, ngcontact, ccx, |ngcontact - ccx| / |ccx|)``.

Two blocks (:class:`~ngcontact.verification.calculix_model.Blocks`): the
reaction force on the block's top per metre (both components), the mean
contact pressure (``|R_y| / L``), the pressure at the interface's centre and
its largest value, the shear at the centre; and :func:`stick`, the largest
``|tau| / (mu0 p)`` over ccx's contact nodes (below 1 the ccx interface
sticks everywhere, where its stick branch is the linear ``lambda = k_t0``
that both codes share).

Press fit (:class:`~ngcontact.verification.calculix_model.PressFit`): the
hoop force of the outer tube on its cut ``x = 0`` [N/m], the radial
displacements of the mantle and the bore at 45 degrees [m], the contact
pressure at 45 degrees and its mean over the arc [Pa].
"""
from __future__ import annotations

import numpy as np

from ngcontact.macro import macro_measures as MM
from ngcontact.verification.calculix_model import Blocks, PressFit

#: key -> (quantity, unit) of the two blocks' rows
BLOCK_ROWS = {"R_x": ("reaction on the top, x", "N/m"), "R_y": ("reaction on the top, y", "N/m"),
              "mean": ("mean contact pressure", "Pa"), "p_mid": ("contact pressure at x = L/2", "Pa"),
              "p_max": ("largest contact pressure", "Pa"), "tau_mid": ("|shear| at x = L/2", "Pa")}

#: key -> (quantity, unit) of the press fit's rows
PRESS_FIT_ROWS = {"hoop": ("hoop force of the outer tube", "N/m"),
                  "u_mantle": ("radial displacement, mantle", "m"),
                  "u_bore": ("radial displacement, bore", "m"), "p_45": ("contact pressure at 45 degrees", "Pa"),
                  "p_mean": ("mean contact pressure", "Pa")}


def rows(names: dict, ours: dict, theirs: dict) -> list[tuple]:
    """``(quantity, unit, ngcontact, ccx, relative difference to ccx)`` for every key of ``ours``."""
    return [(names[k][0], names[k][1], ours[k], theirs[k], abs(ours[k] - theirs[k]) / abs(theirs[k]))
            for k in ours]


def block_measures(sol, b: Blocks, points_per_element: int) -> tuple[dict, dict]:
    """This package's numbers of :data:`BLOCK_ROWS` on the macro solution ``sol``, and its interface profile
    (``x``, ``pressure``, ``shear``)."""
    force = MM.resultant(sol)
    prof = MM.interface_profile(sol, points_per_element)
    x, p, tau = (np.asarray(prof[k], float) for k in ("x", "pressure", "shear"))
    order_x = np.argsort(x)
    at = lambda v, where: float(np.interp(where, x[order_x], v[order_x]))  # noqa: E731
    mid = 0.5 * b.length
    ours = {"R_x": force["x"], "R_y": force["y"], "mean": abs(force["y"]) / b.length,
            "p_mid": at(p, mid), "p_max": float(p.max()), "tau_mid": abs(at(tau, mid))}
    return ours, {"x": x, "pressure": p, "shear": tau}


def block_ccx(cx: dict, b: Blocks) -> dict:
    """ccx's numbers of :data:`BLOCK_ROWS` from its results ``cx`` (:func:`~ngcontact.verification.calculix_model.run`);
    the centre is the slave node ``nx // 2``."""
    i_mid = b.nx // 2
    return {"R_x": cx["rf_x"], "R_y": cx["rf_y"], "mean": abs(cx["rf_y"]) / b.length,
            "p_mid": float(cx["pressure"][i_mid]), "p_max": float(cx["pressure"].max()),
            "tau_mid": abs(float(cx["shear"][i_mid]))}


def stick(cx: dict, mu: float) -> float:
    """The largest ``|tau| / (mu p)`` over ccx's closed contact nodes (0 without friction)."""
    closed = cx["pressure"] > 0
    return float(np.max(np.abs(cx["shear"][closed]) / (mu * cx["pressure"][closed]))) if mu > 0 else 0.0


def _mean(t: np.ndarray, v: np.ndarray) -> float:
    """Trapezoidal mean of the samples ``v`` over ``t`` (numpy >= 1.24 has no ``trapezoid``)."""
    return float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(t)) / (t[-1] - t[0]))


def press_fit_measures(sol, mesh, fit: PressFit, points_per_element: int) -> tuple[dict, dict]:
    """This package's numbers of :data:`PRESS_FIT_ROWS` on the macro solution ``sol`` (on ``mesh``), and its
    interface profile (``theta``, ``pressure``, sorted by the angle)."""
    hoop = MM.equilibrium(sol)["bodies"]["outer"]["x"]["supports"]
    prof = MM.interface_profile(sol, points_per_element)
    diag = np.array([1.0, 1.0]) / np.sqrt(2.0)
    u = {key: float(np.asarray(gf(mesh(*(r * diag)))).ravel() @ diag)
         for key, gf, r in (("mantle", sol.u_counter, fit.c), ("bore", sol.u_rough, fit.a))}
    theta = np.arctan2(np.asarray(prof["y"], float), np.asarray(prof["x"], float))
    p = np.asarray(prof["pressure"], float)
    o = np.argsort(theta)
    ours = {"hoop": abs(hoop), "u_mantle": u["mantle"], "u_bore": u["bore"],
            "p_45": float(np.interp(np.pi / 4, theta[o], p[o])),
            "p_mean": _mean(theta[o], p[o])}
    return ours, {"theta": theta[o], "pressure": p[o]}


def press_fit_ccx(cx: dict, fit: PressFit) -> dict:
    """ccx's numbers of :data:`PRESS_FIT_ROWS` from its results ``cx``
    (:func:`~ngcontact.verification.calculix_model.run_press_fit`); 45 degrees is the node ``n_theta // 2``."""
    pc = cx["pressure"]
    return {"hoop": abs(cx["hoop"]), "u_mantle": cx["u_mantle"], "u_bore": cx["u_bore"],
            "p_45": float(pc[fit.n_theta // 2]), "p_mean": _mean(cx["theta"], pc)}
