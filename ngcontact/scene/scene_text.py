"""A scene table as TOML text: what :func:`ngcontact.scene.loader.load` reads back to the same table.

The scene files are TOML (https://toml.io, v1.0): tables of keys whose values are strings, numbers,
booleans, arrays of them, inline tables and sub-tables.  :func:`dumps` writes the plain data of a parsed
scene (as :mod:`tomllib` returns it) in that grammar: the top-level scalars first, then one ``[section]``
per table (``[a.b]`` for a nested one), one ``[[name]]`` per element of an array of tables
(``[[supports]]``), every other value inline.  Floats are written with :func:`repr`, which round-trips
a double exactly.  File paths are written as given; a caller moving a scene to another directory makes
them absolute first (:func:`with_absolute_paths`).
"""
from __future__ import annotations

import json
import math
import os
import re

_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _key(name: str) -> str:
    return name if _BARE_KEY.fullmatch(name) else json.dumps(name)


def _value(v) -> str:
    """One TOML value, inline."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)   # a JSON string is a TOML basic string
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write a {type(v).__name__} as a TOML value")


def _is_table_array(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def _table(path: list[str], table: dict, out: list[str], header: str | None, always: bool = False) -> None:
    """Append ``table`` under ``header`` (None: the top level; written where needed, or ``always``: an
    element of an array of tables): its scalars, then its sub-tables."""
    scalars = [(k, v) for k, v in table.items() if not isinstance(v, dict) and not _is_table_array(v)]
    if header is not None and (always or scalars or not any(isinstance(v, dict) for v in table.values())):
        out.append(header)
    out.extend(f"{_key(k)} = {_value(v)}" for k, v in scalars)
    for k, v in table.items():
        sub = path + [_key(k)]
        if isinstance(v, dict):
            out.append("")
            _table(sub, v, out, "[" + ".".join(sub) + "]")
        elif _is_table_array(v):
            for item in v:
                out.append("")
                _table(sub, item, out, "[[" + ".".join(sub) + "]]", always=True)


def dumps(data: dict, comment: str = "") -> str:
    """The TOML text of the table ``data``; ``comment`` (lines) is written first as ``#`` comments."""
    out = [f"# {line}".rstrip() for line in comment.splitlines()]
    _table([], data, out, None)
    return re.sub(r"\n{3,}", "\n\n", "\n".join(out)).strip("\n") + "\n"


def with_absolute_paths(data: dict, base_dir: str, keys=("file", "law_file", "cell")) -> dict:
    """A copy of ``data`` with every string under a key of ``keys`` (the scene's file paths, relative to its
    directory ``base_dir``) made absolute, so that the scene reads the same files from anywhere."""
    def walk(node):
        if isinstance(node, dict):
            return {k: (os.path.normpath(os.path.join(base_dir, v)) if isinstance(v, str) and k in keys
                        else walk(v)) for k, v in node.items()}
        if isinstance(node, list):
            return [walk(x) for x in node]
        return node
    return walk(data)
