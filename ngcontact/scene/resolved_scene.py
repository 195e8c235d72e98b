"""Scene kind ``direct``: two bodies whose interface resolves N periods of a cell's roughness.

The resolved micro problem of paper Sec. 3.3 (see :mod:`ngcontact.resolved.resolved_problem`):
the profile and the micro contact law (penalty ``k_n``, constant gap,
friction) come from a ``cell`` scene named by ``geometry.cell``; its
roughness is repeated ``geometry.periods`` times along the interface and
scaled to the period ``eps = (interface length) / periods``.

Shapes (``geometry.shape``, see :mod:`ngcontact.geometry.resolved_shapes`):

``blocks``
    Rough block below, counter block above, ``x0 <= x <= x0 + length``;
    boundaries ``bottom``, ``top``, ``rough_sides``, ``counter_sides``.
    Plane strain, or axisymmetric (``x`` = ``r``: an annular disk whose face
    carries concentric ring grooves).
``femur_stem``
    The axisymmetric femur with a hip stem of the ``macro`` kind
    (``geometry.dimensions`` as there), the stem rough: circumferential
    grooves along the whole interface, cone and cylinder; boundaries
    ``axis``, ``stem_top``, ``stem_side``, ``stem_tip``, ``bone_top``,
    ``bone_outer``, ``canal``, ``base``.

In axisymmetry the components are ``(r, z)`` and forces are per full
revolution.  The resolved surface is the boundary ``contact``.  The
optional ``[study]`` section sets up the epsilon study
(``scripts/epsilon_study.py``) that compares the resolved runs with the
homogenized laws of the same cell on the same bodies with a flat interface.
Lengths in metres, stresses in pascals, stiffnesses in Pa/m.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ngcontact.errors import MISSING, SceneError
from ngcontact.geometry.femur import FemurStemDims
from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.geometry.resolved_shapes import RESOLVED_SHAPES, resolved_shape
from ngcontact.scene.macro_shapes import FEMUR_BOUNDARIES, check_dimensions, check_support_meaning
from ngcontact.scene.sections import (ComputeSpec, MaterialSpec, check_supports_once, SolverSpec, base_dir_field,
                                     check_material_names)
from ngcontact.scene import magnitudes, mesh_size
from ngcontact.scene.supports import SupportSpec, check_values
from ngcontact.scene.schema import (MAX_ORDER, MAX_PERIODS, at_least, closed_interval, nonempty,
                                    open_interval, param, positive)

#: The shapes (:data:`ngcontact.geometry.resolved_shapes.RESOLVED_SHAPES`: what each one is built and measured
#: by); this module validates a scene against their settings, keys and boundary labels.
SHAPES = tuple(RESOLVED_SHAPES)
#: Boundary labels of each shape with what each is (the resolved surface is ``contact``).
BOUNDARY_DOCS: dict[str, dict[str, str]] = {
    "blocks": {"bottom": "bottom face of the rough block (below the interface here; in the macro kind's block "
                         "the rough body is on top)",
               "top": "top face of the counter block", "rough_sides": "left and right faces of the rough block",
               "counter_sides": "left and right faces of the counter block"},
    "femur_stem": {k: v for k, v in FEMUR_BOUNDARIES.items() if k != "interface"},
}
BOUNDARIES = {shape: tuple(labels) for shape, labels in BOUNDARY_DOCS.items()}
COMPONENTS = {"plane_strain": ("x", "y"), "axisymmetric": ("r", "z")}
DIMENSIONS = tuple(f.name for f in dataclasses.fields(FemurStemDims))


@dataclass(frozen=True, kw_only=True)
class DirectGeometry:
    """The bodies and the resolved roughness."""

    cell: str = param(doc="cell scene (relative to this scene) whose profile and contact law are resolved")
    periods: int = param(doc="number N of periods resolved along the interface",
                         check=closed_interval(1, MAX_PERIODS))
    shape: str = param("blocks", doc="two blocks, or the axisymmetric femur with a hip stem", choices=SHAPES)
    setting: str = param("plane_strain", doc="plane strain (x, y) or axisymmetric (r, z; per revolution)",
                         choices=tuple(COMPONENTS))
    length: float | None = param(None, doc="blocks: width L (eps = L / N)", units="m", check=positive())
    h_rough: float | None = param(None, doc="blocks: height of the rough block below the summits", units="m",
                                  check=positive())
    h_counter: float | None = param(None, doc="blocks: height of the counter block above the summits",
                                    units="m", check=positive())
    x0: float = param(0.0, doc="blocks: x (axisymmetric: radius r) of the left faces", units="m",
                      allowed=">= 0")
    dimensions: dict[str, float] | None = param(
        None, doc="femur_stem: dimensions as in the macro kind (eps = interface arc length / N)", units="m",
        allowed=f"all of {', '.join(DIMENSIONS)}")

    def femur_dims(self) -> FemurStemDims:
        return FemurStemDims(**(self.dimensions or {}))

    def check(self, path: str) -> None:
        """The shape's setting, its required keys, no key of another shape; all femur dimensions."""
        if self.x0 < 0:
            raise SceneError(f"{path}.x0", self.x0, ">= 0")
        shape = RESOLVED_SHAPES[self.shape]
        if self.setting not in shape.settings:
            raise SceneError(f"{path}.setting", self.setting,
                             f"shape {shape.name!r} is " + " or ".join(shape.settings))
        for key in shape.required:
            if getattr(self, key) is None:
                raise SceneError(f"{path}.{key}", MISSING, f"required for shape {shape.name!r}")
        for other in RESOLVED_SHAPES.values():
            for key in other.keys:
                if key not in shape.keys and getattr(self, key) is not None:
                    raise SceneError(f"{path}.{key}", getattr(self, key), f"only for shape {other.name!r}")
        if "dimensions" in shape.keys:
            check_dimensions(self.dimensions or {}, f"{path}.dimensions", shape.name, DIMENSIONS)


@dataclass(frozen=True, kw_only=True)
class DirectBodies:
    """Materials of the two bodies."""

    rough: str = param(doc="material of the rough body (blocks: the one below; femur: the stem)")
    counter: str = param(doc="material of the counter body (blocks: the one above; femur: the bone)")


@dataclass(frozen=True, kw_only=True)
class DirectLoad:
    """Surface load on a boundary."""

    boundary: str = param(doc="a boundary of the shape (as for supports)")
    pressure: float = param(0.0, doc="normal pressure, positive pushes into the body", units="Pa")
    traction: tuple[float, float] = param((0.0, 0.0), doc="traction vector (x, y) or (r, z)", units="Pa")


@dataclass(frozen=True, kw_only=True)
class DirectMesh:
    """Mesh graded towards the resolved interface."""

    order: int = param(2, doc="polynomial order of the displacement", check=closed_interval(1, MAX_ORDER))
    maxh: float = param(doc="mesh size in the far field", units="m", check=positive())
    elements_per_period: float = param(8.0, doc="interface mesh size is eps / elements_per_period",
                                       check=positive())
    grading: float = param(0.3, doc="Netgen grading factor (growth of the elements away from the interface)",
                           check=positive())
    max_elements: int = param(mesh_size.MAX_ELEMENTS, doc="refuse a scene whose finest mesh is estimated to "
                              "have more elements (a guard against sizes that hang the mesher)", check=at_least(1))
    tolerance: float | None = param(None, check=open_interval(0, 1), doc="the accuracy the headline quantities "
        "are held to: the contact fraction of the resolved surface (a fraction: its absolute error) and the "
        "contact force's magnitude (its relative error), each reported with its discretization error estimated "
        "from one uniform refinement at the run's order, 3 |Q(h/2) - Q(h)| (results.accuracy); a scene that "
        "states it is "
        "refined towards it: the order raised by one while that buys more per unknown than a local refinement "
        "(up to order 4), then the mesh refined where the stress error indicator is large and at the edges of "
        "the closed set, interface first (up to 8 levels, max_elements and 1e6 unknowns), each mesh level "
        "estimated by the larger of the order ladder and the sequence of levels (a level met by the order "
        "alone held to the uniform refinement's estimate too); results.accuracy.refinement "
        "lists the levels (order, mesh level, unknowns, values, errors); a tolerance out of reach ends the run "
        "(exit 3) with the last level's figures; default: 0.01, only judged (the scene's order and mesh are kept)")


#: Largest number of field-error samples per direction of ``study.grid``: the points of every level are held in
#: memory and evaluated on each of its solutions, after all of them are solved.
MAX_SAMPLES = 2048


@dataclass(frozen=True, kw_only=True)
class StudySpec:
    """Epsilon study: resolved runs against the homogenized laws."""

    periods: tuple[int, ...] = param((4, 8, 16), doc="N of each level (at least 3 for a rate)",
                                     check=closed_interval(1, MAX_PERIODS))
    band: float = param(3.0, doc="half-width of the band around the interface excluded from the field "
                        "error (and from the probes), in periods eps", check=positive())
    interface_maxh: float = param(doc="mesh size along the flat interface of the homogenized runs",
                                  units="m", check=positive())
    probes: tuple[tuple[float, float], ...] = param(
        (), doc="points (x, y) or (r, z) away from the layer where displacements are compared", units="m",
        allowed="pairs of numbers inside a body, outside the band of the coarsest level")
    grid: tuple[int, int] = param((100, 50), doc="sampling grid of the field error: (nx, ny) per block, "
                                  "or (nr, nz) over the femur's bounding box", check=closed_interval(4, MAX_SAMPLES))
    refinement: float = param(2.0, doc="each level is solved again with every mesh size divided by this factor "
                              "(maxh, eps / elements_per_period, interface_maxh); the change delta of each "
                              "error between the two gives its discretization estimate 1.5 delta / (refinement - 1)",
                        check=closed_interval(1.5, 8))
    meshes: int = param(2, doc="discretizations per level: 2 (the scene's and one refined), or 3 (the scene's, "
                        "refined once and twice by study.refinement): the errors are then the finest pair's and "
                        "each estimate the sum of the resolved and the homogenized solution's Richardson tails of "
                        "their two changes, times 1.5 (the observed ratio, at least 1 / refinement; a solution's "
                        "largest change where it does not contract); ngcontact study epsilon --meshes overrides it",
                        check=closed_interval(2, 3))
    discretization_share: float = param(0.1, doc="the rates in eps are fitted on the levels whose discretization "
                                        "estimate is at most this share of the error (the modelling error, not "
                                        "the meshes'); fewer than three such levels: no rate, and the report "
                                        "says why", check=open_interval(0, 1))


@dataclass(frozen=True, kw_only=True)
class DirectScene:
    kind: str = param(doc="problem type", choices=("direct",))
    title: str = param("", doc="free text shown in the report")
    materials: dict[str, MaterialSpec] = param(doc="named materials", check=nonempty())
    bodies: DirectBodies = param(doc="materials of the blocks")
    geometry: DirectGeometry = param(doc="blocks and resolved roughness")
    supports: tuple[SupportSpec, ...] = param(doc="[[supports]]: Dirichlet conditions", check=nonempty())
    loads: tuple[DirectLoad, ...] = param((), doc="[[loads]]: surface loads")
    discretization: DirectMesh = param(doc="mesh and order")
    solver: SolverSpec = param(SolverSpec(), doc="Newton settings")
    study: StudySpec | None = param(None, doc="epsilon study (scripts/epsilon_study.py)")
    compute: ComputeSpec = param(ComputeSpec(), doc="where the epsilon study's levels run")
    base_dir: str = base_dir_field()

    def check(self, path: str) -> None:
        check_material_names(self.materials, {"rough": self.bodies.rough, "counter": self.bodies.counter},
                             "bodies")
        for name in (self.bodies.rough, self.bodies.counter):
            if self.materials[name].C is not None:
                raise SceneError(f"materials.{name}.C", "...", "direct scenes take isotropic E, nu")
        magnitudes.check_surface_loads(self)
        g = self.geometry
        labels, comps = BOUNDARIES[g.shape], COMPONENTS[g.setting]
        groups: tuple[tuple[str, tuple[SupportSpec | DirectLoad, ...]], ...] = (
            ("supports", self.supports), ("loads", self.loads))
        for key, items in groups:
            for i, item in enumerate(items):
                if item.boundary not in labels:
                    raise SceneError(f"{key}[{i}].boundary", item.boundary,
                                     f"one of {', '.join(labels)} (shape {g.shape!r})")
        check_values(self.supports, comps, g.setting)
        check_supports_once(self.supports, comps)
        check_support_meaning(self.supports, comps, g.setting)
        self.check_size()
        st = self.study
        if st is not None:
            if len(st.periods) < 3 or any(b <= a for a, b in zip(st.periods, st.periods[1:])):
                raise SceneError("study.periods", st.periods, "at least 3 increasing numbers of periods")
            STUDY_CHECKS[g.shape](self)

    def check_size(self) -> None:
        """The element estimate of :mod:`ngcontact.scene.mesh_size` at the finest level, against ``max_elements``."""
        g, d = self.geometry, self.discretization
        N = max((g.periods,) + (tuple(self.study.periods) if self.study else ()))
        shape = resolved_shape(g)
        (area, width), length = shape.extent(), shape.interface_length()
        n = mesh_size.estimate(2, area, d.maxh, width=width, interface=length,
                               h_interface=length / N / d.elements_per_period)
        key, value = ("study.periods", N) if self.study and N > g.periods else ("geometry.periods", g.periods)
        mesh_size.refuse_beyond(n, d.max_elements, key, value,
                                hint=" (fewer periods, or fewer discretization.elements_per_period)")

    def check_files(self, load) -> None:
        """The named cell scene must be a valid 2D conforming ``cell`` scene this kind can resolve."""
        from ngcontact.scene.sections import check_input_file, resolve
        path = resolve(self, self.geometry.cell)
        check_input_file("geometry.cell", path, "cell scene", shown=self.geometry.cell,
                         missing="no such cell scene file")
        try:
            cell = load(path)
        except SceneError as exc:
            raise SceneError("geometry.cell", self.geometry.cell, f"invalid cell scene: {exc}") from None
        if cell.kind != "cell":
            raise SceneError("geometry.cell", self.geometry.cell, f"names a {cell.kind!r} scene; need 'cell'")
        g = cell.geometry
        if g.arrangement != "conforming" or not PROFILES[g.profile].parametric:
            raise SceneError("geometry.cell", self.geometry.cell,
                             "need a 2D conforming cell with an analytic profile (flat, rectangular, "
                             "triangular, semicircular, sinusoid)")
        if cell.contact.friction != "none" and cell.contact.w is None:
            raise SceneError("geometry.cell", self.geometry.cell, "its friction has no contact.w (the spectral cell's "
                             "exact friction needs none); the resolved problem regularizes friction with the cell's "
                             "Huber width w: give it one")
        if cell.contact.gap.kind not in ("none", "constant"):
            raise SceneError("geometry.cell", self.geometry.cell,
                             f"gap kind {cell.contact.gap.kind!r} is not resolved; use none or constant")
        check_resolved_penalty(self, cell)
        object.__setattr__(self, "cell_scene", cell)


def check_resolved_penalty(scene: DirectScene, cell) -> None:
    """The cell's ``k_n`` on the resolved interface, meshed at ``eps / elements_per_period``
    (:func:`ngcontact.scene.magnitudes.check_penalty_ratio`; ``k_n`` is used as the cell gives it)."""
    g, d = scene.geometry, scene.discretization
    E, _ = magnitudes.softer(scene.materials, (scene.bodies.rough, scene.bodies.counter))
    h = resolved_shape(g).interface_length() / g.periods / d.elements_per_period
    magnitudes.check_penalty_ratio("geometry.cell", cell.contact.k_n, "the cell's k_n", h,
                                   "the resolved interface mesh size", E, shown=g.cell)


def _check_blocks_study(scene: DirectScene) -> None:
    """Probes inside the blocks and outside the band of the coarsest level; the band stays inside both blocks."""
    st, g = scene.study, scene.geometry
    assert st is not None  # called from check only when the study is given
    # required for shape 'blocks' (DirectGeometry.check, run when the section was built)
    assert g.length is not None and g.h_rough is not None and g.h_counter is not None
    for i, (x, y) in enumerate(st.probes):
        if not (g.x0 < x < g.x0 + g.length and -g.h_rough < y < g.h_counter):
            raise SceneError(f"study.probes[{i}]", (x, y), "must lie inside the blocks")
        if abs(y) <= st.band * g.length / st.periods[0]:
            raise SceneError(f"study.probes[{i}]", (x, y), "must lie outside the band of the "
                             "coarsest level (|y| > band * length / periods[0])")
    if st.band * g.length / st.periods[0] >= min(g.h_rough, g.h_counter):
        raise SceneError("study.band", st.band, "the band of the coarsest level must stay inside "
                         "both blocks")


def _check_femur_study(scene: DirectScene) -> None:
    """Probes inside a body and outside the band of the coarsest level; the band leaves points."""
    from ngcontact.geometry.femur import distance_to_polyline, femur_interface_length, femur_stem_body, \
        femur_stem_interface
    st, dims = scene.study, scene.geometry.femur_dims()
    assert st is not None  # called from check only when the study is given
    segs = femur_stem_interface(dims)
    band = st.band * femur_interface_length(dims) / st.periods[0]
    for i, pt in enumerate(st.probes):
        if femur_stem_body(dims, [pt])[0] < 0:
            raise SceneError(f"study.probes[{i}]", pt, "must lie inside the stem or the bone")
        if distance_to_polyline(segs, [pt])[0] <= band:
            raise SceneError(f"study.probes[{i}]", pt, f"must lie farther than band * eps = {band:.4g} m "
                             "(coarsest level) from the interface")
    r = np.linspace(0.0, dims.r_bone, 41)
    z = np.linspace(0.0, dims.z_stem_top, 41)
    pts = np.column_stack([a.ravel() for a in np.meshgrid(r, z)])
    keep = (femur_stem_body(dims, pts) >= 0) & (distance_to_polyline(segs, pts) > band)
    if not np.any(keep):
        raise SceneError("study.band", st.band, "the band of the coarsest level covers both bodies; "
                         "take a smaller band or more periods")


#: Per shape, the checks of the ``[study]`` section against the bodies (with the wording of each shape).
STUDY_CHECKS: dict[str, Callable[[DirectScene], None]] = {"blocks": _check_blocks_study,
                                                           "femur_stem": _check_femur_study}


def effects(scene: DirectScene) -> tuple[str, ...]:
    """The terms assembled."""
    out = ["elasticity", "resolved_normal_contact"]
    cell = getattr(scene, "cell_scene", None)
    if cell is not None:
        if cell.contact.gap.kind != "none":
            out.append("gap")
        if cell.contact.friction != "none":
            out.append(f"{cell.contact.friction}_friction")
    if any(load.pressure or any(load.traction) for load in scene.loads):
        out.append("surface_loads")
    if any(any(s.displacement) or any(s.slope) or any(s.u0) or any(any(r) for r in s.G) for s in scene.supports):
        out.append("prescribed_displacement")
    return tuple(out)


def with_study_periods(scene: DirectScene, periods) -> DirectScene:
    """The scene with its study's levels replaced (``ngcontact study epsilon --periods``), held to the
    checks of the scene's own levels (a band of the coarsest level inside both bodies, probes outside it).

    Raises
    ------
    SceneError
        Naming ``study.periods`` (from ``--periods``), the levels and what the check demands.
    """
    if scene.study is None:
        raise SceneError("study", None, "the epsilon study needs a [study] section")
    levels = tuple(int(n) for n in periods)
    new = replace(scene, study=replace(scene.study, periods=levels))
    if hasattr(scene, "cell_scene"):          # set by check when the scene was loaded (its linked cell)
        object.__setattr__(new, "cell_scene", scene.cell_scene)
    try:
        STUDY_CHECKS[scene.geometry.shape](new)
    except SceneError as err:
        raise SceneError("study.periods (from --periods)", levels,
                         f"with these levels {err.path} = {err.value!r} fails: {err.allowed}") from None
    return new


def with_study_meshes(scene: DirectScene, meshes: int) -> DirectScene:
    """The scene with its study's ``meshes`` replaced (``ngcontact study epsilon --meshes``).

    Raises
    ------
    SceneError
        Naming ``study.meshes`` (from ``--meshes``) unless it is 2 or 3.
    """
    if scene.study is None:
        raise SceneError("study", None, "the epsilon study needs a [study] section")
    if meshes not in (2, 3):
        raise SceneError("study.meshes (from --meshes)", meshes, "2 or 3")
    new = replace(scene, study=replace(scene.study, meshes=int(meshes)))
    if hasattr(scene, "cell_scene"):          # set by check when the scene was loaded (its linked cell)
        object.__setattr__(new, "cell_scene", scene.cell_scene)
    return new
