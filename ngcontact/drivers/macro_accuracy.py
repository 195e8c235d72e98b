"""The accuracy verdict of a macro run (``results.accuracy``): every headline number with its error.

The verdict has the format of the cell's (:func:`ngcontact.cell.admissibility.verdict`): ``tolerance``
(the scene's ``discretization.tolerance``, else
:data:`~ngcontact.cell.admissibility.DEFAULT_TOLERANCE`), ``tolerance_from``, ``met``, ``checks``,
``estimated``, ``quantities`` (per quantity ``name, value, error, relative_error, met, how``) and ``how``.

* the quantities of :func:`ngcontact.macro.discretization_error.headlines` (peak interface pressure,
  the interface resultant, per body the largest von Mises and Tresca stress) and, with ``[strength]``,
  the safety factor of eq. 78, each with its discretization error estimated from solves at the
  neighbouring orders on the scene's mesh (:mod:`ngcontact.macro.discretization_error`; the safety
  factor's by the linear recovery of eq. 75 on each order, whatever the scene's recovery);
* with ``[two_scale]`` (the neighbouring orders solved with the loop's converged law) also the loop's
  own residual, ``max |sigma_n(k) - sigma_n(k-1)|`` of its last step relative to the peak pressure, and
  the cell table's interpolation error (relative, paper Sec. 3.5; :mod:`ngcontact.coupling.pressure_table`);
  with the scene's tolerance the table's share of the headline quantities instead (``cell_table_share``,
  :mod:`ngcontact.coupling.table_share`), the table's own error then listed but not counted;
* the checks ``equilibrium`` (each body's forces balance, :func:`ngcontact.macro.macro_measures.equilibrium`)
  and ``law_closure`` (the interface's tractions are its law's at its jumps, with the friction threshold of the
  current pressure: :mod:`ngcontact.macro.law_closure`).

In 2D, without ``[two_scale]`` and without a refinement (whose mesh levels judge them), every stress maximum
is also judged by two local refinements at the corners of the boundary
(:mod:`ngcontact.macro.singular_maxima`): the ladder converges to the stress at sample points fixed on the
mesh, which at a singular corner moves with the mesh; such a maximum is reported as mesh dependent.
Where the interface ends closed on a boundary without support, every stress maximum and the safety factor
are mesh dependent (a refinement too judges them so).

Where the bodies have singular points (2D) or edges (3D), each stress maximum and the safety factor have
a counterpart away from them (:mod:`ngcontact.macro.away_maxima`: ``<name>_away``, outside a ball of radius
``discretization.exclusion_radius`` around each point, a tube around each edge, ``accuracy.exclusion``),
estimated as the others; a mesh-dependent maximum with such a counterpart is listed with
``counted = false``.  In 3D the corner check is not taken: a maximum over a whole body attained within
the tubes is mesh dependent (:func:`ngcontact.macro.away_maxima.inside_tubes`), and one where the
interface ends closed as in 2D.  A two-scale run reports the maxima away as a macro run does: their
neighbouring orders and local levels are solved with the loop's converged law, which is pointwise in the
closure (a table of the cell's response), so it holds on any mesh; its maxima over whole bodies and its
safety factor take neither the corner check nor the closed ends, and are judged by the same local levels
as their counterparts away (:mod:`ngcontact.macro.away_sequence`, "The maxima over whole bodies"), so
that a maximum away is never reported above its body's maximum of the same level.

Where a maximum away grows with the local levels at a point outside the balls (2D), as at a kink of the
gap of a closed interface much stiffer than its bodies over the element size (the two-scale femur's
cone-cylinder corner, where the converged cell law is tabulated), that point joins the singular points
and every quantity is judged once more with it (:func:`judged`: the orders and levels solved again,
about as long as the first judgement; once, so a point found on the second pass leaves its maximum away
mesh dependent).  A safety factor that falls with the local levels is judged as the mirror of a growing
maximum (:mod:`ngcontact.macro.away_sequence`), and a refinement towards ``discretization.tolerance``
judges each of its levels by the same two passes (:func:`rejudged`).

A counted quantity whose relative error exceeds the tolerance, or has none (not converging, a stress
singularity), marks the verdict as not met and is said in one warning line.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from typing import Any, Callable, Protocol, TypeVar

import numpy as np

from ngcontact.cell.admissibility import DEFAULT_TOLERANCE
from ngcontact.coupling import homogenization_error
from ngcontact.errors import SceneError
from ngcontact.macro import away_maxima as AM
from ngcontact.macro import away_sequence as AS
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import law_closure as LC
from ngcontact.macro import singular_maxima as SM
from ngcontact.macro.macro_problem import MacroSolution
from ngcontact.scene.schema import MAX_ORDER

log = logging.getLogger(__name__)
#: what a judgement makes besides its estimates (:func:`rejudged`)
T = TypeVar("T")

#: how the verdict's errors are estimated (the report's ``accuracy.how``)
HOW = ("discretization error of each headline quantity from solves at the neighbouring polynomial orders on "
       "the scene's mesh (ngcontact.macro.discretization_error), each stress maximum of a 2D run judged by two "
       "local refinements at the boundary's corners (ngcontact.macro.singular_maxima); each stress maximum and "
       "the safety factor also away from the singular points, in 3D the singular edges (*_away, "
       "ngcontact.macro.away_maxima), judged by two local refinements there as well, counted where the global one "
       "is mesh dependent; the two-scale "
       "loop's residual and the cell table's interpolation error as their own quantities")
#: the meaning of the macro run's checks
CHECKS = {"equilibrium": "the largest force imbalance of a body relative to its largest force",
          "law_closure": LC.MEANING}


@dataclass(frozen=True)
class SafetyFactor:
    """The safety factor of eq. 78 of a solution: ``samples(sol, keep)`` gives ``safety_factor`` with the
    interface point where it is attained and, with ``keep`` (which of an array of points count), the
    smallest over the points kept (``safety_factor_away``); called, the factor alone."""

    samples: Callable[[MacroSolution, Callable[[np.ndarray], np.ndarray] | None], dict[str, DE.Sample]]

    def __call__(self, sol: MacroSolution) -> float:
        return self.samples(sol, None)["safety_factor"].value


def exclusion_for(scene, sol: MacroSolution) -> AM.Exclusion | None:
    """The balls around the singular points of ``sol`` (tubes around its singular edges in 3D,
    :mod:`ngcontact.macro.away_maxima`), with the scene's ``discretization.exclusion_radius``; ``None``
    without any."""
    check_radius(scene, sol.problem)
    return AM.exclusion_of(sol, getattr(scene.discretization, "exclusion_radius", None))


def _added(s: MacroSolution, safety_factor, exclusion: AM.Exclusion | None, dense_inset: float
           ) -> dict[str, DE.Sample]:
    """The maxima away from the singular points and the safety factor(s) of ``s``."""
    out = {} if exclusion is None else AM.away_maxima(s, exclusion, dense_inset)
    if isinstance(safety_factor, SafetyFactor):
        out.update(safety_factor.samples(s, None if exclusion is None else exclusion.outside))
    elif safety_factor is not None:
        out["safety_factor"] = DE.Sample(safety_factor(s))
    return out


def order_samples(scene, sol: MacroSolution, solve: Callable[..., MacroSolution],
                  safety_factor: Callable[[MacroSolution], float] | None = None,
                  component: str | None = None, dense_inset: float = 1e-3,
                  exclusion: AM.Exclusion | None = None) -> dict[int, dict[str, DE.Sample]]:
    """The headline quantities at the three orders of the ladder (``sol`` is the scene's order; the other
    two are solved by ``solve(problem, start)`` on the same mesh with the same law, from ``sol``);
    ``component``: the resultant's (default: the largest of ``sol``'s); ``dense_inset``: of the lattice
    a stress maximum's sampling error is taken on (:func:`ngcontact.macro.discretization_error.body_maxima`);
    ``exclusion``: the balls the maxima away from the singular points are taken outside of."""
    problem, ppe = sol.problem, scene.output.points_per_element
    own = DE.headlines(sol, ppe, component, dense_inset)
    component = next(n for n in own if n.startswith("resultant_")).removeprefix("resultant_")
    own = AM.bounded({**own, **_added(sol, safety_factor, exclusion, dense_inset)})
    out: dict[int, dict[str, DE.Sample]] = {problem.order: own}
    for q in DE.ladder(problem.order, MAX_ORDER):
        if q == problem.order:
            continue
        other = replace(problem, order=q)
        start = DE.start_at_order(sol, other)
        with DE.neighbour_mesh(problem.mesh, problem.order):
            s = solve(other, start)
            out[q] = AM.bounded({**DE.headlines(s, ppe, component, dense_inset),
                                 **_added(s, safety_factor, exclusion, dense_inset)})
    return dict(sorted(out.items()))


def estimates(samples: dict[int, dict[str, DE.Sample]], sol: MacroSolution) -> list[DE.Estimate]:
    """Every headline quantity's :class:`~ngcontact.macro.discretization_error.Estimate` at the scene's order."""
    mesh, order = sol.problem.mesh, sol.problem.order
    corners, h = DE.corner_points(mesh), DE.shortest_boundary_edge(mesh)
    return [DE.estimate(name, {q: s[name] for q, s in samples.items()}, order,
                        corners if name.startswith(("von_mises", "tresca")) else None, h)
            for name in samples[order]]


def two_scale_quantities(two_scale: dict, tolerance: float) -> list[dict[str, Any]]:
    """The loop's residual and the cell table's interpolation error as quantities of the verdict; where the
    scene's tolerance had the table's share of the headline quantities estimated
    (:mod:`ngcontact.coupling.table_share`), that share too, and the table's own error is listed but not
    counted (the share is what it costs the macro quantities)."""
    last = two_scale["history"][-1]
    change = float(last["max_change"] or 0.0)
    peak = float(last["max_pressure"])
    rel = change / peak if peak > 0 else 0.0
    table = float(two_scale["table"]["error_estimate"])
    share = two_scale.get("table_share")
    return [{"name": "two_scale_residual", "value": change, "error": change, "relative_error": rel,
             "controlled": "relative", "met": rel <= tolerance, "counted": True,
             "how": "max |sigma_n(k) - sigma_n(k-1)| over the interface points at the loop's last step [Pa], "
                    "relative to the peak pressure"},
            {"name": "cell_table_interpolation", "value": table, "error": table, "relative_error": table,
             "controlled": "relative", "met": table <= tolerance, "counted": share is None,
             "how": "the monotone cubic's largest error at interval midpoints, relative to the tabulated "
                    "quantities' largest values (two_scale.table_tol bounds it)"}] + ([] if share is None else [share])


def verdict(found: list[DE.Estimate], tolerance: float | None, balance: dict | None,
            two_scale: dict | None = None, how: str = HOW, absolute: tuple[str, ...] = (),
            closure: dict | None = None) -> dict[str, Any]:
    """``results.accuracy`` of a macro run (module docstring); one warning line when it is not met.
    ``balance``: the equilibrium check (``None``: a run without one); ``absolute``: the names of fractions,
    whose error is held to the tolerance itself; ``closure``: the law's closure
    (:func:`ngcontact.macro.law_closure.law_closure`; ``None``: not taken)."""
    limit = DEFAULT_TOLERANCE if tolerance is None else tolerance
    quantities = [e.quantity(limit, e.name in absolute) for e in found]
    if two_scale is not None:
        quantities += two_scale_quantities(two_scale, limit)
    checks = []
    for name, record in (("equilibrium", balance), ("law_closure", closure)):
        if record is not None:
            value, bound = float(record["error"]), float(record["tolerance"])
            checks.append({"load": None, "name": name, "value": value, "limit": bound, "ok": value <= bound,
                           "meaning": CHECKS[name]})
    out: dict[str, Any] = {"tolerance": limit, "tolerance_from": "scene" if tolerance is not None else "default",
           "met": all(c["ok"] for c in checks) and all(q["met"] for q in quantities if q["counted"]), "checks": checks,
           "estimated": True, "quantities": quantities, "how": how}
    if not out["met"]:
        log.warning("ngcontact: warning: %s", warning_line(out))
    return out


def warning_line(accuracy: dict) -> str:
    """The unmet quantities of a verdict in one line."""
    parts = []
    for q in accuracy["quantities"]:
        if q["met"] or not q.get("counted", True):
            continue
        rel = q["relative_error"]
        if q["error"] is None:
            parts.append(f"{q['name']} {q['value']:.4g} has no error estimate ({q['how'].split(': ')[-1]})")
        elif q.get("controlled") == "absolute" or rel is None:
            parts.append(f"{q['name']} {q['value']:.4g} +/- {q['error']:.3g} (absolute)")
        else:
            parts.append(f"{q['name']} {q['value']:.4g} +/- {rel:.2%}")
    parts += [f"{c['name']} {c['value']:.3g} > {c['limit']:.3g}" for c in accuracy["checks"] if not c["ok"]]
    return f"accuracy not met (tolerance {accuracy['tolerance']:.3g}): " + "; ".join(parts)


def safety_factor_of(scene, recovery) -> SafetyFactor | None:
    """The safety factor of eq. 78 by the linear recovery with the strength check's correctors ``recovery``
    (``None``: the scene has no ``[strength]``)."""
    if recovery is None:
        return None
    from ngcontact.drivers.run_strength import linear_safety_factors

    def samples(s: MacroSolution, keep) -> dict[str, DE.Sample]:
        return linear_safety_factors(scene, s, recovery, keep)
    return SafetyFactor(samples)


def away_judged(found: list[DE.Estimate], sol: MacroSolution, solve: Callable[..., MacroSolution],
                exclusion: AM.Exclusion | None, own: dict[str, DE.Sample], safety=None, whole: bool = False
                ) -> list[DE.Estimate]:
    """``found`` with the maxima away from the singular points judged by local refinements at those points
    (:mod:`ngcontact.macro.away_sequence`; ``own``: the samples of ``sol``), with ``whole`` the maxima over
    whole bodies and the safety factor by the same levels; nothing without ``exclusion``."""
    if exclusion is None:
        return found
    at = {k: v for k, v in own.items() if k.endswith(AM.AWAY) or (whole and k.startswith(AM.GLOBAL))}
    finer = AS.levels(sol, solve, exclusion, at, safety.samples if isinstance(safety, SafetyFactor) else None,
                      whole=whole)
    return AS.judged(found, own, finer, AS.beside(sol.problem.mesh, exclusion))


def check_radius(scene, problem) -> None:
    """``discretization.exclusion_radius`` of ``scene`` against the bodies of ``problem``'s mesh, before the
    solve.

    Raises
    ------
    SceneError
        The radius not below the smallest extent of the bodies' bounding boxes
        (:func:`ngcontact.macro.away_maxima.smallest_extent`).
    """
    radius = getattr(scene.discretization, "exclusion_radius", None)
    if radius is None:
        return
    smallest = AM.smallest_extent(problem.mesh, (problem.rough, problem.counter))
    if not 0.0 < radius < smallest:
        raise SceneError("discretization.exclusion_radius", radius, "must be > 0 and below the smallest extent of "
                         f"the bodies' bounding boxes ({smallest:.4g} m)")


class Judged(Protocol):
    """Estimates made already (by a refinement, :mod:`ngcontact.drivers.macro_refinement`), with the balls
    around the singular points they were made with."""

    @property
    def estimates(self) -> list[DE.Estimate]: ...

    @property
    def exclusion(self) -> AM.Exclusion | None: ...


def judged(scene, sol: MacroSolution, solve: Callable[..., MacroSolution], two_scale: bool,
           safety: SafetyFactor | None) -> tuple[list[DE.Estimate], AM.Exclusion | None]:
    """Every headline quantity's estimate on ``sol`` (module docstring) and the region around the singular
    points it was judged with: in 2D, where a maximum away grows with the local levels at a point outside
    the balls (:func:`ngcontact.macro.away_sequence.grown`), that point joins the singular points and the
    quantities are judged once more (module docstring)."""
    def judge(exclusion: AM.Exclusion | None) -> tuple[list[DE.Estimate], None]:
        return _judged(scene, sol, solve, two_scale, safety, exclusion), None
    (found, _), exclusion = rejudged(judge, exclusion_for(scene, sol), sol.problem.mesh)
    return AM.settle(found, exclusion), exclusion


def rejudged(judge: Callable[[AM.Exclusion | None], tuple[list[DE.Estimate], T]], exclusion: AM.Exclusion | None,
             mesh) -> tuple[tuple[list[DE.Estimate], T], AM.Exclusion | None]:
    """``judge(exclusion)`` (the estimates and what else the judgement made) and the region it was made with:
    in 2D, where a maximum away grows (a safety factor away falls) with the local levels at a point outside
    the region (:func:`ngcontact.macro.away_sequence.grown`), that point joins the singular points and
    ``judge`` is called once more with it (module docstring).  The verdict (:func:`judged`) and a refinement's
    levels (:mod:`ngcontact.drivers.macro_refinement`) judge by this one rule."""
    out = judge(exclusion)
    grown = AS.grown(out[0], exclusion, mesh) if mesh.dim == 2 else []
    if grown and exclusion is not None:
        exclusion = exclusion.joined(grown, AS.GROWN)
        out = judge(exclusion)
    return out, exclusion


def _judged(scene, sol: MacroSolution, solve: Callable[..., MacroSolution], two_scale: bool,
            safety: SafetyFactor | None, exclusion: AM.Exclusion | None) -> list[DE.Estimate]:
    """The estimates of :func:`judged` with the region ``exclusion``, before
    :func:`ngcontact.macro.away_maxima.settle`."""
    samples = order_samples(scene, sol, solve, safety, exclusion=exclusion)
    found = estimates(samples, sol)
    if not two_scale and sol.problem.mesh.dim == 2:
        found = SM.check(found, sol, samples[sol.problem.order], solve)
    elif not two_scale:
        found = AM.inside_tubes(SM.at_closed_ends(found, SM.closed_ends(sol)), exclusion)
    return away_judged(found, sol, solve, exclusion, samples[sol.problem.order], safety, whole=two_scale)


def accuracy(scene, sol: MacroSolution, solve: Callable[..., MacroSolution], balance: dict,
             two_scale: dict | None = None, recovery=None, refined: Judged | None = None) -> dict[str, Any]:
    """``results.accuracy`` of the macro solution ``sol`` of ``scene``: the neighbouring orders solved by
    ``solve(problem, start)`` (or the estimates a refinement made already, ``refined``, with its mesh levels
    and its balls), the safety factor re-evaluated with the strength check's correctors ``recovery``."""
    found, exclusion = (None, None) if refined is None else (refined.estimates, refined.exclusion)
    if found is None:
        found, exclusion = judged(scene, sol, solve, two_scale is not None, safety_factor_of(scene, recovery))
    out = verdict(found, scene.discretization.tolerance, balance, two_scale,
                  closure=LC.law_closure(sol, scene.solver.coulomb_rtol))
    if exclusion is not None:
        out["exclusion"] = exclusion.record()
    out["modelling"] = modelling(scene, sol)
    return out


def roughness_period(scene) -> float | None:
    """The period of the roughness the scene's law homogenizes [m]: ``interface.roughness_period``, else the
    law's cell's (or the two-scale loop's) period times ``cell_length_unit``, else ``None``."""
    spec = scene.interface
    if spec.roughness_period is not None:
        return float(spec.roughness_period)
    cell, unit = spec.cell, spec.cell_length_unit
    if cell is None and scene.two_scale is not None:
        cell, unit = scene.two_scale.cell, scene.two_scale.cell_length_unit
    if cell is None:
        return None
    from ngcontact.scene import loader
    from ngcontact.scene.sections import resolve
    return float(loader.load(resolve(scene, cell)).geometry.period) * float(unit)


def modelling(scene, sol: MacroSolution) -> dict[str, Any]:
    """The modelling error of the homogenized interface, estimated from the ratio of the roughness period to
    the interface's length (:mod:`ngcontact.coupling.homogenization_error`; 3D: the square root of its area),
    beside the discretization error; a period not below the interface's length is no homogenization."""
    import ngsolve as ng
    mesh = sol.problem.mesh
    size = float(ng.Integrate(ng.CF(1.0), mesh, ng.BND, definedon=mesh.Boundaries(sol.problem.interface)))
    length = size ** 0.5 if mesh.dim == 3 else size
    period = roughness_period(scene)
    law = "two_scale" if scene.two_scale is not None else scene.interface.law
    out = homogenization_error.estimate(law, period, length)
    if period is not None and period >= length:
        out.update(estimated=False, relative_error=None,
                   how=f"not estimated: the roughness period {period:.3g} m is not smaller than the interface's "
                       f"length {length:.3g} m; state interface.roughness_period (or the cell's length unit, "
                       "interface.cell_length_unit) in metres")
    return out
