"""Part 4 of ``scaling_3d.py``: the 3D FE cell's contact fraction on the bisinusoid against the converged value.

The bisinusoid ``h (2 - cos 2 pi x - cos 2 pi y)``, ``h = 0.01``, two layers
1 deep with ``E* = 1`` (``E = 2 (1 - nu^2)``, ``nu = 0.3``), bottom clamped,
top a rigid plate, mean pressure ``p/p*`` with ``p* = pi E* h / P``
(issue 38 aims at 1 % of the converged contact fraction at ``p/p* = 0.005,
0.02, 0.05`` in at most 60 s each).  The FE cell (small slope: the flat
cell with the gap ``g0``, the same problem as the spectral cell's) with
exact contact, started from the spectral twin on ``128^2``:

* ``edge``: the mesh refined along the twin's contact edge to the edge
  sizes asked for (:func:`ngcontact.cell.fe.contact_edge_mesh.edge_refined_cell`),
  the bodies at ``maxh = 0.3``; order 1, and order 2 on a linear trace on
  ``S_C`` (:mod:`ngcontact.cell.fe.linear_trace`) where asked, with
  Richardson's extrapolation in the edge size over two or more sizes
  (:mod:`ngcontact.cell.fe.edge_size_extrapolation`);
* ``patch``: order 1, the sizes scaled with the twin's patch radius ``a``
  (:func:`~ngcontact.cell.fe.contact_edge_mesh.patch_radius`): the edge at
  ``a / n_edge`` and the bodies below and above the patch at ``a / n_body``
  to a depth ``d a`` (:class:`~ngcontact.cell.fe.contact_edge_mesh.PatchBody`), the bodies' size growing
  with the depth at the rate ``growth`` (``0``: uniform to ``d a``).

Each on the whole period or on its mirror-symmetric quarter (column ``cell``: ``period`` or ``quarter``,
:mod:`ngcontact.drivers.mirror_symmetry`; the bisinusoid is even about the cell's mid-lines): the same
sizes, the twin's points folded into the quarter, about a quarter of the unknowns.

The converged value is the spectral cell's contact fraction extrapolated
from ``1024^2`` and ``2048^2`` (the stiffness and the closure err by one
order in the spacing, the contact fraction, its edges located between points,
by a fraction of a step per edge; ``512^2`` is left out: its values lie off the line of the grids
around it, the normal stiffness at ``p/p* = 0.05`` 0.07 % above ``1024^2``
and ``2048^2``, which agree to 0.01 %, and the extrapolation from ``512^2``
and ``1024^2`` is 0.09 % below that from ``1024^2`` and ``2048^2`` in the
stiffness, 0.08 to 0.11 % off in the contact fraction at the three loads).
Seconds: twin, meshing and solve, with the threads asked for;
per phase: ``twin_seconds``, ``mesh_seconds``, ``solve_seconds`` (the
cell problem's setup, the bodies' assembly, Uzawa's passes with their
Newton steps and tangent solves, the contact fraction), and the tangent
solves' CG iterations.
"""
from __future__ import annotations

import functools
import itertools
import logging
import math
import time

import numpy as np

log = logging.getLogger("scaling_3d")

ACC_H, ACC_RATIOS, ACC_EDGES, QUICK_EDGES, REF_GRIDS = 0.01, (0.005, 0.02, 0.05), (0.02, 0.01), (0.02,), (1024, 2048)
ACC_MAXH, ACC_INTERFACE, ACC_TWIN, ACC_ORDERS = 0.3, 0.1, 128, (1,)
#: the ``patch`` method's sizes: edge ``a / 13``, bodies ``a / 10`` to ``1.8 a``
ACC_PATCH = (13.0, 10.0, 1.8)
#: its bodies' size away from the patch
PATCH_MAXH = 0.15
#: the cells meshed, side by side: the mirror-symmetric quarter and the whole period
ACC_CELLS = ("quarter", "period")


def bisinusoid_spectral(grid: int):
    """The spectral cell of the bisinusoid (module docstring) on a ``grid x grid`` grid."""
    from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
    from ngcontact.geometry.cell3d import bisinusoid_gap
    nu, s = 0.3, np.arange(grid) / grid
    E = 2.0 * (1.0 - nu ** 2)                  # E* = 1 for two equal bodies
    layer = Layer(E, nu, 1.0)
    return SpectralCell(dim=3, period=1.0, grid=grid, rough=layer, counter=layer, k_n=1.0, enforcement="exact",
                        gap=bisinusoid_gap(ACC_H, 1.0, xy=(s[None, :], s[:, None])))


def _fe_solve(cell, order: int, edge: float, load, threads: int) -> tuple[object, object]:
    from ngcontact import runner
    from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
    from ngcontact.fem.materials import isotropic
    from ngcontact.geometry.cell3d import bisinusoid_gap
    from ngcontact.solvers.linear_solver import LinearSolver
    law = isotropic(2.0 * (1.0 - 0.3 ** 2), 0.3)
    assert law.lame is not None                 # an isotropic law has its Lame constants
    model = CellModel(rough=law, counter=law, k_n=100.0 * law.lame[1] / edge, order=order,
                      gap=bisinusoid_gap(ACC_H, 1.0), enforcement="exact", linear_trace=order > 1)
    with runner.threads(threads):
        P = CellProblem(cell, model, linear=LinearSolver("auto"))
        return P, P.solve(load, first=True, measure=False)


def _row(solver: str, size, P, sol, phases: list[float], ratio: float, ref: float, cell: str) -> dict:
    """The row of one solve; ``phases``: the ``perf_counter`` times at its start and after the twin, the
    meshing and the solve."""
    f = float(sol.results["contact_fraction"])
    twin, mesh, solve = (float(t) for t in np.diff(phases))
    seconds = phases[-1] - phases[0]
    log.info("accuracy: %s, %s p/p* %-6g size %-12s ndof %7d: fraction %.6f (converged %.6f, %+.2f %%), %.1f s "
             "(twin %.1f, mesh %.1f, solve %.1f)", solver, cell, ratio, size, P.ndof, f, ref,
             100.0 * (f / ref - 1.0), seconds, twin, mesh, solve)
    return {"part": "accuracy", "solver": solver, "cell": cell, "size": size, "ndof": P.ndof, "seconds": seconds,
            "twin_seconds": twin, "mesh_seconds": mesh, "solve_seconds": solve,
            "newton_steps": sol.iterations, "cg_iterations": sum(P.linear.iterations), "contact_fraction": f,
            "pressure": ratio, "relative_error": f / ref - 1.0}


def edge_rows(edges, orders, threads: int, loads, converged, cells=ACC_CELLS) -> list[dict]:
    """The ``edge`` method (module docstring), per edge size, order, load and cell."""
    from ngcontact.cell.fe.contact_edge_mesh import edge_points, edge_refined_cell
    twin, rows = bisinusoid_spectral(ACC_TWIN), []
    for edge, order, (ratio, ld, ref), which in itertools.product(edges, orders, zip(ACC_RATIOS, loads, converged),
                                                                   cells):
        phases = [time.perf_counter()]
        pts = edge_points(twin.solve(ld).fields["pressure"], 1.0)
        phases.append(time.perf_counter())
        cell = edge_refined_cell(pts, edge_maxh=edge, maxh=ACC_MAXH, interface_maxh=ACC_INTERFACE,
                                 symmetric=which == "quarter")
        phases.append(time.perf_counter())
        P, sol = _fe_solve(cell, order, edge, ld, threads)
        phases.append(time.perf_counter())
        rows.append(_row(f"fe exact order {order}, edge-refined", edge, P, sol, phases, ratio, ref, which))
    return rows


def patch_rows(patch, threads: int, loads, converged, growth: float = 0.0, cells=ACC_CELLS) -> list[dict]:
    """The ``patch`` method (module docstring) per load and cell; ``patch = (n_edge, n_body, d)``."""
    from ngcontact.cell.fe.contact_edge_mesh import edge_points, edge_refined_cell, patch_body, patch_radius
    twin, rows = bisinusoid_spectral(ACC_TWIN), []
    n_edge, n_body, depth = patch
    for (ratio, ld, ref), which in itertools.product(zip(ACC_RATIOS, loads, converged), cells):
        phases = [time.perf_counter()]
        p = twin.solve(ld).fields["pressure"]
        phases.append(time.perf_counter())
        a = patch_radius(p, 1.0)
        body = patch_body(p, 1.0, maxh=a / n_body, depth=depth * a, growth=growth)
        cell = edge_refined_cell(edge_points(p, 1.0), edge_maxh=a / n_edge, maxh=PATCH_MAXH,
                                 interface_maxh=ACC_INTERFACE, body=body, symmetric=which == "quarter")
        phases.append(time.perf_counter())
        P, sol = _fe_solve(cell, 1, a / n_edge, ld, threads)
        phases.append(time.perf_counter())
        size = f"a/{n_edge:g} a/{n_body:g} {depth:g}a" + (f" growth {growth:g}" if growth else "")
        rows.append(_row("fe exact order 1, patch-refined", size, P, sol, phases, ratio, ref, which))
    return rows


def accuracy_aim(edges, orders=ACC_ORDERS, patch=ACC_PATCH, threads: int | None = None,
                 growth: float = 0.0, cells=ACC_CELLS) -> list[dict]:
    """Part 4 (module docstring): the ``edge`` rows, the ``patch`` rows (``patch = None``: none; ``growth``: of
    their bodies' size with the depth) and the extrapolations in the edge size of the order-2 ``edge`` rows;
    per load and cell (``cells``: ``"quarter"``, ``"period"``): seconds, dofs, relative error of the contact
    fraction."""
    from ngcontact import runner
    from ngcontact.cell.cell_load import cell_load
    loads = [cell_load(3, pressure=r * math.pi * ACC_H) for r in ACC_RATIOS]
    converged = [converged_fraction(r) for r in ACC_RATIOS]
    threads = runner.thread_count() if threads is None else threads
    rows = edge_rows(edges, orders, threads, loads, converged, cells) if edges else []
    if patch is not None:
        rows += patch_rows(patch, threads, loads, converged, growth, cells)
    return rows + extrapolated_rows(rows, dict(zip(ACC_RATIOS, converged)))


@functools.lru_cache(maxsize=None)
def twin_headline(grid: int, ratio: float) -> dict[str, float]:
    """The spectral cell's headline quantities (:func:`ngcontact.cell.cell_solution.headline`: contact fraction,
    mean closure, normal stiffness, eq. 34 coefficients) at ``p/p* = ratio`` on a ``grid x grid`` grid, each
    grid and load solved once per process."""
    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.cell_solution import headline
    return headline(bisinusoid_spectral(grid).solve(cell_load(3, pressure=ratio * math.pi * ACC_H)).results)


def twin_fraction(grid: int, ratio: float) -> float:
    """The spectral cell's contact fraction at ``p/p* = ratio`` on a ``grid x grid`` grid (:func:`twin_headline`)."""
    return twin_headline(grid, ratio)["contact_fraction"]


def converged(ratio: float, grids: tuple[int, int] = REF_GRIDS) -> dict[str, float]:
    """The converged bisinusoid at ``p/p* = ratio``: the spectral cell's headline quantities extrapolated from
    ``grids`` ``(n, 2 n)`` (:data:`REF_GRIDS` unless a check asks for finer) as ``2 q_2n - q_n`` (each converges at
    first order in the grid step; module docstring for why not ``512^2``).  The one reference of ``scaling_3d.py``
    (the measured rows and, on ``--republish``, the kept ones) and of ``bisinusoid_scene_accuracy.py``; its ``k_n``
    is 1 and the coefficients ``k_n``, ``g_n`` of exact contact are proportional to it (the contact set does not
    depend on it)."""
    coarse, fine = (twin_headline(n, ratio) for n in grids)
    return {name: 2.0 * fine[name] - coarse[name] for name in fine if name in coarse}


def converged_fraction(ratio: float) -> float:
    """The converged contact fraction at ``p/p* = ratio`` (:func:`converged`)."""
    return converged(ratio)["contact_fraction"]


def twin_floor(value: float, edge: float, ratio: float, twin=twin_fraction) -> tuple[float, int]:
    """The floor of the contact-edge ladder on an extrapolated contact fraction ``value`` whose finest edge size
    is ``edge`` (:meth:`ngcontact.cell.fe.contact_edge_refinement.ContactEdgeRefinement.twin_floors`): ``|q - q_N|
    + TWIN_SAFETY |q_N - q_{N/2}|`` with ``q_N = twin(N, ratio)`` the spectral twin's on the ladder's floor grid
    ``N`` (``FLOOR_GRID``, whatever the edge size); returns the floor (absolute) and ``N``."""
    from ngcontact.cell.fe.contact_edge_refinement import FLOOR_GRID, TWIN_SAFETY
    n = FLOOR_GRID
    fine, coarse = twin(n, ratio), twin(n // 2, ratio)
    return abs(value - fine) + TWIN_SAFETY * abs(fine - coarse), n


def extrapolated_rows(rows: list[dict], converged: dict, twin=twin_fraction) -> list[dict]:
    """Per load solved at order 2 (on a linear trace) at two or more edge sizes: the Richardson extrapolation
    in the edge size (:mod:`ngcontact.cell.fe.edge_size_extrapolation`), its seconds the sum of the solves', its
    dofs the finest's.  Its estimated relative error as the contact-edge ladder of ``ngcontact run`` makes it
    (:mod:`ngcontact.cell.fe.contact_edge_refinement`): ``estimate_gci`` the extrapolation's grid convergence
    index, ``estimate_twin`` the spectral twin's floor (:func:`twin_floor`, ``twin(grid, p/p*)`` the twin's
    contact fraction), ``estimate`` the larger; ``effectivity`` = estimate / |relative_error|.  Order 1 is left
    out: its error is two opposite errors (too stiff a body, a contact set past the edge), not a power of the
    edge size."""
    from ngcontact.cell.fe.edge_size_extrapolation import extrapolate
    out = []
    def cell(r):          # rows of a run before the quarter cell: the period's
        return r.get("cell") or "period"
    for solver, which, ratio in sorted({(r["solver"], cell(r), r["pressure"]) for r in rows
                                        if "order 2" in r["solver"]}):
        sel = [r for r in rows if r["solver"] == solver and cell(r) == which and r["pressure"] == ratio]
        if len(sel) < 2:
            continue
        ext = extrapolate([r["size"] for r in sel], [r["contact_fraction"] for r in sel])
        finest = min(sel, key=lambda r: r["size"])
        floor, n = twin_floor(ext.value, finest["size"], ratio, twin)
        error = ext.value / converged[ratio] - 1.0
        estimate = max(ext.estimate, floor) / ext.value
        out.append({"part": "accuracy", "solver": solver + ", extrapolated", "cell": which,
                    "size": " ".join(f"{r['size']:g}" for r in sel), "ndof": finest["ndof"],
                    "seconds": sum(r["seconds"] for r in sel), "contact_fraction": ext.value, "pressure": ratio,
                    "relative_error": error, "estimate": estimate, "estimate_gci": ext.estimate / ext.value,
                    "estimate_twin": floor / ext.value, "effectivity": estimate / abs(error) if error else ""})
        log.info("accuracy: %s p/p* %g extrapolated (%s): %+.2f %%, estimate %.2f %% (GCI %.2f %%, twin floor "
                 "%.2f %% at %d^2), %.1f s", solver, ratio, ext.how, 100.0 * error, 100.0 * estimate,
                 100.0 * out[-1]["estimate_gci"], 100.0 * out[-1]["estimate_twin"], n, out[-1]["seconds"])
    return out

