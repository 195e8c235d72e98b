"""Scene kind ``cell``: the micro contact problem of one periodic cell.

Sections: ``[geometry]`` (profile and arrangement, :mod:`ngcontact.scene.cell_geometry`), ``[contact]`` (penalty
``k_n``, initial gap, friction law), ``[load]`` (pressure or normal jump, shear or tangential jump, macro
strain; lists are sweeps), ``[bodies]`` (material names), ``[discretization]``, ``[solver]``. With
``contact.geometric_only = true`` only the coefficients of the whole contact surface (paper eq. 34, 42-43) are
computed and no contact problem is solved.  Solved by :mod:`ngcontact.drivers.run_cell`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from ngcontact.errors import MISSING, GeometryError, SceneError
from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.laws.friction import FRICTION_LAWS
from ngcontact.scene.spectral_grid import TOLERANCE_OVER_RTOL, check_spectral_size
from ngcontact.scene.cell_method import MethodChoice, SymmetryChoice, choose, resolved_discretization
from ngcontact.scene.cell_geometry import (CellGeometry, check_features, check_profile_heights, flat_interface,
                                          small_slope)
from ngcontact.scene.sections import (CellDiscretization, ComputeSpec, MaterialSpec, SolverSpec, base_dir_field,
                                     check_material_names)
from ngcontact.scene import magnitudes, mesh_size
from ngcontact.scene.schema import (check_selected, closed_interval, derived_field, nonempty, nonnegative, param,
                                   positive)

GAPS = ("none", "constant", "sinusoid", "bisinusoid", "tabulated")
#: "none" and the names of the micro friction laws (:data:`ngcontact.laws.friction.FRICTION_LAWS`)
FRICTION = ("none", *FRICTION_LAWS)
ENFORCEMENTS = ("penalty", "exact")
#: Most loads of one sweep (each a cell solve with its own fields and files).
MAX_LOADS = 1000


@dataclass(frozen=True, kw_only=True)
class GapSpec:
    """Initial gap g >= 0 on the contact surface."""

    kind: str = param("none", doc="none, constant, sinusoid 2h sin^2(pi x/P) (2D; 3D: waves along x), bisinusoid "
                      "h (2 - cos(2 pi x/P) - cos(2 pi y/P)), tabulated (file)",
                      choices=GAPS)
    value: float | None = param(None, doc="constant gap", units="m", check=nonnegative())
    h: float | None = param(None, doc="gap amplitude h (sinusoid: g in [0, 2h]; bisinusoid: [0, 4h])",
                            units="m", check=positive())
    file: str | None = param(None, doc="tabulated gap: CSV with columns x, g in the scene's length unit, an "
                             "optional header line, x strictly increasing from 0 to the period, the last row "
                             "(x = period) repeating the first g (2D), or .npy array g[i, j] at x = j P/(n_x - 1), "
                             "y = i P/(n_y - 1) whose last row/column repeat the first (3D); g >= 0; a regular "
                             "file of at most 64 MiB, relative to the scene file")

    def check(self, path: str) -> None:
        need = {"none": (), "constant": ("value",), "sinusoid": ("h",),
                "bisinusoid": ("h",), "tabulated": ("file",)}[self.kind]
        check_selected(self, path, "kind", ("value", "h", "file"), need)


@dataclass(frozen=True, kw_only=True)
class ContactSpec:
    """Penalty contact and friction on S_C."""

    k_n: float | None = param(None, doc="penalty (Winkler) stiffness k_n, required with enforcement = 'penalty'; "
                              "with 'exact' optional: the scale of the eq. 34 coefficients in the report and the FE "
                              "cell's augmentation, by default 10 E / h (E the softer body's modulus, h the interface "
                              "mesh size or grid step)", units="Pa/m", check=positive())
    enforcement: str = param("penalty", doc="penalty: the paper's Winkler layer p = k_n [J.n - g]_+ (eq. 65) "
                             "and Huber-regularized friction; exact: non-penetration, the rigid limit k_n -> infinity: "
                             "spectral cell with exact friction (w unused), or FE cell (in 3D at order >= 2 with a "
                             "linear trace on S_C: the bodies of the order, the trace and multiplier of order 1), "
                             "node-to-node at the nodes of the trace (Gauss-Lobatto on segments, vertices of "
                             "triangles) by an "
                             "augmented Lagrangian with Uzawa updates (k_n is its "
                             "augmentation: the speed, not the answer; friction Huber-regularized with w, the "
                             "Coulomb threshold mu times the multiplier)",
                             choices=ENFORCEMENTS)
    gap: GapSpec = param(GapSpec(), doc="initial gap")
    friction: str = param("none", doc="friction law", choices=FRICTION)
    G: float | None = param(None, doc="Tresca threshold", units="Pa", check=nonnegative())
    mu: float | None = param(None, doc="Coulomb coefficient", check=nonnegative())
    w: float | None = param(None, doc="Huber width (stick zone of the slip); required with friction, except by "
                            "the spectral cell's exact friction (enforcement = 'exact', method = 'spectral'), "
                            "which has none", units="m", check=positive())
    geometric_only: bool = param(False, doc="only the coefficients of the whole contact surface; "
                                 "solve no contact problem")

    def check(self, path: str) -> None:
        if self.k_n is None and self.enforcement == "penalty":
            raise SceneError(f"{path}.k_n", MISSING, "required with enforcement = 'penalty' (the Winkler layer's "
                             "stiffness, paper eq. 65); exact contact ('exact') needs none")
        need = () if self.friction == "none" else FRICTION_LAWS[self.friction].parameters
        # exact friction has no width: w is optional under exact enforcement (CellScene.check asks it of the FE cell)
        exact = self.enforcement == "exact" and self.friction != "none"
        check_selected(self, path, "friction", ("G", "mu", "w"), tuple(k for k in need if not (exact and k == "w")),
                       optional=("w",) if exact else ())


@dataclass(frozen=True, kw_only=True)
class LoadSpec:
    """Mean load of the cell; lists of equal length (or length 1) make a sweep of at most :data:`MAX_LOADS`."""

    pressure: tuple[float, ...] | None = param(None, units="Pa", check=positive(), doc="mean normal pressure, "
                                               f"compression positive (at most {MAX_LOADS} loads)")
    normal_jump: tuple[float, ...] | None = param(None, doc="prescribed far-face normal jump "
                                                  "(rough minus counter, positive closes)", units="m")
    shear: tuple[float, ...] | None = param(None, doc="mean shear on the counter's far face along "
                                            "x (2D) or x then y per load (3D: 2 entries per load)",
                                            units="Pa")
    tangential_jump: tuple[float, ...] | None = param(None, doc="prescribed far-face tangential jump "
                                                      "(same layout as shear)", units="m")
    macro_strain: tuple[float, ...] | None = param(None, doc="in-plane macro strain: 2D (e_xx), "
                                                   "3D (e_xx, e_yy, e_xy), one set per sweep", units="")
    independent: bool = param(False, doc="solve every load on its own from the unloaded cell (no continuation "
                              "from the previous load), so that the loads run in parallel (see [compute]); "
                              "frictionless contact only.  Without discretization.tolerance each load is held to the "
                              "default one on its own, as a chained sweep is held (the same results.accuracy): the "
                              "FE cell estimated and refined within budget_dofs, the spectral cell refined by grid "
                              "doubling from discretization.grid (results.method.per_load: each load's grids)")

    def check(self, path: str) -> None:
        if (self.pressure is None) == (self.normal_jump is None):
            raise SceneError(f"{path}.pressure", self.pressure,
                             "give exactly one of pressure and normal_jump")
        if self.shear is not None and self.tangential_jump is not None:
            raise SceneError(f"{path}.shear", self.shear, "give shear or tangential_jump, not both")
        for key, per_load in (("pressure", 1), ("normal_jump", 1), ("shear", 2), ("tangential_jump", 2)):
            v = getattr(self, key)
            if v is not None and not 0 < len(v) <= per_load * MAX_LOADS:
                raise SceneError(f"{path}.{key}", f"{len(v)} entries", f"must not be empty; a sweep takes at most "
                                 f"{MAX_LOADS} loads ({per_load * MAX_LOADS} entries), each a solve of its own")


#: Most realizations of an ensemble.  The 95 % band's half-width is ``t s / sqrt(M)`` (``s`` the members'
#: standard deviation): at 10000 members it is 2 % of ``s``, and more members narrow it by less than the
#: members' own spread shows; and every member is kept in the report (a row per member and load), which a
#: billion members cannot be (a MemoryError after 45 s).
MAX_MEMBERS = 10_000


@dataclass(frozen=True, kw_only=True)
class EnsembleSpec:
    """M realizations of the random surface of ``geometry.spectrum`` (or ``geometry.seed``): seeds ``seed, seed + 1,
    ...``."""

    members: int = param(doc="number of realizations M", check=closed_interval(2, MAX_MEMBERS))


@dataclass(frozen=True, kw_only=True)
class Bodies:
    """Materials of the two bodies."""

    rough: str = param(doc="material of the rough body (below)")
    counter: str = param(doc="material of the counter body (above)")


@dataclass(frozen=True, kw_only=True)
class CellScene:
    kind: str = param(doc="problem type", choices=("cell",))
    title: str = param("", doc="free text shown in the report")
    materials: dict[str, MaterialSpec] = param(doc="named materials", check=nonempty())
    bodies: Bodies = param(doc="materials of the bodies")
    geometry: CellGeometry = param(doc="the periodic cell")
    contact: ContactSpec = param(doc="contact law")
    load: LoadSpec | None = param(None, doc="mean load (omit with contact.geometric_only)")
    discretization: CellDiscretization = param(CellDiscretization(), doc="mesh and order")
    solver: SolverSpec = param(SolverSpec(), doc="Newton settings")
    ensemble: EnsembleSpec | None = param(None, doc="solve the loads on M realizations of the random surface "
                                          "(geometry.profile = 'self_affine' or 'measured_spectrum'); report the "
                                          "mean and the 95 % band; each member on the scene's discretization "
                                          "with its error estimated there (the spectral cell from three coarser "
                                          "grids, the FE cell by one order more), results.accuracy the largest "
                                          "member estimate beside the band")
    compute: ComputeSpec = param(ComputeSpec(), doc="where independent solves run (loads, ensemble members)")
    base_dir: str = base_dir_field()
    #: the method that solves the scene and why (``discretization.method`` resolved by :meth:`resolved`)
    method_choice: MethodChoice | None = derived_field()
    #: its FE cell, quarter or period, and why (``discretization.symmetry``, set by drivers.build.with_symmetry)
    symmetry_choice: SymmetryChoice | None = derived_field()

    def resolved(self) -> CellScene:
        """The scene with its derived field, before anything asks for the method: ``discretization.method =
        "auto"`` resolved to fe or spectral (:func:`~ngcontact.scene.cell_method.choose`), a new scene by
        ``dataclasses.replace``; a scene resolved already is returned as it is."""
        if self.method_choice is not None:
            return self
        choice = choose(self)
        return replace(self, discretization=resolved_discretization(self.discretization, choice),
                       method_choice=choice)

    def check_files(self, load) -> None:
        """Read and validate the tabulated profile / height map / measured topography / gap named by the scene.

        The readers name the entry under the scene's key path they are given
        (``where``), so their :class:`GeometryError` becomes a
        :class:`SceneError` with the same words.
        """
        try:
            self._check_files()
        except GeometryError as exc:
            raise SceneError(exc.name, exc.value, exc.allowed) from None

    def _check_files(self) -> None:
        from ngcontact.geometry import tabulated
        from ngcontact.geometry.profile_registry import file_map
        from ngcontact.scene.sections import resolve
        g = self.geometry
        if g.file is not None:
            where = f"geometry.file ({g.file})"
            if g.dim == 2:      # a 2D profile's file is its CSV (tabulated), a 3D one's a height map
                prof = tabulated.read_profile_csv(resolve(self, g.file), path=where)
                if abs(prof.period - g.period) > 1e-12 * g.period:
                    raise SceneError("geometry.period", g.period,
                                     f"must equal the period of the tabulated profile ({prof.period!r})")
                lo, hi = prof.bounds
                if hi - lo >= min(g.h_rough, g.h_counter):
                    raise SceneError("geometry.file", g.file, f"the profile height {hi - lo!r} must stay "
                                     "below h_rough and h_counter")
                check_profile_heights(g, (lo, hi))     # what the mesher checks, as 'run' meets it
                check_features(prof, "geometry.file", g.file)
            else:
                heights, period = file_map(g, resolve(self, g.file), where)
                if abs(period - g.period) > 1e-9 * period:
                    raise SceneError("geometry.period", g.period, f"must equal the period of the measured "
                                     f"topography {g.file!r}: {period!r} (its physical size in metres, twice it "
                                     "with periodize = 'mirror')")
                if self.discretization.method == "spectral" and self.discretization.grid is None:
                    check_spectral_size(g.dim, spectral_grid(self, heights.shape), "geometry.file", g.file)
        gs = self.contact.gap
        if gs.file is not None:
            where = f"contact.gap.file ({gs.file})"
            if self.geometry.dim == 2:
                x, _ = tabulated.read_gap_csv(resolve(self, gs.file), path=where)
                if abs(x[-1] - g.period) > 1e-12 * g.period:
                    raise SceneError("contact.gap.file", gs.file,
                                     f"must span one period {g.period!r} (it ends at x = {x[-1]!r})")
            else:
                tabulated.read_gap_map(resolve(self, gs.file), path=where)

    def check(self, path: str) -> None:
        check_material_names(self.materials, {"rough": self.bodies.rough,
                                              "counter": self.bodies.counter}, "bodies")
        for name in (self.bodies.rough, self.bodies.counter):
            if self.materials[name].C is not None:
                raise SceneError(f"materials.{name}.C", "...", "cell scenes take isotropic E, nu")
        dim = self.geometry.dim
        if self.contact.k_n is None:       # exact contact without a scale: the default of contact.k_n's doc
            object.__setattr__(self.contact, "k_n", exact_scale(self))
        g = self.contact.gap.kind
        if g == "bisinusoid" and dim != 3:
            raise SceneError("contact.gap.kind", g, f"not available for a {dim}D cell")
        self.check_size()
        magnitudes.check_cell(self)
        if self.contact.geometric_only:
            if self.load is not None:
                raise SceneError("load", "...", "not used with contact.geometric_only = true; remove it")
            return
        if self.load is None:
            raise SceneError("load", MISSING, "required unless contact.geometric_only = true")
        if self.discretization.method == "spectral":
            check_spectral(self)
        else:
            check_fe(self)
        load_states(self)
        if self.load.independent and self.contact.friction != "none":
            raise SceneError("load.independent", True, "solves every load afresh, which a frictional load path "
                             "does not allow; remove the key or set contact.friction = 'none'")
        if self.ensemble is not None and not PROFILES[self.geometry.profile].random:
            raise SceneError("ensemble", "...", "realizations of a random surface need geometry.profile = "
                             "'self_affine' (its spectrum and seed) or 'measured_spectrum' (a measured file's "
                             f"spectrum), not {self.geometry.profile!r}")
        if flat_interface(self.geometry) and self.contact.friction == "none":
            for key in ("shear", "tangential_jump"):
                v = getattr(self.load, key)
                if v is not None and any(x != 0.0 for x in v):
                    raise SceneError(f"load.{key}", v, "a frictionless flat contact surface carries no "
                                     "shear and fixes no tangential jump: give 0 or set contact.friction")

    def check_size(self) -> None:
        """The lengths and the element estimate of :mod:`ngcontact.scene.mesh_size` (``max_elements``)."""
        g, d = self.geometry, self.discretization
        mesh_size.check_cell_lengths(self)
        if d.method == "spectral":
            return          # no mesh: the grid is bounded by its own check
        P, dim = g.period, g.dim
        width = min(P, g.h_rough, g.h_counter)
        n = mesh_size.estimate(dim, P ** (dim - 1) * (g.h_rough + g.h_counter), d.maxh, width=width,
                               interface=P ** (dim - 1), h_interface=d.interface_maxh)
        tall = max(g.h_rough, g.h_counter) / P
        hint = (f" (the bodies are {tall:.3g} periods high; the cell's boundary layer decays within a few "
                "periods, so h_rough and h_counter of 0.5 to 5 periods suffice)") if tall > 20 else ""
        key, value = ("geometry.period", P) if hint else mesh_size.finest_size(d)
        mesh_size.refuse_beyond(n, d.max_elements, key, value, hint=hint)


def check_penalty_ratio(scene: CellScene, spacing: tuple[float, str] | None = None) -> None:
    """``k_n h / E`` of the cell, ``h`` its interface mesh size and ``E`` the softer body's modulus, within
    the bounds of :func:`ngcontact.scene.magnitudes.check_penalty_ratio`.

    ``spacing``: ``(h, what it is)`` instead of the mesh size, and the lower bound only: the spectral cell
    (:func:`check_spectral`) with ``h`` its grid step.  Its penalty adds ``1/k_n`` to the layers' compliance,
    diagonal in Fourier space, and a stiff ``k_n`` only approaches the exact limit it also solves: no
    tangent outweighs another there, so the upper bound does not apply; a soft one makes the jump ``p/k_n``
    dwarf the bodies' deformation as in the FE cell.
    """
    d, c = scene.discretization, scene.contact
    h, what = spacing if spacing is not None else (d.interface_maxh or d.maxh, "the interface mesh size")
    E, _ = magnitudes.softer(scene.materials, (scene.bodies.rough, scene.bodies.counter))
    assert c.k_n is not None  # set by CellScene.check (exact contact: its default scale)
    magnitudes.check_penalty_ratio("contact.k_n", c.k_n, "k_n", h, what, E, upper=spacing is None)


#: ``k_n h / E`` of exact contact's default scale (``contact.k_n``): within the admissible ratios, and an
#: augmentation of the interface as stiff as ten elements of the softer body
EXACT_SCALE_RATIO = 10.0


def exact_scale(scene: CellScene) -> float:
    """The default ``k_n`` of exact contact: :data:`EXACT_SCALE_RATIO` ``E / h``, ``E`` the softer body's
    modulus and ``h`` the interface mesh size (FE) or the grid step (spectral)."""
    d, g = scene.discretization, scene.geometry
    E = min(scene.materials[name].E or 1.0 for name in (scene.bodies.rough, scene.bodies.counter))
    h = g.period / spectral_grid(scene) if d.method == "spectral" else (d.interface_maxh or d.maxh)
    return EXACT_SCALE_RATIO * E / h


def spectral_grid(scene: CellScene, heights_shape: tuple[int, ...] | None = None) -> int:
    """Points per period and direction of a spectral cell: ``discretization.grid`` or the default."""
    if scene.discretization.grid is not None:
        return scene.discretization.grid
    if heights_shape is not None:      # the map's own grid (made even)
        n = max(heights_shape) - 1
        return n + n % 2
    return 1024 if scene.geometry.dim == 2 else 256


def has_twin(scene: CellScene) -> bool:
    """Whether an FE cell scene's first loads can start from its spectral twin
    (:mod:`ngcontact.cell.spectral_start`): the penalty on a flat interface."""
    return scene.contact.enforcement == "penalty" and flat_interface(scene.geometry)


def check_fe(scene: CellScene) -> None:
    """What the FE cell needs of a scene: a Huber width with friction, an admissible penalty and a flat
    interface for the spectral start (exact contact in 3D at order >= 2 takes a linear trace on ``S_C``,
    :mod:`ngcontact.cell.fe.linear_trace`).  A tolerance suits every FE cell (graded
    meshes on a flat 2D frictionless cell, else a sequence of finer interface meshes:
    :mod:`ngcontact.cell.fe.second_discretization`)."""
    c = scene.contact
    if c.friction != "none" and c.w is None:
        raise SceneError("contact.w", MISSING, f"required for friction = {c.friction!r} in an FE cell, which "
                         "regularizes friction with the Huber width w under exact enforcement too (the spectral "
                         "cell's exact friction needs none)")
    check_penalty_ratio(scene)
    if scene.solver.start == "spectral" and not has_twin(scene):
        raise SceneError("solver.start", "spectral", "starts from the spectral cell of the same small-slope cell: "
                         "it needs contact.enforcement = 'penalty' and a flat interface (geometry.profile = "
                         "'flat' or 'flat3d', or 'bisinusoid', 'height_map' or 'self_affine' with arrangement = "
                         f"'summit'), not enforcement {c.enforcement!r} on a {scene.geometry.profile!r} "
                         f"profile in the {scene.geometry.arrangement!r} arrangement; use 'auto' or 'rigid'")


def check_spectral(scene: CellScene) -> None:
    """A spectral cell needs the small-slope model, and a grid it can hold."""
    g, d = scene.geometry, scene.discretization
    if not flat_interface(g):
        raise SceneError("discretization.method", "spectral", "solves the small-slope cell: a flat interface with "
                         "the roughness in the initial gap (geometry.profile = 'flat' or 'flat3d', or 'bisinusoid', "
                         "'height_map' or 'self_affine' with arrangement = 'summit'), not geometry.profile = "
                         f"{g.profile!r} in the {g.arrangement!r} arrangement; use method = 'fe'")
    if d.grid is not None and d.grid % 2:
        raise SceneError("discretization.grid", d.grid, "must be even (the FFT's Nyquist mode is real)")
    n = spectral_grid(scene)           # a height map's own grid: checked when the map is read (check_files)
    check_spectral_size(g.dim, n)
    if d.tolerance is not None and d.tolerance < TOLERANCE_OVER_RTOL * scene.solver.rtol:
        raise SceneError("discretization.tolerance", d.tolerance,
                         f"must be at least {TOLERANCE_OVER_RTOL:g} x solver.rtol = "
                         f"{TOLERANCE_OVER_RTOL * scene.solver.rtol:g} (the grid's solutions are only that accurate, "
                         "so no comparison of two grids can show less); loosen it or lower solver.rtol")
    if scene.contact.enforcement == "penalty":
        check_penalty_ratio(scene, (g.period / n, "the grid step"))


def load_states(scene: CellScene) -> list[dict]:
    """The sweep ``scene.load`` describes, one keyword dict per load state.

    Keys ``pressure`` / ``normal_jump``, ``shear`` / ``tangential_jump`` and
    ``macro_strain`` as :func:`ngcontact.drivers.build.cell_loads` hands them
    to the cell problem; checks that the lists pair up.
    """
    L, dim = scene.load, scene.geometry.dim
    assert L is not None  # required unless contact.geometric_only (CellScene.check)
    nt = dim - 1
    nkey = "pressure" if L.pressure is not None else "normal_jump"
    tkey = "shear" if L.shear is not None else "tangential_jump"
    normal = getattr(L, nkey)
    tang = getattr(L, tkey)
    tang_sets = None
    if tang is not None:
        if len(tang) % nt:
            raise SceneError(f"load.{tkey}", tang, f"needs {nt} entries per load in a {dim}D cell")
        tang_sets = [tuple(tang[i:i + nt]) for i in range(0, len(tang), nt)]
    n = max(len(normal), len(tang_sets or [()]))
    if tang_sets is not None and 1 < len(normal) != len(tang_sets) > 1:
        raise SceneError(f"load.{tkey}", tang, f"makes {len(tang_sets)} loads but load.{nkey} has "
                         f"{len(normal)}; sweeps need equal lengths or length 1")
    ms = L.macro_strain
    if ms is not None and len(ms) != (1 if dim == 2 else 3):
        raise SceneError("load.macro_strain", ms, f"needs {1 if dim == 2 else 3} entries in a {dim}D cell")
    out = []
    for k in range(n):
        nv = normal[k if len(normal) > 1 else 0]
        tv = tang_sets[k if len(tang_sets) > 1 else 0] if tang_sets else None
        out.append(dict(pressure=nv if L.pressure is not None else None,
                        normal_jump=nv if L.normal_jump is not None else None,
                        shear=tv if L.shear is not None else None,
                        tangential_jump=tv if L.tangential_jump is not None else None,
                        macro_strain=ms))
    return out


def effects(scene: CellScene) -> tuple[str, ...]:
    """The terms assembled (geometric_only: only the surface integrals)."""
    if scene.contact.geometric_only:
        return ("contact_surface_coefficients",)
    out = ["elasticity", "exact_normal_contact" if scene.contact.enforcement == "exact" else "normal_contact"]
    if scene.contact.gap.kind != "none" or small_slope(scene.geometry):
        out.append("gap")
    if scene.contact.friction != "none":
        out.append(f"{scene.contact.friction}_friction")
    L = scene.load
    assert L is not None  # required unless contact.geometric_only (CellScene.check)
    out.append("pressure_load" if L.pressure is not None else "prescribed_normal_jump")
    if L.shear is not None and any(v != 0 for v in L.shear):
        out.append("shear_load")
    if L.tangential_jump is not None:
        out.append("prescribed_tangential_jump")
    if L.macro_strain is not None and any(v != 0 for v in L.macro_strain):
        out.append("macro_strain")
    return tuple(out)


