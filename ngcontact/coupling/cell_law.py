"""Interface law of a macro problem taken from a cell's contact surface, cached on disk.

The cell's contact surface ``S_C`` becomes the unilateral direction bundle
(paper eqs. 31-33) through
:func:`ngcontact.cell.coefficients.direction_bundle`: one direction per quadrature
point, with weight ``w_q = k_n ds_q / |T|``, micro normal ``n_q`` in the
cell's macro basis (``n0 = e_y, t0 = e_x``; 3D ``n0 = e_z, t1 = e_x,
t2 = e_y``) and initial gap ``g_q``.  No cell contact problem is solved: the
bundle decides itself which directions close under the macro jump.

* Units: the weights are ratios of lengths times ``k_n``, independent of the
  cell's length unit; the gaps are lengths and are multiplied by
  ``length_unit`` (metres per cell unit).
* A 3D cell under an axisymmetric or plane-strain macro problem: the jump has
  no component along the cell's second tangent ``t2`` (the hoop direction),
  so that component of each ``n_q`` drops out of ``n_q . J``; the bundle is
  projected onto ``(n0, t1)`` exactly.
* Friction of the cell scene is not carried over; the macro scene sets its
  own ``mu0`` / ``G0``.

The arrays are cached in ``cache_dir`` (default ``$NGCONTACT_CACHE`` or
``~/.cache/ngcontact``) under a key that names the cell; the driver
(:func:`ngcontact.drivers.build.law_from_cell`) takes the SHA-256 of the
validated cell scene and of the files it names, so an edited cell scene is
recomputed.
"""
from __future__ import annotations

import logging
import os
import tempfile
from typing import Any, Callable

import numpy as np

from ngcontact.laws import homogenized as il

log = logging.getLogger(__name__)

CACHE_VERSION = "bundle-1"


def cache_dir_default() -> str:
    return os.environ.get("NGCONTACT_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "ngcontact")


def cached_bundle_arrays(key: str, compute: Callable[[], dict], cache_dir: str | None = None
                         ) -> tuple[dict, bool]:
    """``{"w", "n", "g"}`` of a cell's direction bundle and whether it came from the cache.

    ``key`` names the cell (a digest of its description); ``compute()``
    returns the arrays when the cache has none for it.
    """
    cache_dir = cache_dir or cache_dir_default()
    path = os.path.join(cache_dir, f"{key}.npz")
    if os.path.isfile(path):
        with np.load(path) as data:
            log.info("cell bundle from cache %s", path)
            return {k: np.array(data[k]) for k in ("w", "n", "g")}, True
    # Any values: np.savez's stub would otherwise match the arrays against
    # its keyword-only allow_pickle: bool
    arrays: dict[str, Any] = {k: np.asarray(v, float) for k, v in compute().items()}
    os.makedirs(cache_dir, exist_ok=True)
    fd, tmp = tempfile.mkstemp(suffix=".npz", dir=cache_dir)
    os.close(fd)
    try:
        np.savez(tmp, **arrays)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    log.info("cell bundle computed and cached in %s", path)
    return arrays, False


def bundle_law(arrays: dict, *, dim: int, length_unit: float = 1.0) -> il.BundleLaw:
    """The :class:`~ngcontact.laws.homogenized.BundleLaw` of the arrays for a macro frame of ``dim``.

    Directions whose projection vanishes (pure ``t2`` normals) carry no
    stiffness in that frame and are left out; equal directions and gaps merge.
    """
    n = np.asarray(arrays["n"], float)[:, :dim]
    w = np.asarray(arrays["w"], float)
    g = np.asarray(arrays["g"], float) * length_unit
    keep = (np.linalg.norm(n, axis=1) > 1e-12) & (w > 0)
    law = il.BundleLaw(weights=tuple(w[keep]), directions=tuple(map(tuple, n[keep])), gaps=tuple(g[keep]))
    return law.merged()
