"""Moduli, loads and interface stiffnesses a scene may pose: bounds checked before anything is solved.

A modulus of 1e-308, a pressure of 1e300 or a penalty of 1e300 does not fail where it is written: the
solver meets infinities and ends in a convergence failure (exit 3) that names no input.  Each bound
below is checked when the scene is validated and refused as a :class:`~ngcontact.errors.SceneError`
naming the key, its value and the allowed range (exit 2, nothing written).  Where physics bounds a
number the bound is physical; only the absolute scale of the moduli, which a unit fixes, is a range:

* **load against modulus** (:data:`MAX_LOAD_STRAIN`): a stress ``s`` (a pressure, the magnitude of a
  traction or shear) on bodies whose softer one has the modulus ``E`` strains them by about ``s / E``; a
  prescribed far-face jump ``U`` of a cell of height ``H`` is its mean strain ``|U| / H``
  (:mod:`ngcontact.cell.small_strain`).  A strain of 1 compresses the body by its own size, which no
  solid does (metals yield near 1e-3, polymers by 1e-1), so a load beyond it is refused.  Between the
  small-strain bound (0.05) and 1 the run solves and says that linear elasticity does not hold;
* **stiffness ratios** (:data:`MAX_STIFFNESS_RATIO`): the assembled tangent adds blocks of the stiffer
  body (``~ E_stiff h^(d-2)``) or of a penalty interface (``~ k_n h^(d-1)``, ``h`` the interface
  element size) to those of the softer body (``~ E_soft h^(d-2)``).  Rounding a sum perturbs each entry
  by ``eps`` (2.2e-16) times its largest term, so the softer body's share is known to a relative
  ``eps r`` with ``r`` the ratio ``E_stiff / E_soft`` or ``k_n h / E_soft``; at ``r = 1e10`` that is
  2e-6, beyond it the soft body's response drowns in round-off (``k_n = 1e16`` on a cell of ``E = 1``
  reported a pressure 63 % off equilibrium as converged).  A penalty so soft that ``k_n h / E`` is below
  :data:`MIN_PENALTY_RATIO` makes the interface hold nothing: the jump ``p / k_n`` dwarfs the bodies;
* **modulus range** (:data:`MODULUS_RANGE`): every solid lies within 1e2 Pa (gels) and 1.2e12 Pa
  (diamond), so the range holds any stress unit from micropascals to exapascals and dimensionless
  moduli; with the lengths of :data:`~ngcontact.scene.mesh_size.LENGTH_RANGE` and the bounds above, the
  energies and residuals the solvers form (a modulus times at most six lengths, squared in an inner
  product) stay far inside double precision's range of 1e-308 to 1e308.
"""
from __future__ import annotations

import numpy as np

from ngcontact.errors import SceneError

#: Smallest and largest admissible Young's modulus (module docstring: the scale a stress unit fixes).
MODULUS_RANGE = (1e-20, 1e20)
#: Largest admissible ratio of two stiffnesses of one tangent: moduli of the bodies, penalty ``k_n h / E``.
MAX_STIFFNESS_RATIO = 1e10
#: Smallest admissible ``k_n h / E``: below it the interface holds nothing (k_n = 1e-300 gave a far-face
#: jump of 1e298 under a pressure of 0.01).
MIN_PENALTY_RATIO = 1e-8
#: Largest admissible strain of a load, ``s / E`` or ``|U| / H``: the body compressed by its own size.
MAX_LOAD_STRAIN = 1.0


def young_moduli(material) -> tuple[float, float]:
    """The smallest and largest Young's modulus of a :class:`~ngcontact.scene.sections.MaterialSpec`: ``E``
    of an isotropic one, of an anisotropic one the moduli ``1 / S_ii`` along the axes (``S = C^-1``)."""
    if material.C is None:
        return material.E, material.E
    S = np.linalg.inv(np.asarray(material.C, float))
    moduli = [1.0 / S[i, i] for i in range(3)]
    return min(moduli), max(moduli)


def check_modulus(material, path: str) -> None:
    """A material's Young's moduli within :data:`MODULUS_RANGE` (``path``: ``materials.NAME``)."""
    lo, hi = MODULUS_RANGE
    key, value = (f"{path}.E", material.E) if material.C is None else (f"{path}.C", material.C)
    for E in young_moduli(material):
        if not lo <= E <= hi:
            shown = "" if material.C is None else f"its Young's modulus along an axis is {E:.3g}, which "
            raise SceneError(key, value, f"{shown}must lie in [{lo:g}, {hi:g}]: choose a stress unit (e.g. Pa, "
                             "MPa or GPa) in which the bodies' moduli fall in that range")


def softer(materials: dict, names) -> tuple[float, str]:
    """``(E, name)`` of the softest modulus among the materials ``names`` (their smallest :func:`young_moduli`)."""
    return min((young_moduli(materials[name])[0], name) for name in names)


def check_moduli_ratio(materials: dict, names) -> None:
    """The stiffer body's modulus at most :data:`MAX_STIFFNESS_RATIO` times the softer one's."""
    E_soft, soft = softer(materials, names)
    E_stiff, stiff = max((young_moduli(materials[name])[1], name) for name in names)
    if E_stiff > MAX_STIFFNESS_RATIO * E_soft:
        raise SceneError(f"materials.{stiff}", f"E = {E_stiff:g}", f"{E_stiff / E_soft:.3g} times the modulus "
                         f"of materials.{soft} ({E_soft:g}); the bodies' moduli may differ by at most a factor "
                         f"{MAX_STIFFNESS_RATIO:g}, beyond which the softer body's response is lost in the "
                         "round-off of the stiffer one's (double precision); model the stiffer body as rigid "
                         "(a support) or bring the moduli closer")


def check_load_strain(key: str, value, magnitude: float, E: float, name: str, *, width: float | None = None) -> None:
    """A load ``value`` under ``key`` of magnitude ``magnitude``: its stress (``magnitude``, times ``width`` for a
    force density) over the softer body's modulus ``E`` (material ``name``) at most :data:`MAX_LOAD_STRAIN`."""
    strain = abs(magnitude) * (width or 1.0) / E
    if not strain <= MAX_LOAD_STRAIN:
        most = f"{E:g}" if width is None else f"E / {width:g} = {E / width:g} (over the bodies' smallest width)"
        raise SceneError(key, value, f"strains the softer body (materials.{name}, E = {E:g}) by {strain:.3g}; "
                         f"a load must stay below a strain of {MAX_LOAD_STRAIN:g}, i.e. at most {most} in "
                         "magnitude (a body compressed by its own size; linear elasticity holds to about 0.05): "
                         "check the load and the units")


def check_jump_strain(key: str, value: float, height: float) -> None:
    """A prescribed far-face jump ``value`` of a cell of height ``height``: its mean strain at most
    :data:`MAX_LOAD_STRAIN`."""
    strain = abs(value) / height
    if not strain <= MAX_LOAD_STRAIN:
        raise SceneError(key, value, f"over the cell's height h_rough + h_counter = {height:g} is a mean strain "
                         f"of {strain:.3g}; a prescribed jump must stay below a strain of {MAX_LOAD_STRAIN:g}, "
                         f"i.e. at most {MAX_LOAD_STRAIN * height:g} in magnitude (the bodies compressed by their "
                         "own height)")


def check_penalty_ratio(key: str, k: float, symbol: str, h: float, what: str, E: float, *,
                        upper: bool = True, shown=None) -> None:
    """An interface stiffness ``k`` (under ``key``, written ``symbol`` in the message) against the softer
    body's modulus ``E``: ``k h / E`` in [:data:`MIN_PENALTY_RATIO`, :data:`MAX_STIFFNESS_RATIO`]
    (``upper = False``: the lower bound only), ``h`` the element size or grid step ``what`` names.
    ``shown``: the scene's value under ``key`` when ``k`` is derived from it (a table, a cell file)."""
    ratio = k * h / E
    where = ("" if shown is None else f"{symbol} = {k:g}, ") + \
        f"{symbol} h / E = {ratio:.3g} (h = {h:g} {what}, E = {E:g} the softer body's modulus)"
    value = k if shown is None else shown
    if upper and ratio > MAX_STIFFNESS_RATIO:
        raise SceneError(key, value, f"{where} must stay below {MAX_STIFFNESS_RATIO:g}: the penalty would "
                         f"outweigh the bodies beyond what double precision resolves; lower {symbol}")
    if ratio < MIN_PENALTY_RATIO:
        raise SceneError(key, value, f"{where} must be at least {MIN_PENALTY_RATIO:g}: the interface would "
                         f"hold nothing and the jump would dwarf the bodies; raise {symbol}")


def check_cell(scene) -> None:
    """A cell scene's moduli ratio and loads: each pressure and shear against the softer body's modulus,
    each prescribed jump against the cell's height, the macro strain itself at most :data:`MAX_LOAD_STRAIN`."""
    bodies = (scene.bodies.rough, scene.bodies.counter)
    check_moduli_ratio(scene.materials, bodies)
    E, name = softer(scene.materials, bodies)
    L, g = scene.load, scene.geometry
    for key in ("pressure", "shear"):
        for i, s in enumerate(getattr(L, key, None) or ()):
            check_load_strain(f"load.{key}[{i}]", s, s, E, name)
    for key in ("normal_jump", "tangential_jump"):
        for i, u in enumerate(getattr(L, key, None) or ()):
            check_jump_strain(f"load.{key}[{i}]", u, g.h_rough + g.h_counter)
    for i, e in enumerate(getattr(L, "macro_strain", None) or ()):
        if not abs(e) <= MAX_LOAD_STRAIN:
            raise SceneError(f"load.macro_strain[{i}]", e, f"a strain must stay below {MAX_LOAD_STRAIN:g} in "
                             "magnitude (a body stretched or compressed by its own size)")


def check_surface_loads(scene) -> None:
    """A macro or resolved scene's moduli ratio and ``[[loads]]``: each pressure and traction (its magnitude)
    against the softer body's modulus (a load on either body passes through the interface into the other)."""
    bodies = (scene.bodies.rough, scene.bodies.counter)
    check_moduli_ratio(scene.materials, bodies)
    E, name = softer(scene.materials, bodies)
    for i, load in enumerate(scene.loads):
        check_load_strain(f"loads[{i}].pressure", load.pressure, load.pressure, E, name)
        if load.traction:
            check_load_strain(f"loads[{i}].traction", load.traction, float(np.hypot.reduce(load.traction)),
                              E, name)


def check_body_forces(scene, width: float) -> None:
    """A macro scene's body force densities: a force density ``f`` over a body at least ``width`` across (the
    geometry's smallest width) stresses it by at least about ``|f| width``, held like a surface load."""
    E, name = softer(scene.materials, (scene.bodies.rough, scene.bodies.counter))
    for role in ("rough", "counter"):
        f = getattr(scene.body_forces, role)
        if f:
            check_load_strain(f"body_forces.{role}", f, float(np.hypot.reduce(f)), E, name, width=width)


def interface_stiffness(interface) -> tuple[str, str, float] | None:
    """``(key, symbol, k)``: the largest normal stiffness of a macro law given by its numbers: ``kn`` of the
    linear law, the summed ``weights`` of a bundle (its ``k_n0`` when every direction is normal), the
    steepest slope of a tabulated pressure-closure law; ``None`` for a law from a cell or a file (those are
    checked where they are read: :func:`check_cell_law`, :func:`check_file_law`)."""
    if interface.cell is not None or interface.law == "file":
        return None
    if interface.law == "linear":
        return "interface.kn", "kn", interface.kn
    if interface.law == "bundle":
        return "interface.weights", "sum(weights)", float(sum(interface.weights))
    c, p = np.asarray(interface.closure, float), np.asarray(interface.pressure, float)
    return "interface.pressure", "dp/dc", float(np.max(np.diff(p) / np.diff(c))) if len(c) > 1 else 0.0


def check_macro_interface(scene) -> None:
    """A macro law's stiffness against the softer body at the interface mesh size (:func:`check_penalty_ratio`);
    a tabulated law that never stiffens (one row, or flat) is not bounded below."""
    found = interface_stiffness(scene.interface)
    if found is None or not found[2] > 0:
        return
    key, symbol, k = found
    i, d = scene.interface, scene.discretization
    E, _ = softer(scene.materials, (scene.bodies.rough, scene.bodies.counter))
    shown = {"interface.kn": None, "interface.weights": i.weights, "interface.pressure": i.pressure}[key]
    check_penalty_ratio(key, k, symbol, d.interface_maxh or d.maxh, "the interface mesh size", E, shown=shown)


def check_file_law(scene, key: str, shown: str, found: tuple[str, str, float, object]) -> None:
    """The law a macro scene reads from the law file ``shown`` under ``key`` (``interface.law_file``), its
    stiffness ``found`` (:func:`ngcontact.scene.law_file.stiffness`: the field of the file, its symbol, ``k``
    and the file's value there) held as an explicit law's is (:func:`check_macro_interface`): ``k h / E``
    within [:data:`MIN_PENALTY_RATIO`, :data:`MAX_STIFFNESS_RATIO`] at the interface mesh size; a slope
    beyond double precision (``inf``) is beyond the upper bound."""
    field, symbol, k, value = found
    d = scene.discretization
    E, _ = softer(scene.materials, (scene.bodies.rough, scene.bodies.counter))
    check_penalty_ratio(f"{key} ({shown}): {field}", k, symbol, d.interface_maxh or d.maxh,
                        "the interface mesh size", E, shown=value)


def check_cell_law(scene, key: str, rel: str, cell, overridden: bool) -> None:
    """The law a macro scene takes from the cell ``rel`` under ``key`` (``interface.cell``): its weights are
    the cell's ``k_n`` times the contact surface's share of the period
    (:func:`ngcontact.coupling.cell_law.bundle_law`), so ``k_n`` is its stiffness within a factor of the
    surface's length, held like an explicit law's.  (A two-scale loop's law is the cell's tabulated
    response, bodies and penalty in series, whose stiffness a stiff penalty does not raise.)"""
    d = scene.discretization
    E, _ = softer(scene.materials, (scene.bodies.rough, scene.bodies.counter))
    k = cell.contact.k_n
    check_penalty_ratio("interface.cell_k_n" if overridden else key, k, "the cell's k_n", d.interface_maxh or d.maxh,
                        "the interface mesh size", E, shown=None if overridden else rel)
