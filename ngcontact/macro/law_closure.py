"""The closure against the law: the interface's tractions are its law's at its jumps.

A macro solution reports on ``S_0`` the local jump ``a`` and the traction ``tau`` (paper eqs. 69-71;
:func:`ngcontact.macro.macro_measures.interface_tractions`): ``tau`` is the law's ``dW/da`` evaluated by the
solve's own coefficient functions, with the friction threshold ``G`` the solve held fixed
(:attr:`~ngcontact.macro.macro_problem.MacroSolution.threshold`).  The homogenized law as stated
(:mod:`ngcontact.laws.law_protocol`) is

    tau = tau_normal(a; g0) + tau_f(a; G(p)),     p = tau_normal(a; g0)_n,     G(p) = mu0 [p]_+ + G0,

a function of the jump alone.  This check evaluates it anew at the jumps of the interface samples, as
arrays (the evaluation the exporters write and the tables use), with the threshold of the sampled pressure,
and compares:

    closure = max_samples |tau - tau_law(a)| / max_samples |tau|      <= CLOSURE_RTOL.

Its limit is the solver's tolerance: :data:`CLOSURE_RTOL` for a law without state, and for a Coulomb
threshold also the fixed point's ``solver.coulomb_rtol`` (it stops where ``max |p_k - p_(k-1)| <= coulomb_rtol
max p_k``, and the threshold it leaves, ``G(p_(k-1))``, then differs from ``G(p_k)`` by at most ``mu0`` times that,
``mu0 <= 1``), whichever is larger (:func:`limit`).

It fails where the reported state does not satisfy the law: a Coulomb threshold left at an earlier pressure
(the fixed point of paper Sec. 2 stopped before its pressure settled, or a state frozen elsewhere), or an
evaluation of the law in the solve that differs from the law's own (a table or bundle evaluated otherwise in
the energy forms than in the exports).  A frictionless or Tresca law has no state, so there it holds to
round-off unless an evaluation is wrong.  Every macro law (linear, bundle, tabulated, from a file, and the
two-scale loop's cell table) is a traction of the jump, so the check applies to each; exact contact, whose
pressure is a multiplier and not a function of the jump, has no law to check and is not a macro law.

Cheap: one evaluation of the tractions and jumps at the points of a Gauss rule on each interface element
(the energy's order) and one of the law on those arrays.  On a distributed mesh each rank holds its own
samples, and the largest difference and traction are the largest over the ranks
(:func:`closure_of`).
"""
from __future__ import annotations

from typing import Any

import ngsolve as ng
import numpy as np

from ngcontact.fem.quadrature import energy_order
from ngcontact.laws import interface_energy as ie
from ngcontact.macro.macro_energy import gap_cf
from ngcontact.macro.macro_problem import MacroSolution

#: the largest closure of a reported solution: the law is evaluated to round-off (~1e-13 of the tractions), a
#: Coulomb threshold at its fixed point to the solver's ``coulomb_rtol`` (1e-8 by default) times ``mu0``; the
#: bound of :data:`ngcontact.macro.macro_measures.EQUILIBRIUM_RTOL`, the other check of a solution's state
CLOSURE_RTOL = 1e-6
#: what the check measures (the verdict's ``meaning``)
MEANING = ("the largest difference of the interface traction from its law evaluated anew at the jump, with the "
           "friction threshold of the current pressure, relative to the largest traction")


def limit(sol: MacroSolution, coulomb_rtol: float = 0.0) -> float:
    """The closure a solution may show (module docstring): :data:`CLOSURE_RTOL`, or ``coulomb_rtol`` where it is
    larger and the law's friction threshold follows the pressure."""
    friction = sol.problem.law.friction
    return max(CLOSURE_RTOL, coulomb_rtol) if friction is not None and friction.coulomb else CLOSURE_RTOL


def samples(sol: MacroSolution) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """At the Gauss points of every interface element: the reported tractions ``tau`` (rows of components), the
    jumps ``a`` (the same), the macro gap ``g0`` and the threshold the solve held (``G``, zeros without)."""
    p = sol.problem
    mesh = p.mesh
    shape = ng.SEGM if mesh.dim == 2 else ng.TRIG
    rule = ng.IntegrationRule(shape, energy_order(p.order))
    points = mesh.MapToAllElements(rule, mesh.Boundaries(p.interface))
    tau = ie.traction(p.law, sol.local_jump, gap_cf(p.gap), sol.threshold)
    a = list(sol.local_jump)
    G = sol.threshold if sol.threshold is not None else ng.CF(0.0)
    m = len(a)
    values = np.asarray(ng.CF((*tau, *a, gap_cf(p.gap), G))(points)).reshape(-1, 2 * m + 2)
    return values[:, :m].T, values[:, m:2 * m].T, values[:, 2 * m], values[:, 2 * m + 1]


def law_closure(sol: MacroSolution, coulomb_rtol: float = 0.0) -> dict[str, Any]:
    """``{"error", "difference", "scale", "tolerance", "samples"}``: the closure of the module docstring, the
    largest difference, the largest traction it is relative to, its :func:`limit` (the solve's
    ``coulomb_rtol``) and the number of samples (this process's)."""
    tau, a, g0, _ = samples(sol)
    law = sol.problem.law
    comps = list(a)
    expected = [np.asarray(t, float) * np.ones_like(g0) for t in ie.normal_traction(law.normal, comps, g0)]
    if law.friction is not None:
        G = ie.threshold(law.friction, expected[0])
        expected = [e + np.asarray(f, float) * np.ones_like(g0)
                    for e, f in zip(expected, ie.friction_traction(law.friction, comps, G))]
    difference = np.sqrt(sum((t - e) ** 2 for t, e in zip(tau, expected)))
    size = np.sqrt(sum(t ** 2 for t in tau))
    scale = float(size.max()) if size.size else 0.0
    worst = float(difference.max()) if difference.size else 0.0
    return closure_of(worst, scale, limit(sol, coulomb_rtol), int(g0.size))


def closure_of(worst: float, scale: float, tolerance: float, count: int) -> dict[str, Any]:
    """The record of :func:`law_closure` from the largest difference ``worst`` and the largest traction
    ``scale`` (each the largest over the ranks of a distributed mesh)."""
    return {"error": worst / scale if scale > 0 else worst, "difference": worst, "scale": scale,
            "tolerance": tolerance, "samples": count}
