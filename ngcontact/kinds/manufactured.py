"""Scene kind ``manufactured``: verification of the elasticity discretization.

A smooth manufactured displacement ``u*`` defines the body force
``f = -div sigma(u*)`` and Dirichlet data; the discrete solution is compared
with ``u*`` in L2 and H1 over a sequence of meshes and polynomial orders, and
the observed convergence rates are reported (expected ``p + 1`` in L2 and
``p`` in H1 for order ``p``).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..scene import (Discretization, MaterialSpec, SolverSpec, base_dir_field,
                     check_material_names, register)
from ..schema import all_of, at_least, nonempty, param, positive

SETTINGS = ("plane_strain", "axisymmetric", "3d", "periodic_cell")


@dataclass(frozen=True, kw_only=True)
class ManufacturedSection:
    """What to verify."""

    setting: str = param("plane_strain", doc="plane_strain, axisymmetric, 3d, or periodic_cell "
                         "(two bodies bonded along a curved interface, periodic in x)", choices=SETTINGS)
    body: str = param(doc="material of the body (periodic_cell: of the lower body)")
    second_body: str | None = param(None, doc="material of the upper body (periodic_cell only)")
    orders: tuple[int, ...] = param((1, 2, 3), doc="polynomial orders to run",
                                    check=all_of(nonempty(), at_least(1)))
    maxh: tuple[float, ...] = param((0.5, 0.25, 0.125), doc="mesh sizes, coarse to fine (>= 3 for a rate)",
                                    units="m", check=all_of(nonempty(), positive()))


@dataclass(frozen=True, kw_only=True)
class ManufacturedScene:
    kind: str = param(doc="problem type", choices=("manufactured",))
    materials: dict[str, MaterialSpec] = param(doc="named materials", check=nonempty())
    manufactured: ManufacturedSection = param(doc="verification settings")
    title: str = param("", doc="free text shown in the report")
    discretization: Discretization = param(Discretization(), doc="unused here except as defaults")
    solver: SolverSpec = param(SolverSpec(), doc="solver settings")
    base_dir: str = base_dir_field()

    def check(self, path: str) -> None:
        m = self.manufactured
        names = {"body": m.body}
        if m.setting == "periodic_cell":
            if m.second_body is None:
                from ..errors import MISSING, SceneError
                raise SceneError("manufactured.second_body", MISSING,
                                 "required for setting = 'periodic_cell': a material name")
            names["second_body"] = m.second_body
        elif m.second_body is not None:
            from ..errors import MISSING, SceneError
            raise SceneError("manufactured.second_body", m.second_body,
                             f"not used by setting = {m.setting!r}; remove it")
        check_material_names(self.materials, names, "manufactured")


def effects(scene: ManufacturedScene) -> tuple[str, ...]:
    return ("elasticity",)


register("manufactured", ManufacturedScene, "ngcontact.drivers.manufactured:run", effects)
