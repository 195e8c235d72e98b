"""The ladder of an accuracy study: copies of a scene, one discretization knob refined per level.

A scene's answer depends on its discretization through a few knobs; each knob that exists for the
scene's kind and method gives one ladder of ``n`` levels, every level the scene's own table with that
knob's keys replaced (all other keys as the user wrote them):

* ``h`` (FE cells, macro, direct): the mesh sizes halved per level, ``discretization.maxh`` and, where
  the scene sets it, ``interface_maxh`` (direct: ``maxh`` halved and ``elements_per_period`` doubled);
  the a-priori estimate ``e ~ C h^q`` makes the observed rate the slope in ``maxh``;
* ``order`` (the same kinds): the polynomial order one more per level; its error falls faster than any
  power of ``h``, so its rate is stated in the unknowns, ``e ~ C ndof^-r``;
* ``grid`` (spectral cells): the grid points per period doubled per level, rate in the grid step;
* ``k_n`` (cells with ``contact.enforcement = 'penalty'``): the penalty times 10 per level: the
  penalty's share of the answer is ``O(1/k_n)`` (it adds ``1/k_n`` to the interface compliance, paper
  eq. 65), rate in ``1/k_n``;
* ``tolerance`` (cells that set ``discretization.tolerance``; two-scale scenes' ``two_scale.table_tol``):
  divided by 4 per level, rate in the tolerance.

Every ladder ends one level beyond the scene: its level ``n - 2`` is the user's own discretization
(where the knob's range allows; an order ladder starts at the lowest admissible order), the levels
below are coarser, its last is the finest and serves as the study's reference for that knob.  So more
levels only add coarser ones, and no level is larger than one refinement of the scene (``2^d`` its
unknowns for ``h`` in ``d`` dimensions, ``((p + 1) / p)^d`` for the order, twice its grid points per
direction): the study's size is bounded by the scene's own.  Each
level is validated as the scene itself is (:func:`ngcontact.scene.loader.from_dict`): a level the
scene's own checks refuse (a mesh beyond ``max_elements``, a grid beyond the spectral bound, a penalty
outside its admissible ratio) is dropped with its reason, which bounds the study's size; a knob left
with fewer than 3 levels is dropped.
"""
from __future__ import annotations

from abc import ABC, abstractmethod

import copy
import json
from dataclasses import dataclass, field
from typing import Any

from ngcontact.errors import SceneError
from ngcontact.scene import loader
from ngcontact.scene.schema import MAX_ORDER

#: levels of a ladder: the default, and the bounds of ``--levels``
DEFAULT_LEVELS, MIN_LEVELS, MAX_LEVELS = 4, 3, 6
#: kinds the study refines, and what it says of the others
SUPPORTED = "cell (FE and spectral; not with [ensemble]), macro (also two-scale and with [strength]) and direct"


@dataclass(frozen=True)
class Level:
    """One level of one knob's ladder: the scene table with the knob's keys replaced."""

    knob: str
    index: int
    changes: dict[str, Any]      # dotted key -> value of this level
    parameter: float | None      # the knob's variable at this level (None: the unknowns, known after the run)
    size: float | None           # the level's unknowns over the scene's, estimated (None: not known beforehand)
    data: dict = field(repr=False, compare=False)
    scene: Any = field(repr=False, compare=False, default=None)

    @property
    def setting(self) -> str:
        return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}" for k, v in self.changes.items())

    @property
    def key(self) -> str:
        """The level's validated scene, canonical: equal keys are the same run (the scene's own level in every
        ladder)."""
        return json.dumps(loader.as_dict(self.scene) if self.scene is not None else self.data, sort_keys=True,
                          default=str)


class Knob(ABC):
    """A discretization knob: where it applies, its levels' key values and the variable of its rate."""

    name = ""
    variable = ""

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


def space_dim(scene) -> int:
    """The dimension the unknowns fill: a cell's, 3 for a 3D macro scene, else 2."""
    if scene.kind == "cell":
        return scene.geometry.dim
    return 3 if getattr(scene.geometry, "setting", "") == "3d" else 2


def _steps(n: int) -> range:
    """Refinement steps relative to the scene: ``-(n - 2), ..., 0, 1``."""
    return range(-(n - 2), 2)


class MeshSize(Knob):
    name, variable = "h", "maxh"

    def applies(self, scene) -> bool:
        return scene.kind in ("macro", "direct") or getattr(scene.discretization, "method", "fe") == "fe"

    def values(self, scene, n):
        d = scene.discretization
        out = []
        for s in _steps(n):
            f = 2.0 ** -s
            keys: dict[str, Any] = {"discretization.maxh": d.maxh * f}
            if scene.kind == "direct":
                keys["discretization.elements_per_period"] = d.elements_per_period / f
            elif d.interface_maxh is not None:
                keys["discretization.interface_maxh"] = d.interface_maxh * f
            out.append(keys)
        return out

    def parameter(self, changes):
        return changes["discretization.maxh"]

    def size(self, scene, changes):
        return (scene.discretization.maxh / changes["discretization.maxh"]) ** space_dim(scene)


class Order(Knob):
    name, variable = "order", "1/ndof"

    def applies(self, scene) -> bool:
        return MeshSize().applies(scene)

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
    name, variable = "grid", "period / grid"

    def applies(self, scene) -> bool:
        return scene.kind == "cell" and scene.discretization.method == "spectral"

    def values(self, scene, n):
        g = grid_of(scene)
        return [{"discretization.grid": int(g * 2.0 ** s)} for s in _steps(n) if g * 2.0 ** s >= 8]

    def parameter(self, changes):
        return 1.0 / changes["discretization.grid"]

    def size(self, scene, changes):
        return (changes["discretization.grid"] / grid_of(scene)) ** (scene.geometry.dim - 1)


class Penalty(Knob):
    name, variable = "k_n", "1/k_n"

    def applies(self, scene) -> bool:
        return scene.kind == "cell" and scene.contact.enforcement == "penalty" and not scene.contact.geometric_only

    def values(self, scene, n):
        return [{"contact.k_n": scene.contact.k_n * 10.0 ** s} for s in _steps(n)]

    def parameter(self, changes):
        return 1.0 / changes["contact.k_n"]

    def size(self, scene, changes):
        return 1.0


class Tolerance(Knob):
    name, variable = "tolerance", "tolerance"

    def __init__(self, key: str = "discretization.tolerance"):
        self.key = key

    def applies(self, scene) -> bool:
        section, name = self.key.split(".")
        return getattr(getattr(scene, section, None), name, None) is not None

    def values(self, scene, n):
        section, name = self.key.split(".")
        tol = getattr(getattr(scene, section), name)
        return [{self.key: tol * 4.0 ** -s} for s in _steps(n)]

    def parameter(self, changes):
        return changes[self.key]


KNOBS: tuple[Knob, ...] = (MeshSize(), Order(), SpectralGrid(), Penalty(), Tolerance(),
                           Tolerance("two_scale.table_tol"))


def grid_of(scene) -> int:
    """The spectral cell's grid: ``discretization.grid``, else a 3D height map's own, else the default."""
    from ngcontact.scene.cell_scene import spectral_grid
    g = scene.geometry
    if scene.discretization.grid is None and g.file is not None and g.dim == 3:
        from ngcontact.geometry import tabulated
        from ngcontact.scene.sections import resolve
        return spectral_grid(scene, tabulated.read_height_map(resolve(scene, g.file), path="geometry.file").shape)
    return spectral_grid(scene)


def check_study(scene) -> None:
    """Refuse a scene the study cannot refine: a :class:`SceneError` naming the kind and what is supported."""
    if scene.kind not in ("cell", "macro", "direct"):
        raise SceneError("kind", scene.kind, f"the accuracy study refines {SUPPORTED} scenes; a "
                         f"{scene.kind!r} scene is a convergence study of its own: run it with 'ngcontact run'")
    if scene.kind == "cell" and getattr(scene, "ensemble", None) is not None:
        raise SceneError("ensemble", "[ensemble]", f"the accuracy study refines {SUPPORTED} scenes: the members "
                         "of an ensemble are random; study one realization (a cell scene without [ensemble])")


def with_keys(data: dict, changes: dict[str, Any]) -> dict:
    """A deep copy of the scene table ``data`` with the dotted keys of ``changes`` set."""
    out = copy.deepcopy(data)
    for dotted, value in changes.items():
        node = out
        *path, last = dotted.split(".")
        for part in path:
            node = node.setdefault(part, {})
        node[last] = value
    return out


def ladder(scene, data: dict, n: int) -> tuple[list[Level], list[str]]:
    """The levels of every knob of ``scene`` (parsed table ``data``), and one line per level or knob dropped.

    Raises
    ------
    SceneError
        The kind is not supported (:func:`check_study`), ``n`` is out of range, or no knob applies.
    """
    check_study(scene)
    if not MIN_LEVELS <= n <= MAX_LEVELS:
        raise SceneError("--levels", n, f"an integer in [{MIN_LEVELS}, {MAX_LEVELS}]: at least 3 levels give a "
                         "rate, and each level refines the previous one by a factor 2 to 10")
    levels: list[Level] = []
    dropped: list[str] = []
    for knob in KNOBS:
        if not knob.applies(scene):
            continue
        mine = []
        for k, changes in enumerate(knob.values(scene, n)):
            level_data = with_keys(data, changes)
            if not isinstance(knob, Tolerance) and scene.kind in ("macro", "direct"):
                # a macro tolerance refines (order, then mesh) until met: a level of another knob is its setting alone
                level_data.get("discretization", {}).pop("tolerance", None)
            level = Level(knob.name, k, changes, knob.parameter(changes), knob.size(scene, changes), level_data)
            try:
                level = Level(knob.name, k, changes, level.parameter, level.size, level_data,
                              loader.from_dict(level_data, base_dir=scene.base_dir))
            except SceneError as exc:
                dropped.append(f"{knob.name} level {level.setting}: refused by the scene's checks ({exc})")
                continue
            mine.append(level)
        if len(mine) < MIN_LEVELS:
            dropped.append(f"{knob.name}: only {len(mine)} admissible level(s), fewer than {MIN_LEVELS}; "
                           "knob left out")
            continue
        levels.extend(mine)
    if not levels:
        raise SceneError("discretization", "(this scene)", "no discretization knob of this scene gives "
                         f"{MIN_LEVELS} admissible levels: " + "; ".join(dropped))
    return levels, dropped
