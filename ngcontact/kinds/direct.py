"""Scene kind ``direct``: two blocks whose interface resolves N periods of a cell's roughness.

The resolved micro problem of paper Sec. 3.3 (see :mod:`ngcontact.direct`):
the profile and the micro contact law (penalty ``k_n``, constant gap,
friction) come from a ``cell`` scene named by ``geometry.cell``; its
roughness is repeated ``geometry.periods`` times along the block width and
scaled to the period ``eps = length / periods``.  Plane strain, rough block
below, counter block above; boundaries ``bottom``, ``top``, ``rough_sides``,
``counter_sides`` and the resolved surface ``contact``.  The optional
``[study]`` section sets up the epsilon study (``scripts/epsilon_study.py``)
that compares the resolved runs with the homogenized laws of the same cell.
Lengths in metres, stresses in pascals, stiffnesses in Pa/m.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import SceneError
from ..scene import MaterialSpec, SolverSpec, base_dir_field, check_material_names, register
from ..schema import at_least, nonempty, param, positive

BOUNDARIES = ("bottom", "top", "rough_sides", "counter_sides")
COMPONENTS = ("x", "y")


@dataclass(frozen=True, kw_only=True)
class DirectGeometry:
    """The blocks and the resolved roughness."""

    cell: str = param(doc="cell scene (relative to this scene) whose profile and contact law are resolved")
    periods: int = param(doc="number N of periods resolved along the interface", check=at_least(1))
    length: float = param(doc="block width L (eps = L / N)", units="m", check=positive())
    h_rough: float = param(doc="height of the rough block below the summits", units="m", check=positive())
    h_counter: float = param(doc="height of the counter block above the summits", units="m",
                             check=positive())
    setting: str = param("plane_strain", doc="plane strain only (axisymmetry is not implemented)",
                         choices=("plane_strain",))


@dataclass(frozen=True, kw_only=True)
class DirectBodies:
    """Materials of the two blocks."""

    rough: str = param(doc="material of the rough block (below)")
    counter: str = param(doc="material of the counter block (above)")


@dataclass(frozen=True, kw_only=True)
class DirectSupport:
    """Prescribed displacement components on a boundary, constant or linear along it (a tilt)."""

    boundary: str = param(doc="bottom, top, rough_sides or counter_sides", choices=BOUNDARIES)
    components: tuple[str, ...] = param((), doc="components fixed (x, y); empty: all")
    displacement: tuple[float, ...] = param((), doc="value at the boundary's mid-point, one per component "
                                            "(default 0)", units="m")
    slope: tuple[float, ...] = param((), doc="change of each prescribed component per metre along x "
                                     "(top / bottom) or y (sides) (default 0)", units="m/m")


@dataclass(frozen=True, kw_only=True)
class DirectLoad:
    """Surface load on a boundary."""

    boundary: str = param(doc="bottom, top, rough_sides or counter_sides", choices=BOUNDARIES)
    pressure: float = param(0.0, doc="normal pressure, positive pushes into the body", units="Pa")
    traction: tuple[float, float] = param((0.0, 0.0), doc="traction vector (x, y)", units="Pa")


@dataclass(frozen=True, kw_only=True)
class DirectMesh:
    """Mesh graded towards the resolved interface."""

    order: int = param(2, doc="polynomial order of the displacement", check=at_least(1))
    maxh: float = param(doc="mesh size in the far field", units="m", check=positive())
    elements_per_period: float = param(8.0, doc="interface mesh size is eps / elements_per_period",
                                       check=positive())
    grading: float = param(0.3, doc="Netgen grading factor (growth of the elements away from the interface)",
                           check=positive())


@dataclass(frozen=True, kw_only=True)
class StudySpec:
    """Epsilon study: resolved runs against the homogenized laws."""

    periods: tuple[int, ...] = param((4, 8, 16), doc="N of each level (at least 3 for a rate)",
                                     check=at_least(1))
    band: float = param(3.0, doc="half-width of the band around the interface excluded from the field "
                        "error, in periods eps", check=positive())
    interface_maxh: float = param(doc="mesh size along the flat interface of the homogenized runs",
                                  units="m", check=positive())
    probes: tuple[tuple[float, float], ...] = param(
        (), doc="points (x, y) away from the layer where displacements are compared", units="m",
        allowed="pairs of numbers inside the blocks, outside the band")
    grid: tuple[int, int] = param((100, 50), doc="sampling grid (nx, ny per body) of the field error",
                                  check=at_least(4))


@dataclass(frozen=True, kw_only=True)
class DirectScene:
    kind: str = param(doc="problem type", choices=("direct",))
    title: str = param("", doc="free text shown in the report")
    materials: dict[str, MaterialSpec] = param(doc="named materials", check=nonempty())
    bodies: DirectBodies = param(doc="materials of the blocks")
    geometry: DirectGeometry = param(doc="blocks and resolved roughness")
    supports: tuple[DirectSupport, ...] = param(doc="[[supports]]: Dirichlet conditions", check=nonempty())
    loads: tuple[DirectLoad, ...] = param((), doc="[[loads]]: surface loads")
    discretization: DirectMesh = param(doc="mesh and order")
    solver: SolverSpec = param(SolverSpec(), doc="Newton settings")
    study: StudySpec | None = param(None, doc="epsilon study (scripts/epsilon_study.py)")
    base_dir: str = base_dir_field()

    def check(self, path: str) -> None:
        check_material_names(self.materials, {"rough": self.bodies.rough, "counter": self.bodies.counter},
                             "bodies")
        for name in (self.bodies.rough, self.bodies.counter):
            if self.materials[name].C is not None:
                raise SceneError(f"materials.{name}.C", "...", "direct scenes take isotropic E, nu")
        for i, s in enumerate(self.supports):
            for c in s.components:
                if c not in COMPONENTS:
                    raise SceneError(f"supports[{i}].components", c, "must be one of x, y")
            n = len(s.components or COMPONENTS)
            for key in ("displacement", "slope"):
                v = getattr(s, key)
                if v and len(v) != n:
                    raise SceneError(f"supports[{i}].{key}", v, f"one value per component ({n})")
        st = self.study
        if st is not None:
            if len(st.periods) < 3 or any(b <= a for a, b in zip(st.periods, st.periods[1:])):
                raise SceneError("study.periods", st.periods, "at least 3 increasing numbers of periods")
            g = self.geometry
            for i, (x, y) in enumerate(st.probes):
                if not (0 < x < g.length and -g.h_rough < y < g.h_counter):
                    raise SceneError(f"study.probes[{i}]", (x, y), "must lie inside the blocks")
                if abs(y) <= st.band * g.length / st.periods[0]:
                    raise SceneError(f"study.probes[{i}]", (x, y), "must lie outside the band of the "
                                     "coarsest level (|y| > band * length / periods[0])")
            if st.band * g.length / st.periods[0] >= min(g.h_rough, g.h_counter):
                raise SceneError("study.band", st.band, "the band of the coarsest level must stay inside "
                                 "both blocks")

    def check_files(self) -> None:
        """The named cell scene must be a valid 2D conforming ``cell`` scene this kind can resolve."""
        from ..scene import load, resolve
        path = resolve(self, self.geometry.cell)
        try:
            cell = load(path)
        except SceneError as exc:
            raise SceneError("geometry.cell", self.geometry.cell, f"invalid cell scene: {exc}") from None
        if cell.kind != "cell":
            raise SceneError("geometry.cell", self.geometry.cell, f"names a {cell.kind!r} scene; need 'cell'")
        g = cell.geometry
        if g.dim != 2 or g.arrangement != "conforming" or g.profile == "tabulated":
            raise SceneError("geometry.cell", self.geometry.cell,
                             "need a 2D conforming cell with an analytic profile (flat, rectangular, "
                             "triangular, semicircular, sinusoid)")
        if cell.contact.gap.kind not in ("none", "constant"):
            raise SceneError("geometry.cell", self.geometry.cell,
                             f"gap kind {cell.contact.gap.kind!r} is not resolved; use none or constant")
        object.__setattr__(self, "cell_scene", cell)


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
    if any(any(s.displacement) or any(s.slope) for s in scene.supports):
        out.append("prescribed_displacement")
    return tuple(out)


register("direct", DirectScene, "ngcontact.drivers.direct:run", effects)
