"""Periodic 2D roughness profiles and the cells built from them.

A profile is the top of the rough body over one period ``[0, P]``: a chain of
straight lines and circular arcs (exact, meshed as rational quadratic
``spline3`` segments, hence curved high-order elements) or, for smooth
functions, of rational quadratic pieces interpolating the function and its
slope.  The summits lie at ``y = 0`` and the valleys reach down to negative
``y``; every builder returns a :class:`Profile`.

Profiles of paper Fig. 2 / Example 27 (full contact, paper eq. 34):

* :func:`rectangular_valley` -- width ``w``, depth ``d``;
* :func:`triangular_valley`  -- faces at angles ``beta_1, beta_2`` to the
  macro interface ``S_0``, depth ``d = w / (cot beta_1 + cot beta_2)``; the
  face lengths are ``a_i = d / sin beta_i`` and their micro normals
  ``(sin beta_1, cos beta_1)`` and ``(-sin beta_2, cos beta_2)``;
* :func:`semicircular_valley` -- radius ``a`` (an exact arc);

and :func:`flat`, :func:`sinusoid`, :func:`tabulated` (see
:mod:`ngcontact.geometry.tabulated` for the CSV reader).

Two arrangements of the counter body (:func:`interface_segments`):

``conforming``
    the counter body fills the valleys; the whole profile is ``contact``;
``summit``
    the counter body is flat at the summit height ``y = 0`` and touches only
    the summit plateaus (horizontal lines at ``y = 0``), which are
    ``contact``; the rest of the profile and the counter's face over the
    valleys are ``free`` surfaces bounding voids.  A profile without plateaus
    has no contact surface of positive length in this arrangement and is
    rejected: model rounded summits by a flat interface with a gap function
    (the small-slope model).

:func:`profile_cell` meshes a profile with :func:`ngcontact.geometry.cell2d.interface_cell`.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace

from ngcontact.errors import GeometryError
from ngcontact.geometry.cell2d import Cell, Segment, interface_cell

log = logging.getLogger(__name__)

ARRANGEMENTS = ("conforming", "summit")


# ------------------------------------------------------------------ pieces
@dataclass(frozen=True)
class Line:
    """Straight piece from ``start`` to ``end``."""

    start: tuple[float, float]
    end: tuple[float, float]

    def segments(self) -> list:
        return [Segment("line", (self.start, self.end))]

    def translated(self, dx: float) -> "Line":
        return Line(_move(self.start, dx), _move(self.end, dx))

    def split(self, x: float) -> tuple:
        (x0, y0), (x1, y1) = self.start, self.end
        t = (x - x0) / (x1 - x0)
        mid = (x, y0 + t * (y1 - y0))
        return Line(self.start, mid), Line(mid, self.end)


@dataclass(frozen=True)
class Arc:
    """Circular arc of radius ``radius`` about ``center`` from angle ``t0`` to ``t1``.

    Angles in radians; ``t0 < t1`` (counter-clockwise travel) and the span is
    at most ``pi/2``, so that one rational quadratic represents it exactly and
    ``x`` is monotone along it.
    """

    center: tuple[float, float]
    radius: float
    t0: float
    t1: float

    @property
    def start(self) -> tuple:
        return self._at(self.t0)

    @property
    def end(self) -> tuple:
        return self._at(self.t1)

    def _at(self, t: float) -> tuple:
        cx, cy = self.center
        return (cx + self.radius * math.cos(t), cy + self.radius * math.sin(t))

    def segments(self) -> list:
        half = 0.5 * (self.t1 - self.t0)
        tm = 0.5 * (self.t0 + self.t1)
        r = self.radius / math.cos(half)
        cx, cy = self.center
        control = (cx + r * math.cos(tm), cy + r * math.sin(tm))
        return [Segment("spline3", (self.start, control, self.end))]

    def translated(self, dx: float) -> "Arc":
        return replace(self, center=_move(self.center, dx))

    def split(self, x: float) -> tuple:
        cx, _ = self.center
        c = max(-1.0, min(1.0, (x - cx) / self.radius))
        candidates = [s * math.acos(c) + 2 * math.pi * k for s in (1, -1) for k in (-1, 0, 1, 2)]
        t = min(candidates, key=lambda u: abs(u - 0.5 * (self.t0 + self.t1)))
        return replace(self, t1=t), replace(self, t0=t)


@dataclass(frozen=True)
class Curve:
    """Rational quadratic piece ``start``, ``control``, ``end`` (a smooth approximant)."""

    start: tuple[float, float]
    control: tuple[float, float]
    end: tuple[float, float]

    def segments(self) -> list:
        return [Segment("spline3", (self.start, self.control, self.end))]

    def translated(self, dx: float) -> "Curve":
        return Curve(_move(self.start, dx), _move(self.control, dx), _move(self.end, dx))

    def split(self, x: float) -> tuple:
        raise GeometryError("shift", x, "a sampled curve can only be shifted by a multiple "
                         "of its sampling step (the cut must fall on a node)")


def _move(p, dx):
    return (p[0] + dx, p[1])


# ----------------------------------------------------------------- profile
@dataclass(frozen=True)
class Profile:
    """One period of a rough surface: ``pieces`` chain from ``x = 0`` to ``x = period``."""

    name: str
    period: float
    pieces: tuple[Line | Arc | Curve, ...]

    @property
    def depth(self) -> float:
        """Distance from the highest to the lowest point of the chain."""
        lo, hi = self.bounds
        return hi - lo

    @property
    def smallest_feature(self) -> float:
        """The shortest chord of its pieces: the smallest length the mesher must resolve."""
        return min(math.dist(p.start, p.end) for p in self.pieces)

    @property
    def bounds(self) -> tuple:
        """``(y_min, y_max)`` of the chain (arcs included exactly)."""
        ys = []
        for p in self.pieces:
            ys += [p.start[1], p.end[1]]
            if isinstance(p, Arc):
                for t in (-0.5 * math.pi, 0.5 * math.pi, 1.5 * math.pi):
                    if p.t0 < t < p.t1:
                        ys.append(p._at(t)[1])
            if isinstance(p, Curve):
                ys.append(p.control[1])   # convex hull bound
        return min(ys), max(ys)


def _check_positive(key: str, value: float) -> float:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise GeometryError(key, value, "must be a finite number > 0")
    return float(value)


def flat(period: float = 1.0) -> Profile:
    """The flat profile ``y = 0``."""
    P = _check_positive("period", period)
    return Profile("flat", P, (Line((0.0, 0.0), (P, 0.0)),))


def rectangular_valley(width: float, depth: float, period: float = 1.0) -> Profile:
    """A rectangular valley of ``width`` and ``depth`` centred in the period.

    Faces: plateaus of total length ``period - width`` and the valley bottom
    (parallel to ``S_0``), two walls of length ``depth`` (normal to ``S_0``).
    """
    P = _check_positive("period", period)
    w = _check_positive("width", width)
    d = _check_positive("depth", depth)
    if not w < P:
        raise GeometryError("width", width, f"must be < period = {P} (plateaus must remain)")
    x0, x1 = 0.5 * (P - w), 0.5 * (P + w)
    pts = [(0.0, 0.0), (x0, 0.0), (x0, -d), (x1, -d), (x1, 0.0), (P, 0.0)]
    return Profile("rectangular_valley", P, _polyline(pts))


def triangular_valley(angle_left: float, angle_right: float, width: float | None = None,
                      period: float = 1.0) -> Profile:
    """An asymmetric V-shaped valley; ``width=None`` makes a sawtooth spanning the period.

    Parameters
    ----------
    angle_left, angle_right
        Angles ``beta_1, beta_2`` (degrees, in ``(0, 90)``) of the descending
        (left) and ascending (right) face to the macro interface.
    width
        Opening of the valley at the summit line, ``<= period``; centred in
        the period.  ``None`` means the whole period (no plateaus).
    period
        Period ``P``.
    """
    P = _check_positive("period", period)
    for key, a in (("angle_left", angle_left), ("angle_right", angle_right)):
        if not (isinstance(a, (int, float)) and math.isfinite(a) and 0 < a < 90):
            raise GeometryError(key, a, "must be an angle in degrees in (0, 90)")
    w = P if width is None else _check_positive("width", width)
    if w > P:
        raise GeometryError("width", width, f"must be <= period = {P}")
    b1, b2 = math.radians(angle_left), math.radians(angle_right)
    d = w / (1.0 / math.tan(b1) + 1.0 / math.tan(b2))
    x0 = 0.5 * (P - w)
    xb = x0 + d / math.tan(b1)
    pts = [(0.0, 0.0), (x0, 0.0), (xb, -d), (x0 + w, 0.0), (P, 0.0)]
    name = "sawtooth" if width is None else "triangular_valley"
    return Profile(name, P, _polyline(pts))


def semicircular_valley(radius: float, period: float = 1.0) -> Profile:
    """A semicircular valley of ``radius`` centred in the period (two exact quarter arcs)."""
    P = _check_positive("period", period)
    a = _check_positive("radius", radius)
    if not 2 * a < P:
        raise GeometryError("radius", radius, f"must be < period / 2 = {P / 2}")
    c = (0.5 * P, 0.0)
    pieces = (Line((0.0, 0.0), (c[0] - a, 0.0)),
              Arc(c, a, math.pi, 1.5 * math.pi), Arc(c, a, 1.5 * math.pi, 2 * math.pi),
              Line((c[0] + a, 0.0), (P, 0.0)))
    return Profile("semicircular_valley", P, _snap(pieces))


def sinusoid(amplitude: float, period: float = 1.0, pieces: int = 16) -> Profile:
    """``y(x) = amplitude * (cos(2 pi x / period) - 1)``: summit at ``x = 0``, valley ``-2 amplitude``.

    Representation: ``pieces`` rational quadratic segments that interpolate
    ``y`` and its slope at ``pieces + 1`` equidistant nodes (control point at
    the intersection of the node tangents), i.e. a smooth (tangent-continuous)
    approximant, not the exact sinusoid; the geometric error decreases like
    ``(period / pieces)^3``.
    """
    P = _check_positive("period", period)
    A = _check_positive("amplitude", amplitude)
    if not (isinstance(pieces, int) and pieces >= 4 and pieces % 2 == 0):
        raise GeometryError("pieces", pieces, "must be an even integer >= 4")
    k = 2 * math.pi / P
    xs = [P * i / pieces for i in range(pieces + 1)]
    out = []
    for xa, xb in zip(xs[:-1], xs[1:]):
        ya, yb = A * (math.cos(k * xa) - 1), A * (math.cos(k * xb) - 1)
        sa, sb = -A * k * math.sin(k * xa), -A * k * math.sin(k * xb)
        if abs(sa - sb) < 1e-14 * max(1.0, A * k):
            xm = 0.5 * (xa + xb)
        else:
            xm = (yb - ya + sa * xa - sb * xb) / (sa - sb)
        out.append(Curve((xa, ya), (xm, ya + sa * (xm - xa)), (xb, yb)))
    out[0] = replace(out[0], start=(0.0, 0.0))
    out[-1] = replace(out[-1], end=(P, 0.0))
    return Profile("sinusoid", P, tuple(out))


def tabulated(x, y, *, path: str = "profile", lines=None, value: str = "y", what: str = "profile") -> Profile:
    """The periodic polyline through the points ``(x_i, y_i)``, ``x_0 = 0``, ``x_last = period``.

    Validated here: finite values, ``x`` strictly increasing from 0,
    ``y(0) = y(period)`` within ``1e-9`` of the larger of the period and the
    peak-to-valley height.  ``path`` names the source in error messages,
    ``lines`` the line of each point in its file (messages say ``[line n]``;
    without it ``[row i]``, counted from 0), ``value`` and ``what`` the
    names of the second column and of the function.
    """
    xs, ys = list(map(float, x)), list(map(float, y))

    def at(i: int) -> str:
        return f"{path}[line {lines[i]}]" if lines is not None else f"{path}[row {i}]"

    if len(xs) != len(ys) or len(xs) < 3:
        raise GeometryError(path, len(xs), f"needs columns x and {value} of equal length with at least 3 points")
    for i, (a, b) in enumerate(zip(xs, ys)):
        if not (math.isfinite(a) and math.isfinite(b)):
            raise GeometryError(at(i), (a, b), f"x and {value} must be finite numbers")
    if xs[0] != 0.0:
        raise GeometryError(f"{at(0)}.x", xs[0], f"the {what} must start at x = 0")
    for i in range(1, len(xs)):
        if not xs[i] > xs[i - 1]:
            raise GeometryError(f"{at(i)}.x", xs[i], f"x must increase strictly (previous x = {xs[i - 1]!r})")
    P = xs[-1]
    tol = 1e-9 * max(P, max(ys) - min(ys))
    if abs(ys[0] - ys[-1]) > tol:
        raise GeometryError(f"{at(len(ys) - 1)}.{value}", ys[-1],
                            f"the {what} must be periodic: the last row is x = period and repeats the first, "
                            f"{value}(period) = {value}(0) = {ys[0]!r} within {tol:.3g}")
    ys[-1] = ys[0]
    return Profile("tabulated", P, _polyline(list(zip(xs, ys))))


def _polyline(pts) -> tuple:
    pieces = [Line(a, b) for a, b in zip(pts[:-1], pts[1:]) if a != b]
    return _snap(tuple(pieces))


def _snap(pieces) -> tuple:
    """Make consecutive pieces share their end points exactly."""
    out = list(pieces)
    for i in range(1, len(out)):
        prev_end = out[i - 1].end
        if isinstance(out[i], Line):
            out[i] = replace(out[i], start=prev_end)
        elif isinstance(out[i - 1], Line):
            out[i - 1] = replace(out[i - 1], end=out[i].start)
    return tuple(out)


# ------------------------------------------------------------------- shift
def shifted(profile: Profile, fraction: float) -> Profile:
    """The same periodic surface seen through a window moved by ``fraction * period``.

    The new profile is ``y_new(x) = y(x + fraction * period)``: the piece that
    contains the cut is split (lines and arcs anywhere, sampled curves only at
    their nodes).  A cut on a vertical face is rejected.
    """
    P = profile.period
    s = (float(fraction) % 1.0) * P
    if s == 0.0:
        return profile
    tol = 1e-12 * P
    head, tail = [], []
    for p in profile.pieces:
        x0, x1 = p.start[0], p.end[0]
        if abs(x1 - x0) <= tol and abs(x0 - s) <= tol:
            raise GeometryError("shift", fraction, "the cut must not fall on a vertical face")
        if x1 <= s + tol:
            tail.append(p.translated(P - s))
        elif x0 >= s - tol:
            head.append(p.translated(-s))
        else:
            a, b = p.split(s)
            tail.append(a.translated(P - s))
            head.append(b.translated(-s))
    pieces = [_clean_x(p, P) for p in head + tail]
    return Profile(profile.name, P, _snap(tuple(pieces)))


def _clean_x(p, P):
    """Remove round-off from end points on the lateral edges."""
    def fix(q):
        x = q[0]
        if abs(x) < 1e-12 * P:
            x = 0.0
        elif abs(x - P) < 1e-12 * P:
            x = P
        return (x, q[1])
    if isinstance(p, Arc):
        return p
    return replace(p, start=fix(p.start), end=fix(p.end))


# ------------------------------------------------------------ arrangements
def _is_plateau(p, top: float, tol: float) -> bool:
    return isinstance(p, Line) and abs(p.start[1] - top) <= tol and abs(p.end[1] - top) <= tol


def interface_segments(profile: Profile, arrangement: str = "conforming") -> list:
    """The interface as :class:`~ngcontact.geometry.cell2d.Segment` list for ``arrangement``.

    See the module docstring for the arrangements.
    """
    if arrangement not in ARRANGEMENTS:
        raise GeometryError("arrangement", arrangement, f"must be one of {', '.join(ARRANGEMENTS)}")
    if arrangement == "conforming":
        return [s for p in profile.pieces for s in p.segments()]
    lo, top = profile.bounds
    tol = 1e-12 * max(profile.period, top - lo)
    plateau = [_is_plateau(p, top, tol) for p in profile.pieces]
    if not any(plateau):
        raise GeometryError("arrangement", arrangement,
                         f"the {profile.name} profile has no plane summit plateau to carry contact; "
                         "use 'conforming', or a flat interface with a gap function "
                         "(the small-slope model of rounded summits)")
    if not (plateau[0] and plateau[-1]):
        raise GeometryError("arrangement", arrangement,
                         "in the summit arrangement the lateral edges must cut a summit plateau; "
                         "shift the profile so that x = 0 lies on a plateau")
    out, run_start = [], None
    for p, flat_top in zip(profile.pieces, plateau):
        if flat_top:
            out += p.segments()
            continue
        if run_start is None:
            run_start = p.start
        out += [replace(s, label="free", left="void") for s in p.segments()]
        if abs(p.end[1] - top) <= tol:
            out.append(Segment("line", (run_start, p.end), label="free", right="void", left="counter"))
            run_start = None
    return out


def profile_cell(profile: Profile, *, arrangement: str = "conforming", h_rough: float,
                 h_counter: float, maxh: float, interface_maxh: float | None = None,
                 order: int = 1) -> Cell:
    """Mesh the periodic cell of ``profile`` in ``arrangement``.

    Parameters
    ----------
    profile
        A :class:`Profile`; summits at ``y = 0``.
    arrangement
        ``"conforming"`` or ``"summit"``.
    h_rough, h_counter
        Far faces ``bottom`` at ``y = -h_rough`` and ``top`` at ``y = h_counter``;
        the profile must lie strictly between them.
    maxh, interface_maxh, order
        Mesh sizes (bodies, interface) and geometry order (curved elements).

    Returns
    -------
    Cell
        Regions ``rough``, ``counter``; boundaries ``contact``, ``free`` (summit
        arrangement), ``bottom``, ``top``, ``periodic``.
    """
    lo, hi = profile.bounds
    _check_positive("h_rough", h_rough)
    _check_positive("h_counter", h_counter)
    if not lo > -h_rough:
        raise GeometryError("h_rough", h_rough, f"must exceed the profile depth {-lo!r} "
                         "(the roughness must lie inside the rough body)")
    if not hi < h_counter:
        raise GeometryError("h_counter", h_counter, f"must exceed the profile height {hi!r}")
    segments = interface_segments(profile, arrangement)
    log.debug("profile cell %s (%s): %d interface segments", profile.name, arrangement, len(segments))
    return interface_cell(segments, profile.period, h_rough, h_counter, maxh=maxh,
                          interface_maxh=interface_maxh, order=order)
