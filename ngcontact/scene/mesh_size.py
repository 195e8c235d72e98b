"""How many elements a scene's mesh will have, estimated before meshing, against ``max_elements``.

A mesh size far below the bodies' size (``maxh`` tiny, a period of 0.1 mm
in a cell of the default height 1) does not fail: it hangs the mesher and
then exhausts memory.  The scene layer therefore estimates the element
count from the sizes alone and refuses a scene above
``discretization.max_elements``, naming the size that causes it.

The estimate, for a region of area ``A`` (2D) or volume ``V`` (3D) meshed
at size ``h``, with an interface of length ``L`` (area ``S``) meshed at
``h_i`` and graded to ``h`` over ``log2(h / h_i)`` layers::

    2D:  n = 2.3 A / h_e^2 + 4 (L / h_i) (1 + log2(h / h_i))
    3D:  n = 6 V / h_e^3  + 12 (S / h_i^2) (1 + log2(h / h_i))

with ``h_e = min(h, w / 3)``: a domain of width ``w`` (a cell's period or
height) gets at least three elements across it.  Calibrated on the shipped
cells, whose counts it matches to within a factor of two (see the tests);
it is a guard against runaway sizes, not a prediction.
"""
from __future__ import annotations

import math

from ngcontact.errors import SceneError

#: Default of ``discretization.max_elements``.
MAX_ELEMENTS = 300_000


def estimate(dim: int, volume: float, h: float, *, width: float | None = None, interface: float = 0.0,
             h_interface: float | None = None) -> float:
    """Estimated number of elements (module docstring); ``volume`` is an area in 2D."""
    h_e = min(h, width / 3.0) if width else h
    h_i = min(h_interface or h, h_e)
    layers = 1.0 + math.log2(max(1.0, h_e / h_i))
    if dim == 2:
        return 2.3 * volume / h_e ** 2 + 4.0 * interface / h_i * layers
    return 6.0 * volume / h_e ** 3 + 12.0 * interface / h_i ** 2 * layers


#: Lengths the mesher handles: a cell scaled down to 1e-15 crashed it (segmentation fault).
LENGTH_RANGE = (1e-9, 1e9)


def check_lengths(lengths: dict) -> None:
    """Every ``{key: length}`` (``None`` skipped) within :data:`LENGTH_RANGE`."""
    lo, hi = LENGTH_RANGE
    for key, value in lengths.items():
        if value is not None and not lo <= value <= hi:
            raise SceneError(key, value, f"must lie in [{lo:g}, {hi:g}]: choose a length unit (e.g. mm or um) "
                             "in which the geometry's sizes fall in that range")


def finest_size(discretization) -> tuple[str, float]:
    """``(key, value)`` of the finer of ``maxh`` and ``interface_maxh``: the size a refusal names."""
    d = discretization
    if d.interface_maxh is not None and d.interface_maxh < d.maxh:
        return "discretization.interface_maxh", d.interface_maxh
    return "discretization.maxh", d.maxh


def refuse_beyond(n: float, max_elements: int, size_key: str, size: float, *, path: str = "discretization",
                  hint: str = "") -> None:
    """Raise :class:`SceneError` naming ``size_key`` when the estimate ``n`` exceeds ``max_elements``."""
    if n > max_elements:
        raise SceneError(size_key, size, f"the mesh would have about {n:.2g} elements, more than "
                         f"{path}.max_elements = {max_elements}; coarsen it{hint}, or raise "
                         f"{path}.max_elements if the machine can take it")


def check_cell_lengths(scene) -> None:
    """A cell scene's lengths within :data:`LENGTH_RANGE`, whichever method solves it: the period and the
    layers' heights (and an FE cell's mesh sizes) in the range, the initial gap's amplitude or value and the
    prescribed jumps at most its upper end in magnitude (zero is a gap or jump, not a scale).  Beyond it the
    layers' compliance and the energies overflow double precision."""
    g, d, gap, load = scene.geometry, scene.discretization, scene.contact.gap, scene.load
    lengths = {"geometry.period": g.period, "geometry.h_rough": g.h_rough, "geometry.h_counter": g.h_counter}
    if d.method != "spectral":
        lengths.update({"discretization.maxh": d.maxh, "discretization.interface_maxh": d.interface_maxh})
    check_lengths(lengths)
    spans = {"contact.gap.h": gap.h, "contact.gap.value": gap.value}
    for key in ("normal_jump", "tangential_jump"):
        spans.update({f"load.{key}[{i}]": v for i, v in enumerate(getattr(load, key, None) or ())})
    check_magnitudes(spans)


def check_magnitudes(lengths: dict) -> None:
    """Every ``{key: length}`` (``None`` skipped) of any sign, zero included, at most the upper end of
    :data:`LENGTH_RANGE` in magnitude: gaps, interferences and jumps."""
    hi = LENGTH_RANGE[1]
    for key, value in lengths.items():
        if value is not None and abs(value) > hi:
            raise SceneError(key, value, f"must be at most {hi:g} in magnitude: choose a length unit (e.g. mm or "
                             f"um) in which the geometry's sizes fall in [{LENGTH_RANGE[0]:g}, {hi:g}]")
