"""The ``[two_scale]`` section of a macro scene: the coupling loop of paper Sec. 3.5 and how it solves its cell.

The loop tabulates the response of the cell scene named by ``cell`` over the macro pressures
(:mod:`ngcontact.coupling.pressure_table`).  ``cell_method`` solves that cell by another method than
the cell scene's own; ``cell_grid`` (spectral), ``cell_maxh``, ``cell_interface_maxh`` and ``cell_order``
(FE) replace the keys of the same name in the cell scene's ``[discretization]``, so that a scene (and an
accuracy study's level of it) refines the loop's cell without a copy of the cell scene.  A key that the
method solving the cell does not read is refused.
"""
from __future__ import annotations

from dataclasses import dataclass

from ngcontact.errors import SceneError
from ngcontact.scene.schema import MAX_ORDER, at_least, closed_interval, open_interval, param, positive
from ngcontact.scene.sections import MAX_GRID

#: the cell's ``[discretization]`` keys the section replaces, by the method that reads them
CELL_DISCRETIZATION = {"grid": "spectral", "maxh": "fe", "interface_maxh": "fe", "order": "fe"}


@dataclass(frozen=True, kw_only=True)
class TwoScaleSpec:
    """The two-scale coupling loop (paper Sec. 3.5)."""

    cell: str = param(doc="cell scene (kind cell) solved at the macro pressures, relative to this scene; "
                      "lengths in cell_length_unit, its [load] is not used")
    cell_length_unit: float = param(1.0, doc="length of one unit of the cell scene (scales its gap terms)",
                                    units="m", check=positive())
    tol: float = param(doc="stop when max |sigma_n(k) - sigma_n(k-1)| over the interface points is below",
                       units="Pa", check=positive())
    max_iter: int = param(20, doc="largest number of law updates", check=at_least(1))
    table_tol: float = param(0.01, doc="interpolation tolerance of the cell table (monotone cubic): the "
                             "contact fraction, the closure and the law's pressure relative to their "
                             "largest values at interval midpoints; with discretization.tolerance the "
                             "table is refined further where the interface's pressures lie, until its share "
                             "of the macro quantities is below half the tolerance",
                             check=positive())
    max_cell_solves: int = param(800, doc="largest number of cell solves of each of the loop's tables (the "
                                 "pressure table, and the shear table of interface.friction = 'from_cell') in one "
                                 "run, the loop's own and those of the refinement towards discretization.tolerance "
                                 "together; a table that needs more ends the run in exit 3 with its figures",
                                 check=at_least(1))
    table_min: float = param(1e-3, doc="smallest tabulated pressure as a fraction of the largest "
                             "(below it the law follows the table's first secant down to p = 0)",
                             check=open_interval(0, 1))
    cell_method: str | None = param(None, doc="how the loop solves its cell: fe (finite elements) or spectral "
                                    "(the small-slope cell on a grid, for a flat interface with the roughness in "
                                    "the gap); default: the cell scene's discretization.method as it resolves ('auto': "
                                    "spectral for a small-slope cell, else fe; fe for a frictional cell whose shear "
                                    "interface.friction = 'from_cell' tabulates)",
                                    choices=("fe", "spectral"))
    cell_grid: int | None = param(None, doc="spectral cell: its discretization.grid in the loop (default: the "
                                  "cell scene's)", check=closed_interval(8, MAX_GRID))
    cell_maxh: float | None = param(None, doc="FE cell: its discretization.maxh in the loop (default: the cell "
                                    "scene's)", units="cell_length_unit", check=positive())
    cell_interface_maxh: float | None = param(None, doc="FE cell: its discretization.interface_maxh in the loop "
                                              "(default: the cell scene's)", units="cell_length_unit",
                                              check=positive())
    cell_order: int | None = param(None, doc="FE cell: its discretization.order in the loop (default: the cell "
                                   "scene's)", check=closed_interval(1, MAX_ORDER))


def cell_discretization(spec: TwoScaleSpec | None) -> dict:
    """The keys of the loop cell's ``[discretization]`` that ``spec`` replaces (``method`` not among them)."""
    if spec is None:
        return {}
    values = {k: getattr(spec, f"cell_{k}") for k in CELL_DISCRETIZATION}
    return {k: v for k, v in values.items() if v is not None}


def load_cell(load, path: str, rel: str, overrides: dict, spec: TwoScaleSpec, shear_from_cell: bool = False):
    """The loop's cell scene as the loop solves it: ``load(path, overrides, method, discretization)`` with
    ``spec``'s method and discretization keys; a :class:`SceneError` names the key that made it invalid.
    ``shear_from_cell``: the loop also tabulates the cell's shear (``interface.friction = "from_cell"``), which
    needs the FE cell: a frictional cell whose ``method = "auto"`` chose the spectral cell is solved by fe
    (:mod:`ngcontact.scene.cell_method`)."""
    cell = _loaded(load, path, rel, overrides, spec, spec.cell_method)
    choice = cell.method_choice
    if (shear_from_cell and spec.cell_method is None and choice is not None and choice.automatic
            and choice.method != "fe" and cell.contact.friction != "none"):
        cell = _loaded(load, path, rel, overrides, spec, "fe", ("interface.friction", "from_cell"))
    return cell


def _loaded(load, path: str, rel: str, overrides: dict, spec: TwoScaleSpec, method: str | None,
            named: tuple[str, str] | None = None):
    """The cell by ``method`` with ``spec``'s keys; a fault names ``named`` (key, value), else the key of ``spec``
    that made the cell invalid."""
    keys = cell_discretization(spec)
    if method is None and not keys:
        return load(path, overrides)
    try:
        cell = load(path, overrides, method, keys)
    except SceneError as exc:
        if named is not None:
            (key, value), what = named, "by the FE cell its shear table needs"
        elif method is not None:
            key, value, what = "two_scale.cell_method", method, "by this method"
        else:
            (key, value), what = next((f"two_scale.cell_{k}", v) for k, v in keys.items()), "with it"
        raise SceneError(key, value, f"the cell {rel!r} cannot be solved {what}: {exc}") from None
    resolved = getattr(getattr(cell, "discretization", None), "method", None)
    for k, v in keys.items():
        if resolved is not None and CELL_DISCRETIZATION[k] != resolved:
            raise SceneError(f"two_scale.cell_{k}", v, f"sets the {CELL_DISCRETIZATION[k]} cell's "
                             f"discretization.{k}, but the loop solves the cell {rel!r} by method {resolved!r}; "
                             f"remove it, or set two_scale.cell_method = {CELL_DISCRETIZATION[k]!r}")
    return cell
