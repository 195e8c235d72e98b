"""The refiner of a cell scene's FE cell along its contact edge, where the scene has one.

A 3D cell scene meshed as the flat periodic cell (a flat profile or a small-slope one carried by the gap),
with exact contact, no friction and isotropic bodies, has a spectral twin whose contact edges predict the
FE cell's: its second discretization refines along them
(:class:`~ngcontact.cell.fe.contact_edge_refinement.ContactEdgeRefinement`) instead of halving
``interface_maxh`` everywhere.  Every other FE cell keeps the halving.

The bodies' size of such a cell (:func:`bulk_maxh`).  A scene that sets no ``discretization.maxh`` has its
bodies meshed at ``min(BULK_MAXH P, h_rough, h_counter)`` instead of the default ``maxh``, on the scene's
level and on every refined one (``interface_maxh`` keeps its default, ``maxh``).  Netgen's size field
grows from a restricted size ``h_e`` at most like ``h_e + gamma r`` with the distance ``r`` (its grading
``gamma = 0.3``), so the bodies' elements within ``r* = (maxh - h_e) / gamma`` of the contact edges, below
and above the patches where the contact field varies (the Hertz-like field decays over a depth of the
order of the patch width, :mod:`ngcontact.cell.fe.contact_edge_mesh`), are set by the edge's grading, not
by ``maxh``: raising ``maxh`` from ``0.1 P`` to ``0.3 P`` changes only the elements farther than
``r*(0.1 P) ~ P / 3`` from every contact edge, in the far field, where the periodic part of the displacement
decays like ``exp(-2 pi |z| / P)`` and the uniform part, the layers' uniform strain, is linear in ``z`` and
exact on any mesh.  What the contact fraction and the closure carry from the bodies is thus the graded near
field, refined with the edge from level to level, and a coarser far field saves its unknowns at every level
(the errors the scene reaches so: docs/benchmarks.md, section ``bisinusoid_scene_accuracy``).  A scene that
sets ``maxh`` keeps it.

The twin's grids (:func:`edge_refiner`).  Each grid is solved once for every level that asks it (the edge
points of the levels, their start, the bound of the estimates).  A grid finer than every level's start
(beyond :data:`~ngcontact.cell.fe.contact_edge_refinement.TWIN_GRIDS`: the bound's finest) starts its
constrained CG from the next coarser grid's pressure, interpolated bilinearly
(:func:`~ngcontact.cell.spectral.grid_level.prolong`, as the spectral refinement starts its levels): the same
strictly convex problem, so the same minimizer to the solver's tolerance, in fewer steps.
"""
from __future__ import annotations

from typing import Any, Callable

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.cell_solution import headline
from ngcontact.cell.fe.cell_model import CellModel
from ngcontact.cell.fe.contact_edge_mesh import edge_refined_cell
from ngcontact.cell.fe.contact_edge_refinement import TWIN_GRIDS, ContactEdgeRefinement, twin_grid
from ngcontact.cell.fe.fe_cell import FECell
from ngcontact.cell.spectral.grid_level import prolong
from ngcontact.cell.spectral_start import SpectralStart
from ngcontact.drivers.mirror_symmetry import quarter
from ngcontact.scene.cell_method import refines_along_edge
from ngcontact.scene.cell_scene import CellScene, load_states

#: the bodies' size of an edge-refined cell whose scene sets no maxh, in periods (module docstring)
BULK_MAXH = 0.3
#: tolerance of the twin's solve (its contact set places the edge; its answers floor the estimates)
EDGE_TWIN_RTOL = 1e-8


def bulk_maxh(scene: CellScene) -> float:
    """The bodies' ``maxh`` of the scene's FE cell: the scene's where it sets it or the cell does not refine
    along its contact edge, else ``min(BULK_MAXH P, h_rough, h_counter)`` (module docstring), never finer
    than the scene's default."""
    g, d = scene.geometry, scene.discretization
    if "maxh" in d.given or not refines_along_edge(scene):
        return d.maxh
    return max(d.maxh, min(BULK_MAXH * g.period, g.h_rough, g.h_counter))


def scene_sizes(scene: CellScene) -> dict[str, float]:
    """The mesh sizes of the scene's own FE cell where they are not the scene's (:func:`bulk_maxh`): ``maxh``
    and ``interface_maxh`` (its default, the scene's ``maxh``), else none."""
    d = scene.discretization
    bulk = bulk_maxh(scene)
    return {} if bulk == d.maxh else {"maxh": bulk, "interface_maxh": d.interface_maxh or d.maxh}


def edge_refiner(scene: CellScene, model: CellModel, problem: Callable[..., Any],
                 spectral: Callable[..., Any]) -> Callable[[FECell], ContactEdgeRefinement] | None:
    """``(scene's FE cell) -> `` its :class:`ContactEdgeRefinement`, or ``None`` where the scene has none
    (:func:`refines_along_edge`).  ``problem(scene, cell, model, predictor=)``: the scene's cell problem on
    another mesh, each level's started from the twin on that level's grid (:func:`twin_grid`: the state on
    the twin's contact set, the multiplier its pressure, :mod:`ngcontact.cell.spectral_start`);
    ``spectral(scene, grid=, friction=, tol=)``: its spectral cell (both from :mod:`ngcontact.drivers.build`,
    which wires this refiner into the FE cell it makes)."""
    if not refines_along_edge(scene):
        return None
    g, d = scene.geometry, scene.discretization
    h = d.interface_maxh or d.maxh
    symmetric = quarter(scene)                    # the scene's cell's quarter, refined alike
    bulk = bulk_maxh(scene)

    solved: dict[int, list] = {}
    cells: dict[int, Any] = {}

    def twin(grid: int) -> list:
        if grid not in solved:
            cells[grid] = cell = spectral(scene, grid=grid, friction=False, tol=EDGE_TWIN_RTOL)
            loads = [cell_load(g.dim, **state) for state in load_states(scene)]
            if grid > TWIN_GRIDS[1] and grid // 2 in solved:       # no level's start: from the coarser grid
                solved[grid] = [cell.solve(load, start=prolong(s.fields["pressure"]))
                                for load, s in zip(loads, solved[grid // 2])]
            else:
                solved[grid] = [cell.solve(load) for load in loads]
        return solved[grid]

    def pressures(grid: int):
        return [s.fields["pressure"] for s in twin(grid)]

    def heads(grid: int):
        return [headline(s.results) for s in twin(grid)]

    def cell_at(points, edge_maxh, grading):
        cell = edge_refined_cell(points, edge_maxh=edge_maxh, period=g.period, h_rough=g.h_rough,
                                 h_counter=g.h_counter, maxh=bulk, interface_maxh=h, symmetric=symmetric,
                                 grading=grading)
        grid = twin_grid(edge_maxh, float(g.period))
        twin(grid)
        return FECell.of(problem(scene, cell, model, predictor=SpectralStart(cells[grid])))

    return lambda fe: ContactEdgeRefinement(fe, pressures, cell_at, h, float(g.period), twin_heads=heads)
