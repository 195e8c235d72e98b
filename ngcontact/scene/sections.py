"""Sections shared by every scene kind.

* ``[materials.NAME]``: ``E`` and ``nu`` (isotropic) or ``C`` (6x6 Voigt
  matrix), optional ultimate stress ``sigma_u``;
* ``[discretization]``: polynomial order and mesh size;
* ``[solver]``: Newton tolerances and limits.

Descriptions only: the drivers turn them into model objects
(:func:`ngcontact.drivers.scene_laws.elastic_law`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

from ngcontact.errors import MISSING, SceneError
from ngcontact.fem import materials as _materials
from ngcontact.scene import magnitudes
from ngcontact.scene.mesh_size import MAX_ELEMENTS
from ngcontact.scene.schema import MAX_ORDER, at_least, closed_interval, given_field, open_interval, param, positive


@dataclass(frozen=True, kw_only=True)
class MaterialSpec:
    """Elastic material: isotropic ``(E, nu)`` or anisotropic ``C``."""

    E: float | None = param(None, doc="Young's modulus (isotropic); within [1e-20, 1e20] (a stress unit's range) and "
                            "at most 1e10 times the other body's (double precision), each load at most E of the "
                            "softer body (a strain of 1): ngcontact.scene.magnitudes", units="Pa", check=positive())
    nu: float | None = param(None, doc="Poisson's ratio (isotropic)", check=open_interval(-1, 0.5))
    C: tuple[tuple[float, ...], ...] | None = param(
        None, doc="6x6 Voigt stiffness matrix, order 11,22,33,23,13,12 with engineering shear strains",
        units="Pa", allowed="6 rows of 6 numbers, symmetric positive definite")
    sigma_u: float | None = param(None, doc="ultimate stress for the strength check", units="Pa",
                                  check=positive())

    def check(self, path: str) -> None:
        iso = self.E is not None or self.nu is not None
        if iso and self.C is not None:
            raise SceneError(path + ".C", self.C, "give either E and nu or C, not both")
        if self.C is None:
            if self.E is None:
                raise SceneError(path + ".E", MISSING, "required (or give C); a number > 0")
            if self.nu is None:
                raise SceneError(path + ".nu", MISSING, "required (or give C); a number in (-1, 0.5)")
        else:
            try:
                _materials.anisotropic(self.C)
            except ValueError as exc:
                raise SceneError(path + ".C", self.C, str(exc).replace("C ", "", 1)) from None
        magnitudes.check_modulus(self, path)

@dataclass(frozen=True, kw_only=True)
class Discretization:
    """Finite element discretization."""

    order: int = param(2, doc="polynomial order of the displacement", check=closed_interval(1, MAX_ORDER))
    maxh: float = param(0.1, doc="global mesh size", units="m", check=positive())
    interface_maxh: float | None = param(None, doc="mesh size on the interface (default: maxh)",
                                         units="m", check=positive())
    max_elements: int = param(MAX_ELEMENTS, doc="refuse a scene whose mesh is estimated to have more elements "
                              "(a guard against sizes that hang the mesher)", check=at_least(1))


#: Largest spectral grid per direction (2D; in 3D the number of points bounds it, see scene.cell_scene.check_spectral).
MAX_GRID = 2 ** 24


@dataclass(frozen=True, kw_only=True)
class CellDiscretization(Discretization):
    """Finite element discretization of a cell, with accuracy on request."""

    tolerance: float | None = param(
        None, doc="refine until the estimated error of each load's headline quantities is at most this, each "
        "in its measure: the contact fraction absolute, the mean closure (the closure of the pressure-closure "
        "table at the load's pressure) and the normal effective stiffness relative to their value, the "
        "coefficients of paper eq. 34 on the real contact set (k_n, k_t, k_nt, g_n, g_t, G_n, G_t) relative to "
        "the largest of their group (stiffnesses, gap terms, thresholds) on the whole contact surface, which "
        "they reach in full contact (so an entry small at a small load or zero by symmetry is judged on the "
        "scale the macro law uses it at); results.accuracy lists each with its value, absolute and relative "
        "error, measure and scale.  Method 'spectral' estimates all of them and holds them to the tolerance, "
        "a coefficient zero on every grid (flat interface) not estimated; in 2D the effective stiffness (of the "
        "contact set with its edges located between points: as fast as they converge) up to three grids "
        "beyond the one where the others meet it (missed there: a "
        "stated tolerance ends the run, exit 3, the default one gives accuracy.met = false with a warning), in "
        "3D reported with its estimate, counted = false; the graded FE cell and the FE cell refined by "
        "interface_maxh hold all of them (the graded one grades further where a quantity misses by its contact "
        "edges' share, else raises the order).  "
        "Method 'fe' grades the interface mesh "
        "towards the contact edges and "
        "raises the order on the finest (2D frictionless cells with a flat interface), any other FE cell (3D, "
        "curved, frictional) halves interface_maxh level by level (at least three levels, the estimate from "
        "the observed rate, up to 1e6 dofs in 2D and 4e5 in 3D; a flat 3D cell with exact contact and no "
        "friction refines along its spectral twin's contact edges instead, to a tenth of the narrowest patch width "
        "and halved per level (its bodies at maxh 0.3 periods unless maxh is set), reports from three such "
        "levels on the contact fraction extrapolated in that size from the last three, its estimate the grid "
        "convergence index, the last level's own value as loads[k].contact_fraction_last_level, and does not "
        "stop before; the mean closure, the normal effective stiffness and the eq. 34 coefficients are estimated "
        "by their distance from the twin on 2048 x 2048 points times 1.25 plus the twin's own first-order tail, "
        "and where after three such levels the stiffness alone misses the tolerance (its error is made in the "
        "mesh graded away from the edge, not at it) the next levels keep the last edge size and multiply Netgen's "
        "grading 0.3 by 1/sqrt(2) per level), "
        "method 'spectral' doubles the grid's points "
        "per direction from discretization.grid (a height map's or random surface's samples are interpolated "
        "bilinearly, the surface the FE cell meshes too; at least four grids, the estimate the geometric tail "
        "of the last three differences, at their observed rate where their ratios agree (Richardson), else "
        "guarded; in 2D, once the contact edges are located by their fitted quartic, a stated tolerance's stop "
        "waits for three such grids, whose differences alone also estimate the contact fraction and "
        "coefficients; in 2D a grid whose estimate may stop the refinement, and the largest, is also solved "
        "half a step over, every estimate at least the change between the two); the report "
        "gives the estimate per load and the mesh or grid history, and a tolerance out of "
        "reach ends the run (exit 3); default: 0.01 (accuracy.tolerance_from = 'default'): the spectral cell "
        "is refined to it up to 65536 grid points in 2D and 512 x 512 in 3D and, out of reach there, reports "
        "its finest grid with accuracy.met = false and a warning; the FE cell first estimates its own answer's "
        "error by the same sweep one order more on the same mesh (the change times 4: the saturation assumption "
        "that order p + 1 keeps at most 3/4 of the error of order p; one more sweep on about ((p + 1) / p)^dim "
        "times the unknowns; every headline quantity it reports) and reports it where that meets 0.01, else is "
        "refined towards 0.01 as a stated tolerance refines it (a graded cell only where the contact fraction or "
        "the mean closure misses it; a miss of the effective stiffness or an eq. 34 coefficient alone is "
        "reported with accuracy.met = false and a warning), within "
        "discretization.budget_dofs; a budget spent before 0.01 is met reports the "
        "finest answer with accuracy.met = false, one warning naming the estimate, the budget and the dofs "
        "meeting 0.01 would take at the observed rate (accuracy.shortfall), and exit status 0",
        check=open_interval(0, 1))
    estimate: str = param("auto", doc="without a tolerance: auto holds the sweep to the default tolerance as "
                          "discretization.tolerance says (the spectral cell refined; the FE cell estimated by one "
                          "order more on its own mesh, and refined within discretization.budget_dofs where that "
                          "misses it); estimate estimates the scene's own answer and does not refine (the FE cell by "
                          "one order more on its mesh: two sweeps; the spectral cell from three coarser grids, "
                          "each with half the points per direction of the next), a miss reported with "
                          "accuracy.met = false and a warning (for runs not about accuracy: each level of "
                          "ngcontact study accuracy); off skips the estimate (no second solve), and the report says "
                          "'not estimated (discretization.estimate = off)'; no effect with a tolerance",
                          choices=("auto", "estimate", "off"))
    budget_dofs: int | None = param(None, doc="FE cell without a tolerance, estimate = 'auto': the most unknowns "
                                    "of a discretization its refinement towards the default tolerance solves (a "
                                    "finer interface mesh or graded mesh, or a higher order, beyond it is not "
                                    "solved); default 120000 in 2D, 40000 in 3D.  A stated tolerance refines up "
                                    "to 1e6 dofs in 2D and 4e5 in 3D whatever this says; no effect on a spectral "
                                    "cell (its default refinement has its own bound)", check=at_least(1000))
    method: str = param("auto", doc="which cell solves the scene: fe, finite elements on a mesh of the cell (any "
                        "profile; writes the bodies' fields and stresses); spectral, the small-slope cell (flat "
                        "interface, the roughness in the initial gap) as two periodic layers solved with FFTs on a "
                        "uniform grid of the interface; auto (the default), chosen once when the scene is checked "
                        "and stated in the report (results.accuracy.method, its reason in one sentence): spectral "
                        "for a small-slope cell (geometry.profile 'flat' or 'flat3d', or 'bisinusoid', "
                        "'height_map', 'measured_spectrum' or 'self_affine' with arrangement = 'summit') that sets "
                        "no key only the FE cell reads (discretization.order, maxh, interface_maxh, max_elements, "
                        "budget_dofs, symmetry; solver.atol, max_iter, inverse, linear, iterative_from, start, "
                        "coulomb, "
                        "coulomb_rtol, coulomb_max_iter; contact.w with exact friction, which the spectral cell "
                        "solves without a width) and no tolerance below 10 x solver.rtol, else fe; a scene that sets "
                        "discretization.grid is spectral (refused for a cell that is not small-slope, or beside an "
                        "FE-only key); a macro scene's strength.cell, and a two-scale loop whose friction comes "
                        "from a frictional cell, solve an auto cell by fe (they need the FE cell's stresses and "
                        "shear response)", choices=("auto", "fe", "spectral"))
    symmetry: str = param("off", doc="3D FE cell: off meshes the whole period; auto meshes the "
                          "quarter [0, P/2]^2 of a cell that is even about its mid-lines (the initial gap even in "
                          "x and in y, checked on its samples to round-off; a normal load, no in-plane macro "
                          "shear e_xy; no friction; isotropic or axis-orthotropic bodies; the flat small-slope "
                          "mesh) with zero normal displacement and zero shear traction "
                          "on its four mirror faces instead of the periodic identification: the same means over a "
                          "quarter of the unknowns; results.accuracy.symmetry states whether it was used and, if "
                          "not, why (at the same sizes the quarter is the faster cell, not the more accurate one: "
                          "docs/benchmarks.md, section scaling_3d); the cell of a strength check or of a shear "
                          "table, loaded tangentially, keeps its period; default: auto for a cell refined along its "
                          "contact edge (a flat or small-slope 3D mesh, exact contact, no friction, isotropic "
                          "bodies: its extrapolated estimate is checked on the quarter), off for any other",
                          choices=("auto", "off"))
    grid: int | None = param(None, doc="spectral (set with method = 'auto', it asks for the spectral cell): grid "
                             "points per period and direction of the first grid, "
                             "which refinement to the tolerance (the scene's or the default) doubles (default: a "
                             "height map's own grid, else 1024 in 2D and 256 in 3D)",
                             check=closed_interval(8, MAX_GRID))
    given: frozenset[str] = given_field()


@dataclass(frozen=True, kw_only=True)
class SolverSpec:
    """Newton solver settings and the stopping rule of the Coulomb fixed point."""

    rtol: float = param(1e-10, doc="stop when the residual falls below rtol x the first residual (spectral "
                        "cell: when the complementarity residual falls below rtol x the gap's peak-to-valley "
                        "height)", check=positive())
    atol: float = param(0.0, doc="or below this absolute residual", units="N", check=at_least(0))
    max_iter: int = param(40, doc="largest number of Newton steps", check=at_least(1))
    inverse: str = param("sparsecholesky", doc="sparse direct solver",
                         choices=("sparsecholesky", "umfpack"))
    linear: str = param("auto", doc="Newton's tangent solves (FE cells and macro problems) and the solves of "
                        "a cell's effective stiffness: direct (the "
                        "sparse direct solver of 'inverse'), iterative (conjugate gradients preconditioned by "
                        "BDDC with a vertex wirebasket), auto (3D problems iterative from iterative_from free dofs on, "
                        "2D direct); the report "
                        "states the choice and the CG iterations", choices=("direct", "iterative", "auto"))
    iterative_from: int = param(20000, doc="free dofs from which linear = 'auto' solves a 3D problem iteratively "
                                "(about where BDDC-CG overtakes the sparse factorization at order 2)",
                                check=at_least(1))
    start: str = param("auto", doc="FE cell scenes (elsewhere no effect): start of a first load under a "
                       "prescribed pressure: spectral (the "
                       "rigid predictor moved onto the contact set of the spectral cell of the same small-slope cell; "
                       "the penalty on a flat interface only), rigid (the counter translated rigidly to carry the "
                       "pressure on a Winkler layer), closed (every point pushed into contact), auto (spectral where "
                       "the cell allows it, else rigid); with discretization.tolerance, spectral also grades each "
                       "load's first mesh towards the spectral cell's contact edges and starts every mesh from it",
                       choices=("auto", "spectral", "rigid", "closed"))
    cg_max_iter: int = param(10000, doc="spectral cell: largest number of constrained CG (frictionless) or "
                             "accelerated proximal gradient (friction) steps per load",
                             check=at_least(1))
    coulomb: str = param("newton", doc="Coulomb friction (FE cells and macro problems): newton (Newton on the "
                         "coupled equations, the threshold mu p differentiated with the pressure; non-symmetric "
                         "tangent) or fixed_point (Tresca passes with the threshold of the previous pressure, paper "
                         "Sec. 2)", choices=("newton", "fixed_point"))
    coulomb_rtol: float = param(1e-8, doc="Coulomb fixed point (macro, resolved; a penalty cell's fallback, its "
                                "Coulomb Newton stopping at rtol): stop when max |p_k - p_k-1| <= coulomb_rtol x "
                                "max p_k on the contact surface", check=positive())
    coulomb_max_iter: int = param(40, doc="Coulomb fixed point: largest number of Tresca passes", check=at_least(1))
    given: frozenset[str] = given_field()


def check_material_names(materials: dict, names: dict, path: str) -> None:
    """Every ``key -> material name`` in ``names`` must exist in ``materials``."""
    for key, name in names.items():
        if name not in materials:
            raise SceneError(f"{path}.{key}" if path else key, name,
                             "must name a material defined under [materials]: "
                             + ", ".join(sorted(materials)))




@dataclass(frozen=True, kw_only=True)
class ComputeSpec:
    """Where a batch of independent solves runs (:mod:`ngcontact.parallel.executor`); the command line's
    ``--workers`` and ``--scheduler`` take precedence."""

    scheduler: str | None = param(None, doc="address of a dask.distributed scheduler (e.g. 'tcp://10.0.0.5:8786') "
                                  "whose workers solve the batch; default: a pool of local processes")
    workers: int | None = param(None, doc="local worker processes, one NGSolve thread each (default: the cores)",
                                check=at_least(1))

    def check(self, path: str) -> None:
        if self.scheduler is not None and not self.scheduler.strip():
            raise SceneError(f"{path}.scheduler", self.scheduler, "an address such as 'tcp://host:8786', or omit it")


def base_dir_field():
    """The scene file's folder: set by the loader, not read from the file."""
    return field(default=".", init=False, repr=False, compare=False)


def resolve(scene, relpath: str) -> str:
    """Absolute path of a file named in a scene (relative to the scene file)."""
    return os.path.normpath(os.path.join(getattr(scene, "base_dir", "."), relpath))


def check_input_file(key: str, path: str, what: str, *, shown=None, missing: str | None = None,
                     max_bytes: int | None = None) -> None:
    """The file ``path`` a scene reads under ``key`` must exist and be a regular file (checked before it is opened).

    A missing file is ``missing`` (default ``no such <what>``); a directory,
    FIFO or device is named as such (``is a directory; must be a regular
    file (a <what>)``); a file larger than ``max_bytes`` is refused with its
    size.  ``shown`` is the value the message quotes (default ``path``),
    e.g. the path as the scene wrote it.
    """
    from ngcontact.geometry.tabulated import file_kind
    shown = path if shown is None else shown
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise SceneError(key, shown, missing or f"no such {what}") from None
    except OSError as err:
        raise SceneError(key, shown, f"must be a readable {what} ({err.strerror})") from None
    kind = file_kind(st.st_mode)
    if kind is not None:
        raise SceneError(key, shown, f"is {kind}; must be a regular file (a {what})")
    if max_bytes is not None and st.st_size > max_bytes:
        raise SceneError(key, shown, f"is {st.st_size} bytes; a {what} is limited to {max_bytes // 2 ** 20} MiB")


def check_supports_once(supports, comps) -> None:
    """Each component of a boundary is fixed by one ``[[supports]]`` entry only.

    A second entry for the same boundary and component was silently
    ignored; which value holds is then a guess, so the scene is refused.
    """
    seen: dict[tuple[str, str], int] = {}
    for i, s in enumerate(supports):
        for c in (() if getattr(s, "symmetry", False) else (s.components or comps)):
            j = seen.setdefault((s.boundary, c), i)
            if j != i:
                raise SceneError(f"supports[{i}]", s.boundary, f"fixes component {c!r} of boundary "
                                 f"{s.boundary!r}, which supports[{j}] fixes already; give each component "
                                 "of a boundary once")
