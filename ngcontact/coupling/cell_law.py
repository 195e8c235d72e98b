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
recomputed.  Each entry ``<key>.npz`` (compressed; float arrays, and byte arrays
kept as bytes) also holds its own description: the
cache format, the package version that wrote it, the key and the SHA-256 of
the three arrays.  An entry that cannot be read, was written by another
version or format, names another key, fails its checksum or holds arrays of
the wrong shape or non-finite values is discarded with one warning and
recomputed; a cache that cannot be written costs only the caching (one
warning).  Entries are read without pickles.

An entry is a regular file: anything else under its name (a directory, a
symbolic link, a FIFO) is not the package's and is never removed or
replaced: the entry goes to the second name ``<key>.1.npz`` (one warning,
when it is written there), and later runs read it there without a word.
Removing it would risk a user's data (a directory is not removed without
looking into it), and skipping the cache would recompute and warn on every
run.  With both names taken the law is not cached (one warning per run).
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import stat
import tempfile
import zipfile
from importlib.metadata import PackageNotFoundError, version
from typing import Any, Callable

import numpy as np

from ngcontact.laws import homogenized as il
from ngcontact.laws.friction import FrictionLaw

log = logging.getLogger(__name__)

CACHE_VERSION = "bundle-2"
ARRAYS = ("w", "n", "g")


def _package_version() -> str:
    try:
        return version("ngcontact")
    except PackageNotFoundError:  # a source tree that is not installed
        return "unknown"


def _digest(arrays: dict, names=ARRAYS) -> str:
    h = hashlib.sha256()
    for k in names:
        a = np.ascontiguousarray(arrays[k], dtype=float)
        h.update(k.encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


def _bundle_shapes(arrays: dict) -> str | None:
    w, n, g = arrays["w"], arrays["n"], arrays["g"]
    if not (w.ndim == 1 and g.shape == w.shape and n.ndim == 2 and n.shape[0] == w.size and n.shape[1] in (2, 3)):
        return f"arrays of shapes {w.shape}, {n.shape}, {g.shape}"
    return None


def _stored(a) -> np.ndarray:
    """An entry's array as it is kept: bytes (``uint8``, e.g. a mesh file) as they are, anything else as floats."""
    a = np.asarray(a)
    return np.array(a) if a.dtype == np.uint8 else np.array(a, dtype=float)


def _read_entry(path: str, key: str, names=ARRAYS, fmt: str = CACHE_VERSION,
                shapes: Callable[[dict], str | None] = _bundle_shapes) -> dict:
    """The arrays of a cache entry; raises ``ValueError`` naming what is wrong with it."""
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: _stored(data[k]) for k in names}
            meta = json.loads(str(data["meta"]))
    except OSError as exc:
        raise ValueError(f"unreadable ({exc.strerror or type(exc).__name__})") from None
    except KeyError as exc:
        raise ValueError(f"unreadable (no array {exc})") from None
    except (ValueError, TypeError, EOFError, zipfile.BadZipFile):  # numpy's messages advise pickles: not quoted
        raise ValueError("unreadable (not a NumPy .npz archive of this cache)") from None
    if not isinstance(meta, dict):
        raise ValueError("no description")
    for name, want in (("format", fmt), ("version", _package_version()), ("key", key)):
        if meta.get(name) != want:
            raise ValueError(f"{name} {meta.get(name)!r}, expected {want!r}")
    wrong = shapes(arrays)
    if wrong:
        raise ValueError(wrong)
    if not all(np.all(np.isfinite(a)) for a in arrays.values()):
        raise ValueError("non-finite values")
    if meta.get("sha256") != _digest(arrays, names):
        raise ValueError("checksum mismatch (the entry was changed after it was written)")
    return arrays


def cache_dir_default() -> str:
    return os.environ.get("NGCONTACT_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "ngcontact")


def _entry_path(cache_dir: str, key: str) -> tuple[str | None, str | None]:
    """``(path of key's entry, path skipped)``: the first of ``<key>.npz``, ``<key>.1.npz`` that is a regular
    file or free, ``None`` when neither is; the first name when it holds something else (module docstring)."""
    skipped = None
    for name in (f"{key}.npz", f"{key}.1.npz"):
        path = os.path.join(cache_dir, name)
        try:
            mode = os.lstat(path).st_mode
        except OSError:  # free (or the cache directory is missing or unusable: reading finds nothing)
            return path, skipped
        if stat.S_ISREG(mode):
            return path, skipped
        skipped = skipped or path
    return None, skipped


def _kind(path: str) -> str:
    mode = os.lstat(path).st_mode
    return ("a directory" if stat.S_ISDIR(mode) else "a symbolic link" if stat.S_ISLNK(mode)
            else "not a regular file")


def read_cached(key: str, names=ARRAYS, fmt: str = CACHE_VERSION, cache_dir: str | None = None,
                shapes: Callable[[dict], str | None] = _bundle_shapes) -> dict | None:
    """The arrays ``names`` cached under ``key``, or ``None`` (a bad entry is discarded with one warning)."""
    path, _ = _entry_path(cache_dir or cache_dir_default(), key)
    if path is None or not os.path.isfile(path):
        return None
    try:
        found = _read_entry(path, key, names, fmt, shapes)
        log.info("cell data from cache %s", path)
        return found
    except ValueError as exc:
        log.warning("ngcontact: discarding the cache entry %s (%s); recomputing it", path, exc)
        return None


def write_cached(key: str, arrays: dict, names=ARRAYS, fmt: str = CACHE_VERSION,
                 cache_dir: str | None = None) -> None:
    """Write ``arrays`` under ``key`` atomically; a cache that cannot be written costs one warning."""
    cache_dir = cache_dir or cache_dir_default()
    path, skipped = _entry_path(cache_dir, key)
    if path is None:
        log.warning("ngcontact: the cell-law cache entry names %s and %s are taken by things that are not cache "
                    "entries (left as they are); the law is recomputed on every run (move them away)",
                    *(os.path.join(cache_dir, f"{key}{tail}") for tail in (".npz", ".1.npz")))
        return
    if skipped is not None:
        log.warning("ngcontact: %s is %s, not a cache entry, and is left as it is; the entry is written to %s",
                    skipped, _kind(skipped), os.path.basename(path))
    # Any values: np.savez's stub would otherwise match the arrays against
    # its keyword-only allow_pickle: bool
    data: dict[str, Any] = {k: _stored(arrays[k]) for k in names}
    meta = {"format": fmt, "version": _package_version(), "key": key, "sha256": _digest(data, names)}
    tmp = None
    try:
        os.makedirs(cache_dir, exist_ok=True)
        fd, tmp = tempfile.mkstemp(suffix=".npz", dir=cache_dir)
        os.close(fd)
        np.savez_compressed(tmp, meta=np.array(json.dumps(meta)), **data)
        os.replace(tmp, path)
        log.info("cell data computed and cached in %s", path)
    except OSError as exc:
        log.warning("ngcontact: the cell-law cache %s cannot be written (%s); the law is recomputed on every "
                    "run (set NGCONTACT_CACHE to a writable directory)", cache_dir, exc.strerror or exc)
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.remove(tmp)


def cached_bundle_arrays(key: str, compute: Callable[[], dict], cache_dir: str | None = None
                         ) -> tuple[dict, bool]:
    """``{"w", "n", "g"}`` of a cell's direction bundle and whether it came from the cache.

    ``key`` names the cell (a digest of its description); ``compute()``
    returns the arrays when the cache has none for it.
    """
    found = read_cached(key, cache_dir=cache_dir)
    if found is not None:
        return found, True
    arrays = {k: np.asarray(v, float) for k, v in compute().items()}
    write_cached(key, arrays, cache_dir=cache_dir)
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


def friction_from_bundle(arrays: dict, *, k_n: float, friction: FrictionLaw) -> dict[str, float]:
    """Homogenized friction ``mu0``, ``G0`` of a cell's contact surface (paper eqs. 42-43).

    With the bundle's weights ``w_q = k_n ds_q / |T|`` and micro normals
    ``n_q`` (first component ``beta_q = n_q . n0``), the threshold along a
    macro tangent ``t`` is eq. 43 with the paper's ``|alpha|`` taken as
    ``|(I - n_q n_q^T) t|`` (isotropic micro friction, see
    :mod:`ngcontact.cell.coefficients`):

    * micro Tresca threshold ``G``:
      ``G0 = sum_q (w_q / k_n) G |(I - n_q n_q^T) t|`` [stress], ``mu0 = 0``;
    * micro Coulomb coefficient ``mu``: the micro pressure of the closed
      surface under a macro closure ``a_n`` is ``k_n beta_q a_n`` where
      ``beta_q > 0``, so the threshold ``mu sum_q w_q beta_q |(I - n_q n_q^T) t| a_n``
      over the macro pressure ``sum_q w_q beta_q^2 a_n`` gives

          mu0 = mu sum_{beta_q > 0} w_q beta_q |(I - n_q n_q^T) t| / sum_{beta_q > 0} w_q beta_q^2,

      ``G0 = 0`` (``mu0 = mu`` on a flat cell).

    The whole contact surface counts (the bundle's directions open on
    their own, the threshold does not).  In 2D ``|(I - n_q n_q^T) t0| =
    |beta_q|``, so ``mu0 = mu`` and ``G0 = G`` on every profile: the
    roughness's own share of the macro friction is in the bundle's
    directions (a bundle with ``mu0`` slides at ``tau / p = tan theta + mu``
    on a sawtooth with faces at ``theta``, where the resolved interface
    slides at the wedge's ``(tan theta + mu) / (1 - mu tan theta)``), and
    the tabulated cell law of the two-scale loop, which has no such
    directions, takes the cell's tabulated shear instead
    (:mod:`ngcontact.coupling.shear_table`; ``scripts/sawtooth_shear.py``).  With two macro tangents (a 3D
    cell) the larger value is taken, the macro friction being isotropic.
    A micro law's threshold is taken in its affine parts ``G + mu p``
    (:meth:`ngcontact.laws.friction.FrictionLaw.affine_parts`: ``G`` for
    Tresca, ``mu`` for Coulomb); ``mu0`` is computed for a law that
    couples to the pressure only.  Returns ``{"mu0", "G0"}``.
    """
    w = np.asarray(arrays["w"], float)
    n = np.asarray(arrays["n"], float)
    beta = n[:, 0]
    proj = [np.sqrt(np.clip(1.0 - n[:, j] ** 2, 0.0, None)) for j in range(1, n.shape[1])]
    G, mu = friction.affine_parts()
    G0 = float(max(np.sum(w / k_n * G * p) for p in proj))
    if not friction.couples_to_pressure:
        return {"mu0": 0.0, "G0": G0}
    up = beta > 0
    den = float(np.sum(w[up] * beta[up] ** 2))
    if not den > 0:
        raise ValueError("the cell's contact surface has no direction facing the counter body")
    return {"mu0": float(max(mu * np.sum(w[up] * beta[up] * p[up]) / den for p in proj)), "G0": G0}
