"""Scene descriptions -> model objects: the one translator of the package.

The scene layer only describes (frozen dataclasses, validated on load); this
module turns its sections into the objects the model code takes.  Each kind's
driver calls these instead of building its own copies.
"""
from __future__ import annotations

from ngcontact.fem import materials
from ngcontact.scene.sections import MaterialSpec


def elastic_law(spec: MaterialSpec) -> materials.ElasticLaw:
    """The elastic law a ``[materials.NAME]`` section describes (isotropic or Voigt ``C``)."""
    if spec.C is not None:
        return materials.anisotropic(spec.C)
    assert spec.E is not None and spec.nu is not None  # guaranteed by MaterialSpec.check
    return materials.isotropic(spec.E, spec.nu)


def body_laws(scene, names: dict[str, str]) -> dict[str, materials.ElasticLaw]:
    """``{body: law}`` for ``{body: material name}`` of ``scene.materials``."""
    return {body: elastic_law(scene.materials[name]) for body, name in names.items()}
