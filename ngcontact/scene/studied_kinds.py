"""The kinds of scene an accuracy study refines, each with the discretization knobs it has.

A studied kind recognizes its scenes, names the knobs of their discretization
(:mod:`ngcontact.scene.discretization_knobs`, :mod:`ngcontact.scene.cell_table_knobs`) and prepares a
level's table; the study (:mod:`ngcontact.scene.refinement_ladder`) asks the first kind that takes a
scene and knows no kind by name:

* **cell** (FE and spectral): ``h``, ``order`` (FE), ``grid`` (spectral), ``k_n`` (penalty),
  ``tolerance`` (where set); not a cell with ``[ensemble]``, whose members are random;
* **macro** (also with ``[strength]``): ``h``, ``order``, ``tolerance`` (where set);
* **two-scale** (a macro scene with ``[two_scale]``): the macro knobs and the loop's, ``table_tol``,
  ``loop_tol`` and its cell's ``cell_grid`` / ``cell_h``, ``cell_order`` / ``cell_k_n``;
* **resolved** (``kind = "direct"``, the rough geometry meshed period by period): ``h`` (far-field
  ``maxh`` and ``elements_per_period``), ``order``, ``tolerance`` (where set).

A macro or resolved scene that states ``discretization.tolerance`` is refined until it is met (order, then
mesh), so every ladder but the tolerance's own drops it: each level is its own setting.
"""
from __future__ import annotations

from abc import ABC, abstractmethod

from ngcontact.errors import SceneError
from ngcontact.scene.cell_table_knobs import LOOP_KNOBS
from ngcontact.scene.discretization_knobs import (Knob, MeshSize, Order, Penalty, ResolvedMeshSize, SpectralGrid,
                                                  Tolerance)


class StudiedKind(ABC):
    """A kind of scene the study refines: which scenes, their knobs, and a level's table."""

    name = ""
    summary = ""
    knobs: tuple[Knob, ...] = ()

    @abstractmethod
    def takes(self, scene) -> bool:
        ...

    def refusal(self, scene) -> SceneError | None:
        """Why a scene of this kind cannot be studied, if it cannot."""
        return None

    def level_table(self, data: dict, knob: Knob) -> dict:
        """The table of a level of ``knob`` (``data``: the scene's table with the knob's keys set)."""
        return data


class Cell(StudiedKind):
    name, summary = "cell", "cell (FE and spectral; not with [ensemble])"
    knobs: tuple[Knob, ...] = (MeshSize(), Order(), SpectralGrid(), Penalty(), Tolerance())

    def takes(self, scene) -> bool:
        return scene.kind == "cell"

    def refusal(self, scene):
        if getattr(scene, "ensemble", None) is not None:
            return SceneError("ensemble", "[ensemble]", f"the accuracy study refines {supported()} scenes: the "
                              "members of an ensemble are random; study one realization (a cell scene without "
                              "[ensemble])")
        return None

    def level_table(self, data, knob):
        """A level answers on its own discretization: a cell without a tolerance is estimated there and not
        refined towards the default one (``discretization.estimate = "estimate"``, unless the scene opts out
        of the estimate; the FE cell by one order more on its mesh, the spectral cell from coarser grids), so
        each level's cost and error are its knob's.  Refined to the default tolerance, every level of a grid
        ladder would end on the grid where that tolerance is met (the 2D spectral stiffness's drives it to
        the same grid from every start), and the ladder would no longer vary its knob."""
        disc = data.setdefault("discretization", {})
        if disc.get("estimate", "auto") == "auto":
            disc["estimate"] = "estimate"
        return data


class Macro(StudiedKind):
    name, summary = "macro", "macro (also with [strength])"
    knobs: tuple[Knob, ...] = (MeshSize(), Order(), Tolerance())

    def takes(self, scene) -> bool:
        return scene.kind == "macro" and scene.two_scale is None

    def level_table(self, data, knob):
        return without_tolerance(data, knob)


class TwoScale(Macro):
    name, summary = "two-scale", "two-scale (macro with [two_scale]: also the loop's and its cell's knobs)"
    knobs = Macro.knobs + LOOP_KNOBS

    def takes(self, scene) -> bool:
        return scene.kind == "macro" and scene.two_scale is not None


class Resolved(StudiedKind):
    name, summary = "resolved", "resolved (direct)"
    knobs: tuple[Knob, ...] = (ResolvedMeshSize(), Order(), Tolerance())

    def takes(self, scene) -> bool:
        return scene.kind == "direct"

    def level_table(self, data, knob):
        return without_tolerance(data, knob)


def without_tolerance(data: dict, knob: Knob) -> dict:
    """A level's table without ``discretization.tolerance`` unless ``knob`` varies it (a scene that states it
    is refined until it is met, so another knob's level would not be its own setting)."""
    if not knob.sets_tolerance:
        data.get("discretization", {}).pop("tolerance", None)
    return data


#: the studied kinds, asked in this order
KINDS: tuple[StudiedKind, ...] = (Cell(), Macro(), TwoScale(), Resolved())


def supported() -> str:
    """The kinds the study refines, in words."""
    names = [k.summary for k in KINDS]
    return ", ".join(names[:-1]) + " and " + names[-1]


def studied_kind(scene) -> StudiedKind:
    """The studied kind that takes ``scene``; a :class:`SceneError` naming the kind, or the section that makes
    it unstudied, otherwise."""
    kind = next((k for k in KINDS if k.takes(scene)), None)
    if kind is None:
        raise SceneError("kind", scene.kind, f"the accuracy study refines {supported()} scenes; a "
                         f"{scene.kind!r} scene is a convergence study of its own: run it with 'ngcontact run'")
    refused = kind.refusal(scene)
    if refused is not None:
        raise refused
    return kind
