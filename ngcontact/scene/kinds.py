"""The explicit table of scene kinds: name -> description class and effects.

The runner pairs each kind with its driver (:data:`ngcontact.runner.DRIVERS`);
the scene layer itself knows no driver.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ngcontact.scene import cell_scene, macro_scene, manufactured_scene, resolved_scene


@dataclass(frozen=True)
class Kind:
    """A problem type: its scene class and the function naming its effects."""

    scene: type
    effects: Callable[..., tuple[str, ...]]


KINDS: dict[str, Kind] = {
    "manufactured": Kind(manufactured_scene.ManufacturedScene, manufactured_scene.effects),
    "cell": Kind(cell_scene.CellScene, cell_scene.effects),
    "macro": Kind(macro_scene.MacroScene, macro_scene.effects),
    "direct": Kind(resolved_scene.DirectScene, resolved_scene.effects),
}
