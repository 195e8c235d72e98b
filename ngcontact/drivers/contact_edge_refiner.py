"""The refiner of a cell scene's FE cell along its contact edge, where the scene has one.

A 3D cell scene meshed as the flat periodic cell (a flat profile or a small-slope one carried by the gap),
with exact contact, no friction and isotropic bodies, has a spectral twin whose contact edges predict the
FE cell's: its second discretization refines along them
(:class:`~ngcontact.cell.fe.contact_edge_refinement.ContactEdgeRefinement`) instead of halving
``interface_maxh`` everywhere.  Every other FE cell keeps the halving.
"""
from __future__ import annotations

from typing import Any, Callable

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.cell_model import CellModel
from ngcontact.cell.fe.contact_edge_mesh import edge_refined_cell
from ngcontact.cell.fe.contact_edge_refinement import ContactEdgeRefinement
from ngcontact.cell.fe.fe_cell import FECell
from ngcontact.drivers.mirror_symmetry import quarter
from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.scene.cell_geometry import small_slope
from ngcontact.scene.cell_scene import CellScene, load_states

#: grid points per direction of the twin whose contact edges place the refinement
EDGE_TWIN_GRID = 256
#: tolerance of the twin's solve: only its contact set is used
EDGE_TWIN_RTOL = 1e-8


def refines_along_edge(scene: CellScene) -> bool:
    """Whether the scene's FE cell refines along its twin's contact edge (module docstring)."""
    g, c = scene.geometry, scene.contact
    kind = PROFILES[g.profile]
    flat_mesh = kind.solid is None and (kind.heights is None or small_slope(g))
    isotropic = all(scene.materials[m].C is None for m in (scene.bodies.rough, scene.bodies.counter))
    return g.dim == 3 and flat_mesh and c.enforcement == "exact" and c.friction == "none" and isotropic


def edge_refiner(scene: CellScene, model: CellModel, problem: Callable[..., Any],
                 spectral: Callable[..., Any]) -> Callable[[FECell], ContactEdgeRefinement] | None:
    """``(scene's FE cell) -> `` its :class:`ContactEdgeRefinement`, or ``None`` where the scene has none
    (:func:`refines_along_edge`).  ``problem(scene, cell, model)``: the scene's cell problem on another mesh;
    ``spectral(scene, grid=, friction=, tol=)``: its spectral cell (both from :mod:`ngcontact.drivers.build`,
    which wires this refiner into the FE cell it makes)."""
    if not refines_along_edge(scene):
        return None
    g, d = scene.geometry, scene.discretization
    h = d.interface_maxh or d.maxh
    symmetric = quarter(scene)                    # the scene's cell's quarter, refined alike

    def pressures():
        twin = spectral(scene, grid=EDGE_TWIN_GRID, friction=False, tol=EDGE_TWIN_RTOL)
        return [twin.solve(cell_load(g.dim, **state)).fields["pressure"] for state in load_states(scene)]

    def cell_at(points, edge_maxh):
        cell = edge_refined_cell(points, edge_maxh=edge_maxh, period=g.period, h_rough=g.h_rough,
                                 h_counter=g.h_counter, maxh=d.maxh, interface_maxh=h, symmetric=symmetric)
        return FECell.of(problem(scene, cell, model))

    return lambda fe: ContactEdgeRefinement(fe, pressures, cell_at, h, float(g.period))
