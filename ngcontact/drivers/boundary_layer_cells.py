"""The station cells of the first-order corrector's boundary layer on the bodies of a ``direct`` scene.

:class:`ngcontact.coupling.cell_boundary_layer.CellBoundaryLayer` from the scene's cell scaled to the period
``eps`` (:func:`scaled_cell_problem`), each station loaded by the mean macro traction of its period of
``S_0`` (paper eqs. 49-51: the cell problem loaded by ``sigma^0 n``), in the frame ``(n0, t0)`` of the
homogenized solution (pressure ``mean tau_n``, shear on the counter's far face ``-mean tau_t``, as the
effective-stiffness law of :mod:`ngcontact.drivers.study_epsilon` loads its cell).
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import cell_load
from ngcontact.coupling.cell_boundary_layer import CellBoundaryLayer, StationCell
from ngcontact.drivers import run_resolved as drv
from ngcontact.fem import elasticity
from ngcontact.geometry.profiles import profile_cell
from ngcontact.geometry.resolved_bodies import scaled_profile
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import macro_problem as M

#: at most this many station cells per level, spread evenly over the periods
STATIONS = 8


def scaled_cell_problem(scene, eps: float):
    """The FE cell problem of the scene's cell scaled to the period ``eps`` (heights and mesh sizes scale with
    it) with the direct scene's materials and order."""
    from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
    cell_scene = scene.cell_scene
    g, d = cell_scene.geometry, cell_scene.discretization
    s = eps / g.period
    kw = drv.micro_law(cell_scene)
    cell = profile_cell(scaled_profile(drv.profile_of(cell_scene), eps), h_rough=s * g.h_rough,
                        h_counter=s * g.h_counter, maxh=s * d.maxh,
                        interface_maxh=s * (d.interface_maxh or d.maxh), order=d.order)
    mats = drv.materials_of(scene)
    model = CellModel(rough=mats["rough"], counter=mats["counter"], k_n=kw["k_n"],
                      gap=None if kw["gap"] is None else ng.CF(kw["gap"]), friction=kw["friction"],
                      order=scene.discretization.order)
    return CellProblem(cell, model, rtol=scene.solver.rtol, max_iter=scene.solver.max_iter)



def period_traction(sol: M.MacroSolution, x0: float, eps: float, k: int) -> np.ndarray:
    """Mean traction ``(tau_n, tau_t)`` of the homogenized ``sol`` over the period ``k`` of ``S_0``
    (``x0 + k eps < x < x0 + (k + 1) eps``), weighted by the measure weight ``w``."""
    p = sol.problem
    mesh = p.mesh
    lo, hi = x0 + k * eps, x0 + (k + 1) * eps
    ind = ng.IfPos(ng.x - lo, 1.0, 0.0) * ng.IfPos(hi - ng.x, 1.0, 0.0) * elasticity.weight(p.setting)
    on_s0 = mesh.Boundaries(p.interface)
    order = 2 * p.order + 2
    area = ng.Integrate(ind, mesh, ng.BND, definedon=on_s0, order=order)
    vals = [ng.Integrate(t * ind, mesh, ng.BND, definedon=on_s0, order=order) for t in MM.interface_tractions(sol)]
    return np.asarray(vals, float) / area


def station(scene, sol: M.MacroSolution, x0: float, eps: float, k: int) -> StationCell | None:
    """The station cell of period ``k``; ``None`` where the macro interface is open there (no contact load)."""
    tau_n, tau_t = period_traction(sol, x0, eps, k)
    if not tau_n > 0:
        return None
    prob = scaled_cell_problem(scene, eps)
    prob.sweep([cell_load(2, pressure=float(tau_n), shear=(-float(tau_t),))])
    comps = prob.gfu.components
    U = tuple(float(c.vec[0]) for c in comps[2:])
    cell = prob.cell
    return StationCell(x=x0 + (k + 0.5) * eps, mesh=cell.mesh, u_rough=comps[0], u_counter=comps[1] + ng.CF(U),
                       period=eps, h_rough=cell.h_rough, h_counter=cell.h_counter)


def boundary_layer(scene, sol: M.MacroSolution, periods: int) -> CellBoundaryLayer | None:
    """The boundary layer of the homogenized ``sol`` on the blocks of ``scene`` with ``periods`` periods, from
    at most :data:`STATIONS` station cells; ``None`` where no period is in contact."""
    x0 = float(getattr(drv.shape_of(scene), "x0", 0.0))
    eps = drv.eps_of(scene, periods)
    ks = np.unique(np.round(np.linspace(0, periods - 1, min(periods, STATIONS))).astype(int))
    cells = [c for c in (station(scene, sol, x0, eps, int(k)) for k in ks) if c is not None]
    return CellBoundaryLayer(tuple(cells), eps, x0) if cells else None
