"""The homogenized interface law of a cell scene, for a caller outside a macro scene.

The same law a macro scene's ``interface.cell`` gives (:func:`ngcontact.drivers.build.law_from_cell`, the
cell's direction bundle, cached): the unilateral bundle of paper eqs. 31-33 with the weights
``w_q = k_n |ds_q| / |T|``, micro normals ``n_q`` and micro gaps ``g_q``, or its linearization, the
Winkler law of eq. 34 with ``K0 = sum_q w_q n_q n_q^T``; friction optionally from the cell too (paper
eqs. 42-43, :func:`ngcontact.drivers.build.friction_from_cell`).  The result is an
:class:`~ngcontact.laws.homogenized.InterfaceLaw` (what :class:`~ngcontact.macro.macro_problem.MacroProblem`
and :func:`ngcontact.macro.interface_form.interface_form` take) carrying its coefficients.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field

import numpy as np

from ngcontact.coupling import cell_law as cached
from ngcontact.drivers import build
from ngcontact.fem.elasticity import SETTINGS, dimension
from ngcontact.laws import homogenized as il
from ngcontact.macro.interface_form import refuse
from ngcontact.scene.macro_scene import InterfaceSpec

#: the laws a cell gives: its bundle (eqs. 31-33) or the bundle's linearization (eq. 34)
FORMS = ("bundle", "linear")
#: the Huber width of friction from the cell, as a macro scene's ``interface.huber_width``
HUBER_WIDTH = float(next(f.default for f in dataclasses.fields(InterfaceSpec)  # type: ignore[arg-type]
                         if f.name == "huber_width"))


@dataclass(frozen=True, kw_only=True)
class CellLaw(il.InterfaceLaw):
    """An interface law computed from a cell scene, with its coefficients.

    Attributes
    ----------
    normal, friction
        As :class:`~ngcontact.laws.homogenized.InterfaceLaw`.
    setting
        The macro setting the law is written for (its frame's dimension).
    coefficients
        ``K0``: the full-contact stiffness matrix of eq. 34 in the local frame ``(n0, t...)`` [Pa/m];
        the bundle's ``weights`` [Pa/m], ``directions`` and ``gaps`` [m] (eqs. 31-33); with friction from
        the cell ``mu0`` and ``G0`` [Pa] (eqs. 42-43).
    source
        Where the law came from, as a macro run's report has it (``results.law``).
    """

    setting: str
    coefficients: dict = field(compare=False)
    source: dict = field(compare=False)


def _cell_scene(cell):
    """A validated cell scene and its file (``None`` for a scene loaded by the caller)."""
    if isinstance(cell, (str, os.PathLike)):
        path = os.fspath(cell)
        return build.cell_scene_of(path, key="cell"), os.path.abspath(path)
    if getattr(cell, "kind", None) == "cell":
        return build.with_symmetry(cell), None
    raise refuse("cell", cell if getattr(cell, "kind", None) is None else f"a {cell.kind!r} scene",
                 "a cell scene file or a scene of kind 'cell' from ngcontact.load")


def _friction(friction, scene, arrays: dict, huber_width: float) -> tuple[il.Tangential | None, dict]:
    if friction is None:
        return None, {"source": "none"}
    if friction == "from_cell":
        micro = build.micro_friction(scene.contact)
        if micro is None:
            raise refuse("friction", friction, "the cell has no friction (contact.friction = 'none'); give "
                         "None or a Friction")
        values = cached.friction_from_bundle(arrays, k_n=scene.contact.k_n, friction=micro)
        return (il.Friction(mu=values["mu0"], threshold=values["G0"], width=huber_width),
                {"source": "cell", "mu0": values["mu0"], "G0": values["G0"], "huber_width": huber_width,
                 "equations": "paper eqs. 42-43"})
    if isinstance(friction, il.TangentialLaw):
        return friction, {"source": "given", "type": type(friction).__name__}
    raise refuse("friction", friction, "None, 'from_cell' or a friction law (ngcontact.laws.homogenized.Friction)")


def cell_law(cell, *, setting: str = "plane_strain", form: str = "bundle", length_unit: float = 1.0,
             friction=None, huber_width: float = HUBER_WIDTH, cache_dir: str | None = None) -> CellLaw:
    """The homogenized law of a cell scene for a macro interface.

    Parameters
    ----------
    cell
        A cell scene file, or a scene of kind ``cell`` from :func:`ngcontact.load`.
    setting
        ``plane_strain``, ``axisymmetric`` or ``3d``: the macro frame (a 3D cell's bundle is projected on a
        2D frame as a macro scene does).
    form
        ``bundle`` (unilateral, eqs. 31-33) or ``linear`` (``K0`` and the gap forces of eq. 34; 2D only).
    length_unit
        Length of one unit of the cell scene in the macro mesh's unit (scales the gaps), a macro scene's
        ``interface.cell_length_unit``.
    friction
        ``None``, ``"from_cell"`` (eqs. 42-43 of the cell's micro friction, Huber width ``huber_width``)
        or a friction law object.
    cache_dir
        Where the cell's bundle is cached (default: the package's cell-law cache).

    Raises
    ------
    ModelError
        An argument of the wrong type or value (its name, value and what is allowed).
    SceneError
        The cell scene itself is invalid, or names another kind.
    """
    if setting not in SETTINGS:
        raise refuse("setting", setting, "one of " + ", ".join(SETTINGS))
    if form not in FORMS:
        raise refuse("form", form, "one of " + ", ".join(FORMS))
    dim = dimension(setting)
    if form == "linear" and dim == 3:
        raise refuse("form", form, "a linear law from a cell is available in 2D and axisymmetry; use 'bundle'")
    if not (isinstance(length_unit, (int, float)) and length_unit > 0):
        raise refuse("length_unit", length_unit, "a number > 0")
    scene, path = _cell_scene(cell)
    arrays, was_cached = build.cell_bundle_arrays(scene, cache_dir)
    bundle = cached.bundle_law(arrays, dim=dim, length_unit=length_unit)
    K0 = bundle.matrix()
    normal: il.NormalLaw = il.linearized(bundle) if form == "linear" else bundle
    tangential, friction_info = _friction(friction, scene, arrays, huber_width)
    coefficients = {"K0": np.asarray(K0).tolist(), "weights": list(bundle.weights),
                    "directions": [list(d) for d in bundle.directions], "gaps": list(bundle.gaps)}
    coefficients.update({k: friction_info[k] for k in ("mu0", "G0") if k in friction_info})
    source = {"type": form, "cell_scene": path if path is not None else f"<loaded scene {scene.title!r}>",
              "cached": was_cached, "directions": len(bundle.weights), "K0": coefficients["K0"],
              "key": build.cell_key(scene), "cell_overrides": {}, "full_contact_K0": coefficients["K0"],
              "friction": friction_info}
    return CellLaw(normal=normal, friction=tangential, setting=setting, coefficients=coefficients, source=source)
