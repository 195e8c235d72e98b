"""Scene files: TOML descriptions validated into frozen dataclasses.

A scene describes one problem and holds no mesh.  The top-level key ``kind``
selects the problem type; each kind has its own dataclass, registered in
:data:`KINDS` together with the function that runs it and the function that
derives, once, the physical effects the scene calls for (only those terms are
assembled; the report lists them).

Sections shared by all kinds:

* ``[materials.NAME]``: ``E`` and ``nu`` (isotropic) or ``C`` (6x6 Voigt
  matrix), optional ultimate stress ``sigma_u``;
* ``[discretization]``: polynomial order and mesh size;
* ``[solver]``: Newton tolerances and limits.

File paths in a scene are relative to the scene file.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field

from . import materials as _materials
from .errors import MISSING, SceneError
from .schema import at_least, build, nonempty, open_interval, param, positive

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - exercised on 3.10 only
    import tomli as tomllib


# ------------------------------------------------------------ common parts
@dataclass(frozen=True, kw_only=True)
class MaterialSpec:
    """Elastic material: isotropic ``(E, nu)`` or anisotropic ``C``."""

    E: float | None = param(None, doc="Young's modulus (isotropic)", units="Pa", check=positive())
    nu: float | None = param(None, doc="Poisson's ratio (isotropic)", check=open_interval(-1, 0.5))
    C: tuple[tuple[float, ...], ...] | None = param(
        None, doc="6x6 Voigt stiffness matrix, order 11,22,33,23,13,12 with engineering shear strains",
        units="Pa", allowed="6 rows of 6 numbers, symmetric positive definite")
    sigma_u: float | None = param(None, doc="ultimate stress for the strength check", units="Pa",
                                  check=positive())

    def check(self, path: str) -> None:
        iso = self.E is not None or self.nu is not None
        if iso and self.C is not None:
            raise SceneError(path + ".C", self.C, "give either E and nu or C, not both")
        if self.C is None:
            if self.E is None:
                raise SceneError(path + ".E", MISSING, "required (or give C); a number > 0")
            if self.nu is None:
                raise SceneError(path + ".nu", MISSING, "required (or give C); a number in (-1, 0.5)")
            return
        try:
            _materials.anisotropic(self.C)
        except ValueError as exc:
            raise SceneError(path + ".C", self.C, str(exc).replace("C ", "", 1)) from None

    def law(self) -> _materials.ElasticLaw:
        """The elastic law described."""
        if self.C is not None:
            return _materials.anisotropic(self.C)
        return _materials.isotropic(self.E, self.nu)


@dataclass(frozen=True, kw_only=True)
class Discretization:
    """Finite element discretization."""

    order: int = param(2, doc="polynomial order of the displacement", check=at_least(1))
    maxh: float = param(0.1, doc="global mesh size", units="m", check=positive())
    interface_maxh: float | None = param(None, doc="mesh size on the interface (default: maxh)",
                                         units="m", check=positive())


@dataclass(frozen=True, kw_only=True)
class SolverSpec:
    """Newton solver settings."""

    rtol: float = param(1e-10, doc="stop when the residual falls below rtol x the first residual",
                        check=positive())
    atol: float = param(0.0, doc="or below this absolute residual", units="N", check=at_least(0))
    max_iter: int = param(40, doc="largest number of Newton steps", check=at_least(1))
    inverse: str = param("sparsecholesky", doc="sparse direct solver",
                         choices=("sparsecholesky", "umfpack"))


def materials_param(doc: str = "named materials; see [materials.NAME]"):
    return param(doc=doc, check=nonempty())


def check_material_names(materials: dict, names: dict, path: str) -> None:
    """Every ``key -> material name`` in ``names`` must exist in ``materials``."""
    for key, name in names.items():
        if name not in materials:
            raise SceneError(f"{path}.{key}" if path else key, name,
                             "must name a material defined under [materials]: "
                             + ", ".join(sorted(materials)))


# ------------------------------------------------------------ registry
@dataclass(frozen=True, kw_only=True)
class Kind:
    """A problem type: its scene class, runner and effects."""

    scene: type
    runner: str  # "module:function", imported lazily so that `check` stays light
    effects: object  # function scene -> tuple[str, ...]


KINDS: dict[str, Kind] = {}


def register(name: str, scene: type, runner: str, effects) -> None:
    KINDS[name] = Kind(scene=scene, runner=runner, effects=effects)


def load(path: str | os.PathLike):
    """Read and validate a scene file.

    Raises
    ------
    SceneError
        With the key path, the offending value and what is allowed.
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise SceneError("<scene file>", path, "no such file")
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError("<scene file>", path, f"not valid TOML ({exc})") from None
    return from_dict(data, base_dir=os.path.dirname(os.path.abspath(path)))


def from_dict(data: dict, base_dir: str = "."):
    """Validate an already parsed scene table."""
    _ensure_kinds()
    kind = data.get("kind")
    if kind not in KINDS:
        raise SceneError("kind", kind if kind is not None else MISSING,
                         "must be one of " + ", ".join(repr(k) for k in sorted(KINDS)))
    scene = build(KINDS[kind].scene, data)
    object.__setattr__(scene, "base_dir", base_dir)
    check_files = getattr(scene, "check_files", None)
    if callable(check_files):
        check_files()
    return scene


def effects(scene) -> tuple[str, ...]:
    """The physical effects (assembled terms) a scene calls for."""
    return tuple(KINDS[scene.kind].effects(scene))


def resolve(scene, relpath: str) -> str:
    """Absolute path of a file named in a scene (relative to the scene file)."""
    return os.path.normpath(os.path.join(getattr(scene, "base_dir", "."), relpath))


def as_dict(scene) -> dict:
    """The validated scene as plain data (for the report)."""
    return _plain(scene)


def _plain(obj):
    if dataclasses.is_dataclass(obj):
        return {f.name: _plain(getattr(obj, f.name)) for f in dataclasses.fields(obj) if f.init}
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, tuple):
        return [_plain(v) for v in obj]
    return obj


def base_dir_field():
    return field(default=".", init=False, repr=False, compare=False)


def _ensure_kinds() -> None:
    """Import the modules that register the kinds."""
    from . import kinds  # noqa: F401  (registers on import)
