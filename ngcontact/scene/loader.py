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
from ngcontact.scene.schema import MAX_SCENE_BYTES, build, is_key
from ngcontact.scene.sections import check_input_file, resolve

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - exercised on 3.10 only
    import tomli as tomllib

__all__ = ["load", "load_with_contact", "from_dict", "effects", "as_dict", "resolve", "inputs", "parsed"]

#: Real paths of the scene files being loaded, outermost first: a scene that
#: names itself, directly or through others, as a cell is refused by name.
_LOADING: list[str] = []

#: Keys whose string value names a file the scene reads (``cell``: a scene).
FILE_KEYS = ("file", "law_file")
SCENE_KEYS = ("cell",)


def load(path: str | os.PathLike):
    """Read and validate a scene file.

    Raises
    ------
    SceneError
        With the key path, the offending value and what is allowed.
    """
    path = os.fspath(path)
    check_input_file("<scene file>", path, "scene file", missing="no such file", max_bytes=MAX_SCENE_BYTES)
    real = os.path.realpath(path)
    if real in _LOADING:
        chain = " -> ".join(os.path.basename(p) for p in _LOADING[_LOADING.index(real):] + [real])
        raise SceneError("<scene file>", path, f"names itself as a scene to load ({chain}); a cell scene "
                         "must not refer back to the scene that uses it")
    data = _parsed(path)
    _LOADING.append(real)
    try:
        return from_dict(data, base_dir=os.path.dirname(os.path.abspath(path)))
    finally:
        _LOADING.pop()


def load_with_contact(path: str | os.PathLike, overrides: dict | None = None, method: str | None = None,
                      discretization: dict | None = None):
    """:func:`load` a cell scene with some keys of its ``[contact]`` section replaced.

    ``overrides`` maps ``[contact]`` keys (``k_n``, ``friction``, ``mu``,
    ``G``, ``w``) to values; a new ``friction`` drops the cell's own ``mu``,
    ``G`` and ``w`` unless they are overridden too.  ``method`` (``"fe"`` or
    ``"spectral"``), when given, replaces ``discretization.method``, and
    ``discretization`` other keys of that section (``grid``, ``maxh``, ...).
    The result is validated as a whole (a fault names the cell key, e.g.
    ``contact.mu``).
    """
    if not overrides and method is None and not discretization:
        return load(path)
    path = os.fspath(path)
    base = load(path)   # the file itself must be a valid scene
    if base.kind != "cell":
        return base
    data = _parsed(path)
    contact = dict(data.get("contact", {}))
    overrides = overrides or {}
    if "friction" in overrides:
        for key in ("mu", "G", "w"):
            contact.pop(key, None)
    contact.update(overrides)
    data["contact"] = contact
    if method is not None or discretization:
        data["discretization"] = {**data.get("discretization", {}), **(discretization or {}),
                                  **({} if method is None else {"method": method})}
    return from_dict(data, base_dir=os.path.dirname(os.path.abspath(path)))


def parsed(path: str | os.PathLike) -> dict:
    """The TOML table of a scene file as written (no defaults filled in); :func:`load` validates it."""
    path = os.fspath(path)
    check_input_file("<scene file>", path, "scene file", missing="no such file", max_bytes=MAX_SCENE_BYTES)
    return _parsed(path)


def _parsed(path: str) -> dict:
    """The TOML table of the scene file ``path``.

    A UTF-8 byte-order mark at the start is skipped: editors on Windows
    write one, and TOML (UTF-8 without a mark) would refuse the file at
    line 1, column 1 without naming the mark.
    """
    try:
        with open(path, "rb") as fh:
            return tomllib.loads(fh.read().decode("utf-8-sig"))
    except tomllib.TOMLDecodeError as exc:
        raise SceneError("<scene file>", path, f"not valid TOML ({exc})") from None
    except RecursionError:
        raise SceneError("<scene file>", path, "nests arrays or tables too deeply to be a scene") from None
    except UnicodeDecodeError:
        raise SceneError("<scene file>", path, "must be UTF-8 text (TOML)") from None


def from_dict(data: dict, base_dir: str = "."):
    """Validate an already parsed scene table."""
    kind = data.get("kind")
    if not isinstance(kind, str) or kind not in KINDS:
        raise SceneError("kind", kind if kind is not None else MISSING,
                         "must be one of " + ", ".join(repr(k) for k in sorted(KINDS)))
    scene = build(KINDS[kind].scene, data)
    object.__setattr__(scene, "base_dir", base_dir)
    check_files = getattr(scene, "check_files", None)
    if callable(check_files):  # nested scenes (a macro scene's cell) load through this loader
        check_files(load_with_contact)
    return scene


def inputs(scene, path: str | None = None) -> list[str]:
    """The files a validated scene reads: its own file (``path``), its data files and nested scenes.

    Every string under a key named ``file`` is a data file and every string
    under ``cell`` a scene, whose own inputs count too (paths relative to
    the scene that names them).
    """
    out = [os.path.abspath(path)] if path else []

    def walk(node, base):
        if isinstance(node, dict):
            for key, value in node.items():
                if isinstance(value, str) and key in FILE_KEYS:
                    out.append(resolve(base, value))
                elif isinstance(value, str) and key in SCENE_KEYS:
                    nested = resolve(base, value)
                    if nested not in out:
                        out.append(nested)
                        out.extend(p for p in inputs(load(nested)) if p not in out)
                else:
                    walk(value, base)
        elif isinstance(node, (list, tuple)):
            for value in node:
                walk(value, base)

    walk(as_dict(scene), scene)
    return out


def effects(scene) -> tuple[str, ...]:
    """The physical effects (assembled terms) a scene calls for."""
    return tuple(KINDS[scene.kind].effects(scene))


def as_dict(scene) -> dict:
    """The validated scene as plain data (for the report)."""
    return _plain(scene)


def _plain(obj):
    if dataclasses.is_dataclass(obj):
        return {f.name: _plain(getattr(obj, f.name)) for f in dataclasses.fields(obj) if is_key(f)}
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, tuple):
        return [_plain(v) for v in obj]
    return obj

