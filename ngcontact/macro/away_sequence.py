"""The error of the maxima away from the singular points from local refinements at those points.

The maxima away from the singular points (:mod:`ngcontact.macro.away_maxima`) converge, but the order
ladder on one mesh (:mod:`ngcontact.macro.discretization_error`) sees only part of their error: the
elements that touch a singular point carry the unbounded term ``|x - x_i|^(lambda - 1)`` or
``log |x - x_i|``, which no polynomial of any order on them resolves, so the displacement's error there
falls only algebraically with the order and pollutes the stress everywhere (Babuska-Guo: the p-version
converges algebraically on a mesh not graded towards a singular point).  The ladder's geometric
extrapolation from three orders misses that share.

Only smaller elements at the singular points remove it.  So the elements with a vertex at a singular point
(in 3D: on a singular edge, :meth:`ngcontact.macro.singular_set.SingularSet.star`), those the balls'
circles cross (where a maximum away from a singular point is attained when the stress grows towards it;
:data:`CIRCLE` points each) and those holding the maxima away are refined :data:`LEVELS` times (Netgen's
local refinement, on copies of the mesh; each level solved at the scene's order from the last level's
solution interpolated into its space, as the corner check of :mod:`ngcontact.macro.singular_maxima` does),
and each maximum away is taken on every level (``Q_0`` the scene's mesh, ``Q_1``, ``Q_2``).  The finest
level's value and location are reported; its error (:func:`level_error`) from the differences ``d_1 = Q_1 - Q_0``,
``d_2 = Q_2 - Q_1``, their ratio ``rho = |d_2| / |d_1|`` and two shares the levels do not see:

* the order ladder's polynomial share ``e_P``: the ladder's estimate of the scene's mesh without its
  sampling term, plus :data:`~ngcontact.macro.discretization_error.SAFETY` times the sampling error of the
  finest level (``Sample.sampling``: the denser lattice's excess on the mesh the value is reported on).
  The mesh away from the refined elements is the scene's, so the polynomial error there is at most the one
  the ladder measured; a sampling error belongs to the mesh whose points sampled the maximum, and the
  levels refine the elements holding it;
* the move ``m = |Q_2 - Q_0|`` where it contradicts the ladder (``m > e_ladder``, the ladder's estimate of
  the scene's mesh): that estimate saw only part of the error, and as long as the two levels at least
  halve the error of the scene's mesh (the saturation assumption of a refinement) the finest level's
  error is at most ``m``; ``e_m = SAFETY m``, else 0.

Each level halves the elements at the singular points, so the polluting share falls by ``2^-lambda``
per level at a singular point of exponent ``lambda <= 1`` (the error in energy falls like ``h^lambda``
where the elements at the point are halved; a logarithm has ``lambda = 1``): a ratio of at least
:data:`SLOWEST` = 1/2, and at most ``2^-0.544 = 0.69`` (the smallest exponent among the singular points
of :mod:`ngcontact.macro.away_maxima`, a free wedge of 270 degrees).  The two differences agree in rate
where they have one sign and ``1/4 <= rho <= 3/4`` (:data:`AGREE`: that range widened by a factor 2
towards the faster fall of the refined elements' own local error and by a little towards the slower),
and then Richardson's extrapolation with the observed rate gives the error left after the finest level,
the sum of the differences still to come, added to the share the levels do not refine:

    e = e_P + SAFETY |d_2| rho / (1 - rho).

Where they disagree, the estimate says so and takes the larger of what bounds the error:

* one sign, ``rho < 1/4``: faster than the halving allows, so pre-asymptotic (the first level moves
  the circle of the ball out of the elements that touch the point, a step larger than the ones to come);
  the tail at the slowest ratio, ``SAFETY |d_2| SLOWEST / (1 - SLOWEST)``:
  ``e = max(e_P, SAFETY |d_2|, e_m)``;
* one sign, ``3/4 < rho < 1``: slower than any singular point's pollution falls, so not that fall;
  ``e = max(e_P, SAFETY |d_2|, e_m)``;
* ``rho >= 1``: the difference does not shrink, no limit is extrapolated: the same, and without a
  ladder estimate no estimate at all;
* opposite signs, ``rho < 1``: the values oscillate about their limit, which lies between ``Q_1`` and
  ``Q_2``, so ``|e_2| <= |d_2|``: ``e = min(SAFETY |d_2|, max(e_P, e_m))`` (the bracket caps the larger
  of the other bounds; ``SAFETY |d_2|`` without a ladder estimate; an oscillation of a sampled maximum
  is its sample points moving onto the field's maximum as the elements holding it shrink, not the fall
  of the pollution).

Differences below :data:`~ngcontact.macro.discretization_error.NOISE` of the quantity are round-off:
``e = max(e_P, SAFETY max(|d_1|, |d_2|))``.  A ladder without an estimate (a ball's circle inside the
elements at a singular point, where no order converges fast) has ``e_P = e_m = 0`` and leaves the levels
alone.  The check costs about one solve of the scene (two warm-started solves on meshes a little larger).

A stress maximum that grows where the levels refine
    Before the rules above, the levels are asked whether they converge at all
    (:func:`ngcontact.macro.mesh_sequence.growing`, the one test the corner check makes too).  Level ``k``
    halves the elements at the singular points and those holding the maximum, ``h_k = 2^-k h_0`` there, and
    its difference is ``d_k = Q_k - Q_(k-1)``.  A maximum converging at rate ``q`` (``Q_k = Q + C h_k^q``)
    has differences that contract by ``d_(k+1) / d_k = 2^-q``: at most ``2^-0.544 = 0.69`` for the
    pollution of the slowest singular point (above), ``2^-p`` where the elements holding it are halved.  A
    maximum at a point where the stress is unbounded does not: ``log(1/r)`` sampled at ``r ~ h_k`` gains
    ``Q_k = A + B k log 2``, constant differences (``d_(k+1) / d_k = 1``), and ``r^(lambda - 1)`` gains a
    factor ``2^(1 - lambda) > 1`` per level.  So a stress maximum whose magnitude grows at each of the last
    three levels by resolved differences, ``d_k > max(NOISE scale, s_(k-1))``, with

        d_2 >= c d_1,   c = GROWING = 3/4   (:data:`ngcontact.macro.mesh_sequence.GROWING`)

    has no converged value.  A difference is resolved above round-off
    (:data:`~ngcontact.macro.discretization_error.NOISE` of the scale) and above the sampling error
    ``s_(k-1)`` of the level it starts from (``Sample.sampling``, the denser lattice's excess): a sampled
    maximum lies below the field's by up to that error, and a level halves the elements holding it, so its
    lattice alone may raise the value by as much with the field unchanged (the two-scale femur's stem away
    from its corner, on its axis: 10.8604, 10.8657, 10.8815 MPa, each rise below the sampling error of
    22 and 21.5 kPa of the level before, the last level's 1.1 kPa: the lattice finding the maximum, not a
    growing field; two further levels give 10.8745, 10.8763 MPa).  ``c`` lies above the slowest
    contraction of a converging stress (0.69) and below the logarithm's 1 by a margin for a log-singular
    maximum whose sample points still approach the point (the two-scale femur's stem at its corner: 12.94,
    19.26, 25.32 MPa, ratio 0.96).  This holds
    whatever the order ladder's estimate on the scene's mesh: the ladder sees the polynomial error of one
    mesh, not how the value moves as the elements at the point shrink, and a large ladder estimate beside
    growing differences is no bound on a quantity without a limit (the two-scale femur's bone: 54.2,
    56.7, 61.9 MPa, ratio 2.1, and 67.8, 74.5 on two further levels, beside a ladder estimate of 77 %).
    A maximum that grows by contracting differences (converging from below) keeps its estimate from the
    rules above.  A growing one is reported mesh dependent, singular at the finest level's location, with
    the value of the scene's mesh (the mesh every maximum over a whole body is reported on).  Such a point
    need not be one of :func:`ngcontact.macro.away_maxima.singular_points`: a closed interface much stiffer
    than its bodies over the element size, ``k_n h >> E``, transmits a kink of its gap (an interference that
    stops growing, as the two-scale femur's does at the stem's cone-cylinder corner) as a kink of the
    displacement, whose traction grows like ``log r`` down to the law's own length ``E / k_n`` (the Hilbert
    transform of a jump in the gap's slope), far below the element size; a compliant law (``E / k_n`` above
    the element size) smooths the same kink.  A maximum away next to the region's boundary (within the
    diameter of the scene mesh's element holding it, :func:`beside`) is exempt: it grows as the levels resolve
    the circle towards the bounded value there.  In 2D such a point joins the singular points (:func:`grown`,
    at the nearest vertex of the scene's mesh, reason :data:`GROWN`) and the quantities are judged once more
    outside its ball too (:func:`ngcontact.drivers.macro_accuracy.judged`); in 3D the growth runs along an
    edge whose extent the levels do not find, and the maximum away stays mesh dependent.

A safety factor that falls where the levels refine
    The safety factor of eq. 78 is a minimum over the interface, ``sigma_u / sigma_eq`` of the micro stresses
    (eq. 75); its reciprocal, the utilisation ``sigma_eq / sigma_u``, is a maximum of a stress.  Where that
    stress grows like ``log r``, ``A + B k`` on level ``k``, the utilisation grows so and the safety factor
    falls like ``1 / log r``, by differences whose ratio ``A / (A + 2B)`` shows no fixed rate.  So the mirror
    of the test above is taken on the utilisation (:func:`ngcontact.macro.singular_maxima.growing`): levels
    whose utilisation grows at each level, the last difference at least ``GROWING`` of the first, have no
    converged value, whatever the
    ladder's estimate: mesh dependent, singular at the finest level's location, with the value of the
    scene's mesh.  A safety factor that falls by contracting utilisation differences converges from above
    (0.2393, 0.1977, 0.1931, 0.1905, 0.1892: the utilisation's differences contract by 0.14, 0.58, 0.51)
    and keeps its estimate.  The safety factor away is judged as a maximum away is
    (exempt next to the region's boundary; in 2D its point joins the singular points).

The maxima over whole bodies
    Where no other check judges them (a two-scale run, :mod:`ngcontact.drivers.macro_accuracy`), the
    levels also take the maxima over whole bodies and the safety factor over the whole interface
    (``whole``) and judge them as their counterparts away.  On every mesh a maximum over a body is at least
    its maximum away, and the safety factor at most its counterpart away
    (:func:`ngcontact.macro.away_maxima.bounded`); judged so, a maximum away and its body's are reported
    from the finest level where both converge and from the scene's mesh where both grow, the one away
    never above its body's.

In 3D the elements the tubes' rings cross are not refined: the tube around an edge crosses a layer of
elements along its whole length, and refining that layer twice multiplies the unknowns along every
singular edge by about 8 per level, where the elements touching the edge (which carry the polluting
share) and those holding the maxima (where the maximum away sits on the tube) are a thin set.  The rings'
elements are refined where they hold a maximum.  The exponents along an edge are the 2D wedge's, so the
ratios above hold there as well.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Callable

import ngsolve as ng
import numpy as np

from ngcontact.macro import away_maxima as AM
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import error_indicator as EI
from ngcontact.macro import mesh_sequence as MS
from ngcontact.macro import singular_maxima as SM
from ngcontact.macro.macro_problem import MacroSolution

#: local refinements at the singular points (three values with the scene's mesh: an observed rate)
LEVELS = 2
#: points per ball's circle whose elements each level refines
CIRCLE = 64
#: the slowest fall per level of the pollution of a singular point (module docstring)
SLOWEST = 0.5
#: the ratios of the last two differences that agree in rate with the halving (module docstring); above the
#: upper one a growing maximum has no limit (:data:`ngcontact.macro.mesh_sequence.GROWING`)
AGREE = (0.25, MS.GROWING)
#: the safety factor away from the singular points of a solution, given which interface points count
Safety = Callable[[MacroSolution, Callable[[np.ndarray], np.ndarray]], dict[str, DE.Sample]]
#: why a point where a maximum away grows with the levels joins the singular points (:func:`grown`)
GROWN = "the stress grows there with every refinement"
#: whether a location lies next to the region around the singular set (:func:`beside`)
Beside = Callable[[tuple[float, ...] | None], bool]


def sampled(sol: MacroSolution, exclusion: AM.Exclusion, safety: Safety | None, whole: bool = False
            ) -> dict[str, DE.Sample]:
    """The maxima away from the singular points of ``sol`` and, with ``safety``, the safety factor away; with
    ``whole`` the maxima over whole bodies (and the safety factor over the whole interface) as well, each at
    least its counterpart's away (:func:`ngcontact.macro.away_maxima.bounded`)."""
    out = AM.away_maxima(sol, exclusion)
    if whole:
        out.update(DE.body_maxima(sol))
    if safety is not None:
        out.update({k: v for k, v in safety(sol, exclusion.outside).items() if whole or k.endswith(AM.AWAY)})
    return AM.bounded(out)


def levels(sol: MacroSolution, solve: Callable[..., MacroSolution], exclusion: AM.Exclusion,
           at: dict[str, DE.Sample], safety: Safety | None = None, count: int = LEVELS, whole: bool = False
           ) -> list[dict[str, DE.Sample]]:
    """The maxima away (:func:`sampled`; with ``whole`` those over whole bodies too) on ``count`` levels, each
    a copy of the last level's mesh (the first: ``sol``'s) refined at the singular points and at the
    locations of ``at`` (the maxima on ``sol``), solved by ``solve(problem, start)`` at ``sol``'s order from
    the last level's solution."""
    order = max(sol.problem.order, 1)
    points = [s.location for s in at.values() if s.location is not None]
    circle = AM.circles(exclusion, CIRCLE) if sol.problem.mesh.dim == 2 else np.zeros((0, 3))
    out = []
    for _ in range(count):
        mesh = ng.Mesh(sol.problem.mesh.ngmesh.Copy())
        marked = exclusion.singular.star(mesh) | EI.holding(mesh, points + [tuple(x) for x in circle])
        EI.refine_marked(mesh, marked, order)
        problem = replace(sol.problem, mesh=mesh)
        sol = solve(problem, DE.start_at_order(sol, problem))
        out.append(sampled(sol, exclusion, safety, whole))
    return out


def beside(mesh: ng.Mesh, exclusion: AM.Exclusion) -> Beside:
    """Whether a location lies within the diameter of ``mesh``'s element holding it of the region around the
    singular set (a ball's circle, a tube's mantle): where a maximum away grows as the levels resolve the
    region's boundary, towards its bounded value there (module docstring)."""
    def test(point: tuple[float, ...] | None) -> bool:
        if point is None:
            return False
        gap = float(exclusion.singular.distance(np.asarray(point, dtype=float))[0]) - exclusion.radius
        return gap <= element_diameter(mesh, point)
    return test


def element_diameter(mesh: ng.Mesh, point: tuple[float, ...]) -> float:
    """The largest distance between two vertices of ``mesh``'s volume element holding ``point`` (0 where no
    element holds it)."""
    found = mesh(*point)
    if found.nr < 0 or found.vb != ng.VOL:
        return 0.0
    xyz = np.array([mesh[v].point for v in mesh[ng.ElementId(ng.VOL, found.nr)].vertices])
    return float(max(np.linalg.norm(a - b) for a in xyz for b in xyz))


def judged(found: list[DE.Estimate], own: dict[str, DE.Sample], finer: list[dict[str, DE.Sample]],
           near: Beside | None = None) -> list[DE.Estimate]:
    """``found`` with each quantity the levels ``finer`` sampled (the maxima away; with ``whole`` in
    :func:`levels` those over whole bodies too), not mesh dependent, judged by its value on the scene's
    mesh (``own``) and on the levels (module docstring): the value and location of the finest level, or
    mesh dependent where a stress maximum grows with the levels
    (:func:`ngcontact.macro.singular_maxima.growing`; a maximum away not where ``near`` says it is next to
    the region around the singular set); the other estimates unchanged.  A
    body's von Mises and Tresca maxima so judged are singular together
    (:func:`ngcontact.macro.singular_maxima.same_body`)."""
    out, names = [], set()
    for e in found:
        if finer and e.singular_at is None and e.name in own and all(e.name in f for f in finer):
            e = _judged(e, [own[e.name]] + [f[e.name] for f in finer], near)
            names.add(e.name)
        out.append(e)
    together = {e.name: e for e in SM.same_body([e for e in out if e.name in names])}
    return [together.get(e.name, e) for e in out]


def grown(found: list[DE.Estimate], exclusion: AM.Exclusion | None, mesh: ng.Mesh) -> list[tuple[float, ...]]:
    """The points outside the region around the singular set where a maximum away of ``found`` is singular
    (it grows with the levels, :func:`judged`, or with the order at a corner of the boundary,
    :func:`ngcontact.macro.discretization_error.estimate`), each at the vertex of ``mesh`` nearest to it
    (the singular point of the element holding it), none within the radius of another."""
    if exclusion is None:
        return []
    pts = np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])
    out: list[tuple[float, ...]] = []
    for e in found:
        if e.name.endswith(AM.AWAY) and e.singular_at is not None and not exclusion.covers(e.singular_at):
            at = tuple(float(c) for c in pts[int(np.argmin(np.linalg.norm(pts - np.asarray(e.singular_at), axis=1)))])
            if all(np.linalg.norm(np.subtract(at, q)) > exclusion.radius for q in out):
                out.append(at)
    return out


def _judged(e: DE.Estimate, samples: list[DE.Sample], near: Beside | None = None) -> DE.Estimate:
    """The error of the finest of ``samples`` (the scene's mesh, then the levels; module docstring), or the
    scene mesh's value, mesh dependent, where it grows (a safety factor: falls) with the levels."""
    values = [s.value for s in samples]
    shown = ", ".join(f"{v:.6g}" for v in values)
    at = samples[-1].location
    exempt = e.name.endswith(AM.AWAY) and near is not None and at is not None and near(at)
    if SM.growing(e, values, [x.sampling for x in samples]) and at is not None and not exempt:
        return replace(e, error=None, singular_at=at,
                       how=f"{e.how}; {len(values) - 1} local refinements at the singular points and at the "
                           f"{'minima' if e.name.startswith(SM.SAFETY_FACTOR) else 'maxima'}: {shown}: "
                           f"{_unbounded(e.name)}: mesh dependent, singular at {DE._point(at)} (the value of "
                           "the scene's mesh)")
    head = f"{e.how}; {len(values) - 1} local refinements at the singular points: {shown}, the last reported"
    polynomial = None
    if e.error is not None:
        share = max(e.error - DE.SAFETY * samples[0].sampling, 0.0)
        polynomial = share + DE.SAFETY * samples[-1].sampling
        head += (f"; the ladder's share without the scene mesh's sampling {share:.3g}, with {DE.SAFETY:g} x the "
                 f"finest level's sampling error {samples[-1].sampling:.3g}: {polynomial:.3g}")
    error, how = level_error(values, e.scale, polynomial, e.error)
    return replace(e, value=values[-1], location=samples[-1].location, error=error, how=f"{head}; {how}")


def level_error(values: list[float], scale: float, polynomial: float | None, ladder: float | None
                ) -> tuple[float | None, str]:
    """The error of ``values[-1]``, the finest of the levels ``values`` (the scene's mesh first), given the
    ladder's polynomial share ``e_P`` (``polynomial``) and the ladder's estimate of the scene's mesh
    (``ladder``; ``None``: none), and how (module docstring: Richardson with the observed rate where the
    last two differences agree in rate, else the larger of the bounds)."""
    if len(values) < 3:
        return polynomial, f"{len(values)} level(s): no observed rate"
    q0, q1, q2 = values[-3:]
    d1, d2 = q1 - q0, q2 - q1
    base, s = polynomial or 0.0, DE.SAFETY
    moved = abs(q2 - q0)
    e_m = s * moved if ladder is not None and moved > ladder else 0.0
    said = f"levels' differences {d1:.3g}, {d2:.3g}"
    if max(abs(d1), abs(d2)) <= DE.NOISE * scale:
        return max(base, s * max(abs(d1), abs(d2))), f"{said}: they agree to round-off"
    rho = abs(d2) / abs(d1) if d1 != 0 else math.inf
    said += f" (ratio {rho:.2g})"
    if e_m:
        said += (f"; the levels moved the value by {moved:.3g}, more than the ladder's estimate of the scene's "
                 f"mesh, which so saw only part of its error: {s:g} x that move {e_m:.3g}")
    if d1 * d2 >= 0 and AGREE[0] <= rho <= AGREE[1]:
        tail = s * abs(d2) * rho / (1.0 - rho)
        return base + tail, (f"{said}: they agree in rate, Richardson with the observed rate: e_P + {s:g} x "
                             f"|d_2| ratio / (1 - ratio) = {base:.3g} + {tail:.3g}")
    if d1 * d2 >= 0 and rho < AGREE[0]:
        return max(base, s * abs(d2), e_m), (f"{said}: they disagree in rate, faster than the halving allows "
                                             f"(pre-asymptotic): the larger of e_P, the tail at ratio {SLOWEST:g} "
                                             f"({s:g} x |d_2|) and the move's")
    if d1 * d2 < 0 and rho < 1.0:
        larger = max(base, e_m) if polynomial is not None else s * abs(d2)
        return min(s * abs(d2), larger), (f"{said}: they disagree in sign, an oscillation about the limit, which "
                                          f"lies between the last two levels: the larger of e_P and the move's, "
                                          f"at most {s:g} x |d_2|")
    if rho < 1.0:
        return max(base, s * abs(d2), e_m), (f"{said}: they disagree in rate, slower than the halving allows: "
                                             f"the larger of e_P, {s:g} x |d_2| and the move's")
    if polynomial is None:
        return None, f"{said}: the difference does not shrink with the levels (not converging), no ladder estimate"
    return max(base, s * abs(d2), e_m), (f"{said}: the difference does not shrink with the levels (not "
                                         f"converging): the larger of e_P, {s:g} x |d_2| and the move's")


def _unbounded(name: str) -> str:
    """Why a quantity :func:`ngcontact.macro.singular_maxima.growing` says grows (a safety factor: falls) has no
    converged value."""
    if name.startswith(SM.SAFETY_FACTOR):
        return (f"it falls with every halving of the elements holding it, and its reciprocal (the utilisation "
                f"sigma_eq / sigma_u) grows by differences that do not contract as a converging stress's do "
                f"(the last at least {MS.GROWING:g} of the first), as 1 / log r or r^(1 - lambda) falls on the meshes "
                "the levels reach, so this minimum has no converged value there, whatever the ladder's estimate")
    return (f"it grows with every halving of the elements holding it, by differences above its sampling error "
            f"that do not contract as a converging stress's do (the last at least {MS.GROWING:g} of the first), as "
            "log r or r^(lambda - 1) grows on the meshes the levels reach, so this maximum has no converged value "
            "there, whatever the ladder's estimate")
