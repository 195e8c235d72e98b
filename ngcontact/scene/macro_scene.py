"""Scene kind ``macro``: two elastic bodies joined by a homogenized interface law.

The macro problem of paper eqs. 44-48 / 69-71 (see :mod:`ngcontact.macro.macro_problem`) on one of the
built-in geometries: the axisymmetric femur with a press-fitted hip stem (paper Sec. 4.2-4.3), two
coaxial tubes (Lame press fit; plane strain, axisymmetric or 3D) or a block on a base (friction); or on
two bodies read from a CAD or mesh file (``geometry.shape = "file"``, keys in
:mod:`ngcontact.scene.file_geometry`).  The interface law comes from explicit numbers (``linear`` K0,
``bundle`` of directions, ``tabulated`` normal law) or from a ``cell`` scene named by ``interface.cell``
(its direction bundle, computed on the fly and cached on
disk; see :mod:`ngcontact.coupling.cell_law`), with homogenized friction on top.
Supports are those of the ``direct`` kind (:mod:`ngcontact.scene.supports`:
constant, tilted, affine ``u0 + G x``, symmetry planes), on any boundary
label the mesh carries; ``[body_forces]`` loads each body with a constant
force density.  A ``coaxial`` shape with ``a = 0`` has a solid inner shaft.
Lengths in metres, stresses in pascals, interface stiffnesses in Pa/m.

Two optional sections extend the macro solve (this kind rather than new kinds,
because both act on a macro solution and share its geometry, law and output):

* ``[two_scale]``: the coupling loop of paper Sec. 3.5 (:mod:`ngcontact.coupling.two_scale`): the
  scene's interface law is the start (the assumed contact set), and the cell named there, tabulated
  adaptively in the pressure over the macro pressures (cached on disk), supplies its own response
  closure -> pressure as the interface law, until the table covers the macro pressures and the macro
  normal stress stops changing;
* ``[strength]``: micro stresses in the layer and the check of paper eq. 78
  (:mod:`ngcontact.coupling.strength`) against ``materials.NAME.sigma_u`` of both
  bodies.
"""
from __future__ import annotations

from dataclasses import dataclass

from ngcontact.errors import MISSING, SceneError
from ngcontact.fem.elasticity import COMPONENTS
from ngcontact.laws import homogenized as il
from ngcontact.scene.macro_shapes import (REQUIRED, SETTINGS, SHAPES, boundaries_of, check_dimensions,
                                          check_shaft_axis, check_support_meaning, macro_extent)
from ngcontact.scene.macro_shapes import BOUNDARY_DOCS as SHAPE_BOUNDARY_DOCS
from ngcontact.scene.file_geometry import FILE_BOUNDARY_DOCS, BodySpec, FaceSelectorSpec, check_file_geometry
from ngcontact.scene.sections import (MaterialSpec, SolverSpec, base_dir_field,
                                      check_material_names, check_supports_once)
from ngcontact.scene import cell_links, magnitudes, mesh_size
from ngcontact.scene.macro_discretization import MacroDiscretization
from ngcontact.scene.cell_scene import FRICTION
from ngcontact.scene.supports import SupportSpec, check_values
from ngcontact.scene.two_scale_section import TwoScaleSpec, load_cell
from ngcontact.scene.schema import at_least, nonempty, nonnegative, param, positive

LAWS = ("linear", "bundle", "tabulated", "file")
#: the kind's boundary labels by (shape, setting), read by the README reference
BOUNDARY_DOCS: dict = {**SHAPE_BOUNDARY_DOCS, "file": FILE_BOUNDARY_DOCS}


@dataclass(frozen=True, kw_only=True)
class MacroGeometrySpec:
    """Which macro geometry, in which setting, with which dimensions."""

    shape: str = param(doc="femur_stem (regions stem = rough, bone = counter), coaxial (inner = rough, "
                       "outer = counter), block (block = rough on base = counter) or file (two solids of a CAD "
                       "file, see file)", choices=SHAPES)
    setting: str = param("axisymmetric", doc="plane_strain, axisymmetric (r, z) or 3d",
                         choices=("plane_strain", "axisymmetric", "3d"))
    dimensions: dict[str, float] | None = param(
        None, doc="femur_stem: r_stem, r_tip, r_bone, z_tip, z_corner, z_bone_top, z_stem_top (defaults "
        "exist); coaxial: a, b, c (radii), height (axisymmetric/3d); block: length, h_block, h_base",
        units="m", allowed="a table of numbers > 0 (coaxial: a >= 0, a = 0 a solid inner shaft)")
    file: str | None = param(None, doc="shape = file: the CAD file (STEP .step/.stp, IGES .iges/.igs, BREP "
                             ".brep/.brp) of two solids (3d) or two planar faces in z = 0 (plane_strain; "
                             "axisymmetric with x = r, y = z; their boundary curves are the faces to select), "
                             "or the mesh (Netgen .vol, Gmsh .msh) of two regions of "
                             "tetrahedra, relative to this scene; where the bodies touch is the interface; STEP "
                             "and IGES are read in millimetres; a mesh is used as it is (maxh does not apply)")
    length_unit: float | None = param(None, doc="shape = file: metres per unit of the file as read (default "
                                      "0.001 for STEP and IGES, which are read in millimetres; 1 for BREP and "
                                      "meshes)",
                                      units="m", check=positive())
    rough: BodySpec | None = param(None, doc="shape = file: the solid (mesh region) that is the rough body")
    counter: BodySpec | None = param(None, doc="shape = file: the solid (mesh region) that is the counter body")
    boundaries: dict[str, FaceSelectorSpec] | None = param(
        None, doc="shape = file: boundary labels for [[supports]] and [[loads]], each the faces one selector "
        "picks (`ngcontact check` lists the faces)")

    def check(self, path: str) -> None:
        if self.shape == "file" or self.file is not None:
            check_file_geometry(self, path)
            return
        for key in ("length_unit", "rough", "counter", "boundaries"):
            if getattr(self, key) is not None:
                raise SceneError(f"{path}.{key}", getattr(self, key), "only used with shape = 'file'; remove it")
        allowed = SETTINGS[self.shape]
        if self.setting not in allowed:
            raise SceneError(f"{path}.setting", self.setting,
                             f"shape {self.shape!r} takes setting " + " or ".join(repr(s) for s in allowed))
        dims = self.dimensions or {}
        need = REQUIRED[self.shape] + (("height",) if self.shape == "coaxial" and self.setting != "plane_strain"
                                       else ())
        check_dimensions(dims, f"{path}.dimensions", self.shape, need)
        if self.shape == "coaxial" and not dims["a"] < dims["b"] < dims["c"]:
            raise SceneError(f"{path}.dimensions", dims, "need a < b < c")


@dataclass(frozen=True, kw_only=True)
class BodiesSpec:
    """Materials of the two bodies."""

    rough: str = param(doc="material of the rough body, paper D (femur_stem: the stem, whose coating is rough)")
    counter: str = param(doc="material of the counter body, paper Omega (femur_stem: the bone)")


@dataclass(frozen=True, kw_only=True)
class InterfaceSpec:
    """The homogenized interface law on S_0 and the initial gap."""

    law: str = param("bundle", doc="linear (K0, bilateral), bundle (unilateral weighted directions; the "
                     "default, also from a cell), tabulated (pressure against closure) or file (a law file of "
                     "`ngcontact export --format json`, see law_file)", choices=LAWS)
    law_file: str | None = param(None, doc="law = file: the JSON law file, relative to this scene (SI units; "
                                 "cell_length_unit is not applied); a regular file of at most 64 MiB; its table "
                                 "monotone row by row, the used form's stiffness k h / E within "
                                 f"[{magnitudes.MIN_PENALTY_RATIO:g}, {magnitudes.MAX_STIFFNESS_RATIO:g}] as a "
                                 "stated law's: ngcontact.scene.magnitudes")
    law_file_form: str = param("bundle", doc="law = file: which of the file's laws: bundle (exact), tabulated "
                               "(its pressure-closure table, tangential stiffness = its stick slope) or linear (K0)",
                               choices=("bundle", "tabulated", "linear"))
    cell: str | None = param(None, doc="cell scene file (relative to this scene): the law is its direction "
                             "bundle (law = linear: its K0); then omit the explicit numbers")
    cell_length_unit: float = param(1.0, doc="length of one unit of the cell scene (scales its gaps)",
                                    units="m", check=positive())
    roughness_period: float | None = param(None, units="m", check=positive(), doc="the period eps of the "
        "roughness the law homogenizes, for the modelling-error estimate C eps / L (results.accuracy.modelling); "
        "default: a cell's period times cell_length_unit, none for a law given by its numbers")
    kn: float | None = param(None, doc="k_n0 of the linear law", units="Pa/m", check=positive())
    kt: float = param(0.0, doc="k_t0 (linear law; tabulated: tangential stiffness)", units="Pa/m",
                      check=nonnegative())
    knt: float = param(0.0, doc="k_nt0 of the linear law", units="Pa/m")
    gap_force: tuple[float, float] = param((0.0, 0.0), doc="(g_n0, g_t0) of eq. 34 (linear law)", units="Pa")
    weights: tuple[float, ...] | None = param(None, doc="bundle weights w_q", units="Pa/m", check=positive())
    directions: tuple[tuple[float, ...], ...] | None = param(
        None, doc="bundle directions n_q in the local frame (n0, t0) or (n0, t1, t2)",
        allowed="one unit vector per weight")
    gaps: tuple[float, ...] | None = param(None, doc="bundle micro gaps g_q", units="m")
    closure: tuple[float, ...] | None = param(None, doc="tabulated closures c_i, increasing", units="m")
    pressure: tuple[float, ...] | None = param(None, doc="tabulated pressures p_i, from 0, non-decreasing",
                                               units="Pa")
    gap: float = param(0.0, doc="uniform macro normal gap g0 (negative: interference, press fit)", units="m")
    gap_table: tuple[tuple[float, float], ...] | None = param(
        None, doc="piecewise linear gap [[coordinate, g0], ...] along gap_coordinate (replaces gap)",
        units="m", allowed="pairs with increasing coordinate")
    gap_coordinate: str = param("y", doc="coordinate of gap_table (r = x, z = y in axisymmetry)",
                                choices=("x", "y", "z", "r"))
    mu: float = param(0.0, doc="homogenized Coulomb coefficient mu0: threshold mu0 p, solved as solver.coulomb "
                      "says (default: Newton on the coupled equations; or the fixed point on the pressure)",
                      check=nonnegative())
    threshold: float = param(0.0, doc="Tresca threshold G0", units="Pa", check=nonnegative())
    huber_width: float = param(1e-6, doc="Huber width w: largest slip of a sticking point", units="m",
                               check=positive())
    friction: str = param("given", doc="given: mu and threshold above; from_cell: mu0 and G0 of eqs. 42-43 from "
                          "the cell the law comes from (interface.cell, else two_scale.cell); with [two_scale] the "
                          "loop then replaces them by the cell's tabulated shear over pressure and tangential jump",
                          choices=("given", "from_cell"))
    cell_k_n: float | None = param(None, doc="replaces contact.k_n of the cells the law comes from", units="Pa/m",
                                   check=positive())
    cell_friction: str | None = param(None, doc="replaces their contact.friction (with cell_mu or cell_G, "
                                      "and cell_w)", choices=FRICTION)
    cell_mu: float | None = param(None, doc="replaces their contact.mu", check=nonnegative())
    cell_G: float | None = param(None, doc="replaces their contact.G", units="Pa", check=nonnegative())
    cell_w: float | None = param(None, doc="replaces their contact.w (cell length units)", check=positive())

    def check(self, path: str) -> None:
        explicit = {"kn": self.kn, "weights": self.weights, "directions": self.directions, "gaps": self.gaps,
                    "closure": self.closure, "pressure": self.pressure}
        if self.gap_table is not None:
            xs = [q[0] for q in self.gap_table]
            if any(b <= a for a, b in zip(xs, xs[1:])):
                raise SceneError(f"{path}.gap_table", self.gap_table, "coordinates must increase strictly")
            if self.gap != 0.0:
                raise SceneError(f"{path}.gap", self.gap, "give either gap or gap_table")
        if (self.law == "file") != (self.law_file is not None):
            raise SceneError(f"{path}.law_file", self.law_file or MISSING, "give law_file exactly when law = 'file'")
        if self.law == "file":
            for key, value in dict(explicit, cell=self.cell).items():
                if value is not None:
                    raise SceneError(f"{path}.{key}", value, "not used with law = 'file'; remove it")
            return
        if self.cell is not None:
            for key, value in explicit.items():
                if value is not None:
                    raise SceneError(f"{path}.{key}", value, "not used with interface.cell; remove it")
            if self.law == "tabulated":
                raise SceneError(f"{path}.law", self.law, "a cell gives law = 'bundle' or 'linear'")
            return
        need = {"linear": ("kn",), "bundle": ("weights", "directions"), "tabulated": ("closure", "pressure")}
        for key in need[self.law]:
            if explicit[key] is None:
                raise SceneError(f"{path}.{key}", MISSING, f"required for law = {self.law!r} (or name a cell)")
        for key, value in explicit.items():
            if value is not None and key not in need[self.law] + (("gaps",) if self.law == "bundle" else ()):
                raise SceneError(f"{path}.{key}", value, f"not used by law = {self.law!r}; remove it")
        try:  # the law's own admissibility rule; the driver builds the law it solves with
            il.normal_law(self.law, kn=self.kn, kt=self.kt, knt=self.knt, gap_force=self.gap_force,
                          weights=self.weights, directions=self.directions, gaps=self.gaps,
                          closure=self.closure, pressure=self.pressure)
        except ValueError as exc:
            raise SceneError(f"{path}", self.law, str(exc)) from None


@dataclass(frozen=True, kw_only=True)
class LoadSpec:
    """Surface load on a boundary."""

    boundary: str = param(doc="boundary label of the geometry")
    pressure: float = param(0.0, doc="normal pressure, positive pushes into the body", units="Pa")
    traction: tuple[float, ...] = param((), doc="traction vector (global components)", units="Pa")


@dataclass(frozen=True, kw_only=True)
class BodyForceSpec:
    """Constant body forces (force per unit volume, e.g. density times gravity), one vector per body."""

    rough: tuple[float, ...] = param((), doc="force density on the rough body (x, y[, z]; r, z in axisymmetry)",
                                     units="N/m^3")
    counter: tuple[float, ...] = param((), doc="force density on the counter body", units="N/m^3")


@dataclass(frozen=True, kw_only=True)
class OutputSpec:
    """Sampling of the results."""

    #: removed keys -> what replaces them (:func:`~ngcontact.scene.schema.build` names it)
    REMOVED = {"coulomb_tol": "solver.coulomb_rtol (the Coulomb fixed point stops when max |p_k - p_k-1| <= "
                              "coulomb_rtol x max p_k)"}
    points_per_element: int = param(5, doc="samples per interface element in the profile", check=at_least(2))
    vtk_subdivision: int = param(1, doc="subdivision of the VTK output", check=at_least(0))


@dataclass(frozen=True, kw_only=True)
class StrengthSpec:
    """Micro-stress recovery in the interface layer and the strength check (paper eqs. 74-78)."""

    cell: str = param(doc="cell scene (kind cell) of the layer, relative to this scene; its [load] is "
                      "not used (the macro state loads it); its bodies are this scene's rough and counter; "
                      "a 3D cell under a 3D macro scene (its x, y axes on the law's tangents t1, t2)")
    criterion: str = param("von_mises", doc="equivalent stress of eq. 77", choices=("von_mises", "tresca"))
    recovery: str = param("linear", doc="linear: unit-load correctors with the contact set fixed (the "
                          "cell's points without gap), superposed at every interface point (eq. 75); "
                          "nonlinear: in addition the contact cell problem solved at the macro state of "
                          "the nonlinear_points interface points with the largest linear estimate",
                          choices=("linear", "nonlinear"))
    nonlinear_points: int = param(3, doc="interface points re-solved with the contact cell problem "
                                  "(recovery = nonlinear)", check=at_least(1))
    tangential_stiffness: float | None = param(
        None, doc="k_t on the contact set in the linear recovery (sticking summits carry the shear); "
        "default: the cell's k_n when the macro law has friction, else 0 (no shear carried)",
        units="Pa/m", check=nonnegative())


@dataclass(frozen=True, kw_only=True)
class MacroScene:
    kind: str = param(doc="problem type", choices=("macro",))
    title: str = param("", doc="free text shown in the report")
    materials: dict[str, MaterialSpec] = param(doc="named materials", check=nonempty())
    bodies: BodiesSpec = param(doc="materials of the bodies")
    geometry: MacroGeometrySpec = param(doc="the macro geometry")
    interface: InterfaceSpec = param(doc="interface law on S_0")
    supports: tuple[SupportSpec, ...] = param(doc="[[supports]]: Dirichlet conditions", check=nonempty())
    loads: tuple[LoadSpec, ...] = param((), doc="[[loads]]: surface loads")
    body_forces: BodyForceSpec = param(BodyForceSpec(), doc="[body_forces]: constant force densities")
    discretization: MacroDiscretization = param(MacroDiscretization(), doc="mesh and order")
    solver: SolverSpec = param(SolverSpec(), doc="Newton settings")
    output: OutputSpec = param(OutputSpec(), doc="result sampling")
    two_scale: TwoScaleSpec | None = param(None, doc="[two_scale]: coupling loop with a cell (Sec. 3.5)")
    strength: StrengthSpec | None = param(None, doc="[strength]: micro stresses and the check of eq. 78")
    base_dir: str = base_dir_field()

    def check_size(self) -> None:
        """The gap's magnitude and the element estimate of :mod:`ngcontact.scene.mesh_size` (``max_elements``)."""
        g, d, i = self.geometry, self.discretization, self.interface
        mesh_size.check_magnitudes({"interface.gap": i.gap} | {f"interface.gap_table[{k}]": row[1]
                                                                for k, row in enumerate(i.gap_table or ())})
        if g.shape == "file":   # the extent is known once the file is read (drivers/macro_geometry.py)
            mesh_size.check_lengths({"discretization.maxh": d.maxh, "discretization.interface_maxh": d.interface_maxh})
            return
        mesh_size.check_lengths({f"geometry.dimensions.{k}": v for k, v in (g.dimensions or {}).items() if v != 0}
                                | {"discretization.maxh": d.maxh, "discretization.interface_maxh": d.interface_maxh})
        dim, volume, interface, width = macro_extent(g.shape, g.setting, dict(g.dimensions or {}))
        magnitudes.check_body_forces(self, width)
        n = mesh_size.estimate(dim, volume, d.maxh, width=width, interface=interface, h_interface=d.interface_maxh)
        mesh_size.refuse_beyond(d.refined_count(n, dim), d.max_elements, *mesh_size.finest_size(d),
                                hint=" or ask for fewer discretization.refinements" if d.refinements else "")

    def check(self, path: str) -> None:
        check_material_names(self.materials, {"rough": self.bodies.rough, "counter": self.bodies.counter},
                             "bodies")
        magnitudes.check_surface_loads(self)
        magnitudes.check_macro_interface(self)
        self.check_size()
        comps = COMPONENTS[self.geometry.setting]
        shape, setting = self.geometry.shape, self.geometry.setting
        dims = dict(self.geometry.dimensions or {})
        labels = () if shape == "file" else boundaries_of(shape, setting, dims)
        groups: tuple[tuple[str, tuple[SupportSpec | LoadSpec, ...]], ...] = (
            ("supports", self.supports), ("loads", self.loads))
        # a file's labels (selected, or named in the file) are checked against the file, before meshing
        for what, items in (groups if shape != "file" else ()):
            for i, item in enumerate(items):
                if item.boundary not in labels:
                    raise SceneError(f"{what}[{i}].boundary", item.boundary,
                                     f"no such boundary in {shape!r} ({setting}); labels are " + ", ".join(labels))
        check_values(self.supports, comps, setting)
        check_supports_once(self.supports, comps)
        check_support_meaning(self.supports, comps, self.geometry.setting)
        check_shaft_axis(self.supports, shape, setting, dims)
        dim = 3 if self.geometry.setting == "3d" else 2
        for i, load in enumerate(self.loads):
            if load.traction and len(load.traction) != dim:
                raise SceneError(f"loads[{i}].traction", load.traction, f"must have {dim} components")
        for role in ("rough", "counter"):
            f = getattr(self.body_forces, role)
            if f and len(f) != dim:
                raise SceneError(f"body_forces.{role}", f, f"one number per component ({', '.join(comps)})")
        if self.interface.gap_coordinate == "z" and dim == 2 and self.geometry.setting != "axisymmetric":
            raise SceneError("interface.gap_coordinate", "z", "plane strain has coordinates x, y")
        cell_links.check(self.interface, self.two_scale)
        if self.strength is not None:
            for role in ("rough", "counter"):
                name = getattr(self.bodies, role)
                if self.materials[name].sigma_u is None:
                    raise SceneError(f"materials.{name}.sigma_u", MISSING,
                                     f"the ultimate stress of the {role} body is required by [strength]; "
                                     "a number > 0 [Pa]")

    def check_files(self, load) -> None:
        """Every named cell scene exists, is valid and is of kind ``cell``.

        The cells of ``[strength]`` and ``[two_scale]`` are solved, so they
        also need a contact model (not ``contact.geometric_only``).  A fault
        inside a cell scene is reported under the key naming it, e.g.
        ``interface.cell = 'hip.toml': invalid cell scene: materials.bone.nu = ...``.
        ``load(path, overrides=None)``: overrides of the law's cells' ``[contact]``.
        """
        from ngcontact.scene.sections import check_input_file, resolve
        if self.geometry.file is not None:
            check_input_file("geometry.file", resolve(self, self.geometry.file), "CAD file",
                             shown=self.geometry.file, missing="no such CAD file")
        if self.interface.law_file is not None:
            from ngcontact.scene import law_file
            where = resolve(self, self.interface.law_file)
            contents = law_file.read(where)
            try:
                law_file.normal_law_of(contents, self.interface.law_file_form)
            except ValueError as exc:
                raise SceneError("interface.law_file_form", self.interface.law_file_form, str(exc)) from None
            magnitudes.check_file_law(self, "interface.law_file", where,
                                      law_file.stiffness(contents, self.interface.law_file_form))
        files = (("interface.cell", self.interface.cell, False),
                 ("strength.cell", self.strength.cell if self.strength else None, True),
                 ("two_scale.cell", self.two_scale.cell if self.two_scale else None, True))
        overrides = cell_links.overrides(self.interface)
        for key, rel, solved in files:
            if rel is None:
                continue
            check_input_file(key, resolve(self, rel), "cell scene", shown=rel, missing="no such cell scene file")
            try:
                cell = load(resolve(self, rel))
            except SceneError as exc:
                raise SceneError(key, rel, f"invalid cell scene: {exc}") from None
            if overrides and key != "strength.cell" and cell.kind == "cell":
                try:
                    cell = load(resolve(self, rel), overrides)
                except SceneError as exc:
                    raise SceneError("interface.cell_" + next(iter(overrides)), overrides,
                                     f"the cell {rel!r} with these overrides is invalid: {exc}") from None
            if key == "two_scale.cell" and self.two_scale is not None and cell.kind == "cell":
                cell = load_cell(load, resolve(self, rel), rel, overrides, self.two_scale,
                                 shear_from_cell=self.interface.friction == "from_cell")
            if key == "two_scale.cell" and cell.kind == "cell" and cell.discretization.method == "spectral":
                cell_links.check_spectral_loop(self.interface, self.two_scale, rel, cell)
            if cell.kind != "cell":
                raise SceneError(key, rel, f"invalid cell scene: must be of kind 'cell', not {cell.kind!r}")
            if key == "interface.cell" and cell.contact.k_n is not None:   # its bundle's weights are k_n's
                magnitudes.check_cell_law(self, key, rel, cell, "k_n" in overrides)
            cell_links.check_friction_source(self.interface, key, rel, cell)
            if (key == "two_scale.cell" and self.geometry.setting == "3d" and self.interface.friction == "from_cell"
                    and cell.contact.friction != "none"):
                raise SceneError("interface.friction", "from_cell", f"with the frictional cell {rel!r} the two-scale "
                                 "loop tabulates the cell's shear against one tangential jump "
                                 "(coupling.shear_table), which a 3D macro interface with two tangents does not "
                                 "have yet; use interface.friction = 'given' (mu, threshold) in 3D, or a 2D or "
                                 "axisymmetric scene")
            if key == "strength.cell" and self.geometry.setting == "3d" and cell.geometry.dim != 3:
                raise SceneError(key, rel, f"a {cell.geometry.dim}D cell under a 3D macro scene: the macro "
                                 "traction has two tangential components and the layer two in-plane strains, a "
                                 "2D cell takes one of each; use a 3D cell (its x, y axes are the law's "
                                 "tangents t1, t2)")
            if solved and cell.contact.geometric_only:
                raise SceneError(key, rel, "invalid cell scene: contact.geometric_only = true, but this "
                                 "section solves the cell, so it needs a contact model and a [load] section")


def effects(scene: MacroScene) -> tuple[str, ...]:
    """The terms assembled."""
    i = scene.interface
    out = ["elasticity", f"interface_{i.law_file_form}_from_file" if i.law == "file"
           else f"interface_{i.law}" + ("_from_cell" if i.cell else "")]
    if i.gap != 0.0 or i.gap_table is not None:
        out.append("initial_gap")
    if i.mu > 0:
        out.append("coulomb_friction")
    if i.threshold > 0:
        out.append("tresca_friction")
    if any(load.pressure or load.traction for load in scene.loads):
        out.append("surface_loads")
    if any(any(s.displacement) or any(s.slope) or any(s.u0) or any(any(r) for r in s.G) for s in scene.supports):
        out.append("prescribed_displacement")
    if any(scene.body_forces.rough) or any(scene.body_forces.counter):
        out.append("body_forces")
    if scene.two_scale is not None:
        out.append("two_scale_coupling")
    if scene.strength is not None:
        out.append("strength_check")
    return tuple(out)


