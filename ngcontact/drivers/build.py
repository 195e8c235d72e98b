"""Scene descriptions -> model objects: the one translator of the package.

The scene layer only describes (frozen dataclasses, validated on load); this module turns its sections
into the objects the model code takes.  Each kind's driver calls these instead of building its own copies.
"""
from __future__ import annotations

import functools
import hashlib
import json
import math
import os
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ngcontact.cell.cell_solver import CellSolver
from ngcontact.cell.coefficients import direction_bundle
from ngcontact.cell.fe.cell_problem import CellLoad, CellModel, CellProblem, cell_load
from ngcontact.cell.fe.edge_grading import LEVELS_PER_STEP, MAX_STEPS, RATIO, graded_flat_cell
from ngcontact.cell.fe.fe_cell import FECell
from ngcontact.cell.spectral.spectral_solver import SpectralCellSolver
from ngcontact.coupling import cell_law
from ngcontact.drivers.cell_gap import gap_cf, gap_samples, map_heights
from ngcontact.drivers.contact_edge_refiner import edge_refiner, scene_sizes
from ngcontact.drivers.mirror_symmetry import quarter, symmetry_choice
from ngcontact.drivers.scene_laws import elastic_law
from ngcontact.errors import SceneError
from ngcontact.laws import homogenized as il
from ngcontact.laws.friction import FRICTION_LAWS, FrictionLaw
from ngcontact.solvers.linear_solver import LinearSolver
from ngcontact.cell.spectral.layered_cell import Layer, SpectralCell
from ngcontact.cell.spectral_start import SpectralStart
from ngcontact.geometry.profile_registry import PROFILES
from ngcontact.scene.cell_geometry import small_slope
from ngcontact.scene.cell_method import SymmetryChoice
from ngcontact.scene.cell_scene import CellScene, check_fe, has_twin, load_states, spectral_grid
from ngcontact.scene.spectral_grid import DEFAULT_REFINEMENT_POINTS, MAX_SPECTRAL_POINTS
from ngcontact.scene.loader import as_dict, load_with_contact
from ngcontact.scene.schema import replaced
from ngcontact.scene.sections import resolve


def cell_loads(scene: CellScene) -> list[CellLoad]:
    """The sweep of cell loads a cell scene's ``[load]`` section describes."""
    return [cell_load(scene.geometry.dim, **state) for state in load_states(scene)]


def cell_key(cell_scene) -> str:
    """SHA-256 of the validated cell scene and the data files it names."""
    h = hashlib.sha256()
    h.update(cell_law.CACHE_VERSION.encode())
    h.update(json.dumps(as_dict(cell_scene), sort_keys=True, default=str).encode())
    for rel in (getattr(cell_scene.geometry, "file", None), getattr(cell_scene.contact.gap, "file", None)):
        if rel:
            with open(resolve(cell_scene, rel), "rb") as fh:
                h.update(fh.read())
    return h.hexdigest()


def cell_scene_of(path: str, *, key: str, overrides: dict | None = None, method: str | None = None,
                  discretization: dict | None = None) -> CellScene:
    """The cell scene file ``path`` with ``[contact]`` overrides, another ``discretization.method`` and other
    ``[discretization]`` keys if given (:func:`~ngcontact.scene.loader.load_with_contact`)."""
    cell_scene = load_with_contact(path, overrides, method, discretization)
    if cell_scene.kind != "cell":
        raise SceneError(key, path, f"names a {cell_scene.kind!r} scene; a 'cell' scene is needed")
    return with_symmetry(cell_scene)


def with_symmetry(scene: CellScene) -> CellScene:
    """The scene with its derived field ``symmetry_choice``: whether its FE cell is the mirror-symmetric
    quarter (:func:`~ngcontact.drivers.mirror_symmetry.symmetry_choice`, which samples the gap), decided once
    where the drivers take a cell scene in (:func:`cell_scene_of`, :func:`ngcontact.drivers.run_cell.run`, a
    scene handed to :func:`ngcontact.drivers.cell_scene_law.cell_law`); a scene that has it is returned as it
    is.  A scene without it is decided where it is meshed
    (:func:`~ngcontact.drivers.mirror_symmetry.quarter`), alike."""
    if scene.symmetry_choice is not None:
        return scene
    return scene_with(scene, symmetry_choice=symmetry_choice(scene))


def cell_bundle_arrays(cell_scene: CellScene, cache_dir: str | None = None) -> tuple[dict, bool]:
    """``{"w", "n", "g"}`` of the cell's direction bundle (cached) and whether it came from the cache."""
    def compute() -> dict:
        b = direction_bundle(build_cell(cell_scene), kn=cell_scene.contact.k_n, gap=gap_cf(cell_scene))
        return {"w": b.w, "n": b.n, "g": b.g}
    return cell_law.cached_bundle_arrays(cell_key(cell_scene), compute, cache_dir)


def law_from_cell(path: str, *, dim: int, linear: bool = False, length_unit: float = 1.0,
                  cache_dir: str | None = None, overrides: dict | None = None):
    """Normal law from the cell scene file ``path`` and a description for the report.

    Parameters
    ----------
    path
        A scene file of kind ``cell``.
    dim
        Dimension of the macro frame (2 for plane strain and axisymmetry).
    linear
        Return its linearization :class:`~ngcontact.laws.homogenized.LinearLaw`
        (``K0`` and the gap forces of eq. 34) instead of the bundle.
    length_unit, cache_dir
        See :mod:`ngcontact.coupling.cell_law`.
    overrides
        Keys of the cell's ``[contact]`` section replaced (the macro scene's
        ``interface.cell_*``).
    """
    cell_scene = cell_scene_of(path, key="interface.cell", overrides=overrides)
    arrays, cached = cell_bundle_arrays(cell_scene, cache_dir)
    law = cell_law.bundle_law(arrays, dim=dim, length_unit=length_unit)
    K = law.matrix()
    info = {"cell_scene": os.path.abspath(path), "cached": cached, "directions": len(law.weights),
            "K0": K.tolist(), "key": cell_key(cell_scene), "cell_overrides": dict(overrides or {})}
    if linear:
        if dim == 3:
            raise SceneError("interface.law", "linear", "a linear law from a cell is available in 2D and "
                             "axisymmetry; use the bundle in 3D")
        return il.linearized(law), info
    return law, info


def law_from_file(path: str, form: str, *, dim: int) -> tuple[il.NormalLaw, dict]:
    """Normal law of form ``form`` from a law file of ``ngcontact export --format json`` and its description.

    A bundle of a 3D cell under a 2D macro frame is projected as in
    :func:`ngcontact.coupling.cell_law.bundle_law`.
    """
    from ngcontact.scene import law_file
    contents = law_file.read(path)
    try:
        law = law_file.normal_law_of(contents, form)
    except ValueError as exc:
        raise SceneError("interface.law_file_form", form, str(exc)) from None
    if isinstance(law, il.BundleLaw):
        n = len(law.directions[0])
        if n < dim:
            raise SceneError("interface.law_file", path, f"its bundle has {n} components per direction; "
                             f"this setting needs {dim}")
        if n > dim:
            law = cell_law.bundle_law({"w": law.weights, "n": law.directions, "g": law.g}, dim=dim)
    with open(path, "rb") as fh:
        digest = hashlib.sha256(fh.read()).hexdigest()
    return law, {"law_file": os.path.abspath(path), "form": form, "sha256": digest}


def friction_from_cell(path: str, *, width: float, overrides: dict | None = None,
                       cache_dir: str | None = None) -> tuple[il.Friction, dict]:
    """The homogenized friction (paper eqs. 42-43) of the cell scene file ``path`` and its description.

    ``width``: the macro Huber width.  See
    :func:`ngcontact.coupling.cell_law.friction_from_bundle`.
    """
    cell_scene = cell_scene_of(path, key="interface.friction", overrides=overrides)
    c = cell_scene.contact
    micro = micro_friction(c)
    if micro is None:
        raise SceneError("interface.friction", "from_cell", f"the cell {path!r} has no friction")
    arrays, _ = cell_bundle_arrays(cell_scene, cache_dir)
    assert c.k_n is not None  # set by CellScene.check (exact contact: its default scale)
    values = cell_law.friction_from_bundle(arrays, k_n=c.k_n, friction=micro)
    info = {"source": "cell", "cell_scene": os.path.abspath(path), "micro_friction": c.friction,
            "micro_mu": c.mu, "micro_G": c.G, "mu0": values["mu0"], "G0": values["G0"], "huber_width": width,
            "equations": "paper eqs. 42-43", "cell_overrides": dict(overrides or {})}
    return il.Friction(mu=values["mu0"], threshold=values["G0"], width=width), info


def build_cell(scene, maxh=None, interface_maxh=None, order=None):
    """Mesh the cell of ``scene.geometry`` (mesh sizes may be overridden)."""
    g, d = scene.geometry, scene.discretization
    maxh = maxh or d.maxh
    ih = interface_maxh or d.interface_maxh
    order = order or d.order
    kind = PROFILES[g.profile]
    file = resolve(scene, g.file) if kind.reads_file else None
    if g.dim == 3:
        from ngcontact.geometry import cell3d
        if kind.heights is not None and not small_slope(g):    # a free-form surface, meshed as it is
            return cell3d.surface_cell(kind.heights(g, file), period=g.period, h_rough=g.h_rough,
                                       h_counter=g.h_counter, maxh=maxh, interface_maxh=ih,
                                       order=order)
        if kind.solid is None:  # flat, or a small-slope profile carried by the gap; its quarter where symmetric
            return cell3d.flat_cell3d(g.period, g.h_rough, g.h_counter, maxh=maxh, interface_maxh=ih,
                                      symmetric=quarter(scene))
        return kind.solid(g, maxh=maxh, interface_maxh=ih)
    from ngcontact.geometry import profiles as pr
    assert kind.profile is not None  # every 2D profile has its builder
    prof = kind.profile(g, file)
    return pr.profile_cell(prof, arrangement=g.arrangement, h_rough=g.h_rough, h_counter=g.h_counter,
                           maxh=maxh, interface_maxh=ih, order=order)


def cell_solver(scene: CellScene) -> CellSolver:
    """The cell of a cell scene behind the cell protocol (:mod:`ngcontact.cell.cell_solver`): its
    ``discretization.method`` chooses the implementation (:data:`CELL_METHODS`)."""
    return CELL_METHODS[scene.discretization.method](scene)


def fe_cell(scene: CellScene) -> FECell:
    """The FE cell of a scene: mesh, problem (built on first solve), variants, graded meshes and their predictor
    (flat 2D frictionless: edge_grading), the contact edge's refiner where it has one (contact_edge_refiner)."""
    d = scene.discretization
    cell, model = build_cell(scene, **scene_sizes(scene)), model_of(scene)     # contact_edge_refiner.bulk_maxh
    graded = h0 = predictor = None
    if gradable(scene):
        g = scene.geometry
        h0 = d.interface_maxh or d.maxh
        finest = h0 * RATIO ** (MAX_STEPS * LEVELS_PER_STEP)
        # one twin for every load and level, as fine as the finest grading asks (grid-bound), built on demand
        predictor = functools.cache(lambda: predictor_twin(scene, finest))

        def graded(vertices, order):
            mesh = graded_flat_cell(g.period, g.h_rough, g.h_counter, maxh=d.maxh, interface_maxh=h0, order=order,
                                    vertices=vertices)
            return cell_problem(scene, mesh, replace(model, order=order), predictor=predictor())
    friction = model.friction            # the whole surface's eqs. 42-43 take a threshold fixed in advance
    threshold = None if friction is None or friction.couples_to_pressure else friction.threshold(None)
    return FECell(cell, model, lambda: cell_problem(scene, cell, model), threshold=threshold, graded=graded,
                  h0=h0, predictor=predictor, variant=lambda **changes: fe_variant(scene, **changes),
                  interface_maxh=d.interface_maxh or d.maxh, twin=share_twin(scene),
                  refiner=edge_refiner(scene, model, cell_problem, spectral_cell), budget=d.budget_dofs,
                  refine_default=d.estimate == "auto")


#: the spectral twin's grid on which an FE cell's penalty share is measured: it resolves the contact edges
SHARE_GRID = {2: 16384, 3: 256}


def share_twin(scene: CellScene) -> Callable[[], SpectralCellSolver] | None:
    """``() -> `` the spectral cell of an FE cell's small-slope model on :data:`SHARE_GRID` (the penalty's
    share), where it has one: the penalty on a flat interface, frictionless, isotropic bodies."""
    isotropic = all(scene.materials[m].C is None for m in (scene.bodies.rough, scene.bodies.counter))
    if not has_twin(scene) or scene.contact.friction != "none" or not isotropic:
        return None
    heights = map_heights(scene)
    grid = max(SHARE_GRID[scene.geometry.dim], spectral_grid(scene, None if heights is None else heights.shape))
    return lambda: spectral_variant(scene, grid)


def scene_with(scene: CellScene, **sections) -> CellScene:
    """``scene`` with these sections (or derived fields) replaced, in the folder of the scene file (its data
    files' base)."""
    out = replace(scene, **sections)
    object.__setattr__(out, "base_dir", getattr(scene, "base_dir", "."))
    return out


def gradable(scene: CellScene) -> bool:
    """Whether an FE cell refines by meshes graded towards its contact edges: a flat 2D interface (the edges
    are points on a line) and no friction (every load is solved afresh on its own mesh)."""
    g = scene.geometry
    return g.dim == 2 and PROFILES[g.profile].flat and scene.contact.friction == "none"


#: the keys of a variant of a cell scene and their sections
VARIED = {"order": "discretization", "interface_maxh": "discretization", "enforcement": "contact", "k_n": "contact"}


def fe_variant(scene: CellScene, **changes) -> FECell | None:
    """The FE cell of ``scene`` with the :data:`VARIED` keys changed, without its tolerance; ``None`` where
    the scene's checks (:func:`~ngcontact.scene.cell_scene.check_fe`) refuse the change."""
    sections = {name: getattr(scene, name) for name in set(VARIED.values())}
    for key, value in changes.items():
        sections[VARIED[key]] = replaced(sections[VARIED[key]], **{key: value})
    sections["discretization"] = replaced(sections["discretization"], tolerance=None)
    varied = scene_with(scene, **sections)
    try:
        if not varied.contact.geometric_only:   # a scene without a solve skips the solve's checks (CellScene)
            check_fe(varied)
    except SceneError:
        return None
    return fe_cell(varied)


def spectral_cell_solver(scene: CellScene) -> SpectralCellSolver:
    """The spectral cell of a small-slope scene, with the recipe of its finer grids (refinement)."""
    dim = scene.geometry.dim
    return SpectralCellSolver(spectral_cell(scene), make_cell=lambda n: spectral_cell(scene, grid=n),
                              max_points=MAX_SPECTRAL_POINTS[dim], default_max_points=DEFAULT_REFINEMENT_POINTS[dim],
                              variant=lambda grid, **changes: spectral_variant(scene, grid, **changes),
                              refine_default=scene.discretization.estimate == "auto")


def spectral_variant(scene: CellScene, grid: int, **contact) -> SpectralCellSolver:
    """The spectral cell of ``scene`` on ``grid`` with the ``[contact]`` keys ``contact`` changed (its
    enforcement, its penalty): the same discretization, another interface model."""
    varied = scene_with(scene, contact=replace(scene.contact, **contact))
    return SpectralCellSolver(spectral_cell(varied, grid=grid),
                              variant=lambda grid, **more: spectral_variant(varied, grid, **more))


def cell_facts(scene: CellScene) -> dict[str, float]:
    """What a cell scene's model and discretization assume, as numbers for the accuracy verdict
    (:func:`ngcontact.cell.admissibility.cell_checks`): the rms slope of a small-slope cell's gap (flat
    interface, roughness in the gap; on the spectral grid of the scene), and for the FE cell of a height map
    its interface element size over the map's spacing."""
    from ngcontact.cell.admissibility import gap_slopes
    from ngcontact.scene.cell_scene import flat_interface
    g, d = scene.geometry, scene.discretization
    facts: dict[str, float] = {}
    if not flat_interface(g) or (scene.contact.gap.kind == "none" and not small_slope(g)):
        return facts
    heights = map_heights(scene)
    grid = spectral_grid(scene, None if heights is None else heights.shape)
    facts["rms_slope"] = gap_slopes(gap_samples(scene, grid, heights), g.period)[0]
    if heights is not None and d.method == "fe":
        spacing = g.period / (max(heights.shape) - 1)
        facts["interface_resolution"] = float((d.interface_maxh or d.maxh) / spacing)
    return facts


#: the cell protocol's implementations by ``discretization.method``
CELL_METHODS: dict[str, Callable[[CellScene], CellSolver]] = {"fe": fe_cell, "spectral": spectral_cell_solver}


def recovery_cell_problem(cell_path: str, *, key: str, overrides: dict | None = None,
                    method: str | None = None, discretization: dict | None = None) -> tuple[CellScene, CellProblem]:
    """:func:`recovery_cell_scene` and its meshed FE :class:`CellProblem` with the macro strain term."""
    cs = recovery_cell_scene(cell_path, key=key, overrides=overrides, method=method, discretization=discretization)
    return cs, cell_problem(cs, model=replace(model_of(cs), macro_strain=True))


def recovery_cell_scene(cell_path: str, *, key: str, overrides: dict | None = None, method: str | None = None,
                        discretization: dict | None = None) -> CellScene:
    """Cell scene (with ``[contact]`` overrides, ``method = "fe"`` for a spectral scene; a cell whose
    ``method = "auto"`` chose the spectral cell is solved by fe) of the FE cell for what only it gives: the
    micro stresses of the strength recovery (paper eqs. 74-78) and the shear response, over the cell's period
    (:data:`RECOVERY_PERIOD`); its problem has the scene's ``[solver]`` settings (:func:`cell_problem`)."""
    cs = cell_scene_of(cell_path, key=key, overrides=overrides, method=method, discretization=discretization)
    choice = cs.method_choice
    if method is None and choice is not None and choice.automatic and choice.method != "fe":
        # an "auto" cell is solved by the cell the recovery needs (ngcontact.scene.cell_method)
        cs = cell_scene_of(cell_path, key=key, overrides=overrides, method="fe", discretization=discretization)
    if cs.contact.geometric_only:
        raise SceneError(key, cell_path, "the cell scene has contact.geometric_only = true; the recovery "
                         "solves the cell, so it needs a contact model and a [load] section")
    if CELL_METHODS[cs.discretization.method] is not fe_cell:
        raise SceneError(key, cell_path, f"the cell scene is solved by discretization.method = "
                         f"{cs.discretization.method!r}; the strength recovery needs the body stresses and the macro "
                         "strain term of the FE cell: use a cell scene with method = 'fe'")
    return scene_with(cs, symmetry_choice=SymmetryChoice(False, RECOVERY_PERIOD, cs.discretization.symmetry))


#: why the recovery's cell is its period whatever ``discretization.symmetry``: the quarter's mirror faces (zero
#: normal displacement) would hold its tangential loads wrongly
RECOVERY_PERIOD = "the recovery's correctors and the shear response load the cell tangentially"

#: the FE cell problem's start of first loads for each ``solver.start`` of a scene (``None``: its default)
FE_START = {"auto": None, "spectral": "predictor", "rigid": "rigid", "closed": "closed"}


def cell_problem(scene: CellScene, cell=None, model: CellModel | None = None,
                 predictor: SpectralStart | None = None) -> CellProblem:
    """The FE cell problem of a cell scene: its mesh (``cell``, default :func:`build_cell`), its model
    (default :func:`model_of`), the ``[solver]`` settings, and the spectral predictor that starts its first
    loads where it has one (``predictor``, built by the caller for several meshes of one cell; default
    :func:`predictor_twin` of the scene)."""
    s = scene.solver
    return CellProblem(build_cell(scene) if cell is None else cell, model_of(scene) if model is None else model,
                       rtol=s.rtol, atol=s.atol, max_iter=s.max_iter, inverse=s.inverse,
                       linear=linear_solver(scene), coulomb=s.coulomb,
                       predictor=predictor_twin(scene) if predictor is None else predictor,
                       start=FE_START[s.start])


def linear_solver(scene) -> LinearSolver:
    """The tangent solves of a scene's Newton iterations: ``solver.linear``, ``iterative_from``, ``inverse``."""
    s = scene.solver
    return LinearSolver(policy=s.linear, inverse=s.inverse, threshold=s.iterative_from)


def spectral_cell(scene: CellScene, grid: int | None = None, friction: bool = True,
                  tol: float | None = None, heights: np.ndarray | None = None) -> SpectralCell:
    """The spectral cell (:mod:`ngcontact.cell.spectral.layered_cell`) of a small-slope cell scene.

    ``grid``: points per direction instead of the scene's (a gap given by a formula); ``friction = False``:
    the cell without the scene's friction; ``tol``: its solver's tolerance instead of ``solver.rtol``;
    ``heights``: the profile's height map when the caller has it already (:func:`map_heights`).
    """
    g, c, s = scene.geometry, scene.contact, scene.solver
    if heights is None:
        heights = map_heights(scene)
    if grid is None:
        grid = spectral_grid(scene, None if heights is None else heights.shape)

    def layer(name, h):
        m = scene.materials[name]
        # set: the scene layer requires isotropic E and nu of both bodies for the spectral cell
        assert m.E is not None and m.nu is not None
        return Layer(E=m.E, nu=m.nu, h=h)
    assert c.k_n is not None  # set by CellScene.check (exact contact: its default scale)
    return SpectralCell(dim=g.dim, period=g.period, grid=grid, rough=layer(scene.bodies.rough, g.h_rough),
                        counter=layer(scene.bodies.counter, g.h_counter), gap=gap_samples(scene, grid, heights),
                        k_n=c.k_n, enforcement=c.enforcement, tol=s.rtol if tol is None else tol,
                        max_iter=s.cg_max_iter, friction=micro_friction(c) if friction else None)


#: grid points of the spectral predictor's twin per interface element size (at least), and its bounds
TWIN_POINTS_PER_ELEMENT = 4
TWIN_GRID = {2: (64, 8192), 3: (64, 512)}
#: tolerance of the twin's solve: only its contact set is used, so it need not reach ``solver.rtol``
TWIN_RTOL = 1e-8


def predictor_twin(scene: CellScene, interface_maxh: float | None = None) -> SpectralStart | None:
    """The predictor of an FE cell's first loads from its spectral twin's contact set
    (:class:`ngcontact.cell.spectral_start.SpectralStart`), or ``None`` where there is none.

    A twin exists for the penalty on a cell the spectral cell can solve (the small-slope model:
    :func:`ngcontact.scene.cell_scene.has_twin`) unless ``solver.start`` asks for another start; it is
    frictionless and solves to ``TWIN_RTOL``.  Its grid is the power of two with
    ``TWIN_POINTS_PER_ELEMENT`` points per interface element size (``interface_maxh``, else the scene's),
    and no fewer than a height map's own samples, within ``TWIN_GRID`` (a map finer than the upper bound is
    resampled bilinearly, as the FE cell interpolates it).
    """
    from ngcontact.scene.cell_scene import has_twin
    if scene.solver.start in ("rigid", "closed") or not has_twin(scene):
        return None
    g, d = scene.geometry, scene.discretization
    h = interface_maxh or d.interface_maxh or d.maxh
    low, high = TWIN_GRID[g.dim]
    grid = 2 ** math.ceil(math.log2(TWIN_POINTS_PER_ELEMENT * g.period / h))
    heights = map_heights(scene)
    if heights is not None:
        grid = max(grid, spectral_grid(scene, heights.shape))
    return SpectralStart(spectral_cell(scene, grid=int(min(max(grid, low), high)), friction=False,
                                       tol=TWIN_RTOL, heights=heights))


def micro_friction(contact) -> FrictionLaw | None:
    """The micro friction of a cell scene's ``[contact]`` section (``None`` without friction): the law of
    :data:`ngcontact.laws.friction.FRICTION_LAWS` of its name, built from the section's ``parameters``."""
    if contact.friction == "none":
        return None
    law = FRICTION_LAWS[contact.friction]
    return law(**{key: getattr(contact, key) for key in law.parameters})


def model_of(scene) -> CellModel:
    """The FE cell's model of a scene; exact contact in 3D at order >= 2 on a linear trace (its module)."""
    c, order, ms = scene.contact, scene.discretization.order, getattr(scene.load, "macro_strain", None) is not None
    return CellModel(rough=elastic_law(scene.materials[scene.bodies.rough]),
                     counter=elastic_law(scene.materials[scene.bodies.counter]),
                     k_n=c.k_n, gap=gap_cf(scene), friction=micro_friction(c), order=order,
                     macro_strain=ms, coulomb_rtol=scene.solver.coulomb_rtol,
                     coulomb_max_iter=scene.solver.coulomb_max_iter, enforcement=c.enforcement,
                     linear_trace=c.enforcement == "exact" and scene.geometry.dim == 3 and order > 1)
