"""How a macro scene takes its interface law from a cell scene: overrides, friction source, refusals.

A macro scene names a cell through ``interface.cell`` (the law is the
cell's direction bundle) or ``[two_scale].cell`` (the law is the cell's
tabulated response, paper Sec. 3.5).  ``interface.cell_k_n``,
``cell_friction``, ``cell_mu``, ``cell_G`` and ``cell_w`` replace the keys of
that cell's ``[contact]`` section without copying the cell scene;
``interface.friction = "from_cell"`` takes the homogenized friction
``mu0``, ``G0`` (paper eqs. 42-43) from the same cell.  These checks need
the interface section and the two-scale section together.  ``two_scale.cell_method``
solves the loop's cell by another method than the cell scene's own (its
pressure table by the spectral small-slope cell, say).  Both work in
every setting (in 3D the loop samples the interface surface).
"""
from __future__ import annotations

from ngcontact.errors import SceneError


def overrides(interface) -> dict:
    """The ``[contact]`` keys of the cell scene the ``[interface]`` section overrides."""
    keys = {"k_n": interface.cell_k_n, "friction": interface.cell_friction, "mu": interface.cell_mu,
            "G": interface.cell_G, "w": interface.cell_w}
    return {k: v for k, v in keys.items() if v is not None}


def check(interface, two_scale) -> None:
    """Refuse cell keys without a cell, and friction given twice."""
    cell = interface.cell or (two_scale.cell if two_scale is not None else None)
    if cell is None:
        for key, value in overrides(interface).items():
            raise SceneError(f"interface.cell_{key}", value, "overrides a cell's contact, but the scene "
                             "names no cell (interface.cell or two_scale.cell)")
        if interface.friction == "from_cell":
            raise SceneError("interface.friction", "from_cell", "needs a cell: interface.cell or two_scale.cell")
    if interface.friction == "from_cell" and (interface.mu or interface.threshold):
        raise SceneError("interface.mu" if interface.mu else "interface.threshold",
                         interface.mu or interface.threshold,
                         "not used with interface.friction = 'from_cell' (the cell gives mu0 and G0); remove it")


def check_friction_source(interface, key: str, rel: str, cell) -> None:
    """With ``friction = "from_cell"``, the cell the law comes from (``key``) must have friction."""
    law_cell = "interface.cell" if interface.cell is not None else "two_scale.cell"
    if interface.friction == "from_cell" and key == law_cell and cell.contact.friction == "none":
        raise SceneError("interface.friction", "from_cell", f"the cell {rel!r} ({key}) has no friction "
                         "(contact.friction = 'none'); give it one with interface.cell_friction, or use "
                         "interface.friction = 'given'")


def check_spectral_loop(interface, two_scale, rel: str, cell) -> None:
    """The loop solves a spectral cell (``discretization.method = "spectral"``) for its pressure table only:
    the shear table of ``interface.friction = "from_cell"`` with a frictional cell needs the FE cell."""
    if interface.friction == "from_cell" and cell.contact.friction != "none":
        key, value = (("two_scale.cell_method", "spectral") if two_scale is not None and two_scale.cell_method
                      else ("two_scale.cell", rel))
        raise SceneError(key, value, "the loop solves a spectral cell for its pressure table only; the shear "
                         "table of interface.friction = 'from_cell' with a frictional cell needs the FE cell: "
                         "use two_scale.cell_method = 'fe', or interface.friction = 'given'")
