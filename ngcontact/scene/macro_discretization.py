"""The ``[discretization]`` section of a macro scene: mesh, order, uniform refinements and the accuracy aimed at.

``refinements = k`` splits every element of the mesh made with ``maxh``
(and ``interface_maxh``) ``k`` times uniformly (a triangle into 4, a
tetrahedron into 8, new boundary points on the geometry), so the mesh size
is ``maxh / 2^k`` everywhere, and the mesh is curved to ``order`` after the
last split.  In one process the whole mesh is refined; under ``mpiexec``
the coarse mesh is distributed and every rank refines its own part
(:mod:`ngcontact.distributed.macro_mesh`), so that no rank ever holds the
fine mesh whole.  Both give the same mesh, hence the same report.
"""
from __future__ import annotations

from dataclasses import dataclass

from ngcontact.scene.schema import closed_interval, open_interval, param, positive
from ngcontact.scene.sections import Discretization

#: the most uniform refinements a scene may ask for (3D: 8^4 = 4096 times the elements)
MAX_REFINEMENTS = 4


@dataclass(frozen=True, kw_only=True)
class MacroDiscretization(Discretization):
    """Finite element discretization of a macro scene, and the accuracy its headline numbers are held to."""

    tolerance: float | None = param(None, check=open_interval(0, 1), doc="the relative accuracy the headline "
        "quantities (peak interface pressure, resultant, largest von Mises and Tresca stress per body, safety "
        "factor; two-scale: the loop's residual and the cell table's interpolation error) are held to: each is "
        "reported with its discretization error, estimated from solves one order below and above on the same "
        "mesh, and results.accuracy.met says whether every one is within; a scene that states it is refined "
        "towards it: the order is raised by one on the scene's mesh while it pays (up to order 4), then the mesh "
        "is refined where the stress error indicator is large, interface first (up to 12 levels and 2e6 "
        "unknowns; results.accuracy.refinement lists the levels, their order, mesh level and unknowns), and a "
        "tolerance out of reach ends the run (exit 3); with [two_scale] the cell table is refined first: its "
        "share of the headline quantities, the safety factor included (from their changes as the table's "
        "intervals holding the interface's pressures are halved twice and the macro problem is solved again; "
        "with the cell's own friction the shear table's rows and jumps the interface uses too, its part "
        "added) is held to half the tolerance by making nodes of those midpoints where the table's own error "
        "is largest (up to 8 times; results.accuracy's cell_table_share, per quantity, per table and per "
        "round, the table's own interpolation error then listed but not counted), and the "
        "grown table is written back to the cell-law cache with the estimate's cell solves, so the next run "
        "starts from it and solves no cell again; default: 0.01, only judged (the scene's order and cell "
        "table are kept)")
    exclusion_radius: float | None = param(None, check=positive(), units="m", doc="radius of the ball around each "
        "singular point of the stress (where the interface ends closed on an unsupported boundary, a clamp "
        "meets an unsupported boundary, a re-entrant corner, a load with a "
        "traction ends; in 3D the tube around each such edge, a re-entrant edge by the body's dihedral angle) "
        "outside which each body's largest von Mises and Tresca stress and the safety factor are also "
        "reported, with their own error estimates (von_mises_<body>_away, ..., safety_factor_away in "
        "results.accuracy, with where each is attained; accuracy.exclusion lists the points, in 3D the "
        "edges): these converge, so they count in accuracy.met and in a refinement's target, while the global "
        "maxima, mesh dependent there, are listed with counted = false; 2D, axisymmetric and 3D runs, with "
        "[two_scale] too; must be below the smallest extent of the bodies' bounding boxes; default: a quarter "
        "of that extent")
    refinements: int = param(0, check=closed_interval(0, MAX_REFINEMENTS), doc="uniform refinements of the "
        "mesh made with maxh: every element split this many times (a triangle into 4, a tetrahedron into 8, "
        "new boundary points on the geometry; h = maxh / 2^k), curved to order after the last; under mpiexec "
        "the coarse mesh is distributed and each rank refines its part, so no rank holds the fine mesh whole "
        "(the way to meshes beyond one process's memory); max_elements bounds the refined count")

    def refined_count(self, n: float, dim: int) -> float:
        """The element count ``n`` of the mesh made with ``maxh`` after the uniform refinements."""
        return n * float(2 ** dim) ** self.refinements
