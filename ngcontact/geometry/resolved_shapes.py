"""The shapes of the resolved (``direct``) kind: one class per shape, one table of them.

The resolved micro problem of paper Sec. 3.3 is solved on two bodies whose
interface carries ``N`` periods of a cell's roughness, scaled to the period
``eps = |S_0| / N`` (``|S_0|`` the arc length of the macro interface); the
epsilon study compares it with the macro problem on the same bodies with the
flat interface ``S_0`` (paper Prop. 29).  What depends on the shape of the
bodies is answered by a :class:`ResolvedShape`:

* the arc length of ``S_0`` and the period ``eps`` of ``N`` periods;
* the mesh with ``N`` resolved periods, and the mesh of the macro
  counterpart with the flat interface ``S_0``;
* which body a point lies in (with the flat interface), and its distance
  from ``S_0``: the probes are read from that body, the band of half-width
  ``band * eps`` around ``S_0`` is excluded from the field error;
* the midpoint grid of the field error outside that band;
* the part of the interface whose transmitted force the study compares;
* its boundary labels, which of them run along ``x`` (a support's slope is
  taken along ``x`` there), the settings it admits, and its size for the
  mesh estimate.

:data:`RESOLVED_SHAPES` maps the scene's ``geometry.shape`` to its class;
each class builds itself from the numbers of a ``[geometry]`` section
(:meth:`ResolvedShape.of`).  Coordinates: ``(x, y)``, in axisymmetry
``(r, z)``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

import ngsolve as ng
import numpy as np

from ngcontact.geometry import femur as fm
from ngcontact.geometry import resolved_bodies as rb
from ngcontact.geometry.profiles import Profile

#: Region names of the rough and the counter body in the resolved kind (the femur's stem and bone too).
REGIONS = ("rough", "counter")


class ResolvedShape(Protocol):
    """What the resolved driver and the epsilon study ask of the bodies (see the module docstring)."""

    #: the scene's ``geometry.shape``
    name: ClassVar[str]
    #: settings the shape admits
    settings: ClassVar[tuple[str, ...]]
    #: keys of the ``[geometry]`` section the shape uses, and those of them it requires
    keys: ClassVar[tuple[str, ...]]
    required: ClassVar[tuple[str, ...]]
    #: boundary labels of the meshes (the interface's own label aside)
    boundaries: ClassVar[tuple[str, ...]]
    #: boundaries along which ``x`` (``r``) varies: a support's slope is taken along ``x`` there, else ``y``
    horizontal: ClassVar[tuple[str, ...]]

    @classmethod
    def of(cls, section: Any) -> ResolvedShape:
        """The shape from the numbers of a ``[geometry]`` section (attributes named as its keys)."""
        ...

    def interface_length(self) -> float:
        """Arc length ``|S_0|`` of the macro interface."""
        ...

    def eps(self, periods: int) -> float:
        """Period of ``periods`` resolved periods, ``|S_0| / N``."""
        ...

    def resolved(self, profile: Profile, periods: int, *, maxh: float, interface_maxh: float, order: int,
                 grading: float, periodic: bool = False) -> rb.ResolvedGeometry | fm.FemurMesh:
        """The mesh with ``periods`` scaled copies of ``profile`` along the interface (boundary ``contact``)."""
        ...

    def flat(self, *, maxh: float, interface_maxh: float, grading: float) -> rb.ResolvedGeometry | fm.FemurMesh:
        """The same bodies with the flat macro interface ``S_0`` (boundary ``interface``)."""
        ...

    def body_of(self, points) -> np.ndarray:
        """Body of each point with the flat interface: 0 rough, 1 counter, -1 outside."""
        ...

    def interface_distance(self, points) -> np.ndarray:
        """Distance of each point from ``S_0``."""
        ...

    def interface_part(self) -> ng.CoefficientFunction:
        """Indicator of the part of the interface whose transmitted force the epsilon study compares."""
        ...

    def sample_grid(self, grid: tuple[int, int], band: float) -> tuple[np.ndarray, np.ndarray]:
        """Midpoints and areas of a uniform ``grid`` outside the band ``band`` around ``S_0``."""
        ...

    def extent(self) -> tuple[float, float]:
        """``(area, smallest width)`` of the bodies, for the mesh estimate."""
        ...


def _points(points) -> np.ndarray:
    return np.asarray(points, float).reshape(-1, 2)


@dataclass(frozen=True)
class Blocks:
    """Rough block below, counter block above, ``x0 <= x <= x0 + length``; ``S_0`` is ``y = 0``.

    Meshed by :func:`ngcontact.geometry.resolved_bodies.resolved_blocks` and
    :func:`~ngcontact.geometry.resolved_bodies.flat_blocks`.
    """

    length: float
    h_rough: float
    h_counter: float
    x0: float = 0.0

    name: ClassVar[str] = "blocks"
    settings: ClassVar[tuple[str, ...]] = ("plane_strain", "axisymmetric")
    keys: ClassVar[tuple[str, ...]] = ("length", "h_rough", "h_counter")
    required: ClassVar[tuple[str, ...]] = ("length", "h_rough", "h_counter")
    boundaries: ClassVar[tuple[str, ...]] = ("bottom", "top", "rough_sides", "counter_sides")
    horizontal: ClassVar[tuple[str, ...]] = ("top", "bottom")

    @classmethod
    def of(cls, section: Any) -> Blocks:
        return cls(length=section.length, h_rough=section.h_rough, h_counter=section.h_counter, x0=section.x0)

    def interface_length(self) -> float:
        return float(self.length)

    def eps(self, periods: int) -> float:
        return self.interface_length() / periods

    def resolved(self, profile: Profile, periods: int, *, maxh: float, interface_maxh: float, order: int,
                 grading: float, periodic: bool = False) -> rb.ResolvedGeometry:
        return rb.resolved_blocks(profile, periods, self.length, self.h_rough, self.h_counter, maxh=maxh,
                                  interface_maxh=interface_maxh, order=order, periodic=periodic, grading=grading,
                                  x0=self.x0)

    def flat(self, *, maxh: float, interface_maxh: float, grading: float) -> rb.ResolvedGeometry:
        return rb.flat_blocks(self.length, self.h_rough, self.h_counter, maxh=maxh, interface_maxh=interface_maxh,
                              grading=grading, x0=self.x0)

    def body_of(self, points) -> np.ndarray:
        pts = _points(points)
        inside = (pts[:, 0] > self.x0) & (pts[:, 0] < self.x0 + self.length) & (pts[:, 1] > -self.h_rough) & \
            (pts[:, 1] < self.h_counter)
        return np.where(inside, np.where(pts[:, 1] < 0, 0, 1), -1)

    def interface_distance(self, points) -> np.ndarray:
        return np.abs(_points(points)[:, 1])

    def interface_part(self) -> ng.CoefficientFunction:
        """The left half ``x < x0 + L/2``."""
        return ng.IfPos(self.x0 + 0.5 * self.length - ng.x, 1.0, 0.0)

    def sample_grid(self, grid: tuple[int, int], band: float) -> tuple[np.ndarray, np.ndarray]:
        """``nx x ny`` cells in each block outside ``|y| <= band``."""
        nx, ny = grid
        xs = self.x0 + (np.arange(nx) + 0.5) * self.length / nx
        pl, wl = [], []
        for lo, hi in ((-self.h_rough, -band), (band, self.h_counter)):
            ys = lo + (np.arange(ny) + 0.5) * (hi - lo) / ny
            X, Y = np.meshgrid(xs, ys)
            pl.append(np.column_stack([X.ravel(), Y.ravel()]))
            wl.append(np.full(X.size, (self.length / nx) * (hi - lo) / ny))
        return np.concatenate(pl), np.concatenate(wl)

    def extent(self) -> tuple[float, float]:
        return self.length * (self.h_rough + self.h_counter), min(self.h_rough, self.h_counter)


@dataclass(frozen=True)
class FemurStem:
    """The axisymmetric femur with a hip stem whose stem carries the roughness (:mod:`ngcontact.geometry.femur`).

    ``S_0`` is the cone from the stem tip to the corner and the cylinder up
    to the bone top; ``N`` periods are split between them in whole periods
    (:func:`ngcontact.geometry.femur.split_periods`).
    """

    dims: fm.FemurStemDims = field(default_factory=fm.FemurStemDims)

    name: ClassVar[str] = "femur_stem"
    settings: ClassVar[tuple[str, ...]] = ("axisymmetric",)
    keys: ClassVar[tuple[str, ...]] = ("dimensions",)
    required: ClassVar[tuple[str, ...]] = ()
    boundaries: ClassVar[tuple[str, ...]] = tuple(fm.BOUNDARIES)
    horizontal: ClassVar[tuple[str, ...]] = ("base", "stem_top", "stem_tip", "bone_top")

    @classmethod
    def of(cls, section: Any) -> FemurStem:
        return cls(fm.FemurStemDims(**(section.dimensions or {})))

    def interface_length(self) -> float:
        return fm.femur_interface_length(self.dims)

    def eps(self, periods: int) -> float:
        return self.interface_length() / periods

    def resolved(self, profile: Profile, periods: int, *, maxh: float, interface_maxh: float, order: int,
                 grading: float, periodic: bool = False) -> fm.FemurMesh:
        if periodic:
            raise ValueError("the femur has no periodic variant")
        return fm.femur_stem(self.dims, profile, periods, maxh=maxh, interface_maxh=interface_maxh, order=order,
                             grading=grading, regions=REGIONS)

    def flat(self, *, maxh: float, interface_maxh: float, grading: float) -> fm.FemurMesh:
        return fm.femur_stem(self.dims, None, 0, maxh=maxh, interface_maxh=interface_maxh, grading=grading,
                             regions=REGIONS)

    def body_of(self, points) -> np.ndarray:
        return fm.femur_stem_body(self.dims, _points(points))

    def interface_distance(self, points) -> np.ndarray:
        return fm.distance_to_polyline(fm.femur_stem_interface(self.dims), _points(points))

    def interface_part(self) -> ng.CoefficientFunction:
        """The cylindrical part ``z > z_corner`` (its share of the axial load against the cone's)."""
        return ng.IfPos(ng.y - self.dims.z_corner, 1.0, 0.0)

    def sample_grid(self, grid: tuple[int, int], band: float) -> tuple[np.ndarray, np.ndarray]:
        """``nr x nz`` cells over ``[0, r_bone] x [0, z_stem_top]``, midpoints in a body outside the band."""
        nx, ny = grid
        d = self.dims
        dr, dz = d.r_bone / nx, d.z_stem_top / ny
        R, Z = np.meshgrid((np.arange(nx) + 0.5) * dr, (np.arange(ny) + 0.5) * dz)
        cand = np.column_stack([R.ravel(), Z.ravel()])
        keep = (self.body_of(cand) >= 0) & (self.interface_distance(cand) > band)
        return cand[keep], np.full(int(np.sum(keep)), dr * dz)

    def extent(self) -> tuple[float, float]:
        d = self.dims
        return d.r_bone * d.z_stem_top, d.r_bone - d.r_stem


#: The scene's ``geometry.shape`` -> the class of that shape.
RESOLVED_SHAPES: dict[str, type[Blocks] | type[FemurStem]] = {cls.name: cls for cls in (Blocks, FemurStem)}


def resolved_shape(section: Any) -> Blocks | FemurStem:
    """The shape a ``[geometry]`` section of the ``direct`` kind names, built from its numbers."""
    return RESOLVED_SHAPES[section.shape].of(section)
