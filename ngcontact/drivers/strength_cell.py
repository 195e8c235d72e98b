"""The strength check's cell: its fixed-set corrector states, cached on disk and shipped for the main job.

The linear recovery (paper eqs. 72-75, :mod:`ngcontact.coupling.strength`) needs the cell's mesh and the
displacement states of the cell with its contact set held fixed at the zero load and at each unit load
(:func:`~ngcontact.coupling.strength.corrector_states`): the mesh and one factorization of the cell's
stiffness are most of its cost.  The stresses the check reads, eq. 75's ``sigma_g`` and ``Sigma_k`` at the
element points, are sampled again from the states on the mesh
(:func:`~ngcontact.coupling.strength.sampled_correctors`, the same code as after a solve): there are
several samples per element and six stress components per sample, so the samples are many times the size of
the states.

An entry holds the mesh (Netgen's ``.vol.gz``, as bytes), the states and the cell's heights and period; it
is kept as an entry of the cell-law cache (:mod:`ngcontact.coupling.cell_law`: format, package version, key
and checksum checked; a bad entry is discarded with one warning) under :func:`recovery_key`, which covers
all the entry is a function of:

* the validated cell scene and the files it names (:func:`ngcontact.drivers.build.cell_key`): the cell, its
  materials, contact, discretization and solver settings;
* the tangential stiffness ``k_t`` of the fixed set (whether the set is the gap-free part of ``S_C`` follows
  from the scene);
* the code that computes it: the modules of :data:`SOURCES`, byte for byte, the package's version,
  NGSolve's and Netgen's versions and :data:`FORMAT`.

Any change of the cell, its discretization or that code so gives another key and a computation, never a
stale entry.  An entry is looked for in the package's own data (:data:`SHIPPED`, written by
``scripts/ship_strength_cell.py`` for the main job's cell, ``geometries/femur_stem.toml``), then in the
user's cache; else the cell is meshed and solved and its entry cached.  :func:`fixed_set_correctors` says
which: ``"shipped"``, ``"cached"`` or ``"computed"``.  A cell with curved elements (a 2D profile cell of
order > 1) is never kept: a mesh file holds the straight elements only, their curvature comes from the
geometry, which is not in it.
"""
from __future__ import annotations

import hashlib
import logging
import os
import tempfile
from dataclasses import replace
from pathlib import Path

import ngsolve as ng
import netgen
import numpy as np
from netgen.meshing import Mesh as NetgenMesh

from ngcontact.cell.fe.cell_problem import CellProblem
from ngcontact.coupling import cell_law
from ngcontact.coupling import strength as S
from ngcontact.drivers.build import cell_key, cell_problem, model_of
from ngcontact.geometry.cell2d import Cell
from ngcontact.scene.cell_scene import CellScene

log = logging.getLogger(__name__)

#: the entry's layout; changed by hand when the arrays change meaning
FORMAT = "strength-states-1"
#: the arrays of an entry: the mesh file's bytes, the states (K + 1, ndof), [h_rough, h_counter, symmetric, *period]
NAMES = ("mesh", "states", "cell")
PACKAGE = Path(__file__).resolve().parents[1]
#: where the package's own entries are (scripts/ship_strength_cell.py writes them)
SHIPPED = str(PACKAGE / "data" / "strength_cells")
#: the modules (relative to the package) whose code computes an entry: those its computation runs, but the
#: scene's reading and checks (the validated scene is in the key) and :mod:`ngcontact.quiet`
SOURCES = (
    "cell/coefficients.py", "cell/fe/cell_energy.py", "cell/fe/cell_model.py", "cell/fe/cell_problem.py",
    "cell/fe/contact_quadrature.py", "cell/fe/discrete_cell.py", "cell/fe/edge_cuts.py", "cell/fe/linear_trace.py",
    "cell/fe/load_start.py", "cell/fe/measures.py", "coupling/strength.py", "drivers/build.py",
    "drivers/cell_gap.py", "drivers/mirror_symmetry.py", "drivers/scene_laws.py", "drivers/strength_cell.py",
    "fem/elasticity.py", "fem/materials.py", "fem/quadrature.py", "fem/two_body.py", "geometry/cell2d.py",
    "geometry/cell3d.py", "geometry/mesher.py", "geometry/profile_registry.py",
    "geometry/profiles.py", "geometry/tabulated.py", "laws/penalty.py", "scene/cell_geometry.py",
    "scene/cell_method.py", "scene/cell_scene.py", "solvers/linear_solver.py",
)


def source_digest() -> str:
    """SHA-256 of the modules of :data:`SOURCES` (a missing one counts as such)."""
    h = hashlib.sha256()
    for rel in SOURCES:
        try:
            data = (PACKAGE / rel).read_bytes()
        except OSError:
            data = b"(missing)"
        h.update(rel.encode() + b"\0" + hashlib.sha256(data).digest())
    return h.hexdigest()


def recovery_key(cs: CellScene, tangential_stiffness: float) -> str:
    """The key of the strength cell ``cs`` (:func:`ngcontact.drivers.build.recovery_cell_scene`) with the
    stick stiffness ``tangential_stiffness`` (module docstring)."""
    h = hashlib.sha256()
    for part in (FORMAT, cell_key(cs), repr(float(tangential_stiffness)), cell_law._package_version(),
                 ng.__version__, netgen.__version__, source_digest()):
        h.update(part.encode() + b"\0")
    return h.hexdigest()


def contact_set(problem: CellProblem):
    """The fixed contact set of the recovery: the part of ``S_C`` without gap (``None``: all of ``S_C``)."""
    if problem.gap is None:
        return None
    return ng.IfPos(problem.gap - 1e-14 * max(problem.largest_gap(), 1e-300), 0.0, 1.0)


def compute_entry(cs: CellScene, tangential_stiffness: float) -> tuple[CellProblem, np.ndarray, dict | None]:
    """The cell of ``cs`` meshed and solved: its problem, its corrector states and the arrays of its entry
    (:data:`NAMES`; ``None`` for curved elements, which a mesh file does not keep: their geometry is not in it)."""
    problem = cell_problem(cs, model=_model(cs))
    states = S.corrector_states(problem, contact_set=contact_set(problem), tangential_stiffness=tangential_stiffness)
    c = problem.cell
    if problem.mesh.GetCurveOrder() > 1:
        return problem, states, None
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cell.vol.gz")
        problem.mesh.ngmesh.Save(path)
        mesh = np.frombuffer(Path(path).read_bytes(), dtype=np.uint8)
    return problem, states, {"mesh": mesh, "states": states,
                     "cell": np.array([c.h_rough, c.h_counter, float(c.symmetric), *c.period])}


def problem_of_entry(cs: CellScene, arrays: dict) -> CellProblem:
    """The cell problem of ``cs`` on the mesh of an entry.

    Raises
    ------
    ValueError
        The mesh cannot be read, or its problem has another number of unknowns than the states.
    """
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "cell.vol.gz")
        Path(path).write_bytes(np.asarray(arrays["mesh"], dtype=np.uint8).tobytes())
        ngmesh = NetgenMesh()
        try:
            ngmesh.Load(path)
        except Exception as exc:  # netgen's NgException, not exported by a stable name
            raise ValueError(f"its mesh cannot be read ({exc})") from None
    h_rough, h_counter, symmetric, *period = (float(v) for v in arrays["cell"])
    cell = Cell(mesh=ng.Mesh(ngmesh), dim=ngmesh.dim, period=tuple(period), h_rough=h_rough,
                h_counter=h_counter, symmetric=bool(symmetric))
    problem = cell_problem(cs, cell=cell, model=_model(cs))
    if arrays["states"].shape[1] != problem.ndof:
        raise ValueError(f"{arrays['states'].shape[1]} unknowns in its states, {problem.ndof} on its mesh")
    return problem


def _model(cs: CellScene):
    return replace(model_of(cs), macro_strain=True)


def _shapes(arrays: dict) -> str | None:
    mesh, states, cell = arrays["mesh"], arrays["states"], arrays["cell"]
    if not (mesh.ndim == 1 and mesh.dtype == np.uint8 and states.ndim == 2 and cell.ndim == 1
            and len(cell) in (4, 5)):
        return f"arrays of shapes {mesh.shape}, {states.shape}, {cell.shape}"
    return None


def read_entry(key: str, cache_dir: str) -> dict | None:
    """The entry ``key`` in ``cache_dir`` (:func:`ngcontact.coupling.cell_law.read_cached`), or ``None``."""
    return cell_law.read_cached(key, NAMES, FORMAT, cache_dir, _shapes)


def write_entry(key: str, arrays: dict, cache_dir: str) -> None:
    """Write an entry (:func:`ngcontact.coupling.cell_law.write_cached`)."""
    cell_law.write_cached(key, arrays, NAMES, FORMAT, cache_dir)


def fixed_set_correctors(cs: CellScene, tangential_stiffness: float, cache_dir: str | None = None
                         ) -> tuple[CellProblem, S.Correctors, str]:
    """The cell problem of ``cs``, its correctors (eq. 75) and where its entry came from: ``"shipped"``,
    ``"cached"`` (``cache_dir``, default the cell-law cache's) or ``"computed"`` (module docstring)."""
    key = recovery_key(cs, tangential_stiffness)
    for source, where in (("shipped", SHIPPED), ("cached", cache_dir or cell_law.cache_dir_default())):
        arrays = read_entry(key, where)
        if arrays is None:
            continue
        try:
            problem = problem_of_entry(cs, arrays)
        except ValueError as exc:
            log.warning("ngcontact: the strength cell's entry %s in %s is not used (%s); recomputing it",
                        key, where, exc)
            continue
        log.info("strength cell: corrector states %s (%s)", source, key)
        return problem, S.sampled_correctors(problem, arrays["states"],
                                             tangential_stiffness=tangential_stiffness), source
    problem, states, arrays = compute_entry(cs, tangential_stiffness)
    if arrays is not None:
        write_entry(key, arrays, cache_dir or cell_law.cache_dir_default())
    return problem, S.sampled_correctors(problem, states, tangential_stiffness=tangential_stiffness), "computed"
