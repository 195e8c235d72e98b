"""Scene sections -> the constitutive laws the model code takes: each body's elastic law (isotropic, or the
Voigt matrix ``C``) and the homogenized interface law of an ``[interface]`` section's numbers (paper eq. 34
and its friction), one translation for every kind's driver."""
from __future__ import annotations

from ngcontact.fem import materials
from ngcontact.laws import homogenized as il
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


def interface_normal_law(spec) -> il.NormalLaw | None:
    """The homogenized normal law of an ``[interface]`` section's numbers (``None`` with a cell)."""
    if spec.cell is not None:
        return None
    return il.normal_law(spec.law, kn=spec.kn, kt=spec.kt, knt=spec.knt, gap_force=spec.gap_force,
                         weights=spec.weights, directions=spec.directions, gaps=spec.gaps,
                         closure=spec.closure, pressure=spec.pressure)


def interface_friction(spec) -> il.Friction | None:
    """Homogenized friction of an ``[interface]`` section (``None`` without mu and threshold)."""
    if spec.mu == 0.0 and spec.threshold == 0.0:
        return None
    return il.Friction(mu=spec.mu, threshold=spec.threshold, width=spec.huber_width)
