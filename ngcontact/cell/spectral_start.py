"""The spectral predictor: a small-slope FE cell's first load started on its spectral twin's contact set.

A small-slope cell (a flat ``S_C`` whose roughness is the initial gap
``g0``, paper eqs. 49-51 in the penalized form of eq. 65) is also the
problem the spectral cell solves on a grid with FFTs
(:mod:`ngcontact.cell.spectral.layered_cell`): the same two periodic layers, the
same penalty ``k_n``.  Its solution costs a fraction of a second and
gives, on its grid, the penetration of eq. 65 at the solution,

    s*(x) = J_n - g0 = p / k_n  (in contact),   -gamma  (open),

(``J_n`` the closure, ``p`` the pressure, ``gamma`` the elastic gap).

Why it is the start to take.  The penalized energy is piecewise quadratic:
on a fixed active set ``A = {s > 0}`` it is the quadratic energy of the
bodies with springs ``k_n`` on ``A``.  A Newton step from any state whose
active set is ``A`` therefore lands on the minimizer of that quadratic
energy, whatever the rest of the state; only the start's active set
matters.  The rigid predictor (:mod:`ngcontact.cell.fe.predictor`) can only
offer a level set of the gap, which the elastic bodies then reshape, and
Newton moves the contact edge over several steps (on the bisinusoid cell
the active set overshoots the solution's and retreats over several
of them).  The twin's contact set is
the solution's up to the two discretizations.

The start.  The rigid predictor's state (fluctuations zero, the counter
at the rigid approach), then the rough body's trace on ``S_C`` moved along
the normal by ``s* - s`` (``s`` the penetration of that state), so that the
start's penetration is the twin's, interpolated bilinearly from its grid
(:func:`ngcontact.fem.interpolants.periodic_grid`) and set into the trace's polynomials.  The
body's interior is left as it is: the state is not smooth, but only its
active set enters the first Newton step.  The trace cannot follow the
penetration's kink at the contact edge within an element, so the start's
active set is the twin's but for a band along the edge.

The Newton tolerance, ``|r| <= rtol |r_0|``, refers to the first residual,
as from any start: the spectral start's is much smaller than
the rigid start's, so the answer is held to a tighter absolute tolerance
(about one Newton step more than the same absolute tolerance would take).
A tolerance referred to the rigid start's residual would not do: with a
stiff penalty (``k_n h / E ~ 1e10``) that residual is
the penalty force of the rigid start's misfit, and the spectral start would
be taken as converged before a step.

Applies to the penalty's first loads under a prescribed pressure on a
small-slope cell (the twin is built by
:func:`ngcontact.drivers.build.predictor_twin`; :func:`flat_level` refuses
a cell whose ``S_C`` is not flat).  The twin is frictionless and takes the
first load's normal traction and macro strain: a first load's shear or
tangential jump is left out, the start is the contact set of the normal
load (a frictionless flat ``S_C`` carries no shear anyway; with friction
Newton takes up the shear from there).  A twin that fails leaves the
rigid start, recorded with the reason, and so does one whose contact set
misses every point of ``S_C`` (a light load: the start would float).
Exact contact (Uzawa's iteration, :mod:`ngcontact.cell.fe.contact_multiplier`) takes the exact twin
(:func:`start_multiplier_on_twin`): the state stays the rigid predictor's and the multiplier starts as
the twin's pressure, near Uzawa's fixed point; the edge-refined levels of the 3D cell start so, each from
the twin on its own grid (:mod:`ngcontact.drivers.contact_edge_refiner`).
A frictionless sweep starts every pressure afresh from the twin
(:meth:`~ngcontact.cell.fe.cell_problem.CellProblem.sweep`: one minimizer, so
the previous state need not be kept); a frictional one continues from the
previous solution as before (:mod:`ngcontact.cell.fe.predictor`).  A graded
solve (:mod:`ngcontact.cell.fe.edge_grading`) takes its first mesh's edges
from the twin (:func:`twin_edges`) and starts every level afresh from it,
the twin as fine as the grid allows: a coarse twin's edges lie too far
from the solution's for the fresh starts to save steps.  From the spectral start
Newton takes fewer steps per load than from the rigid one on the
bisinusoid cell (at every size), the height map, the Westergaard sweep and
the tabulated gap, with the same contact fractions to round-off
(docs/benchmarks.md, sections newton_steps and scaling_3d).
"""
from __future__ import annotations

import logging
from dataclasses import replace

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import CellLoad
from ngcontact.cell.fe.measures import sample_surface
from ngcontact.cell.spectral.layered_cell import SpectralCell, SpectralSolution
from ngcontact.errors import ConvergenceError
from ngcontact.fem.interpolants import periodic_grid

log = logging.getLogger(__name__)


class SpectralStart:
    """The predictor of an FE cell's first loads: its spectral twin's contact set (module docstring).

    An implementation of :class:`ngcontact.cell.fe.load_start.Predictor`, made by the builder
    (:func:`ngcontact.drivers.build.predictor_twin`) and passed to the FE cell problem, which knows nothing
    of the spectral cell.  ``twin`` is the frictionless spectral cell of the same small-slope cell.
    """

    def __init__(self, twin: SpectralCell):
        self.twin = twin

    def check(self, mesh) -> None:
        """Refuse a mesh whose ``S_C`` is not flat: the twin solves the small-slope cell only
        (:func:`flat_level`)."""
        flat_level(mesh)

    def start(self, problem, load: CellLoad) -> dict:
        """Move ``problem``'s state onto the twin's contact set (:func:`spectral_start`); the start's record."""
        return spectral_start(problem, load, self.twin)

    def edges(self, load: CellLoad) -> tuple[np.ndarray, float] | None:
        """The contact edges of the twin's solution of ``load`` and their accuracy (:func:`twin_edges`)."""
        return twin_edges(self.twin, load)


def spectral_start(problem, load: CellLoad, twin: SpectralCell) -> dict:
    """Move ``problem.gfu`` (at the rigid predictor's state) onto ``twin``'s contact set (module docstring).

    Returns the record of the start for the report: the twin's grid, its iterations and contact fraction.
    A twin that fails (its solver does not converge), or whose contact set misses every point of ``S_C``
    (a light load on a coarse mesh: the start would float, its tangent singular), leaves the rigid start,
    and the record says why: it is a predictor, and the cell problem is solved from the rigid start as
    before.
    """
    sol = twin_solution(twin, load, "starting from the rigid predictor")
    if isinstance(sol, str):
        return {"kind": "rigid", "twin_failed": sol}
    if problem.multiplier is not None:
        return start_multiplier_on_twin(problem, sol, twin)
    target = periodic_grid(sol.fields["closure"] - twin.g0, twin.period)
    move = ng.GridFunction(problem.X)
    move.components[0].Set((target - problem.penetration) * problem.n, ng.BND,
                           definedon=problem.mesh.Boundaries("contact"))
    problem.gfu.components[0].vec.data += move.components[0].vec
    if not np.any(sample_surface(problem, {"s": problem.penetration})["s"] > 0.0):
        # the twin's contact patches fall between the mesh's points: a start without contact has no tangent
        # in the far-face approach (the layer floats); the rigid predictor's start always carries the load
        problem.gfu.components[0].vec.data -= move.components[0].vec
        log.info("spectral predictor: the twin's contact set (fraction %.3g) misses every point of S_C; "
                 "starting from the rigid predictor", sol.results["contact_fraction"])
        return {"kind": "rigid", "twin_failed": f"the twin's contact set (fraction "
                f"{sol.results['contact_fraction']:.3g}) misses every point of S_C"}
    log.info("spectral predictor: %d-point grid, contact fraction %.6f", twin.grid, sol.results["contact_fraction"])
    return {"kind": "spectral", "grid": twin.grid, "iterations": sol.iterations,
            "contact_fraction": float(sol.results["contact_fraction"])}


def start_multiplier_on_twin(problem, sol: SpectralSolution, twin: SpectralCell) -> dict:
    """Exact contact: Uzawa's multiplier starts as the twin's pressure, the state at the rigid start.

    With a zero multiplier Uzawa's first pass solves the penalty problem of the start's augmentation, whose
    contact set and pressure the later passes correct.  With ``lambda`` the exact twin's pressure
    (interpolated bilinearly at the multiplier's points, ``>= 0``) the passes start near their fixed point,
    which does not depend on the start (:mod:`ngcontact.solvers.uzawa`).  The state stays the rigid
    predictor's: it penetrates over the rigid overlap, so the augmented pressure ``lambda + k s`` is positive
    there and the first tangent carries the load (the twin's state, closed on its contact set, would leave
    the interpolation's misfit as the only penetration).  Returns the start's record.
    """
    m = problem.multiplier
    m.set_point_values(np.maximum(m.at_points(periodic_grid(sol.fields["pressure"], twin.period)), 0.0))
    log.info("spectral predictor: %d-point grid, the multiplier at the twin's pressure", twin.grid)
    return {"kind": "spectral multiplier", "grid": twin.grid, "iterations": sol.iterations,
            "contact_fraction": float(sol.results["contact_fraction"])}


def twin_solution(twin: SpectralCell, load: CellLoad, fallback: str) -> SpectralSolution | str:
    """The twin's solution of ``load``'s normal part, or, where its solver fails, the reason (logged at INFO
    with what the caller does instead, ``fallback``: a predictor's failure only costs Newton steps, the
    answer is the same, so it is no warning to the user)."""
    try:
        return twin.solve(normal_load(load))
    except (ConvergenceError, ValueError, FloatingPointError) as err:
        log.info("spectral predictor: the twin failed (%s); %s", err, fallback)
        return str(err)


def normal_load(load: CellLoad) -> CellLoad:
    """The twin's load: ``load``'s normal traction and macro strain, without shear or prescribed jumps."""
    d = len(load.traction)
    return replace(load, traction=(0.0,) * (d - 1) + (load.traction[d - 1],), jump=(None,) * d)


def twin_edges(twin: SpectralCell, load: CellLoad) -> tuple[np.ndarray, float] | None:
    """The contact edges of ``twin``'s solution of ``load`` (a 2D cell's 1D grid) and the grid spacing.

    An edge lies between two neighbouring grid points, one carrying pressure and one not; it is placed
    midway, within half a spacing of the twin's own edge.  ``None`` where the twin fails or its contact set
    has no edge (none, or all of the period): the caller grades without a seed
    (:func:`ngcontact.cell.fe.edge_grading.solve_to_tolerance`).
    """
    if twin.dim != 2:
        raise ValueError(f"twin.dim = {twin.dim}: contact edges are located on the 1D grid of a 2D cell")
    sol = twin_solution(twin, load, "the grading starts without its edges")
    if isinstance(sol, str):
        return None
    on = sol.fields["pressure"] > 0.0
    spacing = twin.period / twin.grid
    edges = (np.arange(twin.grid) + 0.5)[on != np.roll(on, -1)] * spacing
    return (edges, spacing) if edges.size else None


def flat_level(mesh) -> float:
    """The normal coordinate of a flat ``S_C`` (the last axis; the small-slope cell's interface).

    Raises
    ------
    ValueError
        ``S_C`` is not a plane normal to the last axis: no spectral twin solves this cell.
    """
    dim = mesh.dim
    level = np.array([mesh[v].point[dim - 1] for el in mesh.Boundaries("contact").Elements() for v in el.vertices])
    if level.size == 0:
        raise ValueError("the cell has no contact surface S_C")
    span = float(np.ptp(level))
    if span > 1e-12 * max(1.0, float(np.max(np.abs(level)))):
        raise ValueError(f"S_C spans {span:.3g} along the last axis: it is not flat, and a spectral twin solves "
                         "the small-slope cell (a flat interface with the roughness in the gap) only")
    return float(level.mean())
