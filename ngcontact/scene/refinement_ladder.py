"""The ladder of an accuracy study: copies of a scene, one discretization knob refined per level.

A scene's answer depends on its discretization through a few knobs; each knob that exists for the
scene's studied kind and method (:mod:`ngcontact.scene.studied_kinds`: cell, macro, two-scale,
resolved) gives one ladder of ``n`` levels, every level the scene's own table with that knob's keys
replaced (all other keys as the user wrote them).  The knobs and the variables their rates are stated in
are those of :mod:`ngcontact.scene.discretization_knobs` (``h``, ``order``, ``grid``, ``k_n``,
``tolerance``) and, for a two-scale loop, :mod:`ngcontact.scene.cell_table_knobs` (``table_tol``,
``loop_tol``, the loop cell's ``cell_grid``, ``cell_h``, ``cell_order``, ``cell_k_n``).

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

import copy
import json
from dataclasses import dataclass, field
from typing import Any

from ngcontact.errors import SceneError
from ngcontact.scene import loader
from ngcontact.scene.discretization_knobs import Knob, Tolerance
from ngcontact.scene.studied_kinds import KINDS, StudiedKind, studied_kind, supported

#: levels of a ladder: the default, and the bounds of ``--levels``
DEFAULT_LEVELS, MIN_LEVELS, MAX_LEVELS = 4, 3, 6
#: kinds the study refines, and what it says of the others
SUPPORTED = supported()


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


#: every knob of every studied kind, by name (a knob's name means one variable in every kind)
KNOBS: tuple[Knob, ...] = tuple({k.name: k for kind in KINDS for k in kind.knobs}.values())


def check_study(scene) -> StudiedKind:
    """The studied kind of ``scene`` (:func:`ngcontact.scene.studied_kinds.studied_kind`); a :class:`SceneError`
    naming the kind and what is supported where the study cannot refine it."""
    return studied_kind(scene)


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


def own_key(scene, data: dict) -> str:
    """The :attr:`Level.key` of the scene's own level (parsed table ``data``): the table as a level of its kind
    prepares it (a cell estimated on its own discretization, :meth:`StudiedKind.level_table`), its tolerance
    kept as the user runs it, so that the level of each ladder that is the scene is found as such."""
    table = check_study(scene).level_table(copy.deepcopy(data), Tolerance())
    return Level("own", 0, {}, None, None, table, loader.from_dict(table, base_dir=scene.base_dir)).key


def ladder(scene, data: dict, n: int) -> tuple[list[Level], list[str]]:
    """The levels of every knob of ``scene`` (parsed table ``data``), and one line per level or knob dropped.

    Raises
    ------
    SceneError
        The kind is not supported (:func:`check_study`), ``n`` is out of range, or no knob applies.
    """
    kind = check_study(scene)
    if not MIN_LEVELS <= n <= MAX_LEVELS:
        raise SceneError("--levels", n, f"an integer in [{MIN_LEVELS}, {MAX_LEVELS}]: at least 3 levels give a "
                         "rate, and each level refines the previous one by a factor 2 to 10")
    levels: list[Level] = []
    dropped: list[str] = []
    for knob in kind.knobs:
        if not knob.applies(scene):
            continue
        mine = []
        for k, changes in enumerate(knob.values(scene, n)):
            level_data = kind.level_table(with_keys(data, knob.table_changes(scene, changes)), knob)
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
