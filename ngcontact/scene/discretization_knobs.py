"""The discretization knobs of an accuracy study: what one ladder refines, and the variable of its rate.

A knob names the scene keys one ladder changes, their values level by level and the variable the
observed rate is stated in (:mod:`ngcontact.scene.refinement_ladder` builds the levels; which knobs a
scene has is its studied kind's, :mod:`ngcontact.scene.studied_kinds`):

* ``h`` (FE cells, macro scenes): the mesh sizes halved per level, ``discretization.maxh`` and, where
  the scene sets it, ``interface_maxh``; the a-priori estimate ``e ~ C h^q`` makes the observed rate the
  slope in ``maxh``; for a resolved (``direct``) scene ``maxh`` halved and ``elements_per_period``
  doubled (the interface mesh size ``eps / elements_per_period`` halved with it);
* ``order`` (the same kinds): the polynomial order one more per level; its error falls faster than any
  power of ``h``, so its rate is stated in the unknowns, ``e ~ C ndof^-r``;
* ``grid`` (spectral cells): the grid points per period doubled per level, rate in the grid step;
* ``k_n`` (cells with ``contact.enforcement = 'penalty'``): the penalty times 10 per level: the
  penalty's share of the answer is ``O(1/k_n)`` (it adds ``1/k_n`` to the interface compliance, paper
  eq. 65), rate in ``1/k_n``;
* ``tolerance`` (cells and macro scenes that set ``discretization.tolerance``), divided by 4 per level,
  rate in the tolerance; the same knob over another key is a two-scale loop's table or loop tolerance
  (:mod:`ngcontact.scene.cell_table_knobs`).

Every knob's levels run from coarser ones through the scene's own (level ``n - 2``) to one refinement
of it (level ``n - 1``, the ladder's reference; :func:`steps`).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any

from ngcontact.scene.schema import MAX_ORDER


class Knob(ABC):
    """A discretization knob: where it applies, its levels' key values and the variable of its rate."""

    name = ""
    variable = ""
    #: whether the knob's levels vary ``discretization.tolerance`` (a macro scene's other ladders drop it)
    sets_tolerance = False

    @abstractmethod
    def applies(self, scene) -> bool:
        ...

    @abstractmethod
    def values(self, scene, n: int) -> list[dict[str, Any]]:
        """The keys of each of the ``n`` levels, coarsest first, the scene's own at ``n - 2``."""

    @abstractmethod
    def parameter(self, changes: dict[str, Any]) -> float | None:
        ...

    def size(self, scene, changes: dict[str, Any]) -> float | None:
        """The level's unknowns over the scene's, estimated (None: the knob does not fix them)."""
        return None

    def table_changes(self, scene, changes: dict[str, Any]) -> dict[str, Any]:
        """The keys a level writes into the scene's table: ``changes``, but where a knob's key is unset in the
        scene and its value is the one the scene already solves with (so that the scene's own level is the
        scene itself)."""
        return changes


def space_dim(scene) -> int:
    """The dimension the unknowns fill: a cell's own, 3 for a 3D macro scene, else 2."""
    dim = getattr(scene.geometry, "dim", None)
    if isinstance(dim, int):
        return dim
    return 3 if getattr(scene.geometry, "setting", "") == "3d" else 2


def steps(n: int) -> range:
    """Refinement steps relative to the scene: ``-(n - 2), ..., 0, 1``."""
    return range(-(n - 2), 2)


def is_fe(discretization) -> bool:
    """Whether a ``[discretization]`` section is solved by finite elements (macro and resolved ones always)."""
    return getattr(discretization, "method", "fe") == "fe"


class MeshSize(Knob):
    """``maxh`` and, where set, ``interface_maxh`` halved per level."""

    name, variable = "h", "maxh"

    def applies(self, scene) -> bool:
        return is_fe(scene.discretization)

    def values(self, scene, n):
        d = scene.discretization
        out = []
        for s in steps(n):
            f = 2.0 ** -s
            keys: dict[str, Any] = {"discretization.maxh": d.maxh * f}
            if d.interface_maxh is not None:
                keys["discretization.interface_maxh"] = d.interface_maxh * f
            out.append(keys)
        return out

    def parameter(self, changes):
        return changes["discretization.maxh"]

    def size(self, scene, changes):
        return (scene.discretization.maxh / changes["discretization.maxh"]) ** space_dim(scene)


class ResolvedMeshSize(MeshSize):
    """A resolved scene's far-field ``maxh`` halved and its ``elements_per_period`` doubled per level."""

    def values(self, scene, n):
        d = scene.discretization
        return [{"discretization.maxh": d.maxh * 2.0 ** -s, "discretization.elements_per_period":
                 d.elements_per_period * 2.0 ** s} for s in steps(n)]


class Order(Knob):
    """The polynomial order one more per level, from the lowest admissible one."""

    name, variable = "order", "1/ndof"

    def applies(self, scene) -> bool:
        return is_fe(scene.discretization)

    def values(self, scene, n):
        axisymmetric = getattr(scene.geometry, "setting", "") == "axisymmetric"
        lowest = 2 if axisymmetric else 1     # order 1 leaves no interior sample off the axis of revolution
        p = scene.discretization.order
        first = max(lowest, min(p - (n - 2), MAX_ORDER - n + 1))
        return [{"discretization.order": q} for q in range(first, min(first + n, MAX_ORDER + 1))]

    def parameter(self, changes):
        return None

    def size(self, scene, changes):
        """Lagrange elements of order ``q`` carry about ``q^d`` nodes each."""
        return (changes["discretization.order"] / scene.discretization.order) ** space_dim(scene)


class SpectralGrid(Knob):
    """A spectral cell's grid points per period doubled per level."""

    name, variable = "grid", "period / grid"

    def applies(self, scene) -> bool:
        return scene.discretization.method == "spectral"

    def values(self, scene, n):
        g = grid_of(scene)
        return [{"discretization.grid": int(g * 2.0 ** s)} for s in steps(n) if g * 2.0 ** s >= 8]

    def parameter(self, changes):
        return 1.0 / changes["discretization.grid"]

    def size(self, scene, changes):
        return (changes["discretization.grid"] / grid_of(scene)) ** (scene.geometry.dim - 1)


class Penalty(Knob):
    """A penalty cell's ``k_n`` times 10 per level."""

    name, variable = "k_n", "1/k_n"

    def applies(self, scene) -> bool:
        return scene.contact.enforcement == "penalty" and not scene.contact.geometric_only

    def values(self, scene, n):
        return [{"contact.k_n": scene.contact.k_n * 10.0 ** s} for s in steps(n)]

    def parameter(self, changes):
        return 1.0 / changes["contact.k_n"]

    def size(self, scene, changes):
        return 1.0


class Tolerance(Knob):
    """A tolerance the scene sets (``key``, dotted), divided by 4 per level."""

    variable = "tolerance"

    def __init__(self, key: str = "discretization.tolerance", name: str = "tolerance"):
        self.key, self.name = key, name
        self.sets_tolerance = key == "discretization.tolerance"

    def applies(self, scene) -> bool:
        section, name = self.key.split(".")
        return getattr(getattr(scene, section, None), name, None) is not None

    def values(self, scene, n):
        section, name = self.key.split(".")
        tol = getattr(getattr(scene, section), name)
        return [{self.key: tol * 4.0 ** -s} for s in steps(n)]

    def parameter(self, changes):
        return changes[self.key]


def grid_of(scene) -> int:
    """The spectral cell's grid: ``discretization.grid``, else a 3D height map's own, else the default."""
    from ngcontact.scene.cell_scene import spectral_grid
    g = scene.geometry
    if scene.discretization.grid is None and g.file is not None and g.dim == 3:
        from ngcontact.geometry import tabulated
        from ngcontact.scene.sections import resolve
        return spectral_grid(scene, tabulated.read_height_map(resolve(scene, g.file), path="geometry.file").shape)
    return spectral_grid(scene)
