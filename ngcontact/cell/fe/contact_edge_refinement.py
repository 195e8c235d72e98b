"""The second discretization of a flat 3D cell with exact contact: meshes refined along the contact edge.

On the flat periodic 3D cell with exact non-penetration (paper eqs. 49-51 in the rigid limit of eq. 65) the
contact fraction's error is made at the contact edge: the node-to-node contact set places the edge within a
part of the element size there (:mod:`ngcontact.cell.fe.exact_contact_set`), an error of first order in that
size (:mod:`ngcontact.cell.fe.contact_edge_mesh`, "Why the edge").  Halving ``interface_maxh`` everywhere
(:class:`~ngcontact.cell.fe.second_discretization.InterfaceHalving`) multiplies the elements of ``S_C`` by
four per level, nearly all of them on open surface or inside the patches.

:class:`ContactEdgeRefinement` keeps the scene's ``maxh`` and ``interface_maxh`` and refines at the contact
edge only: level 0 is the scene's cell, level ``k >= 1`` the cell of
:func:`~ngcontact.cell.fe.contact_edge_mesh.edge_refined_cell` restricted to ``edge_maxh = h_k`` at the
edge points (:func:`~ngcontact.cell.fe.contact_edge_mesh.edge_points`) of the spectral twin's solutions at
the sweep's loads (the same layers and gap on a periodic grid).

The sizes.  An edge placed ``delta`` off moves the contact fraction ``f`` by ``delta L / P^2`` (``L`` the
edges' length), a relative error ``2 delta / l`` with ``l = 2 A / L`` the patches' width
(:func:`~ngcontact.cell.fe.contact_edge_mesh.patch_length`); with ``delta`` a part of the edge size ``h``
the relative error is a function of ``h / l``.  So the first refined level is already a fixed part of the
narrowest load's ``l`` and the others halve it,

    h_k = min(interface_maxh / 2, l / N_1) / 2^(k - 1),        N_1 = EDGE_CELLS,

(at most the interface halving's sizes ``interface_maxh / 2^k``, which it is without a contact edge at any
load, so that the sizes always halve): the contact fraction's relative error is
then the same at every load, a light load's small patch is refined as far relative to its size as a heavy
load's, and each level's elements along the edge, ``L / h_k``, are as many at every load (``L / h_k = 2 A
N_1 2^(k-1) / l^2`` with ``A`` of order ``l^2`` per patch).  No level coarser than ``l / N_1`` is solved:
those see the patch with a few elements across, where the edge term is not yet ``C h``
(:mod:`ngcontact.cell.fe.edge_size_extrapolation`) and a geometric tail on them claims less than the error.

The points.  Netgen restricts the size at each point given and grades away from it, so where the twin's
points are further apart along the edge than ``h_k`` the edge between them is meshed coarser than ``h_k``
(and by how much depends on where the points fall): the twin of level ``k`` has a grid step ``Delta <= h_k``
(the power of two ``n >= P / h_k`` points per direction, within :data:`TWIN_GRIDS`), so that its edge
points are at most ``h_k`` apart along the edge and within ``Delta / 2`` of the twin's own edge.

The estimate.  The answers converge at first order in ``h_k``, so the estimate takes the halving's rule
(:data:`~ngcontact.cell.fe.second_discretization.HALVING_RATE`), but for the contact fraction: from three
refined levels on it is reported as the Richardson extrapolation in the edge size of the last three
(:mod:`ngcontact.cell.fe.edge_size_extrapolation`), with that module's estimate (the grid convergence index
of the last level), the refiner answering
:class:`~ngcontact.cell.fe.second_discretization.Extrapolating`; a sweep on this ladder is not taken as
converged before that extrapolation exists (:meth:`ContactEdgeRefinement.ready`).

The grading.  Netgen grows the size from ``h_k`` at the edge at most like ``h_k + gamma r`` with the distance
``r`` (``gamma`` its grading, :data:`~ngcontact.cell.fe.contact_edge_mesh.GRADING`), so beyond ``r ~ h_k /
gamma`` the elements are about ``gamma r`` whatever ``h_k``, and the error the bodies make there (order 2 on a
linear trace on ``S_C``) does not fall with the edge size: on the bisinusoid's quarter at Netgen's 0.3 the
normal stiffness stays at one offset above the converged one over the edge levels.  That offset is made in
the graded band around the edge, not a patch width away: refining the bodies below and above the patch
(:class:`~ngcontact.cell.fe.contact_edge_mesh.PatchBody`) or ``S_C`` around it to a small part of ``l``
leaves it, a smaller grading lowers it.  A grading falling with every edge level, ``gamma_k = 0.3 2^(-beta
(k - 1))``, does not pay: the near field holds about ``L l / (gamma^2 h_k)`` elements (``L`` the edges'
length), so at ``beta = 1/2`` a level's unknowns grow about 4-fold instead of 2-fold, and each step moves two
sizes at once, which the extrapolation in ``h_k`` alone misreads (its estimate far above the contact
fraction's error).  So the edge sequence keeps the one grading (:attr:`ContactEdgeRefinement.grading`,
Netgen's 0.3), that error, the same at every edge level and so in no difference of the sequence, is what
the twin's bound below measures, and the grading is refined on its own levels after the edge sequence where
that bound misses the tolerance ("The grading's levels" below).

The twin's bound.  Those estimates see only the edge size; the error made at the sizes the ladder keeps
(``interface_maxh`` away from the edge, the bodies at the grading's size, the linear trace) does not change
from level to level and is not in them.  A geometric tail of the levels presumes that their limit is the
converged value; where a part ``E_0`` of the error is fixed along the ladder, the tail bounds the rest and
says nothing of ``E_0``, and where ``E_0`` has the other sign than the edge's part it also overstates the
error of the level at which the two cancel (the differences still show the edge's part falling, the sum is
smaller).  The twin solves the same continuum problem (the flat layers, the same gap carried as a function
on a flat ``S_C``, the same materials, exact frictionless contact), so with ``q_N`` its value on ``N``
points per direction and ``q`` the exact one, for the reported ``q_h``

    |q_h - q| <= |q_h - q_N| + |q_N - q|,
    |q_N - q| <= TWIN_SAFETY max(|q_N - q_{N/2}|, |q_{N/2} - q_{N/4}| / 2) = U,

the whole error, the part fixed along the ladder with the rest, measured rather than modelled.  The twin's
own tail ``U`` is the spectral cell's guarded bound
(:mod:`ngcontact.cell.spectral.refinement`): first order in its grid step, so a geometric tail at rate 1/2
equals the next difference, taken as the last one or the one before halved, whichever is larger (the
stiffness's differences change sign from grid to grid, and a last one that vanished at a crossing under-bounds
the twin's error), times :data:`TWIN_SAFETY` = 2 for the scatter about that rate
(:data:`ngcontact.cell.spectral.refinement.ERRATIC`).  The bound itself is

    B = DISTANCE_SAFETY |q_h - q_N| + U,

the measured distance with Roache's safety factor :data:`DISTANCE_SAFETY` (1.25, the three-grid factor of the
edge extrapolation's grid convergence index, :mod:`ngcontact.cell.fe.edge_size_extrapolation`): without it
the effectivity would exceed 1 by ``U / |q_h - q|`` only, a margin that rests on the twin's rate alone where
the ladder's error is much larger than the twin's.  ``N`` is :data:`FLOOR_GRID` at every level, not the grid
that places the level's edge: the grids of the first levels (256, 512 points) lie off the first-order line of
the finer ones, and a bound as large as the tolerance would hold back the levels whose own error is within
it; ``N/4`` enters only through its difference halved.  The three solves are made once per sweep (``N/4``
is often among the grids that place the edges, and the cheapest); their cost and the bound's effectivity
against the spectral cell converged on finer grids are in the bisinusoid's benchmark section
(``docs/benchmarks.md``, ``bisinusoid_scene_accuracy``).

Each of the mean closure, the normal stiffness and the normal coefficients of eq. 34 on the real contact set,
``k_n`` and ``g_n`` (the twin integrates the same ``k_n`` and gap over its contact set), whose ladder's
estimate is a geometric tail, takes ``B`` in its place (:data:`TWIN_MEASURED`); the contact fraction, whose
extrapolation's grid convergence index admits a fixed part up to its safety factor times its correction,
takes the larger of that and ``B`` (:meth:`ContactEdgeRefinement.twin_floors`).

The grading's levels.  Every estimated quantity is held to the tolerance, the stiffness by its own knob
(:meth:`ContactEdgeRefinement.steer`, the loop's
:class:`~ngcontact.cell.fe.second_discretization.Steered`): where the edge sequence's extrapolation exists
(:meth:`~ContactEdgeRefinement.ready`) and only the quantities of :data:`GRADED` (the stiffness, whose
error is the grading's) miss the tolerance, the next level keeps the last edge level's size and points and
multiplies the grading by :data:`GRADING_STEP` = ``1/sqrt(2)``, each further level again, so that the near
field's ``L l / (gamma^2 h)`` elements double per level as they do per halving of the edge size.  The
contact fraction stays the extrapolation of the edge sequence (its levels share one grading and their sizes
form one sequence; :meth:`~ContactEdgeRefinement.extrapolated`), the last level's own value beside it; the
closure, the stiffness and the coefficients are the last level's with its bound ``B``.  A quantity the
grading does not reduce that misses the tolerance once those levels have begun ends the ladder there, with
the reason (a stated tolerance: exit 3).  What the grading's level costs and the effectivity of the
stiffness's bound on the bisinusoid: ``docs/benchmarks.md``, section ``bisinusoid_scene_accuracy``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

import math

from ngcontact.cell.fe.contact_edge_mesh import GRADING, edge_points, patch_length
from ngcontact.cell.fe.edge_size_extrapolation import EdgeSizeExtrapolation, extrapolate
from ngcontact.cell.fe.observed_rate import Convergence
from ngcontact.cell.fe.second_discretization import HALVING_RATE


#: the refined levels whose contact fractions are extrapolated (the last ones)
EXTRAPOLATED_LEVELS = 3
#: ``N_1``: the first refined level's edge size is the narrowest patch width over this (module docstring)
EDGE_CELLS = 10.0
#: the twin's grid points per direction: at least the first, at most the second (module docstring)
TWIN_GRIDS = (256, 1024)
#: ``N`` of the twin's bound, on every level (module docstring, "The twin's bound"); ``N/2``, ``N/4`` with it
FLOOR_GRID = 2048
#: the twin's own error over the larger of its last difference and the one before halved (module docstring,
#: "The twin's bound")
TWIN_SAFETY = 2.0
#: the factor on the distance of the reported value from the twin's (module docstring, "The twin's bound")
DISTANCE_SAFETY = 1.25
#: the quantities given the twin's bound
TWIN_FLOORED = ("contact_fraction", "mean_closure", "normal_stiffness", "coefficient_k_n", "coefficient_g_n")
#: those whose estimate is the twin's bound in place of the ladder's geometric tail (the rest: the larger)
TWIN_MEASURED = ("mean_closure", "normal_stiffness", "coefficient_k_n", "coefficient_g_n")
#: the quantities whose error is the grading's: where only they miss the tolerance after the edge sequence, the
#: next level refines the grading (module docstring, "The grading's levels")
GRADED = ("normal_stiffness",)
#: the grading's factor from one grading level to the next (module docstring, "The grading's levels")
GRADING_STEP = 2.0 ** -0.5


def twin_grid(edge_maxh: float, period: float) -> int:
    """The twin's points per direction at edge size ``edge_maxh``: the power of two ``n >= P / h``, within
    :data:`TWIN_GRIDS` (module docstring)."""
    n = 2 ** math.ceil(math.log2(period / edge_maxh - 1e-9))
    return int(min(max(n, TWIN_GRIDS[0]), TWIN_GRIDS[1]))


def twin_edge_points(pressures: list[np.ndarray], period: float) -> np.ndarray:
    """The edge points of every pressure grid of the twin (one per load), together."""
    pts = [edge_points(p, period) for p in pressures]
    return np.concatenate(pts) if pts else np.empty((0, 2))


@dataclass
class ContactEdgeRefinement:
    """Level ``k``: the scene's cell, then its mesh refined to ``h_k`` along the twin's contact edges (module
    docstring).

    ``scene_cell`` is level 0; ``pressures(grid)`` gives the twin's pressure grids at the loads on a
    ``grid x grid`` grid (each grid asked once); ``cell_at(points, edge_maxh, grading)`` the cell (``sweep``,
    ``unknowns``) on the mesh refined at ``points`` with Netgen's ``grading`` (:attr:`grading` on the edge
    sequence, finer on the grading's levels: module docstring); ``period`` the cell's period;
    ``twin_heads(grid)``, where given, the twin's headline quantities at the loads on that grid (from the same
    solves as ``pressures``).
    """

    scene_cell: Any
    pressures: Callable[[int], list[np.ndarray]]
    cell_at: Callable[[np.ndarray, float, float], Any]
    interface_maxh: float
    period: float
    rule: Convergence = HALVING_RATE
    twin_heads: Callable[[int], list[dict[str, float]]] | None = None
    grading: float = GRADING
    #: the quantities whose estimate is the twin's bound alone (:data:`TWIN_MEASURED`)
    measured: tuple[str, ...] = TWIN_MEASURED
    #: the quantities not held to the tolerance (none: every estimated quantity has its knob)
    uncontrolled: tuple[str, ...] = ()
    #: the quantities the grading's levels reduce (:data:`GRADED`)
    graded: tuple[str, ...] = GRADED
    #: the last level of the edge sequence, once the grading's levels have begun (:meth:`steer`)
    edge_levels: int | None = None
    _grids: dict[int, list[np.ndarray]] = field(default_factory=dict, repr=False)

    def twin(self, grid: int) -> list[np.ndarray]:
        """The twin's pressure grids at the loads on ``grid`` (computed once per grid)."""
        if grid not in self._grids:
            self._grids[grid] = self.pressures(grid)
        return self._grids[grid]

    def width(self) -> float | None:
        """The narrowest patch width ``l`` over the loads on the coarsest twin (module docstring), ``None``
        where no load has a contact edge."""
        widths = [w for p in self.twin(TWIN_GRIDS[0]) if (w := patch_length(p, self.period)) is not None]
        return min(widths) if widths else None

    def edge_maxh(self, k: int) -> float:
        """``h_k`` (module docstring)."""
        width = self.width()
        if width is None:
            return self.interface_maxh / 2 ** k
        return min(self.interface_maxh / 2, width / EDGE_CELLS) / 2 ** (k - 1)

    def edge_level(self, k: int) -> int:
        """The level of the edge sequence whose edge size and points level ``k`` has: ``k``, or the last edge
        level for a grading level (module docstring, "The grading's levels")."""
        return k if self.edge_levels is None else min(k, self.edge_levels)

    def grading_of(self, k: int) -> float:
        """Level ``k``'s grading: :attr:`grading` on the edge sequence, times :data:`GRADING_STEP` per grading
        level after it."""
        steps = 0 if self.edge_levels is None else max(k - self.edge_levels, 0)
        return self.grading * GRADING_STEP ** steps

    def steer(self, k: int, missing: set[str]) -> str | None:
        """The knob of level ``k`` (:class:`~ngcontact.cell.fe.second_discretization.Steered`): the grading once
        the edge sequence gives its extrapolation and only quantities of :attr:`graded` miss the tolerance, the
        edge size before; a quantity the grading does not reduce missing it after the grading's levels began
        is out of this ladder's reach (the reason)."""
        if self.edge_levels is None:
            if missing and missing <= set(self.graded) and self.ready(k):
                self.edge_levels = k - 1
            return None
        rest = sorted(missing - set(self.graded))
        if rest:
            return (f"{', '.join(rest)} missed the tolerance after the edge sequence ended at level "
                    f"{self.edge_levels}, and the grading's levels do not reduce it")
        return None

    def points(self, k: int = 1) -> np.ndarray:
        """The twin's edge points at the loads for level ``k``, on the grid of :func:`twin_grid`."""
        return twin_edge_points(self.twin(twin_grid(self.edge_maxh(k), self.period)), self.period)

    def level(self, k: int) -> Any:
        if k == 0:
            return self.scene_cell
        edge = self.edge_level(k)
        return self.cell_at(self.points(edge), self.edge_maxh(edge), self.grading_of(k))

    def sequence(self, heads: list[list[dict[str, float]]]) -> list[list[dict[str, float]]]:
        """The levels of the geometric tails (the mean closure, the stiffness, the coefficients): the refined
        ones of the edge sequence, once there are two; level 0 is not refined at the edge, and its step to
        level 1 changes the mesh everywhere, not the edge size, so it is no difference of the sequence in
        ``h_k``; a grading level moves another size (module docstring)."""
        edge = heads[:self.edge_level(len(heads) - 1) + 1]
        return edge[1:] if len(edge) > 2 else edge

    def ready(self, levels: int) -> bool:
        """Whether ``levels`` solved levels (the scene's and the refined) give the extrapolation (module
        docstring): at least :data:`EXTRAPOLATED_LEVELS` refined ones."""
        return levels - 1 >= EXTRAPOLATED_LEVELS

    def extrapolated(self, heads: list[list[dict[str, float]]]) -> dict[str, list[EdgeSizeExtrapolation | None]]:
        """Per load the contact fraction extrapolated from the last three refined levels (module docstring);
        ``None`` per load before three refined levels."""
        refined = list(range(1, self.edge_level(len(heads) - 1) + 1))[-EXTRAPOLATED_LEVELS:]
        if len(refined) < EXTRAPOLATED_LEVELS:
            return {}
        sizes = [self.edge_maxh(k) for k in refined]
        out: list[EdgeSizeExtrapolation | None] = []
        for load in range(len(heads[-1])):
            values = [heads[k][load]["contact_fraction"] for k in refined if "contact_fraction" in heads[k][load]]
            out.append(extrapolate(sizes, values) if len(values) == len(sizes) else None)
        return {"contact_fraction": out}

    def twin_floors(self, reported: list[dict[str, float]], k: int) -> list[dict[str, tuple[float, str]]]:
        """Per load, per quantity of :data:`TWIN_FLOORED`, the bound
        ``DISTANCE_SAFETY |q_h - q_N| + TWIN_SAFETY max(|q_N - q_{N/2}|, |q_{N/2} - q_{N/4}| / 2)`` of the absolute
        error of level ``k``'s reported value ``q_h`` and its form in words (module docstring, "The twin's
        bound"); none without the twin's quantities or at level 0."""
        if self.twin_heads is None or k == 0:
            return [{} for _ in reported]
        n = FLOOR_GRID
        quarter, half, fine = self.twin_heads(n // 4), self.twin_heads(n // 2), self.twin_heads(n)   # coarse first
        if not len(fine) == len(half) == len(quarter) == len(reported):
            return [{} for _ in reported]
        form = (f"spectral twin: {DISTANCE_SAFETY:g} |q - q_N| + {TWIN_SAFETY:g} max(|q_N - q_N/2|, "
                f"|q_N/2 - q_N/4| / 2), N = {n}")
        return [{name: (DISTANCE_SAFETY * abs(q[name] - a[name])
                        + TWIN_SAFETY * max(abs(a[name] - b[name]), 0.5 * abs(b[name] - c[name])), form)
                 for name in TWIN_FLOORED if all(name in x for x in (q, a, b, c))}
                for q, a, b, c in zip(reported, fine, half, quarter)]

    def describe(self, k: int) -> str:
        if k == 0:
            return f"interface_maxh {self.interface_maxh:g}"
        edge = self.edge_level(k)
        graded = f", grading {self.grading_of(k):.3g}" if edge < k else ""
        return (f"edge_maxh {self.edge_maxh(edge):g} along the contact edge{graded} "
                f"(interface_maxh {self.interface_maxh:g})")

