"""Results of a load of the spectral small-slope cell (:mod:`ngcontact.cell.spectral.layered_cell`).

Results use the names of the FE cell (:mod:`ngcontact.cell.fe.measures`):
``contact_fraction`` (the share of the period in contact, its edges
located between grid points, below), ``mean_pressure``,
``mean_closure`` (the mean of ``J_n``), ``far_face_jump``,
``effective_stiffness`` (``d pbar / d Delta_interface`` at the current
contact set, the FE cell's ``(S^-1 - S_0^-1)^-1``; its normal component
only, also with friction) and the coefficients of
eq. 34 on the real contact set.

Contact edges in 2D: beyond an edge at ``a`` the gap of a smooth contact
grows like ``(x - a)^(3/2)``, so ``r = gap^(2/3)`` is a smooth function of
``x`` with a simple root at ``a``.  The collocated pressure is in error at
the last contact points, and that error perturbs the gap most at the first
open points and less the farther away they lie (on Westergaard's sinusoid
the root of the line through the first two open points is off by a
fraction of a grid step, that of a quartic fitted to points farther
away by ten times less).  So each edge is placed at
the root of the least-squares quartic of ``r`` over the window of open
points ``EDGE_WINDOW`` (shortened, in proportion, to a sixteenth of the open
run when the run is short, and to the reach below: the gap must be smooth at
the scale of the window; at least ``EDGE_MIN_POINTS`` points), when the fit
explains ``r`` to ``EDGE_FIT_RTOL`` of its size (the root then kept within
half a grid step of the last contact point and the first open point);
otherwise (short open runs, rough gaps) at the root of the line through the
first two open points, kept within the step between them.
(The other side's ``p^2``, linear for a ``sqrt`` edge, carries the
collocation error itself: 2e-5 of the fraction at 65,536 points.)

Contact edges in 3D: each row and each column of the grid is a profile that crosses the contact edge at some
angle ``theta`` to its normal; ``gap^(2/3)`` is linear in the distance normal to a smooth edge, so along the row
it is linear too (with slope over ``cos theta``), and the line through the first two open points places the
row's crossing as in 2D (:func:`row_weights`).  The rows' located lengths, summed, are the area by the midpoint
rule across the rows, and the columns' alike; their mean is the contact fraction.  The quartic is not fitted in
3D: a row crosses the edge obliquely, runs along it where it is tangent to a patch, and its window would reach
across the patch's curvature.  Counting the points in contact instead errs by a layer of points along the edges,
first order in the step with a constant several times the located edges' (``docs/benchmarks.md``, the random
64 x 64 map; ``tests/cell/test_spectral_cell.py`` on the bisinusoid).

The quartic's reach.  A least-squares quartic on ``[lo, hi]`` steps beyond
the edge converges to ``r`` at the rate of the largest Bernstein ellipse
about the window in which ``r`` is analytic: with the nearest singularity
of ``r`` at a distance ``R`` from the edge, ``rho = z + sqrt(z^2 - 1)``
with ``z = 2 R / hi - 1`` where it lies ahead of the edge (in the open run)
and ``z = 2 R / hi + 1`` behind it (in the contact patch), and the fit's
error goes as ``rho^-5``.  ``r`` has such singularities at the other end of
the edge's contact patch (on a Hertzian or Westergaard patch of width
``w`` the gap beyond one edge is singular at the other, ``R = w``), and at
each kink of a piecewise-linear gap (a height map's interpolant,
:func:`kinks`): ahead of the edge ``g0`` itself has a slope that jumps
there; behind it, in contact, ``g0''``'s Dirac makes the pressure
singular like ``ln|x - x_k|`` (its Hilbert transform), and the gap's
continuation beyond the edge, an integral of that pressure against the
logarithmic kernel, carries the singularity with it.  So the window
reaches at most ``1 / EDGE_REACH_SHARE`` of the distance from the last
contact point to the nearest of them (its patch's length; the nearest kink,
on either side): at half that distance ``rho >= 3 + sqrt 8``, ``rho^-5 <=
1.5e-4`` ahead and ``rho^-5 <= 1e-5`` behind, while a window reaching the
singularity (``z = 1`` ahead) does not converge at all.  Without that
reach, the window of a contact island a few hundred steps wide at a sample
of a random profile spanned up to twice the island, and the island's
located edges jumped by half a step or more between 2^18, 2^19 and 2^20
points (random profiles of 64 samples, seeds 2 and 7 at p = 0.001, one
step worth 1e-4 of the normal stiffness); within it they agree to a
twentieth of a step.  An edge within a few steps of a kink is left to the
line (the window holds too few points), as a smooth gap's narrow patch.

The normal stiffness in 2D (exact contact) on the located set.  The tangent
problem at a fixed contact set is a flat punch: its pressure ``p'`` is
singular like ``1/sqrt(distance)`` at each edge, and the stiffness of a set
of collocation points is that of the continuous set whose edges lie
:data:`PUNCH_EDGE` of a step beyond its last contact points.  The offset is
found against the periodic flat punch of half-width ``a`` on a period ``L``
of two half-planes, ``K = pi E* / (2 L ln(1 / sin(pi a / L)))``; it is the
same on every grid and every ``a``, since the local problem at an edge is
the same half-line problem (``tests/cell/test_spectral_located_stiffness.py``
measures it and the second-order convergence below).  The stiffness of the
set whose edges are at the located ``i + t`` is then ``K_set + sum_e dK_e
(t_e - PUNCH_EDGE)``, ``dK_e`` the change of ``K`` with edge ``e`` alone a
step out: the change ``K_grown - K_set`` with every edge that may move a
step out (three open points ahead, so its open run stays open) moved, shared
among them as their stress intensities squared, which the collocated ``p'``
at each last contact point is proportional to (the local problem again).
The set's ``K`` converges at first order in the step, the located one at
second order until the located edges' own error takes over (the spectral
refinement's section of ``docs/benchmarks.md``).  Where the edges are
located to a fraction of a step only (beside a kink of a map), the
stiffness's error is theirs: ``sum_e dK_e`` times their error in steps
(:mod:`~ngcontact.cell.spectral.contact_edges`).

Functions of a :class:`~ngcontact.cell.spectral.layered_cell.SpectralCell` ``cell``.
"""
from __future__ import annotations

import hashlib

import numpy as np

from ngcontact.cell.coefficients import Coefficients
from ngcontact.solvers.constrained_cg import masked_cg


#: open points (grid steps beyond the last contact point) that the edge's quartic is fitted to
EDGE_WINDOW = (40, 400)
#: fewest points of a (shortened) window: below, the line through the first two open points
EDGE_MIN_POINTS = 12
#: the share of the open run ahead of the edge that the window may reach
EDGE_RUN_SHARE = 16
#: the window reaches at most this share of the distance to its patch's other end or the nearest kink (docstring)
EDGE_REACH_SHARE = 2
#: largest rms misfit of that quartic, relative to the largest ``gap^(2/3)`` in the window
EDGE_FIT_RTOL = 1e-4
#: a point's second difference of the gap over the smaller of its neighbours' that makes it a kink
KINK_RATIO = 4.0
#: the share of a step that bounds an edge's located position by the line (calibration: ``contact_edges``)
LOCATED_STEP = 0.25
#: the share of a step that bounds an edge's located position by the quartic, with exact contact (the same)
FITTED_STEP = 0.1


def contact_fraction(cell, p: np.ndarray, gap: np.ndarray) -> float:
    """Contact area per period: edges located between grid points, in 3D along the rows and the columns
    (module docstring)."""
    return float(contact_weights(cell, p, gap).sum()) / cell.points


def contact_weights(cell, p: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """Each grid point's share of its step in the real contact set: 1 in contact, 0 open, except beside an edge
    located between points (module docstring): the last contact point ``i`` before an edge at ``i + t`` steps keeps
    ``min(t, 1/2) + 1/2`` of its step and the first open point gains ``max(t - 1/2, 0)``, so that the weights sum to
    the located contact length, and a smooth function summed with them (eq. 34's integrands) is integrated over the
    located set.  In 3D each row and each column is such a profile, its edges located by the line
    (:func:`row_weights`), and the two directions' weights are averaged."""
    on = p > 0
    if cell.dim == 3:
        root = np.maximum(gap, 0.0) ** (2.0 / 3.0)
        return (row_weights(on, root, 0) + row_weights(on, root, 1)) / 2.0
    weights = on.astype(float)
    for i, step, t in located_edges(cell, on, gap):
        shift = t - 0.5                             # open share of the step between i and the first open point
        weights[(i + step) % cell.grid if shift > 0 else i] += shift
    return weights


def row_weights(on: np.ndarray, root: np.ndarray, axis: int) -> np.ndarray:
    """The weights of :func:`contact_weights` of a 3D contact set ``on`` read as profiles along ``axis``, each
    edge at the root of the line through the first two open points' ``root = gap^(2/3)`` (:func:`line_offset`)."""
    weights = on.astype(float)
    n = on.shape[axis]
    for step in (1, -1):
        last = on & ~np.roll(on, -step, axis)                  # last contact point before an edge
        at = np.nonzero(last)
        shift = line_offset(np.roll(root, -step, axis)[last], np.roll(root, -2 * step, axis)[last],
                            ~np.roll(on, -2 * step, axis)[last]) - 0.5
        ahead = list(at)
        ahead[axis] = (at[axis] + step) % n
        np.add.at(weights, tuple(ahead), np.maximum(shift, 0.0))
        np.add.at(weights, at, np.minimum(shift, 0.0))
    return weights


def line_offset(first, second, beyond_open) -> np.ndarray:
    """Distance in grid steps, in ``[0, 1]``, from the last contact point to the root of the line through
    ``gap^(2/3)`` at the first two open points (``first``, ``second``); half a step where that line does not rise
    or the second point is in contact (``beyond_open`` false).  Arrays of edges, or one edge's numbers."""
    rising = (second > first) & beyond_open
    line = np.where(rising, first / np.where(rising, second - first, 1.0), 0.5)
    return 1.0 - np.clip(line, 0.0, 1.0)


def located_edges(cell, on: np.ndarray, gap: np.ndarray) -> list[tuple[int, int, float]]:
    """The 2D contact edges of the contact set ``on`` as ``(last contact point i, step, offset t)``: the edge at
    ``i + step t`` grid steps (:func:`edge_offset` on ``gap^(2/3)``), ``step = +1`` for an edge to the right of
    its patch, ``-1`` to the left; none in 3D (there :func:`row_weights`), in full contact or without contact."""
    if cell.dim == 3 or on.all() or not on.any():
        return []
    root = np.maximum(gap, 0.0) ** (2.0 / 3.0)       # smooth, with a simple root at a smooth contact edge
    at = np.flatnonzero(kinks(cell.g0))
    return [(int(i), step, edge_offset(root, on, int(i), step, at)[0])
            for step in (1, -1) for i in np.flatnonzero(on & ~np.roll(on, -step))]


def edge_offset(root: np.ndarray, on: np.ndarray, i: int, step: int,
                at: np.ndarray | None = None) -> tuple[float, bool]:
    """Distance in grid steps from the last contact point ``i`` to the edge (module docstring), and whether
    the quartic located it (``False``: the line through the first two open points).

    In ``[0, 1]`` from the line; from the quartic within half a step more on
    either side (the collocated solution may hold one point too many or too
    few in contact).

    ``root = gap^(2/3)`` on the periodic grid, ``step = +1`` (edge to the
    right of ``i``) or ``-1``; ``at`` the points at a kink of the gap
    (:func:`kinks`; none where not given).  The window reaches at most
    ``1 / EDGE_REACH_SHARE`` of the way to the other end of the edge's
    contact patch and to the nearest kink (module docstring).
    """
    offset = float(line_offset(root[(i + step) % root.size], root[(i + 2 * step) % root.size],
                               not on[(i + 2 * step) % root.size]))
    lo, hi = edge_window(root, on, i, step, at)
    fitted = quartic_root(root, i, step, lo, hi, offset) if hi - lo >= EDGE_MIN_POINTS else None
    return (offset, False) if fitted is None else (fitted, True)


def edge_window(root: np.ndarray, on: np.ndarray, i: int, step: int,
                at: np.ndarray | None = None) -> tuple[int, int]:
    """The quartic's window ``[lo, hi)`` in steps beyond the last contact point ``i`` (:func:`edge_offset`, module
    docstring): at most ``EDGE_WINDOW``, a sixteenth of the open run ahead, half the way to the patch's other end
    and to the nearest kink."""
    n = root.size
    ahead = (i + step * np.arange(1, n)) % n
    run = int(np.argmax(on[ahead])) if on[ahead].any() else n - 1     # open points before the next contact
    patch = int(np.argmin(on[(i - step * np.arange(n)) % n]))         # contact points back to the patch's end
    kink = int(np.abs((at - i + n // 2) % n - n // 2).min()) if at is not None and at.size else n
    hi = min(EDGE_WINDOW[1], run // EDGE_RUN_SHARE, patch // EDGE_REACH_SHARE, kink // EDGE_REACH_SHARE)
    return max(EDGE_WINDOW[0] * hi // EDGE_WINDOW[1], 2), hi


def quartic_root(root: np.ndarray, i: int, step: int, lo: int, hi: int, near: float) -> float | None:
    """The root nearest ``near`` (in steps beyond ``i``, within half a step of the last contact point and the
    first open point) of the least-squares quartic of ``root`` on the window ``[lo, hi)``; ``None`` where the fit
    misses ``root`` by more than ``EDGE_FIT_RTOL`` of its size or has no such root (module docstring)."""
    t = np.arange(lo, hi, dtype=float)
    r = root[(i + step * np.arange(lo, hi)) % root.size]
    coef, misfit, *_ = np.polyfit(t, r, 4, full=True)
    if not misfit.size or np.sqrt(misfit[0] / t.size) > EDGE_FIT_RTOL * float(r.max()):
        return None
    roots = np.roots(coef)
    real = roots[np.abs(roots.imag) <= 1e-9 * np.abs(roots)].real
    real = real[(real >= -0.5) & (real <= 1.5)]
    return float(real[np.argmin(np.abs(real - near))]) if real.size else None


def kinks(g0: np.ndarray) -> np.ndarray:
    """The points of a periodic 1D gap at a kink of its piecewise-linear interpolant
    (:mod:`~ngcontact.cell.spectral.contact_edges`): whose
    second difference ``c_i = |g_(i-1) - 2 g_i + g_(i+1)|`` exceeds :data:`KINK_RATIO` times the larger of
    ``c_(i-2)`` and ``c_(i+2)``, and rounding.  A Dirac of ``g0''`` falls on the one or two points beside the kink
    (on a point, or between two), while a smooth curvature varies little over two steps: where it crosses zero
    linearly, ``c_i = a |x_i|`` lies below ``a (|x_i| + 2 h)``, the larger of the two."""
    c = np.abs(np.roll(g0, 1) - 2.0 * g0 + np.roll(g0, -1))
    beside = np.maximum(np.roll(c, 2), np.roll(c, -2))
    return (c > KINK_RATIO * beside) & (c > 1e3 * np.finfo(float).eps * float(np.abs(g0).max()))


def edges_fitted(cell, p: np.ndarray, gap: np.ndarray) -> bool:
    """Whether every contact edge of a 2D cell with contact and an open gap is located by the quartic of
    :func:`edge_offset` (the sharp locator; module docstring); ``False`` in 3D, in full contact or without
    contact (no edge located between points)."""
    on = p > 0
    if cell.dim == 3 or on.all() or not on.any():
        return False
    root = np.maximum(gap, 0.0) ** (2.0 / 3.0)
    at = np.flatnonzero(kinks(cell.g0))
    return all(edge_offset(root, on, int(i), step, at)[1]
               for step in (1, -1) for i in np.flatnonzero(on & ~np.roll(on, -step)))


#: where the edge of the collocated flat punch lies beyond its last contact point, in grid steps (module docstring)
PUNCH_EDGE = 0.31
#: the open points ahead of a 2D edge that let it move a step out in :func:`edge_stiffness` (its open run stays open)
GROW_OPEN = 3
#: relative residual of the masked CG of :func:`effective_stiffness` (its ``K`` converges as its square)
STIFFNESS_RTOL = 1e-7


def effective_stiffness(cell, active: np.ndarray, gap: np.ndarray | None = None) -> dict:
    """``K = d pbar / d Delta_interface`` on the contact set ``active`` (the FE cell's names).

    At a fixed contact set a unit interface approach needs the pressure
    ``p'`` with ``(C p' + p'/k_n) = 1`` on the set and 0 elsewhere
    (uniform mode of ``C`` excluded: it is the bulk's share), so
    ``K = mean(p')``; the far-face stiffness adds the layers in series,
    ``S = (1/K + c0)^-1``, and the reference ``S_0 = 1/c0``.  ``K`` is the CG iterate's energy ``<1, p'>`` over the
    number of points, whose error ``|e|_A^2 <= |r|^2 / lambda_min`` is quadratic in the residual ``r``: at most
    ``STIFFNESS_RTOL^2`` times the condition number of the operator on the set (of the order of the points
    per direction) relative to ``K``.  In 2D with exact contact and the deformed ``gap`` given, ``K`` is that of
    the set with its edges located between points (:func:`edge_stiffness`, module docstring).
    """
    idx = np.flatnonzero(active.ravel())
    S0 = 1.0 / cell.c0
    if idx.size == 0:
        return {"components": ["n0"], "matrix": [[0.0]], "compliance": None, "total": [[0.0]],
                "reference": [[S0]]}
    # the fluctuation operator is singular on the full surface (constants): in full contact K is infinite
    if idx.size == cell.points and cell.enforcement == "exact":
        return {"components": ["n0"], "matrix": None, "compliance": [[0.0]], "total": [[S0]],
                "reference": [[S0]]}
    if gap is not None and cell.dim == 2 and cell.enforcement == "exact":
        K = edge_stiffness(cell, active, gap)["located"]
    else:
        K = float(tangent_pressure(cell, active).sum()) / cell.points
    S = 1.0 / (1.0 / K + cell.c0)
    return {"components": ["n0"], "matrix": [[K]], "compliance": [[1.0 / K]], "total": [[S]],
            "reference": [[S0]]}


def tangent_pressure(cell, active: np.ndarray) -> np.ndarray:
    """The pressure ``p'`` of a unit interface approach on the contact set ``active`` (:func:`effective_stiffness`)."""
    x, _ = masked_cg(cell.interface_compliance(uniform=False), active, np.ones(cell.shape), rtol=STIFFNESS_RTOL,
                     precondition=cell.inverse_compliance() if cell.preconditioned else None)
    return x


def edge_stiffness(cell, on: np.ndarray, gap: np.ndarray) -> dict:
    """The normal stiffness of a 2D contact set ``on`` with its edges located on the deformed ``gap`` (module
    docstring): ``{"set": K of the collocated set, "located": K of the located set, "edges": {(i, step): (t,
    dK)}}``, per edge (:func:`located_edges`) its offset and the change of ``K`` were it alone a step out.
    Two masked CG solves, once per cell, set and gap."""
    key = ("edge_stiffness", hashlib.sha1(on.tobytes() + np.maximum(gap, 0.0).tobytes()).hexdigest())
    return cell.cached(key, lambda: _edge_stiffness(cell, on, gap))


def _edge_stiffness(cell, on: np.ndarray, gap: np.ndarray) -> dict:
    n = cell.points
    x = tangent_pressure(cell, on)
    K = float(x.sum()) / n
    edges = located_edges(cell, on, gap)
    # an edge with fewer than GROW_OPEN open points ahead would close its open run a step out: not moved
    moved = [(i, step) for i, step, _ in edges if not on[(i + step * np.arange(1, GROW_OPEN + 1)) % n].any()]
    movers = moved or [(i, step) for i, step, _ in edges]       # none may move alone: all, for the shares
    grown = on.copy()
    for i, step in movers:
        grown[(i + step) % n] = True
    if not edges or grown.all():
        return {"set": K, "located": K, "edges": {}}
    change = float(tangent_pressure(cell, grown).sum()) / n - K
    # each edge's share of the change goes as its stress intensity squared, read off its last contact point
    per_weight = change / sum(float(x[i]) ** 2 for i, _ in movers)
    shares = {(i, step): (t, per_weight * float(x[i]) ** 2) for i, step, t in edges}
    located = K + sum(shares[e][1] * (shares[e][0] - PUNCH_EDGE) for e in moved)
    return {"set": K, "located": located, "edges": shares}


def coefficients(cell, active: np.ndarray, threshold: np.ndarray | None = None,
                 weights: np.ndarray | None = None) -> Coefficients:
    """Eqs. 34, 42-43 on the real contact set of a flat interface (``n = n0`` everywhere).

    ``K0 = k_n |S_real| / |T|`` on ``n0`` only, ``g_n = k_n mean(1_real g0)``,
    and the friction threshold ``G_t = mean(1_real G)`` per tangential
    direction (``G`` the Tresca threshold or ``mu p``), ``G_n = 0``.  ``1_real`` is ``active``, or the
    ``weights`` of :func:`contact_weights` where given (2D: the set with its edges located between points,
    whose ``K0`` is ``k_n`` times the reported contact fraction).
    """
    w = active.astype(float) if weights is None else weights
    frac = float(w.sum()) / cell.points
    kn0 = cell.k_n * frac
    g_n = cell.k_n * float((w * cell.g0).sum()) / cell.points
    G_t = float((w * threshold).sum()) / cell.points if threshold is not None else 0.0
    nt = cell.dim - 1
    K0 = np.zeros((cell.dim, cell.dim))
    K0[0, 0] = kn0

    def tangential(v):
        return v if nt == 1 else (v, v)
    return Coefficients(k_n=kn0, k_t=tangential(0.0), k_nt=tangential(0.0), g_n=g_n, g_t=tangential(0.0),
                        mu=tangential(0.0), G_n=0.0, G_t=tangential(G_t), K0=K0, contact_fraction=frac)
