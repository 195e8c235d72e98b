"""Scene files: TOML descriptions validated into frozen dataclasses.

A scene describes one problem and holds no mesh.  The top-level key ``kind``
selects the problem type, whose description class and effects stand in the
explicit table :data:`ngcontact.scene.kinds.KINDS`; the effects are the
physical terms the scene calls for (only those are assembled; the report
lists them).  File paths in a scene are relative to the scene file.
"""
from __future__ import annotations

import dataclasses
import os

from ngcontact.errors import MISSING, SceneError
from ngcontact.scene.kinds import KINDS
from ngcontact.scene.schema import build
from ngcontact.scene.sections import resolve

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - exercised on 3.10 only
    import tomli as tomllib

__all__ = ["load", "from_dict", "effects", "as_dict", "resolve"]


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
    kind = data.get("kind")
    if kind not in KINDS:
        raise SceneError("kind", kind if kind is not None else MISSING,
                         "must be one of " + ", ".join(repr(k) for k in sorted(KINDS)))
    scene = build(KINDS[kind].scene, data)
    object.__setattr__(scene, "base_dir", base_dir)
    check_files = getattr(scene, "check_files", None)
    if callable(check_files):  # nested scenes (a macro scene's cell) load through this loader
        check_files(load)
    return scene


def effects(scene) -> tuple[str, ...]:
    """The physical effects (assembled terms) a scene calls for."""
    return tuple(KINDS[scene.kind].effects(scene))


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

