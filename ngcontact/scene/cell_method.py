"""Which cell solves a cell scene: ``discretization.method`` and the rule of ``"auto"``.

Two implementations answer the cell protocol (:mod:`ngcontact.cell.cell_solver`): the FE cell, a mesh of
both bodies for any profile, and the spectral cell (:mod:`ngcontact.cell.spectral.layered_cell`), the
small-slope model of the same cell, a flat contact surface ``S_C`` with the roughness in the initial gap,
solved as two periodic elastic layers with FFTs.  On a small-slope cell both solve the same equations (the
FE cell's predictor and penalty share are that spectral twin), and the spectral cell refines its grid to the
default tolerance far faster than the FE cell refines its mesh, so it is the default there.

``method = "auto"`` (the default) is resolved once, when the scene is built and before its checks
(:meth:`ngcontact.scene.cell_scene.CellScene.resolved`), into a :class:`MethodChoice`: the method and the
reason in one sentence, which the report states; the scene holds it as its typed field ``method_choice``.
The rule, in order:

1. a scene that sets ``discretization.grid`` (only the spectral cell's grid) is spectral; it is refused
   for a cell that is not small-slope, and beside a key only the FE cell reads (:data:`FE_ONLY`);
2. a cell that is not small-slope (:func:`~ngcontact.scene.cell_geometry.flat_interface` false) is fe;
3. a scene that sets a key only the FE cell reads (:data:`FE_ONLY`: its mesh, order, Newton and
   linear-solver settings, its first loads' start) is fe, and so is exact friction with a Huber width
   ``contact.w`` (the FE cell regularizes friction with it under exact enforcement; the spectral cell's
   exact friction has no width, so the answers differ by that regularization);
4. a tolerance below what the spectral cell's solver resolves (``TOLERANCE_OVER_RTOL x solver.rtol``,
   :mod:`ngcontact.scene.spectral_grid`) is fe;
5. every other cell is spectral: the spectral cell solves every gap kind, both enforcements, the friction
   laws (with the FE cell's Huber width under the penalty), pressure and jump loads, macro strains,
   ensembles and independent loads.

What only the FE cell writes, the bodies' displacement fields (VTK) and their largest stresses, needs
``method = "fe"``; the links of a macro scene that need them (``strength.cell``, the shear table of a
two-scale loop with friction from its cell) solve an ``auto`` cell by fe (:attr:`MethodChoice.automatic`).

Which FE cell, its mirror-symmetric quarter or its period (``discretization.symmetry``), is the scene's
second resolved choice, a :class:`SymmetryChoice` in its typed field ``symmetry_choice``.  Its rule
(:mod:`ngcontact.drivers.mirror_symmetry`) samples the initial gap, read from the scene's files after the
checks, so the drivers resolve it, once, where they take a cell scene in
(:func:`ngcontact.drivers.build.with_symmetry`), not :meth:`~ngcontact.scene.cell_scene.CellScene.resolved`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TypeVar

from ngcontact.errors import SceneError
from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.scene.cell_geometry import flat_interface, small_slope
from ngcontact.scene.spectral_grid import TOLERANCE_OVER_RTOL
from ngcontact.scene.sections import CellDiscretization

D = TypeVar("D", bound=CellDiscretization)

#: the keys only the FE cell reads, by section (the spectral cell has no mesh, no Newton steps, no sparse solve)
FE_ONLY: dict[str, tuple[str, ...]] = {
    "discretization": ("order", "maxh", "interface_maxh", "max_elements", "budget_dofs", "symmetry"),
    "solver": ("atol", "max_iter", "inverse", "linear", "iterative_from", "start", "coulomb", "coulomb_rtol",
               "coulomb_max_iter"),
}


@dataclass(frozen=True)
class MethodChoice:
    """The method that solves a cell scene (``"fe"`` or ``"spectral"``), what the scene asked for
    (``"auto"``, ``"fe"``, ``"spectral"``) and why, in one sentence."""

    method: str
    reason: str
    requested: str = "auto"

    @property
    def automatic(self) -> bool:
        """Whether the method was chosen by the rule (``method = "auto"``), not set by the scene."""
        return self.requested == "auto"

    @property
    def statement(self) -> str:
        """The choice in one line: ``"spectral: a small-slope cell (...), no FE-only key set"``."""
        return f"{self.method}: {self.reason}"

    def as_dict(self) -> dict:
        return {"method": self.method, "requested": self.requested, "reason": self.reason,
                "statement": self.statement}


@dataclass(frozen=True)
class SymmetryChoice:
    """Whether the FE cell is meshed as its symmetric quarter (``used``), what the scene asked for
    (``requested``: ``"auto"`` or ``"off"``) and why, in one sentence."""

    used: bool
    reason: str
    requested: str = "auto"

    @property
    def statement(self) -> str:
        return ("symmetric quarter: " if self.used else "full period: ") + self.reason

    def as_dict(self) -> dict:
        return {"used": self.used, "requested": self.requested, "reason": self.reason,
                "statement": self.statement}


def fe_only_keys(scene) -> list[str]:
    """The keys of :data:`FE_ONLY` the scene sets (dotted), and ``contact.w`` with exact friction."""
    keys = [f"{section}.{k}" for section, names in FE_ONLY.items()
            for k in names if k in getattr(getattr(scene, section), "given", ())]
    c = scene.contact
    if c.enforcement == "exact" and c.friction != "none" and c.w is not None:
        keys.append("contact.w")
    return keys


def small_slope_text(scene) -> str:
    """What makes the cell small-slope, for the reason: ``flat interface, ...`` and where its roughness is."""
    g, gap = scene.geometry, scene.contact.gap.kind
    if small_slope(g):
        return f"flat interface, the {g.profile} roughness in the initial gap"
    return "flat interface, no initial gap" if gap == "none" else f"flat interface, a {gap} initial gap"


def not_small_slope_text(geometry) -> str:
    return (f"geometry.profile {geometry.profile!r} in the {geometry.arrangement!r} arrangement is not "
            "small-slope")


def choose(scene) -> MethodChoice:
    """The :class:`MethodChoice` of a cell scene (module docstring); a :class:`SceneError` for a grid set where
    the spectral cell cannot solve the scene or beside an FE-only key."""
    d, g = scene.discretization, scene.geometry
    if d.method != "auto":
        return MethodChoice(d.method, f"set by discretization.method = {d.method!r}", requested=d.method)
    fe_keys = fe_only_keys(scene)
    if "grid" in d.given:
        if not flat_interface(g):
            raise SceneError("discretization.grid", d.grid, "sets the spectral cell's grid, which solves the "
                             f"small-slope cell only, but {not_small_slope_text(g)}: remove it (the FE cell "
                             "solves this cell), or set discretization.method = 'fe'")
        if fe_keys:
            raise SceneError("discretization.grid", d.grid, f"sets the spectral cell's grid, but {fe_keys[0]} "
                             "is set too, which only the FE cell reads: set discretization.method = 'spectral' "
                             "or 'fe', or remove one of them")
        return MethodChoice("spectral", f"discretization.grid = {d.grid} is set, which only the spectral cell "
                            f"reads, on a small-slope cell ({small_slope_text(scene)})")
    if not flat_interface(g):
        return MethodChoice("fe", not_small_slope_text(g))
    if fe_keys:
        verb = "is" if len(fe_keys) == 1 else "are"
        return MethodChoice("fe", f"a small-slope cell, but {', '.join(fe_keys)} {verb} set, which only the FE "
                            "cell reads" + (" (the spectral cell's exact friction has no Huber width)"
                                            if "contact.w" in fe_keys else ""))
    floor = TOLERANCE_OVER_RTOL * scene.solver.rtol
    if d.tolerance is not None and d.tolerance < floor:
        return MethodChoice("fe", f"a small-slope cell, but discretization.tolerance = {d.tolerance:g} is below "
                            f"what the spectral cell's solver resolves ({TOLERANCE_OVER_RTOL:g} x solver.rtol = "
                            f"{floor:g})")
    return MethodChoice("spectral", f"a small-slope cell ({small_slope_text(scene)}), no FE-only key set")


def refines_along_edge(scene) -> bool:
    """Whether the scene's FE cell refines along its spectral twin's contact edge
    (:mod:`ngcontact.drivers.contact_edge_refiner`): a 3D cell meshed flat (a flat profile, or a small-slope
    one carried by the gap), exact contact, no friction, isotropic bodies."""
    g, c = scene.geometry, scene.contact
    kind = PROFILES[g.profile]
    flat_mesh = kind.solid is None and (kind.heights is None or small_slope(g))
    isotropic = all(scene.materials[m].C is None for m in (scene.bodies.rough, scene.bodies.counter))
    return g.dim == 3 and flat_mesh and c.enforcement == "exact" and c.friction == "none" and isotropic


def resolved_discretization(d: D, choice: MethodChoice) -> D:
    """The scene's ``[discretization]`` with its ``method`` the chosen one (the scene's new section, by
    ``dataclasses.replace``; :meth:`ngcontact.scene.cell_scene.CellScene.resolved`)."""
    out = replace(d, method=choice.method)
    object.__setattr__(out, "given", d.given)      # the keys the section's table set (not a field of replace)
    return out
