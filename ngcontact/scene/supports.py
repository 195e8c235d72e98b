"""The ``[[supports]]`` of the ``macro`` and ``direct`` kinds: one description, one set of checks.

A support prescribes displacement components on a named boundary:

* constant, or tilted: ``displacement`` is the value at the boundary's
  mid-point and ``slope`` its change per metre along the boundary (along
  ``x`` / ``r`` on a horizontal boundary, ``y`` / ``z`` on a vertical one;
  a straight 2D boundary), so ``u_c = displacement_c + slope_c (s - s_mid)``;
* affine: ``u_c(x) = u0_c + sum_j G_cj x_j`` in absolute coordinates, a
  vector ``u0`` and a matrix ``G`` with one row per prescribed component
  (any boundary, any setting; the tilted support is the special case of a
  ``G`` with one column);
* a symmetry plane: ``symmetry = true`` fixes the normal displacement of a
  boundary that is a plane normal to a coordinate axis (a straight line in
  2D; in axisymmetry ``r = const`` gives ``u_r = 0``, ``z = const`` gives
  ``u_z = 0``), found from the mesh.

The driver turns these into :class:`ngcontact.fem.two_body.Support` once the
mesh exists (the plane's axis and the slope's direction are read off it).
"""
from __future__ import annotations

from dataclasses import dataclass

from ngcontact.errors import SceneError
from ngcontact.scene.mesh_size import LENGTH_RANGE, check_magnitudes
from ngcontact.scene.schema import distinct, param


@dataclass(frozen=True, kw_only=True)
class SupportSpec:
    """Prescribed displacement components on a boundary: constant, tilted, affine, or a symmetry plane."""

    boundary: str = param(doc="boundary label of the geometry (the scene's shape lists them)")
    components: tuple[str, ...] = param((), doc="components fixed (x, y, z; r, z in axisymmetry); empty: all",
                                        check=distinct())
    displacement: tuple[float, ...] = param((), doc="value at the boundary's mid-point, one per component "
                                            "(default 0)", units="m")
    slope: tuple[float, ...] = param((), doc="change of each prescribed component per metre along the "
                                     "boundary: along x (r) on horizontal boundaries, y (z) on vertical ones "
                                     "(default 0; 2D only)", units="m/m")
    u0: tuple[float, ...] = param((), doc="affine support u = u0 + G x: the value at the origin, one per "
                                  "component (default 0; instead of displacement and slope)", units="m")
    G: tuple[tuple[float, ...], ...] = param(
        (), doc="affine support u = u0 + G x: the displacement gradient, one row per component, one column "
        "per coordinate (x, y[, z]; r, z in axisymmetry)", units="m/m",
        allowed="a matrix: one row per prescribed component, one number per coordinate")
    symmetry: bool = param(False, doc="a symmetry plane: fix the normal displacement of this boundary, which "
                           "must be a plane normal to a coordinate axis (give no components or values)")

    def affine(self) -> bool:
        """Whether the support is given as ``u0 + G x``."""
        return bool(self.u0) or bool(self.G)


def check_values(supports, comps: tuple[str, ...], setting: str) -> None:
    """Components known; one value per component; ``G``'s shape; no mixed forms; symmetry alone; values and
    gradients at most the upper end of the length range in magnitude (:mod:`ngcontact.scene.mesh_size`).

    Raises :class:`SceneError` naming ``supports[i].KEY``, the value and what
    is allowed.
    """
    dim = 3 if setting == "3d" else 2
    for i, s in enumerate(supports):
        for c in s.components:
            if c not in comps:
                raise SceneError(f"supports[{i}].components", c, "must be one of " + ", ".join(comps))
        n = len(s.components or comps)
        if s.symmetry:
            for key in ("components", "displacement", "slope", "u0", "G"):
                if getattr(s, key):
                    raise SceneError(f"supports[{i}].{key}", getattr(s, key), "not used with symmetry = true "
                                     "(the plane fixes its normal component at zero); remove it")
            continue
        for key in ("displacement", "slope", "u0"):
            v = getattr(s, key)
            if v and len(v) != n:
                raise SceneError(f"supports[{i}].{key}", v, f"one value per component ({n}: "
                                 + ", ".join(s.components or comps) + ")")
        if s.G and (len(s.G) != n or any(len(row) != dim for row in s.G)):
            raise SceneError(f"supports[{i}].G", [list(row) for row in s.G],
                             f"one row per prescribed component ({n}: {', '.join(s.components or comps)}), each "
                             f"with {dim} numbers (the derivatives along {', '.join(comps)})")
        if s.affine() and (s.displacement or s.slope):
            key = "displacement" if s.displacement else "slope"
            raise SceneError(f"supports[{i}].{key}", getattr(s, key), "give either displacement and slope "
                             "(values at the boundary's mid-point) or u0 and G (u = u0 + G x), not both")
        check_magnitudes({f"supports[{i}].{key}[{k}]": v for key in ("displacement", "u0")
                          for k, v in enumerate(getattr(s, key))})
        for key, v in [(f"slope[{k}]", v) for k, v in enumerate(s.slope)] + [
                (f"G[{r}][{c}]", v) for r, row in enumerate(s.G) for c, v in enumerate(row)]:
            if abs(v) > LENGTH_RANGE[1]:
                raise SceneError(f"supports[{i}].{key}", v, f"must be at most {LENGTH_RANGE[1]:g} in magnitude (a "
                                 "displacement gradient, metres per metre)")
        if s.slope and dim == 3:
            raise SceneError(f"supports[{i}].slope", s.slope, "a face in 3D has two directions: give the "
                             "tilt as u0 and G (u = u0 + G x)")
