"""The knobs of a two-scale loop's cell table: what the accuracy study refines besides the macro solve.

The loop (paper Sec. 3.5) tabulates its cell's response over the macro pressures and stops when the
macro normal stress changes by less than ``two_scale.tol``; its answer depends on

* ``table_tol``: the table's interpolation tolerance ``two_scale.table_tol``, divided by 4 per level
  (the monotone cubic's midpoint error is held below it, so the answer's share falls with it);
* ``loop_tol``: the loop's stopping tolerance ``two_scale.tol`` [Pa], divided by 4 per level (the
  loop's residual, the last change of the interface pressure, is below it);
* the cell's own discretization, as the loop solves the cell (``two_scale.cell_method``), set through
  the section's keys that replace the cell scene's (:mod:`ngcontact.scene.two_scale_section`):
  ``cell_grid`` (spectral: ``two_scale.cell_grid`` doubled per level, rate in the grid step),
  ``cell_h`` (FE: ``two_scale.cell_maxh`` and, where the cell has one, ``cell_interface_maxh`` halved,
  rate in the cell's ``maxh``) and ``cell_order`` (FE: one order more per level, rate in the macro
  unknowns, which stay the same: the order ladder's rate is not stated for it, see :meth:`CellOrder.parameter`);
* ``cell_k_n``: a penalty cell's ``k_n`` through ``interface.cell_k_n``, times 10 per level (its share
  of the answer is ``O(1/k_n)``, paper eq. 65).

Each ladder runs as the others do (:func:`ngcontact.scene.discretization_knobs.steps`): coarser levels,
the scene's own at ``n - 2``, one refinement of it last.  A level changes the loop's cell only, so the
macro unknowns stay the scene's; the cell's cost is not estimated beforehand (``size`` None).
"""
from __future__ import annotations

from typing import Any

from ngcontact.scene import cell_links, loader
from ngcontact.scene.discretization_knobs import Knob, Tolerance, grid_of, steps
from ngcontact.scene.sections import resolve
from ngcontact.scene.two_scale_section import load_cell


def loop_cell(scene):
    """The cell scene of ``scene``'s two-scale loop as the loop solves it (its contact overrides, method and
    discretization keys applied)."""
    spec = scene.two_scale
    overrides = cell_links.overrides(scene.interface)
    return load_cell(loader.load_with_contact, resolve(scene, spec.cell), spec.cell, overrides, spec,
                     shear_from_cell=scene.interface.friction == "from_cell")


class LoopCellKnob(Knob):
    """A knob of the loop's cell: its own level leaves the keys the scene does not set unset."""

    def table_changes(self, scene, changes):
        own = self.values(scene, 2)[0]          # step 0: the values the loop solves with now
        return {k: v for k, v in changes.items() if not (scene_value(scene, k) is None and own.get(k) == v)}


def scene_value(scene, dotted: str):
    """The value of a dotted key of a validated scene (None: unset)."""
    node = scene
    for part in dotted.split("."):
        node = getattr(node, part, None)
    return node


class CellGrid(LoopCellKnob):
    """The loop's spectral cell: its grid points per period doubled per level."""

    name, variable = "cell_grid", "period / grid"

    def applies(self, scene) -> bool:
        return loop_cell(scene).discretization.method == "spectral"

    def values(self, scene, n):
        g = grid_of(loop_cell(scene))
        return [{"two_scale.cell_grid": int(g * 2.0 ** s)} for s in steps(n) if g * 2.0 ** s >= 8]

    def parameter(self, changes):
        return 1.0 / changes["two_scale.cell_grid"]


class CellMeshSize(LoopCellKnob):
    """The loop's FE cell: its ``maxh`` and, where set, ``interface_maxh`` halved per level."""

    name, variable = "cell_h", "cell maxh"

    def applies(self, scene) -> bool:
        return loop_cell(scene).discretization.method == "fe"

    def values(self, scene, n):
        d = loop_cell(scene).discretization
        out = []
        for s in steps(n):
            keys: dict[str, Any] = {"two_scale.cell_maxh": d.maxh * 2.0 ** -s}
            if d.interface_maxh is not None:
                keys["two_scale.cell_interface_maxh"] = d.interface_maxh * 2.0 ** -s
            out.append(keys)
        return out

    def parameter(self, changes):
        return changes["two_scale.cell_maxh"]


class CellOrder(LoopCellKnob):
    """The loop's FE cell: its polynomial order one more per level, from order 1."""

    name, variable = "cell_order", "1/cell order"

    def applies(self, scene) -> bool:
        return loop_cell(scene).discretization.method == "fe"

    def values(self, scene, n):
        from ngcontact.scene.schema import MAX_ORDER
        p = loop_cell(scene).discretization.order
        first = max(1, min(p - (n - 2), MAX_ORDER - n + 1))
        return [{"two_scale.cell_order": q} for q in range(first, min(first + n, MAX_ORDER + 1))]

    def parameter(self, changes):
        """The order itself: the macro unknowns do not change with the cell's order, so the rate is stated
        against ``1 / order`` (a slope that grows with the order where the error falls exponentially)."""
        return 1.0 / changes["two_scale.cell_order"]


class CellPenalty(LoopCellKnob):
    """The loop's penalty cell: ``interface.cell_k_n`` times 10 per level."""

    name, variable = "cell_k_n", "1/k_n"

    def applies(self, scene) -> bool:
        contact = loop_cell(scene).contact
        return contact.enforcement == "penalty"

    def values(self, scene, n):
        k_n = loop_cell(scene).contact.k_n
        return [{"interface.cell_k_n": k_n * 10.0 ** s} for s in steps(n)]

    def parameter(self, changes):
        return 1.0 / changes["interface.cell_k_n"]


#: the loop's knobs, after the macro solve's own
LOOP_KNOBS: tuple[Knob, ...] = (Tolerance("two_scale.table_tol", "table_tol"), Tolerance("two_scale.tol", "loop_tol"),
                                CellGrid(), CellMeshSize(), CellOrder(), CellPenalty())
