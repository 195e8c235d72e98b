"""The roughness profiles a cell scene may name: one table from ``geometry.profile`` to its builder and facts.

Each :class:`ProfileKind` says what the scene layer validates and what
``drivers/build.py`` builds for one name:

* its dimension and the keys of the ``[geometry]`` section it requires
  (``optional`` ones aside), and the key that sets its smallest feature;
* a 2D profile's builder, :class:`~ngcontact.geometry.profiles.Profile`
  from the section's numbers or, for ``tabulated``, from its file;
* a 3D profile's shape: flat (``flat3d``), a solid of its own builder
  (``square_hills``, paper Fig. 6), or a free-form surface (``bisinusoid``,
  ``height_map``, ``self_affine``, ``measured_spectrum``) given by its heights, meshed as the real
  surface in the conforming arrangement and represented by the small-slope
  model in the summit arrangement (a flat interface whose initial gap is
  the height below the highest summit);
* of a free-form surface, whether its gap has a formula (the bisinusoid) or
  its heights are samples on a grid of their own (a file, a drawn random surface,
  which the spectral cell samples on that grid), and whether it is drawn
  from a spectrum with a seed (realizations of an ensemble).

Builders take the ``[geometry]`` section as any object whose attributes are
named as its keys, and the path of its ``file`` (resolved by the caller) or
``None``; geometry knows nothing of scenes.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ngcontact.errors import GeometryError
from ngcontact.geometry import profiles as pr


@dataclass(frozen=True, kw_only=True)
class ProfileKind:
    """One name of ``geometry.profile`` (see the module docstring)."""

    name: str
    dim: int
    #: keys of the ``[geometry]`` section the profile requires, and those it may take
    keys: tuple[str, ...] = ()
    optional: tuple[str, ...] = ()
    #: the key whose value sets the profile's smallest feature (reported when it is too small)
    feature: str = "period"
    #: 2D: ``(section, file) -> Profile``
    profile: Callable[[Any, str | None], pr.Profile] | None = None
    #: a flat interface (the small-slope model with no roughness)
    flat: bool = False
    #: 3D free-form surface: ``(section, file) -> heights`` in the layout of a height map
    heights: Callable[[Any, str | None], np.ndarray] | None = None
    #: of a free-form surface whose small-slope gap has a formula: ``(section, xy) -> gap`` (a
    #: CoefficientFunction for ``xy = None``, else its values at the arrays ``xy = (x, y)``)
    gap: Callable[[Any, Any], Any] | None = None
    #: drawn from a power spectrum with a seed
    random: bool = False
    #: 3D solid of its own builder: ``(section, maxh=, interface_maxh=) -> Cell``
    solid: Callable[..., Any] | None = None
    #: further admissibility checks of the section's numbers, raising :class:`GeometryError`
    check: Callable[[Any], None] | None = None

    @property
    def reads_file(self) -> bool:
        """The profile is read from the section's ``file``."""
        return "file" in self.keys

    @property
    def parametric(self) -> bool:
        """A 2D profile built from the section's numbers alone."""
        return self.profile is not None and not self.reads_file

    @property
    def free_form(self) -> bool:
        """A 3D free-form surface given by its heights (small-slope model in the summit arrangement)."""
        return self.heights is not None

    @property
    def own_grid(self) -> bool:
        """A free-form surface whose heights are samples on a grid of their own (no formula for its gap)."""
        return self.free_form and self.gap is None


def _tabulated(g, file):
    from ngcontact.geometry.tabulated import read_profile_csv
    return read_profile_csv(file, path="geometry.file")


def _bisinusoid_heights(g, file):
    from ngcontact.geometry import cell3d
    return cell3d.bisinusoid_heights(g.amplitude, g.period)


def _bisinusoid_gap(g, xy):
    from ngcontact.geometry import cell3d
    return cell3d.bisinusoid_gap(g.amplitude, g.period, xy=xy)


#: keys of a measured topography file (:mod:`ngcontact.geometry.topography`): what the scene states of it
MEASURED_KEYS = ("units", "size", "detrend", "periodic", "periodize", "window_width")


def reading(g):
    """What the ``[geometry]`` section states of a measured file (:class:`~ngcontact.geometry.topography.Reading`)."""
    from ngcontact.geometry.topography import Reading
    return Reading(**{key: getattr(g, key, None) for key in MEASURED_KEYS})


def file_map(g, file, where: str = "geometry.file") -> tuple[np.ndarray, float]:
    """The height map of ``file`` in the package's layout and its period: a ``.npy`` map of the section's
    period, or a measured topography made periodic (:func:`ngcontact.geometry.topography.read_measured`);
    ``where`` names the file in messages."""
    from ngcontact.geometry import topography
    if topography.is_measured(file):
        m = topography.read_measured(file, reading(g), where)
        return m.heights, m.period
    from ngcontact.geometry.tabulated import read_height_map
    return read_height_map(file, path=where), g.period


def _height_map(g, file):
    return file_map(g, file)[0]


def _measured_spectrum(g, file):
    """A random surface with the radially averaged spectrum of the file's map, on its grid
    (:func:`ngcontact.geometry.random_surface.from_psd`), drawn with ``g.seed``; a flat map draws flat."""
    from ngcontact.geometry.random_surface import as_height_map, from_psd, radial_psd
    H, period = file_map(g, file)
    z = H[:-1, :-1] - H[:-1, :-1].mean()
    if not np.any(z):
        return np.zeros_like(H)
    q, C = radial_psd(z, period)
    return as_height_map(from_psd(q, C, grid=max(z.shape), period=period, seed=g.seed or 0))


def _self_affine(g, file):
    """The surface drawn from ``g.spectrum`` (:mod:`ngcontact.geometry.random_surface`); rms 0: flat."""
    from ngcontact.geometry.random_surface import as_height_map, self_affine
    sp = g.spectrum
    if (sp.rms_height if sp.rms_height is not None else sp.rms_slope) == 0.0:
        return np.zeros((sp.grid + 1, sp.grid + 1))      # rms 0: the flat surface
    return as_height_map(self_affine(dim=3, grid=sp.grid, period=g.period, hurst=sp.hurst, rms_height=sp.rms_height,
                                     rms_slope=sp.rms_slope, rolloff=sp.rolloff, cutoff=sp.cutoff, seed=sp.seed))


def _square_hills(g, *, maxh, interface_maxh):
    from ngcontact.geometry import cell3d
    return cell3d.square_hills_cell(g.width, g.depth, period=g.period, arrangement=g.arrangement, h_rough=g.h_rough,
                                    h_counter=g.h_counter, maxh=maxh, interface_maxh=interface_maxh)


def _check_square_hills(g) -> None:
    """The hills must not touch, and their base must lie inside the rough body."""
    if not g.width < g.period:
        raise GeometryError("width", g.width, f"must be < period = {g.period!r} (hills must not touch)")
    if not g.depth < g.h_rough:
        raise GeometryError("depth", g.depth, f"must be < h_rough = {g.h_rough!r} "
                            "(the hill base must lie inside the rough body)")


_KINDS = (
    ProfileKind(name="flat", dim=2, profile=lambda g, file: pr.flat(g.period), flat=True),
    ProfileKind(name="rectangular", dim=2, keys=("width", "depth"), feature="width",
                profile=lambda g, file: pr.rectangular_valley(g.width, g.depth, g.period)),
    ProfileKind(name="triangular", dim=2, keys=("angles",), optional=("width",), feature="width",
                profile=lambda g, file: pr.triangular_valley(g.angles[0], g.angles[1], g.width, g.period)),
    ProfileKind(name="semicircular", dim=2, keys=("radius",), feature="radius",
                profile=lambda g, file: pr.semicircular_valley(g.radius, g.period)),
    ProfileKind(name="sinusoid", dim=2, keys=("amplitude",), feature="amplitude",
                profile=lambda g, file: pr.sinusoid(g.amplitude, g.period)),
    ProfileKind(name="tabulated", dim=2, keys=("file",), profile=_tabulated),
    ProfileKind(name="flat3d", dim=3, flat=True),
    ProfileKind(name="square_hills", dim=3, keys=("width", "depth"), solid=_square_hills, check=_check_square_hills),
    ProfileKind(name="bisinusoid", dim=3, keys=("amplitude",), heights=_bisinusoid_heights, gap=_bisinusoid_gap),
    ProfileKind(name="height_map", dim=3, keys=("file",), optional=MEASURED_KEYS, heights=_height_map),
    ProfileKind(name="measured_spectrum", dim=3, keys=("file",), optional=MEASURED_KEYS + ("seed",),
                heights=_measured_spectrum, random=True),
    ProfileKind(name="self_affine", dim=3, keys=("spectrum",), heights=_self_affine, random=True),
)
#: ``geometry.profile`` -> what that profile is and how it is built.
PROFILES: dict[str, ProfileKind] = {k.name: k for k in _KINDS}
