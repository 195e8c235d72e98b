"""The reference an estimate of a maximum away from the singular points is measured against.

An effectivity (estimate / true error, issue 35) needs the limit of the quantity it judges.  The maxima
away from the singular points (:mod:`ngcontact.macro.away_maxima`) are suprema over a set,

    M_B(r) = sup { sigma_eq(x) : x in B, |x - x_i| > r },        S(r) = inf { sigma_u / sigma_eq^micro(x) },

the second over the interface points outside the balls (the safety factor of paper eq. 78, with the micro
stresses of eq. 75).  Their limit is that of the field (a refined solution) and that of the supremum over
the set (a dense sampling).  A run samples its own solution at a few points per element, which is right
for the estimate of that run (its sampling error is a share it estimates); a reference sampled the same way
carries the sampling error of its own mesh, and where the supremum sits at a corner of the set with a large
gradient, that error does not fall with the order at all.  The femur's bone stress and safety factor grow
towards the closed end of the interface at the bone's top, so their suprema are attained where the ball's
circle crosses the interface: a sample ``delta`` off that point misses the gradient times ``delta``
(the femur's safety factor falls by about 0.07 per mm towards the edge, so five samples per 1 mm
interface element, the nearest about 0.2 mm off the circle, miss about 0.014).

So the reference (:func:`reference`) solves at order :data:`ORDER` on the scene's mesh sizes divided by
:data:`DIVIDE`, with the elements where a ball's circle crosses the interface or leaves the bodies
(:func:`crossings`) refined :data:`LEVELS` times before the solve (Netgen's local refinement, 2D), so that
the interface samples there lie close to the crossing, and samples

* each body's stress on a lattice of :data:`LATTICE` intervals per element edge reaching the element's faces
  (:func:`ngcontact.macro.discretization_error.dense_rule`), outside the balls, and on :data:`RIM` points of
  each ball's circle (:func:`ngcontact.macro.away_maxima.circles`); a maximum on a circle carries the
  field's change to its neighbouring points as its sampling error (the distance to a crossing is at most one
  step);
* the safety factor at :data:`INTERFACE` points per interface element (the recovery's points,
  :func:`ngcontact.drivers.run_strength.linear_safety_factors`), the nearest a fraction ``1 / (INTERFACE - 1)``
  of an element ``2^LEVELS`` times smaller than the mesh's off the crossing;
* the peak pressure and the resultant at the same interface points (the maxima over whole bodies, mesh
  dependent at a singular point, as :func:`ngcontact.macro.discretization_error.headlines` takes them).

Its own error is stated by a companion (:func:`uncertainty`): the same rule on the mesh sizes divided by
``DIVIDE / 2``, whose difference to the reference bounds the companion's error and so, the error falling
with the mesh, the reference's; plus the reference's sampling error on the circles.
"""
from __future__ import annotations

from dataclasses import replace

import ngsolve as ng
import numpy as np

from ngcontact.drivers.run_macro import build_geometry, problem_of, solve_scene
from ngcontact.drivers.run_strength import linear_safety_factors
from ngcontact.fem.materials import tresca, von_mises
from ngcontact.macro import away_maxima as AM
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import error_indicator as EI
from ngcontact.macro import macro_measures as MM
from ngcontact.macro.macro_problem import MacroSolution

#: the scene's mesh sizes are divided by this for the reference
DIVIDE = 4
#: the order of the reference's solve
ORDER = 4
#: refinements, before the reference's solve, of the elements where a ball's circle crosses a boundary
LEVELS = 5
#: intervals per element edge of the lattice the stress is sampled on (2D; 3D: a quarter)
LATTICE = 24
#: points per ball's circle (2D) the stress is sampled on
RIM = 65536
#: points per interface element the safety factor is sampled at
INTERFACE = 21
#: the lattice's inset from the element's faces (reference coordinates; off the axis ``r = 0``)
INSET = 1e-6


def regions_at(mesh: ng.Mesh, points: np.ndarray, regions: tuple[str, ...]) -> np.ndarray:
    """Per point the index of the body of ``regions`` holding it, -1 outside the mesh."""
    located = mesh(*points.T)
    found = located["nr"] >= 0
    out = np.full(len(points), -1)
    index = mesh.MaterialCF({r: float(k) for k, r in enumerate(regions)}, default=-1.0)
    out[found] = np.rint(np.asarray(index(located[found])).ravel()).astype(int)
    return out


def crossings(mesh: ng.Mesh, exclusion: AM.Exclusion, regions: tuple[str, ...]) -> np.ndarray:
    """The points of the balls' circles (:data:`RIM` each) next to where a circle crosses the interface or
    leaves the bodies: where the body holding consecutive points changes."""
    rim = AM.circles(exclusion, RIM)
    label = regions_at(mesh, rim, regions)
    change = np.flatnonzero(label[1:] != label[:-1])
    return rim[np.unique(np.concatenate([change, change + 1]))]


def refined(scene, exclusion: AM.Exclusion, divide: int = DIVIDE, order: int = ORDER) -> MacroSolution:
    """``scene`` solved at ``order`` on its mesh sizes divided by ``divide`` (curved at that order), the elements
    at the :func:`crossings` refined :data:`LEVELS` times before the solve (2D; module docstring)."""
    d = scene.discretization
    geometry = build_geometry(scene, maxh=d.maxh / divide, interface_maxh=(d.interface_maxh or d.maxh) / divide,
                              order=order)
    problem, _ = problem_of(scene, geometry)
    mesh = problem.mesh
    if mesh.dim == 2:
        at = [tuple(p) for p in crossings(mesh, exclusion, (problem.rough, problem.counter))]
        for _ in range(LEVELS if at else 0):
            EI.refine_marked(mesh, EI.holding(mesh, at), order)
    return solve_scene(scene, replace(problem, mesh=mesh, order=order))


def suprema(sol: MacroSolution, exclusion: AM.Exclusion) -> dict[str, DE.Sample]:
    """Per body the largest von Mises and Tresca stress of ``sol`` outside the balls (``<name>_<body>_away``),
    over the lattice and the circles of the module docstring, with where each is attained; a maximum on a
    circle carries as its sampling error the difference to its neighbours on the circle (the field's change
    over one step, which bounds the distance to a crossing)."""
    mesh = sol.problem.mesh
    regions = (sol.problem.rough, sol.problem.counter)
    sig = MM.stress(sol)
    coords = ng.CF((ng.x, ng.y, ng.z)[:mesh.dim])
    rule = DE.dense_rule(mesh.dim, INSET, LATTICE if mesh.dim == 2 else LATTICE // 4)
    rim = AM.circles(exclusion, RIM) if mesh.dim == 2 else np.zeros((0, mesh.dim))
    label = regions_at(mesh, rim, regions)
    on_rim = np.zeros((len(rim), 3, 3))
    if (label >= 0).any():
        on_rim[label >= 0] = np.asarray(sig(mesh(*rim[label >= 0].T))).reshape(-1, 3, 3)
    out = {}
    for index, region in enumerate(regions):
        lattice = mesh.MapToAllElements(rule, mesh.Materials(region))
        xyz = np.asarray(coords(lattice)).reshape(-1, mesh.dim)
        kept = exclusion.outside(xyz)
        stress, xyz = np.asarray(sig(lattice)).reshape(-1, 3, 3)[kept], xyz[kept]
        for name, measure in (("von_mises", von_mises), ("tresca", tresca)):
            values = measure(stress)
            k = int(np.argmax(values))
            best = DE.Sample(float(values[k]), tuple(float(c) for c in xyz[k]))
            ring = np.where(label == index, measure(on_rim), -np.inf)
            if len(ring) and ring.max() > best.value:
                j = int(np.argmax(ring))
                step = max((abs(ring[j] - ring[i]) for i in (j - 1, (j + 1) % len(ring)) if np.isfinite(ring[i])),
                           default=0.0)
                best = DE.Sample(float(ring[j]), tuple(float(c) for c in rim[j]), sampling=float(step))
            out[f"{name}_{region}{AM.AWAY}"] = best
    return out


def safety_factors(scene, sol: MacroSolution, recovery, exclusion: AM.Exclusion) -> dict[str, DE.Sample]:
    """The smallest safety factor of ``sol`` over the interface (``safety_factor``) and over its points outside
    the balls (``safety_factor_away``; paper eq. 78 by the linear recovery ``recovery``), at
    :data:`INTERFACE` points per interface element."""
    dense = replace(scene, output=replace(scene.output, points_per_element=INTERFACE))
    return linear_safety_factors(dense, sol, recovery, exclusion.outside)


def sampled(scene, sol: MacroSolution, exclusion: AM.Exclusion, recovery=None, component: str | None = None
            ) -> dict[str, DE.Sample]:
    """The headline quantities of ``sol`` sampled densely: the peak pressure and the resultant (``component``)
    at :data:`INTERFACE` points per interface element, each body's maximum over the lattice
    (:func:`ngcontact.macro.discretization_error.headlines`: mesh dependent at a singular point), the
    :func:`suprema` and, with ``recovery`` (the scene has ``[strength]``), the :func:`safety_factors`."""
    out = DE.headlines(sol, INTERFACE, component, INSET)
    out.update(suprema(sol, exclusion))
    if recovery is not None:
        out.update(safety_factors(scene, sol, recovery, exclusion))
    return out


def reference(scene, exclusion: AM.Exclusion, recovery=None, component: str | None = None,
              divide: int = DIVIDE, order: int = ORDER) -> dict[str, DE.Sample]:
    """The reference of the module docstring: :func:`sampled` on :func:`refined`, outside the balls of
    ``exclusion`` (the run's, so that both take the same set)."""
    return sampled(scene, refined(scene, exclusion, divide, order), exclusion, recovery, component)


def uncertainty(found: dict[str, DE.Sample], companion: dict[str, DE.Sample]) -> dict[str, float]:
    """Per quantity the reference's own uncertainty (module docstring): its difference to the ``companion``
    (the same rule on the mesh sizes divided by ``DIVIDE / 2``) plus its own sampling error."""
    return {k: abs(v.value - companion[k].value) + v.sampling for k, v in found.items() if k in companion}
