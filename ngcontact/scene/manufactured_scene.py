"""Scene kind ``manufactured``: verification of the elasticity discretization.

A smooth manufactured displacement ``u*`` defines the body force
``f = -div sigma(u*)``, Dirichlet and traction data, and on the periodic
two-material cell the traction jump across the bonded curved interface (see
:mod:`ngcontact.verification.manufactured`).  The discrete solution is compared with
``u*`` in L2 and the H1 seminorm over nested, uniformly refined meshes
(level ``k`` = the mesh generated with ``maxh``, refined ``k`` times, so
``h = maxh / 2^k``) and every polynomial order asked for; the observed
convergence rates are fitted by least squares and reported beside the
expected ``p + 1`` (L2) and ``p`` (H1).

Levels start at one refinement: Netgen's first uniform refinement changes
the shape of the generated triangles (the later ones do not), which would
bend the first point of a rate fit.
"""
from __future__ import annotations

from dataclasses import dataclass

from ngcontact.errors import MISSING, SceneError
from ngcontact.scene.sections import (MaterialSpec, SolverSpec, base_dir_field,
                     check_material_names)
from ngcontact.scene import mesh_size
from ngcontact.scene.schema import MAX_LEVELS, MAX_ORDER, all_of, closed_interval, distinct, nonempty, param, positive

SETTINGS = ("plane_strain", "axisymmetric", "3d", "periodic_cell")


@dataclass(frozen=True, kw_only=True)
class ManufacturedSection:
    """What to verify."""

    setting: str = param("plane_strain", doc="plane_strain, axisymmetric, 3d, or periodic_cell "
                         "(two bodies bonded along a curved interface, periodic in x)", choices=SETTINGS)
    body: str = param(doc="material of the body (periodic_cell: of the lower body)")
    second_body: str | None = param(None, doc="material of the upper body (periodic_cell only)")
    orders: tuple[int, ...] = param((1, 2, 3), doc="polynomial orders to run",
                                    check=all_of(nonempty(), closed_interval(1, MAX_ORDER), distinct()))
    maxh: float = param(0.25, doc="mesh size given to the mesher; level k is that mesh refined "
                        "uniformly k times, h = maxh / 2^k", units="m", check=positive())
    levels: int = param(3, doc="number of levels k = 1..levels in the rate fit",
                        check=closed_interval(3, MAX_LEVELS))
    max_elements: int = param(mesh_size.MAX_ELEMENTS, doc="refuse a study whose finest mesh is estimated to "
                              "have more elements", check=closed_interval(1, 10 ** 9))
    rate_tolerance: float = param(0.25, doc="largest admissible |observed - expected| rate for "
                                  "results.verified", check=positive())


@dataclass(frozen=True, kw_only=True)
class ManufacturedScene:
    kind: str = param(doc="problem type", choices=("manufactured",))
    materials: dict[str, MaterialSpec] = param(doc="named materials", check=nonempty())
    manufactured: ManufacturedSection = param(doc="verification settings")
    title: str = param("", doc="free text shown in the report")
    solver: SolverSpec = param(SolverSpec(), doc="solver settings (only `inverse` is used: the "
                               "problems are linear, one direct solve per level)")
    base_dir: str = base_dir_field()

    def check(self, path: str) -> None:
        m = self.manufactured
        names = {"body": m.body}
        if m.setting == "periodic_cell":
            if m.second_body is None:
                raise SceneError("manufactured.second_body", MISSING,
                                 "required for setting = 'periodic_cell': a material name")
            names["second_body"] = m.second_body
        elif m.second_body is not None:
            raise SceneError("manufactured.second_body", m.second_body,
                             f"not used by setting = {m.setting!r}; remove it")
        check_material_names(self.materials, names, "manufactured")
        dim = 3 if m.setting == "3d" else 2
        finest = mesh_size.estimate(dim, 1.0, m.maxh) * (2 ** dim) ** m.levels   # unit domains, refined
        mesh_size.refuse_beyond(finest, m.max_elements, "manufactured.levels", m.levels, path="manufactured",
                                hint=" (each level multiplies the elements by 2^dim)")


def effects(scene: ManufacturedScene) -> tuple[str, ...]:
    return ("elasticity",)


