"""The discretization error of a macro solution's headline quantities, from solves at neighbouring orders.

The headline quantities ``Q`` of a macro solution (:func:`headlines`): the peak interface pressure, the
interface resultant (its largest component), and per body the largest von Mises and Tresca stress (paper
eq. 77); the drivers add the strength check's safety factor.  Their error ``e_p = Q_p - Q`` at the scene's
order ``p`` is estimated from the same quantities at two neighbouring orders on the **same mesh**
(:func:`ladder`: ``p - 1, p, p + 1``; ``p, p + 1, p + 2`` at order 1; ``p - 2, p - 1, p`` at the highest
order).

Why one order more on the same mesh, not one uniform refinement
    A uniform refinement multiplies the unknowns by 4 in 2D and by 8 in 3D; one order more by about
    ``((p + 2) / (p + 1))^2`` in 2D (1.7 at order 3) and ``((p + 2) / (p + 1))^3`` in 3D (3.4 at order 2),
    and one order less costs less than the scene's own solve.  Each is solved from the reported solution
    interpolated into its space (:func:`start_at_order`), so its Newton steps are few.  The mesh, its
    curved boundary and the interface's sampling stay those of the reported solution, so the difference
    sees the polynomial error alone.  On a solution that is smooth on each element the p-error falls geometrically,
    ``|e_{p+1}| ~ rho |e_p|`` (Babuska-Guo), and three orders measure ``rho``; a singular point (a
    re-entrant corner, a change of boundary condition along a straight edge) slows or stops that fall,
    which the same three orders detect (below).  A refinement would need three meshes (a 64-fold cost in
    3D) to see a rate at all.

The estimate
    With the differences ``d_lo = Q_p - Q_{p-1}``, ``d_hi = Q_{p+1} - Q_p`` and their observed ratio
    ``rho = |d_hi| / |d_lo|``:

    * geometric convergence gives ``e_p = sum_{q >= p} d_q = d_hi / (1 - rho)``;
    * where the fall slows with the order (algebraic p-convergence near a weak singular point, such as
      the femur stem's cone-cylinder corner, where the ratio grows with the order), the geometric extrapolation
      from three orders underestimates.  ``e_p`` is bracketed by ``|d_hi| <= |e_p| <= |d_lo|`` as long as
      the error does not change sign from ``p`` to ``p + 1`` and at least halves from ``p - 1`` to ``p``;
      the logarithmic midpoint of that bracket is ``sqrt(|d_lo d_hi|)``.

    The estimate takes the larger of the two, the midpoint at most twice the extrapolation (where the
    ratio is tiny, ``|d_lo|`` is the pre-asymptotic error of order ``p - 1`` and says nothing of
    ``e_p``), times the factor of safety :data:`SAFETY` = 1.5 (as Roache's grid convergence index with
    three levels and an observed rate multiplies its extrapolation by 1.25):

        e_p = 1.5 max(g, min(m, 2 g)),    g = |d_hi| / (1 - rho),  m = sqrt(|d_lo d_hi|),

    so between 1.5 and 3 times the geometric extrapolation; ``how`` says which rules.  Where the two
    differences have opposite signs, the values oscillate about their limit, which lies between
    ``Q_p`` and ``Q_{p+1}`` while the oscillation decays (``rho < 1``): then ``e_p = 1.5 |d_hi|`` (the
    geometric sum would count an oscillation's swings as a drift).  A sharp
    extrapolation sits at an effectivity of 1 and falls below it as often as above: hence the factor.
    Its effectivity against the package's oracles (Lame's press fit with the interface compliance in
    series, a refined femur as reference) is tested in ``tests/macro/test_discretization_error.py`` and
    tabulated by ``scripts/macro_effectivity.py``.  At order 1
    the ladder is ``1, 2, 3``: 1.5 times the sum of ``|Q_2 - Q_1|`` and the extrapolation of order 2.

The mesh of an order-1 run
    An order-1 run leaves its mesh straight-sided (:data:`NEIGHBOUR_CURVE`): a curved boundary or
    interface is a polygon, whose vertices are corners of that polygon's own solution.  Orders 2 and 3
    on the polygon converge slowly there (ratios near 0.9, a stress maximum at a polygon vertex growing
    with the order like a singularity) and towards the polygon's solution, not the scene's.  So the
    neighbours of order 1 are solved on the same mesh curved at order 2 (:func:`neighbour_mesh`), the
    geometry an order-2 run has: ``d_lo = Q_2 - Q_1`` then carries the polygon's geometric error
    with the polynomial one, and ``d_hi`` sees a smooth boundary.  From order 2 on, the scene's own
    curved mesh serves every order of the ladder.

A stress maximum is the largest of the field's values at a few points per element; a refinement moves
those points, the orders on one mesh do not.  The maximum over a denser lattice of points on the
reported solution measures that share (``Sample.sampling``), and :data:`SAFETY` times it is added.

Where the orders agree to round-off (differences below :data:`NOISE` of the quantity, as a resultant that
balances the applied load at every order), the estimate is :data:`SAFETY` times the larger difference.

Where no estimate exists
    ``rho >= 1`` (:data:`NOT_CONVERGING`): the difference does not shrink with the order, so no error
    can be extrapolated from it.  A stress maximum that sits at a corner of the mesh's boundary (a vertex
    where two boundary labels meet or the boundary turns, :func:`corner_points`) at the two highest
    orders and grows with every order at ``rho > 1/2`` (:data:`SINGULAR_RATIO`) is a stress singularity:
    its value depends on the mesh and has no limit.  Either is reported as such, with no error
    (``error = None``) and ``met = false``, never as a small estimate.
"""
from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Callable

import ngsolve as ng
import numpy as np

from ngcontact.fem import elasticity
from ngcontact.fem.materials import tresca, von_mises
from ngcontact.macro import macro_measures as MM
from ngcontact.macro.macro_problem import MacroProblem, MacroSolution, space_and_frame

#: observed ratio of successive differences from which the quantity is taken as not converging
NOT_CONVERGING = 1.0
#: differences below this share of the quantity's magnitude are round-off and the solver's tolerance
NOISE = 1e-8
#: factor of safety on the extrapolated error (module docstring)
SAFETY = 1.5
#: a stress maximum at a corner that grows with the order at a ratio above this is a singularity
SINGULAR_RATIO = 0.5
#: a maximum closer to a corner than this share of the shortest boundary edge sits at that corner
AT_CORNER = 0.05
#: turning angle of the boundary at a vertex [rad] above which the vertex is a corner
CORNER_ANGLE = math.radians(30.0)
#: the order the mesh is curved at while the neighbours of an order-1 solution are solved (module docstring)
NEIGHBOUR_CURVE = 2


@dataclass(frozen=True)
class Sample:
    """One headline quantity of one solution: its value, where it is attained (a maximum) and the
    magnitude its relative error is taken against (default ``|value|``)."""

    value: float
    location: tuple[float, ...] | None = None
    scale: float | None = None
    sampling: float = 0.0       # how far a denser sampling of the same field moves a maximum

    @property
    def magnitude(self) -> float:
        return abs(self.value) if self.scale is None else max(abs(self.value), self.scale)


def ladder(order: int, max_order: int) -> tuple[int, int, int]:
    """The three orders the estimate of order ``order`` solves with (module docstring)."""
    if order <= 1:
        return (order, order + 1, order + 2)
    if order >= max_order:
        return (order - 2, order - 1, order)
    return (order - 1, order, order + 1)


@contextmanager
def neighbour_mesh(mesh: ng.Mesh, order: int) -> Iterator[ng.Mesh]:
    """``mesh`` as the neighbours of a solution of ``order`` are solved and sampled on (module docstring):
    itself, but curved at :data:`NEIGHBOUR_CURVE` for an order-1 solution on a straight-sided mesh, which
    is straight-sided again on leaving."""
    if order > 1 or mesh.GetCurveOrder() > 1:
        yield mesh
        return
    mesh.Curve(NEIGHBOUR_CURVE)
    try:
        yield mesh
    finally:
        mesh.Curve(1)


def start_at_order(sol: MacroSolution, problem: MacroProblem) -> ng.BaseVector:
    """``sol`` as a vector of ``problem``'s space (the same mesh, another order): the start of its solve.

    Each body's displacement is interpolated into the space of the other order, exactly where that
    order is higher (the spaces are nested on one mesh), so Newton starts next to the solution.
    """
    fes, _ = space_and_frame(problem)
    gfu = ng.GridFunction(fes)
    for k, region in enumerate((problem.rough, problem.counter)):
        gfu.components[k].Set(sol.gfu.components[k], definedon=problem.mesh.Materials(region))
    return gfu.vec


# ------------------------------------------------------------------ the quantities of one solution
def body_maxima(sol: MacroSolution, dense_inset: float = 1e-3,
                keep: Callable[[np.ndarray], np.ndarray] | None = None) -> dict[str, Sample]:
    """Per body the largest von Mises and Tresca stress (``von_mises_<region>``, ``tresca_<region>``),
    sampled as :func:`ngcontact.macro.macro_measures.field_extrema` samples, with their location, and
    the maximum's sampling error: how much larger the maximum over a denser lattice of points per
    element (:func:`dense_rule`, moved ``dense_inset`` inwards) is.  A refinement moves the sample points;
    the orders on one mesh do not, so this share of the error is measured apart.  A tiny ``dense_inset``
    reaches the elements' faces, where a maximum on the boundary is attained (the mesh levels of
    :mod:`ngcontact.drivers.macro_refinement`, where this offset outgrows the orders' differences).
    ``keep``: of an array of points (one row each) those the maxima are taken over (default: all; a body
    without such a point has no entry)."""
    p = sol.problem
    mesh = p.mesh
    sig = MM.stress(sol)
    coords = ng.CF((ng.x, ng.y, ng.z)[:mesh.dim])
    out: dict[str, Sample] = {}
    for region in (p.rough, p.counter):
        where = mesh.Materials(region)
        mips = mesh.MapToAllElements(MM._sample_rule(mesh.dim), where)
        s = np.asarray(sig(mips)).reshape(-1, 3, 3)
        lattice = mesh.MapToAllElements(dense_rule(mesh.dim, dense_inset), where)
        dense = np.asarray(sig(lattice)).reshape(-1, 3, 3)
        xyz = np.asarray(coords(mips)).reshape(-1, mesh.dim)
        if keep is not None:
            inside = keep(xyz)
            s, xyz = s[inside], xyz[inside]
            dense = dense[keep(np.asarray(coords(lattice)).reshape(-1, mesh.dim))]
            if not len(s) or not len(dense):
                continue
        for name, measure in (("von_mises", von_mises), ("tresca", tresca)):
            values = measure(s)
            k = int(np.argmax(values))
            finer = max(float(measure(dense).max()) - float(values[k]), 0.0)
            out[f"{name}_{region}"] = Sample(float(values[k]), tuple(float(c) for c in xyz[k]), sampling=finer)
    return out


def dense_rule(dim: int, inset: float = 1e-3, intervals: int | None = None) -> ng.IntegrationRule:
    """A lattice of points in the reference element (``intervals`` per edge, default 6 in 2D, 4 in 3D), moved
    ``inset`` inwards as :func:`ngcontact.macro.macro_measures.field_extrema`'s points are."""
    n = intervals or (6 if dim == 2 else 4)
    span = 1.0 - (dim + 1) * inset
    pts = [tuple(inset + span * c / n for c in idx) for idx in np.ndindex(*(n + 1,) * dim) if sum(idx) <= n]
    return ng.IntegrationRule(pts, [0.0] * len(pts))


def headlines(sol: MacroSolution, points_per_element: int = 5, component: str | None = None,
              dense_inset: float = 1e-3) -> dict[str, Sample]:
    """The headline quantities of ``sol`` (module docstring): ``peak_pressure``, ``resultant_<component>``
    (default: the largest component; its relative error against the interface's total traction
    ``int |tau| w ds`` where the resultant nearly cancels, as in a press fit) and :func:`body_maxima`."""
    p = sol.problem
    if p.mesh.dim == 2:
        prof = MM.interface_profile(sol, points_per_element)
        names = [n for n in prof if n in ("x", "y", "r", "z")]
    else:
        prof = MM.interface_surface(sol)
        names = ["x", "y", "z"]
    k = int(np.argmax(prof["pressure"]))
    out = {"peak_pressure": Sample(float(prof["pressure"][k]), tuple(float(prof[n][k]) for n in names))}
    res = MM.resultant(sol)
    comp = max(res, key=lambda c: abs(res[c])) if component is None else component
    out[f"resultant_{comp}"] = Sample(res[comp], None, traction_magnitude(sol))
    out.update(body_maxima(sol, dense_inset))
    return out


def traction_magnitude(sol: MacroSolution) -> float:
    """``int_S0 |tau| w ds``: the force the interface carries, whatever its resultant."""
    p = sol.problem
    tau = MM.interface_tractions(sol)
    size = ng.sqrt(sum(t * t for t in tau))
    return float(ng.Integrate(size * elasticity.weight(p.setting), p.mesh, ng.BND,
                              definedon=p.mesh.Boundaries(p.interface), order=2 * p.order + 2))


# ------------------------------------------------------------------ singular points
def corner_points(mesh: ng.Mesh) -> np.ndarray:
    """Vertices of the mesh's boundary (the interface included) where two boundary labels meet or, in 2D,
    the boundary turns by more than :data:`CORNER_ANGLE`, one row of coordinates each.  In 3D the
    vertices on the edges between labelled faces."""
    labels, edges, pts = boundary_vertices(mesh)
    corners = [v for v, names in labels.items() if len(names) > 1]
    if mesh.dim == 2:
        corners += [v for v, nb in edges.items() if len(labels[v]) == 1 and _turn(pts, v, nb) > CORNER_ANGLE]
    return pts[sorted(set(corners))] if corners else np.zeros((0, mesh.dim))


def boundary_vertices(mesh: ng.Mesh, bodies_only: bool = False
                      ) -> tuple[dict[int, set[str]], dict[int, list[int]], np.ndarray]:
    """Per boundary vertex its labels and its neighbours along the boundary, and every vertex's point;
    ``bodies_only``: without the boundary elements inside one body (:func:`internal_faces`)."""
    labels: dict[int, set[str]] = {}
    edges: dict[int, list[int]] = {}
    inner = internal_faces(mesh) if bodies_only else set()
    for el in mesh.Elements(ng.BND):
        vs = [v.nr for v in el.vertices]
        if tuple(sorted(vs)) in inner:
            continue
        for v in vs:
            labels.setdefault(v, set()).add(el.mat)
            edges.setdefault(v, []).extend(w for w in vs if w != v)
    return labels, edges, np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])


def internal_faces(mesh: ng.Mesh) -> set[tuple[int, ...]]:
    """The facets (sorted vertex numbers) between two simplices of one body: labelled boundary elements there
    (a solid's internal faces, as the 3D femur's stem has where its cone and cylinders meet) bound no body."""
    seen: dict[tuple[int, ...], str] = {}
    out = set()
    for el in mesh.Elements(ng.VOL):
        vs = [v.nr for v in el.vertices]
        for k in range(len(vs)):
            facet = tuple(sorted(vs[:k] + vs[k + 1:]))
            if seen.get(facet) == el.mat:
                out.add(facet)
            seen[facet] = el.mat
    return out


def _turn(pts: np.ndarray, v: int, neighbours: list[int]) -> float:
    """The turning angle of a 2D boundary at vertex ``v`` between its two boundary edges (0: straight)."""
    if len(neighbours) != 2:
        return math.pi
    a, b = pts[neighbours[0]] - pts[v], pts[v] - pts[neighbours[1]]
    cos = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return math.acos(max(-1.0, min(1.0, cos)))


def shortest_boundary_edge(mesh: ng.Mesh) -> float:
    """The shortest edge of the mesh's boundary elements."""
    pts = np.array([mesh[ng.NodeId(ng.VERTEX, i)].point for i in range(mesh.nv)])
    best = math.inf
    for el in mesh.Elements(ng.BND):
        vs = [v.nr for v in el.vertices]
        for i in range(len(vs)):
            best = min(best, float(np.linalg.norm(pts[vs[i]] - pts[vs[i - 1]])))
    return best


def at_corner(location: tuple[float, ...] | None, corners: np.ndarray, h: float) -> tuple[float, ...] | None:
    """The corner a maximum sits at (within :data:`AT_CORNER` ``h``), or None."""
    if location is None or not len(corners):
        return None
    dist = np.linalg.norm(corners - np.asarray(location), axis=1)
    k = int(np.argmin(dist))
    return tuple(float(c) for c in corners[k]) if dist[k] <= AT_CORNER * h else None


# ------------------------------------------------------------------ the estimate
@dataclass(frozen=True)
class Estimate:
    """The estimated discretization error of one headline quantity at the reported order."""

    name: str
    value: float
    error: float | None          # None: no error can be estimated (not converging, singular)
    scale: float                 # the magnitude the relative error is taken against
    ratio: float                 # observed ratio of successive differences, rho
    orders: tuple[int, int, int]
    how: str
    singular_at: tuple[float, ...] | None = None
    counted: bool = True                       # held to the tolerance (ngcontact.macro.away_maxima.settle)
    location: tuple[float, ...] | None = None  # where the reported value is attained (a maximum)

    @property
    def relative_error(self) -> float | None:
        if self.error is None:
            return None
        if self.scale > 0:
            return self.error / self.scale
        return 0.0 if self.error == 0 else None

    def quantity(self, tolerance: float, absolute: bool = False) -> dict[str, Any]:
        """The verdict's entry (the format of :func:`ngcontact.cell.admissibility.quantities`); ``absolute``:
        the error itself is held to ``tolerance`` (a fraction), as a cell's contact fraction is."""
        rel = self.relative_error
        if absolute:
            controlled = self.error
            rel = None if self.error is None else (self.error / abs(self.value) if self.value else None)
        else:
            controlled = rel
        out: dict[str, Any] = {"name": self.name, "value": self.value, "error": self.error,
                               "relative_error": rel, "controlled": "absolute" if absolute else "relative",
                               "met": controlled is not None and controlled <= tolerance, "counted": self.counted,
                               "how": self.how,
                               "orders": list(self.orders),
                               "ratio": self.ratio if math.isfinite(self.ratio) else None}
        if self.singular_at is not None:
            out["singular_at"] = list(self.singular_at)
        if self.location is not None:
            out["location"] = list(self.location)
        return out


def estimate(name: str, by_order: dict[int, Sample], order: int, corners: np.ndarray | None = None,
             h: float = 0.0) -> Estimate:
    """The error of ``by_order[order]`` from the three orders of ``by_order`` (module docstring);
    ``corners`` and ``h`` (:func:`corner_points`, :func:`shortest_boundary_edge`) detect a singular maximum."""
    lo, mid, hi = sorted(by_order)
    q = {k: s.value for k, s in by_order.items()}
    d_lo, d_hi = q[mid] - q[lo], q[hi] - q[mid]
    rho = abs(d_hi) / abs(d_lo) if d_lo != 0 else (0.0 if d_hi == 0 else math.inf)
    scale = by_order[order].magnitude
    base: dict[str, Any] = dict(name=name, value=q[order], scale=scale, ratio=rho, orders=(lo, mid, hi),
                                location=by_order[order].location)
    head = f"orders {lo}, {mid}, {hi} on the scene's mesh: differences {d_lo:.3g}, {d_hi:.3g} (ratio {rho:.2g})"
    if max(abs(d_lo), abs(d_hi)) <= NOISE * scale:
        return Estimate(**base, error=SAFETY * max(abs(d_lo), abs(d_hi)),
                        how=f"{head}: the orders agree to round-off and the solver's tolerance")
    corner = None if corners is None else at_corner(by_order[hi].location, corners, h)
    growing = abs(q[lo]) < abs(q[mid]) < abs(q[hi]) and rho > SINGULAR_RATIO
    if corners is not None and corner is not None and growing \
            and corner == at_corner(by_order[mid].location, corners, h):
        return Estimate(**base, error=None, singular_at=corner,
                        how=f"{head}: the maximum sits at the corner {_point(corner)} and grows with every order: "
                            "a stress singularity, whose value depends on the mesh and does not converge")
    if rho >= NOT_CONVERGING:
        return Estimate(**base, error=None,
                        how=f"{head}: the difference does not shrink with the order, so no error can be "
                            "extrapolated from it (not converging)")
    geometric, bracket = abs(d_hi) / (1.0 - rho), math.sqrt(abs(d_lo * d_hi))
    if d_lo * d_hi < 0:
        raw, rule = abs(d_hi), (f"the differences alternate in sign, so the limit lies between orders {mid} and "
                                f"{hi}: {SAFETY:g} x |d_hi|")
    elif geometric >= bracket:
        raw, rule = geometric, f"{SAFETY:g} x the geometric extrapolation |d_hi| / (1 - ratio)"
    else:
        raw = min(bracket, 2.0 * geometric)
        rule = (f"the differences fall unevenly: {SAFETY:g} x sqrt(|d_lo d_hi|) (at most twice the geometric "
                f"extrapolation {geometric:.3g})")
    e_mid = SAFETY * raw
    sampled = by_order[order].sampling
    if sampled > 0:
        rule += f"; plus {SAFETY:g} x the maximum's sampling error {sampled:.3g}"
    if order == lo:
        return Estimate(**base, error=SAFETY * (abs(d_lo) + raw + sampled),
                        how=f"{head}; {SAFETY:g} x (|d_lo| + the error of order {mid}), that by {rule}")
    if order == hi:
        return Estimate(**base, error=rho * e_mid + SAFETY * sampled,
                        how=f"{head}; ratio x the error of order {mid} by {rule}")
    return Estimate(**base, error=e_mid + SAFETY * sampled, how=f"{head}; {rule}")


def _point(xyz: tuple[float, ...]) -> str:
    return "(" + ", ".join(f"{c:.4g}" for c in xyz) + ")"
