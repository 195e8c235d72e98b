"""Interface law of a macro problem taken from a named ``cell`` scene, cached on disk.

The cell's contact surface ``S_C`` becomes the unilateral direction bundle of
DESIGN Sec. 3 (paper eqs. 31-33) through
:func:`ngcontact.homogenize.direction_bundle`: one direction per quadrature
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
``~/.cache/ngcontact``) under the SHA-256 of the validated cell scene and the
contents of the files it names, so an edited cell scene is recomputed.
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile

import numpy as np

from ngcontact.laws import homogenized as il

log = logging.getLogger(__name__)

CACHE_VERSION = "bundle-1"


def cache_dir_default() -> str:
    return os.environ.get("NGCONTACT_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "ngcontact")


def cell_key(cell_scene) -> str:
    """SHA-256 of the validated cell scene and the data files it names."""
    from ngcontact.scene.loader import as_dict
    from ngcontact.scene.sections import resolve
    h = hashlib.sha256()
    h.update(CACHE_VERSION.encode())
    h.update(json.dumps(as_dict(cell_scene), sort_keys=True, default=str).encode())
    for rel in (getattr(cell_scene.geometry, "file", None), getattr(cell_scene.contact.gap, "file", None)):
        if rel:
            with open(resolve(cell_scene, rel), "rb") as fh:
                h.update(fh.read())
    return h.hexdigest()


def cell_bundle_arrays(cell_scene, cache_dir: str | None = None) -> tuple[dict, bool]:
    """``{"w", "n", "g"}`` of the cell's direction bundle and whether it came from the cache."""
    cache_dir = cache_dir or cache_dir_default()
    path = os.path.join(cache_dir, f"{cell_key(cell_scene)}.npz")
    if os.path.isfile(path):
        with np.load(path) as data:
            log.info("cell bundle from cache %s", path)
            return {k: np.array(data[k]) for k in ("w", "n", "g")}, True
    from ngcontact.drivers.run_cell import build_cell, gap_cf
    from ngcontact.cell.coefficients import direction_bundle
    cell = build_cell(cell_scene)
    b = direction_bundle(cell, kn=cell_scene.contact.k_n, gap=gap_cf(cell_scene))
    arrays = {"w": np.asarray(b.w, float), "n": np.asarray(b.n, float), "g": np.asarray(b.g, float)}
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
    """The :class:`~ngcontact.interface_law.BundleLaw` of the arrays for a macro frame of ``dim``.

    Directions whose projection vanishes (pure ``t2`` normals) carry no
    stiffness in that frame and are left out; equal directions and gaps merge.
    """
    n = np.asarray(arrays["n"], float)[:, :dim]
    w = np.asarray(arrays["w"], float)
    g = np.asarray(arrays["g"], float) * length_unit
    keep = (np.linalg.norm(n, axis=1) > 1e-12) & (w > 0)
    law = il.BundleLaw(weights=tuple(w[keep]), directions=tuple(map(tuple, n[keep])), gaps=tuple(g[keep]))
    return law.merged()


def law_from_cell(path: str, *, dim: int, linear: bool = False, length_unit: float = 1.0,
                  cache_dir: str | None = None):
    """Normal law from the cell scene file ``path`` and a description for the report.

    Parameters
    ----------
    path
        A scene file of kind ``cell``.
    dim
        Dimension of the macro frame (2 for plane strain and axisymmetry).
    linear
        Return its linearization :class:`~ngcontact.interface_law.LinearLaw`
        (``K0`` and the gap forces of eq. 34) instead of the bundle.
    length_unit, cache_dir
        See the module docstring.
    """
    from ngcontact.errors import SceneError
    from ngcontact.scene.loader import load
    cell_scene = load(path)
    if cell_scene.kind != "cell":
        raise SceneError("interface.cell", path, f"names a {cell_scene.kind!r} scene; a 'cell' scene is needed")
    arrays, cached = cell_bundle_arrays(cell_scene, cache_dir)
    law = bundle_law(arrays, dim=dim, length_unit=length_unit)
    K = law.matrix()
    info = {"cell_scene": os.path.abspath(path), "cached": cached, "directions": len(law.weights),
            "K0": K.tolist(), "key": cell_key(cell_scene)}
    if linear:
        if dim == 3:
            raise SceneError("interface.law", "linear", "a linear law from a cell is available in 2D and "
                             "axisymmetry; use the bundle in 3D")
        law = il.linearized(law)
    return law, info
