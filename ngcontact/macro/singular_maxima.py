"""Whether a body's largest stress has a converged value: the interface's closed ends, a mesh check at corners.

The order ladder (:mod:`ngcontact.macro.discretization_error`) estimates the error of a stress maximum
from the orders ``p - 1, p, p + 1`` on one mesh.  The maximum is taken over sample points of each
element (at a small inset from its faces), so what the orders converge to is the stress **at those
points**: a limit that exists for every mesh but moves with it.  Where the exact stress is bounded and
smooth, that limit is within the sampling error of the maximum, and the ladder's estimate stands.  Where
it is not, the ladder is silent:

Why a corner's maximum needs a mesh check
    Near a vertex of a body's boundary where the boundary turns or its data change (a re-entrant corner,
    the end of the interface where the law's traction stops, a clamp meeting a free face), the stress of
    linear elasticity behaves like ``r^(lambda - 1)`` in the distance ``r`` from the vertex (Williams
    1952), with ``lambda`` the smallest eigenvalue of the wedge with its two faces' conditions: below 1 at
    a re-entrant corner or a clamped-free corner (the stress grows without bound), and a term
    ``log r`` where the two faces' tractions do not match at the vertex (a pressure or shear that ends
    with a jump, as a press fit's does where the bone ends).  Such a maximum is unbounded: its value is
    set by the element size at the vertex and the sample points' inset, and every order on the mesh
    agrees on it.  A corner with ``lambda > 1`` has a bounded stress that converges, but slowly
    (algebraically in the element size), and the geometric fall of the order ladder overstates the
    rate.

Where the interface ends closed on a free boundary
    At a vertex where the interface ends on a boundary without support (free or loaded: the femur's bone
    top and the stem above it, a block's free side) while the interface is closed there (pressure above
    :data:`CLOSED` of its peak, :func:`closed_ends`), each body's traction jumps from the law's to none (or
    to a different load) and the frictional or stiff tangential coupling ends: a straight edge with a
    shear step has ``sigma ~ (2 tau / pi) log r``, a 90-degree edge whose faces' shears disagree a
    ``log r`` term, a face held tangentially next to a free face ``r^(lambda - 1)`` with ``lambda < 1``.
    Every stress maximum of both bodies is then reported as mesh dependent, singular at that end, without
    a solve: its largest stress is unbounded, and a maximum elsewhere on a coarse mesh is overtaken there
    under refinement (:func:`at_closed_ends`).  So is the safety factor of eq. 78: the micro stresses are
    linear in the interface's stress and strain (eq. 75), which grow towards that end.  Their
    counterparts away from the singular points converge (:mod:`ngcontact.macro.away_maxima`; maxima named
    ``*_away`` are not checked here).  An end on a supported boundary (a symmetry plane, as Lame's quarter ring has) is
    a mirror, not an end, and is left to the check below.

The check
    Every element with a vertex at a corner of the mesh's boundary (:func:`corners_of`: where two boundary
    labels meet or the boundary kinks by more than :data:`SHARP`) and the elements holding a body's
    maximum are refined :data:`LEVELS` times (Netgen's local refinement, on copies of the mesh: the reported
    solution stays on the scene's), each level solved at the scene's order from the last level's solution
    interpolated into its space (the meshes are nested, so the solve starts next to its solution).  Each
    level halves the elements at the corners, so the sample points there move closer to the vertex by a
    factor 2.  The body's maximum and the largest stress within one boundary edge of each corner are taken
    on every level (``Q_0, Q_1, Q_2``), each with its sampling error (the denser lattice's excess).

    A maximum grows when its levels have no limit by the one test of
    :func:`ngcontact.macro.mesh_sequence.growing`, the test the levels at the singular points make
    (:mod:`ngcontact.macro.away_sequence`): it rises at each level by more than round-off and the sampling
    error of the level it starts from, and the last rise is at least
    :data:`~ngcontact.macro.mesh_sequence.GROWING` of the first (``log r`` gains a constant per halving,
    ``r^(lambda - 1)`` a factor ``2^(1 - lambda)``, a converging maximum's rises contract by ``2^-0.544``
    or faster).  The ladder's estimate plays no part: it measures the polynomial error of one mesh, and a
    quantity without a limit has no error it could be compared with.  Then:

    * a corner whose stress so grows and reaches :data:`RELEVANT` of the body's maximum makes that maximum
      **mesh dependent, singular at** the corner (``error = None``, ``met = false``), never a small
      estimate; so does a body maximum that grows so;
    * a body maximum that sits at a corner (within :data:`~ngcontact.macro.discretization_error.AT_CORNER`
      of the scene's shortest boundary edge) and whose levels neither converge nor grow has no rate and
      no limit that could be extrapolated: mesh dependent as well;
    * otherwise the sequence's estimate is taken where it exceeds the ladder's, so a slowly converging
      corner is estimated from the mesh.  The value reported is the scene mesh's ``Q_0`` (the solution
      stays on it), so its error is the move the levels made, ``|Q_2 - Q_0|``, plus the error left after
      the finest level (:func:`ngcontact.macro.mesh_sequence.sequence_error`, the geometric tail of the
      level differences with the factor of safety); a sequence that does not converge away from the
      corners takes at least that move plus its last difference times the factor of safety.

A corner whose stress grows but stays below :data:`RELEVANT` of the body's maximum leaves the maximum
as it is: its value is the largest stress away from that corner, which the corner reaches only after
many more halvings (a ``log r`` term gains a constant per halving).  A maximum the order ladder already
found singular stays singular.  The check costs about one solve of the scene (two warm-started solves
on meshes a little larger than the scene's); a scene whose interface ends closed needs none.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Callable

import ngsolve as ng
import numpy as np

from ngcontact.fem.materials import tresca, von_mises
from ngcontact.macro import discretization_error as DE
from ngcontact.macro import error_indicator as EI
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import mesh_sequence as MS
from ngcontact.macro.macro_problem import MacroSolution

#: local refinements at the corners (three values with the scene's mesh: an observed rate)
LEVELS = 2
#: a corner whose stress grows without bound but stays below this share of the body's maximum leaves the
#: maximum as it is (module docstring)
RELEVANT = 0.5
#: the share of the peak pressure above which the interface is closed at its end
CLOSED = 1e-3
#: turning angle of a boundary at a vertex of one label above which the vertex is a corner of the check (a
#: kink of the geometry; the vertices of a coarse polygon approximating an arc turn by less)
SHARP = math.radians(60.0)
#: the stress measures whose maxima are checked
STRESS = ("von_mises_", "tresca_")
#: the suffix of a maximum taken away from the singular points (:mod:`ngcontact.macro.away_maxima`), not checked
AWAY = "_away"
#: the safety factor of eq. 78, mesh dependent at a closed end as the stress maxima are
SAFETY_FACTOR = "safety_factor"


def checked_names(found: list[DE.Estimate]) -> list[str]:
    """The stress maxima over the whole bodies among the estimates."""
    return [e.name for e in found if e.name.startswith(STRESS) and not e.name.endswith(AWAY)]


def corner_maxima(sol: MacroSolution, corners: np.ndarray, radius: float
                  ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Per stress measure and body (``von_mises_<region>``, ``tresca_<region>``) the largest value at the
    sample points of :func:`ngcontact.macro.macro_measures.field_extrema` within ``radius`` of each corner
    (one entry per row of ``corners``; 0 where the body has no point there), and its sampling error: how much
    larger the largest value on the denser lattice of
    :func:`ngcontact.macro.discretization_error.dense_rule` within that radius is (as
    :func:`ngcontact.macro.discretization_error.body_maxima` measures a body's)."""
    p = sol.problem
    mesh = p.mesh
    sig = MM.stress(sol)
    coords = ng.CF((ng.x, ng.y, ng.z)[:mesh.dim])
    out: dict[str, np.ndarray] = {}
    sampling: dict[str, np.ndarray] = {}
    for region in (p.rough, p.counter):
        by_rule = []
        for rule in (MM._sample_rule(mesh.dim), DE.dense_rule(mesh.dim)):
            mips = mesh.MapToAllElements(rule, mesh.Materials(region))
            xyz = np.asarray(coords(mips)).reshape(-1, mesh.dim)
            near = np.linalg.norm(xyz[:, None, :] - corners[None, :, :], axis=2) <= radius
            by_rule.append((np.asarray(sig(mips)).reshape(-1, 3, 3), near))
        for name, measure in (("von_mises", von_mises), ("tresca", tresca)):
            coarse, dense = (np.where(near, measure(s)[:, None], 0.0).max(axis=0, initial=0.0)
                             for s, near in by_rule)
            out[f"{name}_{region}"] = coarse
            sampling[f"{name}_{region}"] = np.maximum(dense - coarse, 0.0)
    return out, sampling


def corners_of(mesh: ng.Mesh) -> np.ndarray:
    """The corners the check refines at (2D): the boundary vertices where two labels meet, and those of one
    label where the boundary turns by more than :data:`SHARP`; one row of coordinates each."""
    labels, edges, pts = DE.boundary_vertices(mesh)
    found = [v for v, names in labels.items()
             if len(names) > 1 or DE._turn(pts, v, edges[v]) > SHARP]
    return pts[sorted(found)] if found else np.zeros((0, mesh.dim))


def closed_ends(sol: MacroSolution, points_per_element: int = 5) -> list[tuple[tuple[float, ...], float]]:
    """The ends of the interface on a boundary without support (free or loaded) where the interface is
    closed (pressure above :data:`CLOSED` of its peak), each with its pressure, the largest first (3D: the
    vertices of its boundary edges there, :func:`ngcontact.macro.macro_measures.interface_surface`; faces
    inside one body are no boundary)."""
    p = sol.problem
    labels, _, pts = DE.boundary_vertices(p.mesh, bodies_only=p.mesh.dim == 3)
    supported = {s.label for s in p.supports}
    ends = [v for v, names in labels.items()
            if p.interface in names and len(names) > 1 and not (names - {p.interface}) & supported]
    if not ends:
        return []
    if p.mesh.dim == 2:
        prof = MM.interface_profile(sol, points_per_element)
        xy = np.column_stack([prof[n] for n in prof if n in ("x", "y", "r", "z")][:2])
    else:
        prof = MM.interface_surface(sol)
        xy = np.column_stack([prof["x"], prof["y"], prof["z"]])
    pressure = np.asarray(prof["pressure"], dtype=float)
    peak = float(pressure.max(initial=0.0))
    out = []
    for v in ends:
        at = float(pressure[int(np.argmin(np.linalg.norm(xy - pts[v], axis=1)))])
        if peak > 0 and at > CLOSED * peak:
            out.append((tuple(float(c) for c in pts[v]), at))
    return sorted(out, key=lambda t: -t[1])


def at_closed_end(e: DE.Estimate, end: tuple[tuple[float, ...], float]) -> DE.Estimate:
    """``e`` (a stress maximum or the safety factor) reported as mesh dependent at the closed end ``end`` of
    the interface."""
    point, pressure = end
    what = ("neither body's largest stress has" if e.name != SAFETY_FACTOR else
            "the micro stresses, linear in the interface's stress and strain there (eq. 75), grow as well and "
            "the smallest safety factor has")
    return replace(e, error=None, singular_at=point,
                   how=f"{e.how}; the interface ends at {DE._point(point)} on a boundary without support while "
                       f"closed (pressure {pressure:.4g} there): the traction jumps there from the law's to none, "
                       "and the stress of both bodies grows towards that point like log r or r^(lambda - 1) "
                       f"(Williams 1952), so {what} a converged value: mesh dependent, singular at {DE._point(point)}")


def at_closed_ends(found: list[DE.Estimate], ends: list[tuple[tuple[float, ...], float]]) -> list[DE.Estimate]:
    """``found`` with every stress maximum over a whole body and the safety factor mesh dependent at the
    first of the closed ends ``ends`` (:func:`closed_ends`; none: ``found`` as it is)."""
    if not ends:
        return found
    names = set(checked_names(found)) | {SAFETY_FACTOR}
    return [at_closed_end(e, ends[0]) if e.name in names and e.singular_at is None else e for e in found]


def star(mesh: ng.Mesh, corners: np.ndarray) -> np.ndarray:
    """The volume elements that have a vertex at one of ``corners`` (all of them: a stress maximum at a
    vertex is sampled in each element around it), as a boolean array."""
    out = np.zeros(mesh.ne, dtype=bool)
    if not len(corners):
        return out
    pts = np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])
    tol = 1e-9 * float(np.abs(pts).max())
    at = {i for i in range(mesh.nv) if np.min(np.linalg.norm(corners - pts[i], axis=1)) <= tol}
    for el in mesh.Elements(ng.VOL):
        out[el.nr] = any(v.nr in at for v in el.vertices)
    return out


def local_levels(sol: MacroSolution, solve: Callable[..., MacroSolution], points: list[tuple[float, ...]],
                 corners: np.ndarray, radius: float, levels: int = LEVELS
                 ) -> list[tuple[dict[str, DE.Sample], tuple[dict[str, np.ndarray], dict[str, np.ndarray]]]]:
    """Per level the body maxima and :func:`corner_maxima` (within ``radius`` of ``corners``) of ``levels``
    solves, each on a copy of the last level's mesh (the first: ``sol``'s) refined at ``points``, at
    ``sol``'s order, each solved by ``solve(problem, start)`` from the last level's solution interpolated
    into its space (:func:`ngcontact.macro.discretization_error.start_at_order`: the meshes are nested)."""
    order = max(sol.problem.order, 1)
    out = []
    for _ in range(levels):
        mesh = ng.Mesh(sol.problem.mesh.ngmesh.Copy())
        EI.refine_marked(mesh, EI.holding(mesh, points) | star(mesh, corners), order)
        problem = replace(sol.problem, mesh=mesh)
        sol = solve(problem, DE.start_at_order(sol, problem))
        out.append((DE.body_maxima(sol), corner_maxima(sol, corners, radius)))
    return out


def growing(e: DE.Estimate, values: list[float], sampling: list[float] | None = None) -> bool:
    """Whether the levels ``values`` of the quantity ``e`` (the scene's mesh first; ``sampling``: their
    sampling errors) grow without a limit (:func:`ngcontact.macro.mesh_sequence.growing`): a maximum's
    magnitude, a safety factor's (a minimum's) reciprocal, the utilisation."""
    return MS.growing(values, e.scale, sampling, minimum=e.name.startswith(SAFETY_FACTOR))


def growing_corner(e: DE.Estimate, values: list[float], at_corners: np.ndarray,
                   sampling: np.ndarray | None = None) -> int | None:
    """The corner (column of ``at_corners``: levels x corners, the largest stress near each; ``sampling``: its
    sampling errors, default 0) whose stress grows without a limit (:func:`growing`, on the scale of the
    body's maximum ``e``) and reaches :data:`RELEVANT` of the body's maximum ``values[-1]`` on the finest
    level; the largest such, or ``None``."""
    grows = [k for k in range(at_corners.shape[1])
             if growing(e, list(at_corners[:, k]), None if sampling is None else list(sampling[:, k]))
             and at_corners[-1, k] >= RELEVANT * abs(values[-1])]
    return max(grows, key=lambda k: at_corners[-1, k]) if grows else None


def judged(e: DE.Estimate, samples: list[DE.Sample], at_corners: np.ndarray, corners: np.ndarray,
           h: float, sampling: np.ndarray | None = None) -> DE.Estimate:
    """The ladder's estimate ``e`` of a stress maximum judged by its values on the scene's mesh and the
    local levels ``samples``, and the largest stress near each of ``corners`` on each level
    (``at_corners``, levels x corners; ``sampling``: their sampling errors, default 0) (module docstring);
    ``h``: the scene's shortest boundary edge, of which a maximum within
    :data:`~ngcontact.macro.discretization_error.AT_CORNER` sits at a corner."""
    values = [s.value for s in samples]
    shown = ", ".join(f"{v:.4g}" for v in values)
    head = f"{e.how}; corner check ({len(values) - 1} local refinements at the boundary's corners): {shown}"
    if e.singular_at is not None:
        return replace(e, how=f"{head}: the order ladder found the singularity already")
    k = growing_corner(e, values, at_corners, sampling)
    if k is not None or growing(e, values, [s.sampling for s in samples]):
        where = tuple(float(c) for c in corners[k]) if k is not None else samples[-1].location
        near = "" if k is None else " (" + ", ".join(f"{v:.4g}" for v in at_corners[:, k]) + " next to it)"
        return replace(e, error=None, singular_at=where,
                       how=f"{head}: the stress grows with every halving of the elements at the corner{near}, as "
                           "r^(lambda - 1) or log r at a singular corner, so the body's largest stress has no "
                           "converged value: mesh dependent, singular"
                           + ("" if where is None else f" at {DE._point(where)}"))
    seq, how = MS.sequence_error(values, e.scale)
    corner = DE.at_corner(samples[-1].location, corners, h)
    if seq is None and corner is not None and len(values) >= 3 and abs(values[-1] - values[-2]) > (e.error or 0.0):
        return replace(e, error=None, singular_at=corner,
                       how=f"{head}; {how}, at the corner {DE._point(corner)}: the body's largest stress sits at a "
                           f"corner and moves with every halving of its elements: mesh dependent, singular at "
                           f"{DE._point(corner)}")
    moved = abs(values[-1] - values[0])
    said = f"the scene mesh's value, reported, lies {moved:.3g} from the finest level's"
    if seq is None:
        if e.error is None:
            return replace(e, how=f"{head}; {how}")
        last = moved + DE.SAFETY * abs(values[-1] - values[-2])
        return replace(e, error=max(e.error, last),
                       how=f"{head}; {how}; {said}: at least that plus {DE.SAFETY:g} x the last difference, "
                           f"{last:.3g}")
    total = moved + seq
    how = f"{how}; {said}: with the tail {total:.3g}"
    if e.error is None or total > e.error:
        return replace(e, error=total, singular_at=None, how=f"{head}; {how}, larger than the order ladder's")
    return replace(e, how=f"{head}; {how}, below the order ladder's")


def check(found: list[DE.Estimate], sol: MacroSolution, samples: dict[str, DE.Sample],
          solve: Callable[..., MacroSolution], levels: int = LEVELS) -> list[DE.Estimate]:
    """``found`` with every stress maximum judged by the local levels at the corners and the maxima of
    ``samples`` (the scene's order's, :func:`judged`); the other estimates unchanged."""
    names = checked_names(found)
    if not names:
        return found
    ends = closed_ends(sol)
    if ends:
        return at_closed_ends(found, ends)
    if levels < 1:
        return found
    mesh = sol.problem.mesh
    corners, h = corners_of(mesh), DE.shortest_boundary_edge(mesh)
    points = [loc for loc in (samples[n].location for n in names) if loc is not None]
    finer = local_levels(sol, solve, points, corners, h, levels)
    near = [corner_maxima(sol, corners, h)] + [n for _, n in finer]
    out = []
    for e in found:
        if e.name in names:
            e = judged(e, [samples[e.name]] + [m[e.name] for m, _ in finer],
                       np.array([n[e.name] for n, _ in near]), corners, h,
                       sampling=np.array([s[e.name] for _, s in near]))
        out.append(e)
    return same_body(out)


def _body(name: str) -> str:
    """The region of a stress maximum's name (``von_mises_<region>``, ``tresca_<region>``)."""
    return next((name[len(p):] for p in STRESS if name.startswith(p)), name)


def same_body(found: list[DE.Estimate]) -> list[DE.Estimate]:
    """Every stress maximum of a body with one found singular at a corner made singular at that corner too:
    ``sqrt(3)/2 tresca <= von_mises <= tresca``, so where one is unbounded, so is the other."""
    singular = {_body(e.name): e for e in found if e.name.startswith(STRESS) and e.singular_at is not None}
    out = []
    for e in found:
        hit = singular.get(_body(e.name)) if e.name.startswith(STRESS) and e.singular_at is None else None
        if hit is not None and hit.singular_at is not None:
            e = replace(e, error=None, singular_at=hit.singular_at,
                        how=f"{e.how}; {hit.name} grows without bound at the corner and sqrt(3)/2 tresca <= "
                            "von_mises <= tresca, so this maximum has no converged value either: mesh dependent, "
                            f"singular at {DE._point(hit.singular_at)}")
        out.append(e)
    return out
