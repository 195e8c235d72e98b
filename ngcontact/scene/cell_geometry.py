"""The ``[geometry]`` section of a cell scene: the periodic cell's profile and arrangement.

Mapped onto the builders of :mod:`ngcontact.geometry.profiles` (2D) and
:mod:`ngcontact.geometry.cell3d` (3D) by the table of profiles
:data:`ngcontact.geometry.profile_registry.PROFILES` (the keys each profile
requires, its builder and what it is); a self-affine random surface is drawn
by :mod:`ngcontact.geometry.random_surface` from its ``spectrum``; a height map is read from a ``.npy``
file or from a measured topography (:mod:`ngcontact.geometry.topography`).  The
small-slope profiles (:func:`small_slope`) are a flat interface whose initial
gap carries the roughness.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from ngcontact.errors import GeometryError, SceneError
from ngcontact.geometry.profile_registry import MEASURED_KEYS, PROFILES
from ngcontact.geometry.topography import DETREND, PERIODIZE, UNITS, is_measured
from ngcontact.scene.schema import (at_least, check_selected, closed_interval, nonnegative, open_interval, param,
                                    positive, left_open)


PROFILES_2D = tuple(name for name, kind in PROFILES.items() if kind.dim == 2)
PROFILES_3D = tuple(name for name, kind in PROFILES.items() if kind.dim == 3)
#: 3D free-form profiles: meshed as the real surface with Netgen's OCC kernel
#: in the conforming arrangement; in the summit arrangement represented by the
#: small-slope model (a flat interface whose initial gap is the height below
#: the highest summit).
GAP_PROFILES = tuple(name for name, kind in PROFILES.items() if kind.free_form)


@dataclass(frozen=True, kw_only=True)
class SpectrumSpec:
    """A random periodic self-affine surface (:mod:`ngcontact.geometry.random_surface`)."""

    hurst: float = param(doc="Hurst exponent H: power spectrum C(q) ~ q^(-2(1+H)) between roll-off and cut-off",
                         check=open_interval(0, 1))
    rms_height: float | None = param(None, doc="root-mean-square height (give this or rms_slope; 0: a flat surface)",
                                     units="m", check=nonnegative())
    rms_slope: float | None = param(None, doc="root-mean-square slope (give this or rms_height; 0: a flat surface)",
                                    check=nonnegative())
    rolloff: float | None = param(None, doc="roll-off wavelength: the spectrum is flat for longer ones (default: "
                                  "the period)", units="m", check=positive())
    cutoff: float | None = param(None, doc="shortest wavelength (default: 4 grid steps)", units="m",
                                 check=positive())
    grid: int = param(256, doc="points per period and direction the surface is drawn on (even)",
                      check=closed_interval(8, 4096))
    seed: int = param(0, doc="seed of the random generator (the same seed draws the same surface)",
                      check=at_least(0))

    def check(self, path: str) -> None:
        if (self.rms_height is None) == (self.rms_slope is None):
            raise SceneError(f"{path}.rms_height", self.rms_height, "give exactly one of rms_height and rms_slope")
        if self.grid % 2:
            raise SceneError(f"{path}.grid", self.grid, "must be even")


@dataclass(frozen=True, kw_only=True)
class CellGeometry:
    """The periodic cell (mesh naming contract of ngcontact.geometry)."""

    profile: str = param(doc="roughness profile", choices=PROFILES_2D + PROFILES_3D)
    arrangement: str = param("conforming", doc="counter body fills the valleys (conforming) or "
                             "touches the summits only (summit; for bisinusoid and height_map the "
                             "small-slope model: a flat interface with the heights as initial gap)",
                             choices=("conforming", "summit"))
    period: float = param(1.0, doc="cell period |T| (per tangential direction)", units="m",
                          check=positive())
    h_rough: float = param(1.0, doc="depth of the rough body below the summits", units="m",
                           check=positive())
    h_counter: float = param(1.0, doc="height of the counter body above the summits", units="m",
                             check=positive())
    width: float | None = param(None, doc="valley width (rectangular; triangular: omit for a "
                                "sawtooth spanning the period); hill side (square_hills)",
                                units="m", check=positive())
    depth: float | None = param(None, doc="valley depth (rectangular); hill height (square_hills)",
                                units="m", check=positive())
    radius: float | None = param(None, doc="valley radius (semicircular)", units="m", check=positive())
    angles: tuple[float, float] | None = param(None, doc="face angles to S_0 (triangular)",
                                               units="deg", check=open_interval(0, 90))
    amplitude: float | None = param(None, doc="profile amplitude (sinusoid, bisinusoid)", units="m",
                                    check=positive())
    file: str | None = param(None, doc="tabulated profile: CSV with columns x, y in the scene's length unit, "
                             "an optional header line, x increasing from 0 to the period by steps of at least 1e-6 of "
                             "it, the last row (x = period) repeating the first y, at most 4096 rows (2D); height map: "
                             ".npy array "
                             "whose last row/column repeat the first (3D, small-slope model), or a measured "
                             "topography in an instrument's format (X3P, DATX, OPD, SUR, PLU, IBW, DI, plain-text "
                             "matrix, ...; read by SurfaceTopography, pip install 'ngcontact[topography]'; its "
                             "heights in metres and period = its physical size, twice it with periodize = "
                             "'mirror'; an X3P file whose MD5 checksums, md5checksum.hex's and the point data's, "
                             "do not match is refused as corrupted); a regular file of at most 64 MiB, relative to "
                             "the scene file")
    spectrum: SpectrumSpec | None = param(None, doc="self_affine: the power spectrum and seed of the random surface")
    units: str | None = param(None, doc="measured file: the length unit of its heights and size, where the file "
                              "states none (a different one than the file's is refused)", choices=tuple(UNITS))
    size: tuple[float, float] | None = param(None, doc="measured file: the scan's physical size (x, y) in its "
                                             "length unit (the file's, else geometry.units), where the file "
                                             "states none", check=positive())
    detrend: str | None = param(None, doc="measured file: remove nothing (none, the default), the least-squares "
                                "plane (mean_plane: tilt) or quadratic (curvature: tilt and form); a periodic scan "
                                "takes none",
                                choices=tuple(DETREND))
    periodic: bool | None = param(None, doc="measured file: the scan is periodic (default: what the file says; "
                                  "instruments' files say not periodic)")
    periodize: str | None = param(None, doc="measured file that is not periodic (required for it): mirror (the "
                                  "scan and its reflections, period twice its size) or window (tapered to the mean "
                                  "plane within window_width of its edges, period its size)", choices=PERIODIZE)
    window_width: float | None = param(None, doc="periodize = 'window': the fraction of the scan at each edge "
                                       "that is tapered (cosine) to the mean plane", check=left_open(0, 0.5))
    seed: int | None = param(None, doc="measured_spectrum: seed of the random surface drawn with the file's "
                             "spectrum (default 0; an ensemble's members take seed, seed + 1, ...)",
                             check=at_least(0))

    @property
    def dim(self) -> int:
        return PROFILES[self.profile].dim

    @property
    def random_seed(self) -> int | None:
        """The seed of a random surface (``spectrum.seed``, else ``seed``), ``None`` for a given one."""
        if not PROFILES[self.profile].random:
            return None
        return self.spectrum.seed if self.spectrum is not None else (self.seed or 0)

    def reseeded(self, offset: int) -> CellGeometry:
        """The same section with its random surface's seed advanced by ``offset``."""
        seed = self.random_seed
        if seed is None:
            raise ValueError(f"geometry.profile = {self.profile!r} draws no random surface")
        if self.spectrum is not None:
            return replace(self, spectrum=replace(self.spectrum, seed=seed + offset))
        return replace(self, seed=seed + offset)

    def check(self, path: str) -> None:
        kind = PROFILES[self.profile]
        check_selected(self, path, "profile", ("width", "depth", "radius", "angles", "amplitude", "file", "spectrum",
                                               *MEASURED_KEYS, "seed"),
                       kind.keys, kind.optional)
        if self.file is not None and not is_measured(self.file):
            for key in MEASURED_KEYS:
                if getattr(self, key) is not None:
                    raise SceneError(f"{path}.{key}", getattr(self, key), f"states what a measured topography file "
                                     f"does not; {self.file!r} is a .npy height map in the package's layout: remove "
                                     "it")
        if self.window_width is not None and self.periodize != "window":
            raise SceneError(f"{path}.window_width", self.window_width, "used by periodize = 'window' only; remove it")
        try:
            if kind.check is not None:
                kind.check(self)
            # a profile read from its file is checked when the file is read (CellScene.check_files)
            profile = profile_2d(self) if kind.parametric else None
        except GeometryError as exc:  # the builders name their own arguments (width, angle_left, ...)
            key = _BUILDER_KEYS.get(exc.name, exc.name)
            raise SceneError(f"{path}.{key}", exc.value, exc.allowed) from None
        if profile is not None:
            check_profile_heights(self, profile.bounds, path)
            check_features(profile, f"{path}.{kind.feature}", getattr(self, kind.feature))


_BUILDER_KEYS = {"angle_left": "angles", "angle_right": "angles"}


def profile_2d(g: CellGeometry):
    """The :class:`~ngcontact.geometry.profiles.Profile` of a parametric 2D geometry section.

    The keys a profile uses are required by :meth:`CellGeometry.check` (``check_selected``).
    """
    kind = PROFILES[g.profile]
    if kind.profile is None or not kind.parametric:
        raise ValueError(f"profile {g.profile!r} is not a parametric 2D profile")
    return kind.profile(g, None)

#: Smallest feature of a profile, relative to its period, that the mesher resolves (a semicircle of
#: radius 0.4999999 leaves plateaus of 2e-7 and one of radius 1e-9 an arc of 1e-9: 'meshing failed').
MIN_FEATURE = 1e-4


def check_features(profile, key: str, value) -> None:
    """Every piece of the profile must be at least :data:`MIN_FEATURE` periods long."""
    small = profile.smallest_feature
    if not small >= MIN_FEATURE * profile.period:
        raise SceneError(key, value, f"leaves a piece of the profile {small:.3g} long, below {MIN_FEATURE:g} of "
                         f"the period {profile.period:g}, which the mesher cannot resolve")


def check_profile_heights(g: CellGeometry, bounds: tuple, path: str = "geometry") -> None:
    """The profile ``(y_min, y_max)`` must lie strictly between the far faces of the cell."""
    lo, hi = bounds
    if not lo > -g.h_rough:
        raise SceneError(f"{path}.h_rough", g.h_rough, f"must exceed the profile depth {-lo!r} "
                         "(the roughness must lie inside the rough body)")
    if not hi < g.h_counter:
        raise SceneError(f"{path}.h_counter", g.h_counter, f"must exceed the profile height {hi!r}")


def small_slope(geometry: CellGeometry) -> bool:
    """A free-form 3D profile in the summit arrangement: flat interface plus gap."""
    return PROFILES[geometry.profile].free_form and geometry.arrangement == "summit"


def flat_interface(geometry: CellGeometry) -> bool:
    """The small-slope model: a flat ``S_C`` with the roughness in the initial gap (what the spectral cell solves)."""
    return PROFILES[geometry.profile].flat or small_slope(geometry)
