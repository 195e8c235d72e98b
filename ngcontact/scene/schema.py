"""Declarative, validated descriptions built from TOML tables.

A scene section is a frozen dataclass whose fields carry their documentation
and their admissible values in ``dataclasses.field(metadata=...)``, created
with :func:`param`.  :func:`build` turns a parsed TOML table into such a
dataclass and rejects, with a :class:`~ngcontact.errors.SceneError` naming the
key path, the value and what is allowed,

* unknown keys (the message lists the known ones; a key the section's
  ``REMOVED`` table lists is named with what replaces it),
* values of the wrong type (``bool`` is never a number, an ``int`` is accepted
  where a ``float`` is asked for),
* NaN or infinite numbers anywhere (TOML admits ``nan`` and ``inf``),
* values outside their range or set of choices,
* strings (and names of tables) longer than :data:`MAX_STRING` characters.

A section that declares a field ``given`` (``init=False``) is told the keys
its table set (:data:`GIVEN`), so that a rule can tell a key the scene wrote
from one left at its default (``discretization.method = "auto"``,
:mod:`ngcontact.scene.cell_method`).

A field the scene derives from its keys rather than reads from its file
(:func:`derived_field`: a cell scene's resolved ``discretization.method``, and
its FE cell's symmetry, which the drivers resolve since its rule reads the
gap's files) is no key: :func:`build` leaves it out of the table and, where the
dataclass has a method ``resolved(self)``, builds the instance that method
returns (the scene with its derived fields, by ``dataclasses.replace``) before
the checks.

Cross-field rules live in a method ``check(self, path)`` of the dataclass,
called after construction.  :func:`describe` walks the same metadata to write
the scene-file reference of the README, so documentation and validation come
from one source.
"""
from __future__ import annotations

import dataclasses
import math
import types
import typing
from typing import Any, Callable, Union

from ngcontact.errors import MISSING, SceneError

Check = Callable[[Any], "str | None"]


def param(default=dataclasses.MISSING, *, doc: str, units: str = "",
          check: Check | None = None, choices: tuple | None = None,
          allowed: str | None = None):
    """A documented, validated dataclass field.

    Parameters
    ----------
    default
        Default value; omit for a required key.
    doc
        One-line meaning, shown in the README reference.
    units
        Physical units, or ``""`` for dimensionless / not applicable.
    check
        Function of the value returning ``None`` when it is admissible and a
        short description of what is allowed otherwise.
    choices
        Admissible values of a string (or other) key.
    allowed
        Human description of the admissible range for the reference table;
        derived from ``check`` or ``choices`` when omitted.
    """
    meta = {"doc": doc, "units": units, "check": check, "choices": choices,
            "allowed": allowed}
    if isinstance(default, (list, dict, set)):
        raise TypeError("mutable defaults are not allowed; use a tuple")
    return dataclasses.field(default=default, metadata=meta)


# ----------------------------------------------------------------- checks
#: Largest polynomial order: beyond it a single element has thousands of dofs and the
#: quadrature tables of the compiled library run out (order 100 ended in std::bad_alloc).
MAX_ORDER = 10
#: Largest number of resolved periods and of uniform refinement levels (more hung the mesher).
MAX_PERIODS = 1024
MAX_LEVELS = 8
#: Longest string of a scene (a title, a file name, a label): the longest path Linux accepts (PATH_MAX);
#: a string is copied into the reports, so an unbounded one made them as large as itself.
MAX_STRING = 4096
#: Largest scene file (bytes), checked before it is parsed; the shipped scenes are below 6 kB.
MAX_SCENE_BYTES = 2 ** 20


#: the name of a section's field that holds the keys its table set (see the module docstring)
GIVEN = "given"


def given_field():
    """The field :data:`GIVEN` of a section: the keys its table set, filled in by :func:`build`."""
    return dataclasses.field(default=frozenset(), init=False, repr=False, compare=False)


def replaced(section, **changes):
    """``dataclasses.replace(section, **changes)`` keeping the keys the section's table set (its
    :data:`GIVEN`, which ``replace`` resets): a changed section's defaults are decided as the original's."""
    out = dataclasses.replace(section, **changes)
    if hasattr(section, GIVEN):
        object.__setattr__(out, GIVEN, getattr(section, GIVEN))
    return out


#: the metadata flag of a :func:`derived_field`
DERIVED = "derived"


def derived_field():
    """A field the scene derives from its keys (module docstring): typed, set through the constructor or
    ``dataclasses.replace`` by the dataclass's ``resolved`` (or by the driver that resolves it), ``None``
    until then; not a key of the file, the reference or the report's scene."""
    return dataclasses.field(default=None, repr=False, compare=False, metadata={DERIVED: True})


def is_key(f: dataclasses.Field) -> bool:
    """Whether field ``f`` is a key of the scene file (not a loader's or a :func:`derived_field`)."""
    return f.init and not f.metadata.get(DERIVED, False)


def _named(text: str, fn: Callable[[Any], bool]) -> Check:
    def check(value):
        return None if fn(value) else text
    # the description is kept as a function attribute, read back with
    # getattr(check, "text", "") by all_of and describe
    setattr(check, "text", text)
    return check


def positive() -> Check:
    return _named("must be > 0", lambda v: _all(v, lambda x: x > 0))


def nonnegative() -> Check:
    return _named("must be >= 0", lambda v: _all(v, lambda x: x >= 0))


def at_least(lo) -> Check:
    return _named(f"must be >= {lo}", lambda v: _all(v, lambda x: x >= lo))


def open_interval(lo, hi) -> Check:
    return _named(f"must lie in ({lo}, {hi})", lambda v: _all(v, lambda x: lo < x < hi))


def half_open(lo, hi) -> Check:
    return _named(f"must lie in [{lo}, {hi})", lambda v: _all(v, lambda x: lo <= x < hi))


def left_open(lo, hi) -> Check:
    return _named(f"must lie in ({lo}, {hi}]", lambda v: _all(v, lambda x: lo < x <= hi))


def closed_interval(lo, hi) -> Check:
    return _named(f"must lie in [{lo}, {hi}]", lambda v: _all(v, lambda x: lo <= x <= hi))


def nonempty() -> Check:
    return _named("must not be empty", lambda v: len(v) > 0)


def distinct() -> Check:
    """Entries that name something (a component, an order) once each: a repeated one was dropped silently."""
    return _named("must not repeat an entry", lambda v: len(set(v)) == len(v))


def all_of(*checks: Check) -> Check:
    def check(value):
        for c in checks:
            msg = c(value)
            if msg:
                return msg
        return None
    setattr(check, "text", "; ".join(getattr(c, "text", "") for c in checks))
    return check


def _all(value, pred) -> bool:
    if isinstance(value, tuple):
        return all(_all(v, pred) for v in value)
    return pred(value)


def check_selected(obj, path: str, selector: str, keys, need, optional=()) -> None:
    """Keys that a choice (``selector``, e.g. ``friction``) requires or does not use.

    For each of ``keys`` in order: absent but in ``need`` is an error
    ``path.key = <missing>: required for selector = 'value'``; present but in
    neither ``need`` nor ``optional`` is ``path.key = value: not used by
    selector = 'value'; remove it``.
    """
    choice = getattr(obj, selector)
    for key in keys:
        value = getattr(obj, key)
        if key in need and value is None:
            raise SceneError(f"{path}.{key}", MISSING, f"required for {selector} = {choice!r}")
        if key not in need and key not in optional and value is not None:
            raise SceneError(f"{path}.{key}", value, f"not used by {selector} = {choice!r}; remove it")


# ------------------------------------------------------------------ build
def build(cls, data: Any, path: str = ""):
    """Validate the TOML table ``data`` into an instance of dataclass ``cls``.

    Parameters
    ----------
    cls
        A dataclass whose fields were declared with :func:`param`.
    data
        The parsed TOML table.
    path
        Key path of ``data`` within the scene, used in error messages.
    """
    if not isinstance(data, dict):
        raise SceneError(path or "<scene>", data, "must be a table")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if is_key(f)}
    unknown = sorted(set(data) - set(fields))
    if unknown:
        key = unknown[0]
        successor = getattr(cls, "REMOVED", {}).get(key)
        if successor is not None:
            raise SceneError(_join(path, key), data[key], f"removed; use {successor}")
        raise SceneError(_join(path, key), data[key],
                         "unknown key; allowed keys here are " + ", ".join(sorted(fields)))
    values = {}
    for name, f in fields.items():
        key = _join(path, name)
        if name not in data:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise SceneError(key, MISSING, "required key; " + _allowed_text(f, hints[name]))
            continue
        value = _convert(hints[name], data[name], key)
        _apply_checks(f, value, key)
        values[name] = value
    obj = cls(**values)
    if any(f.name == GIVEN and not f.init for f in dataclasses.fields(cls)):
        object.__setattr__(obj, GIVEN, frozenset(values))
    resolved = getattr(obj, "resolved", None)
    if callable(resolved):
        obj = resolved()
    check = getattr(obj, "check", None)
    if callable(check):
        check(path)
    return obj


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key


def _apply_checks(f, value, key):
    if value is None:
        return
    choices = f.metadata.get("choices")
    if choices is not None and value not in choices:
        raise SceneError(key, value, "must be one of " + ", ".join(repr(c) for c in choices))
    check = f.metadata.get("check")
    if check is not None:
        msg = check(value)
        if msg:
            raise SceneError(key, value, msg)


def _convert(tp, value, key):
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        options = [a for a in args if a is not type(None)]
        if len(options) == 1:  # an optional value: keep the inner key path (e.g. load.pressure[1])
            return _convert(options[0], value, key)
        errors = []
        for a in options:
            try:
                return _convert(a, value, key)
            except SceneError as exc:
                errors.append(exc.allowed)
        raise SceneError(key, value, " or ".join(dict.fromkeys(errors)))
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SceneError(key, value, "must be a number")
        if not math.isfinite(value):
            raise SceneError(key, value, "must be a finite number")
        return float(value)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise SceneError(key, value, "must be an integer")
        return value
    if tp is bool:
        if not isinstance(value, bool):
            raise SceneError(key, value, "must be true or false")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise SceneError(key, value, "must be a string")
        if len(value) > MAX_STRING:
            raise SceneError(key, value, f"must be at most {MAX_STRING} characters")
        return value
    if origin is tuple:
        if not isinstance(value, (list, tuple)):
            raise SceneError(key, value, f"must be a list of {_type_name(args[0])}")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(args[0], v, f"{key}[{i}]") for i, v in enumerate(value))
        if len(value) != len(args):
            raise SceneError(key, value, f"must be a list of {len(args)} entries")
        return tuple(_convert(a, v, f"{key}[{i}]") for i, (a, v) in enumerate(zip(args, value)))
    if origin is dict:
        if not isinstance(value, dict):
            raise SceneError(key, value, "must be a table")
        for k in value:
            if len(k) > MAX_STRING:
                raise SceneError(key, k, f"a name must be at most {MAX_STRING} characters")
        return {k: _convert(args[1], v, _join(key, k)) for k, v in value.items()}
    if dataclasses.is_dataclass(tp):
        return build(tp, value, key)
    raise TypeError(f"unsupported field type {tp!r} at {key}")


def _type_name(tp) -> str:
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (Union, types.UnionType):
        return " or ".join(_type_name(a) for a in args if a is not type(None))
    if origin is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            return f"list of {_type_name(args[0])}"
        return f"list of {len(args)} numbers"
    if origin is dict:
        return "table of tables"
    if dataclasses.is_dataclass(tp):
        return "table"
    return {float: "number", int: "integer", bool: "boolean", str: "string"}.get(tp, str(tp))


def _allowed_text(f, tp) -> str:
    meta = f.metadata
    if meta.get("allowed"):
        return meta["allowed"]
    if meta.get("choices"):
        return "one of " + ", ".join(repr(c) for c in meta["choices"])
    check = meta.get("check")
    text = getattr(check, "text", "") if check else ""
    if _unwrap_optional(tp) is str and not text:
        text = f"at most {MAX_STRING} characters"
    return f"{_type_name(tp)}" + (f", {text}" if text else "")


# --------------------------------------------------------------- describe
def describe(cls, path: str = "") -> list[dict]:
    """Rows (key, type, default, units, allowed, meaning) of a scene section.

    Nested dataclasses are expanded; ``dict[str, Section]`` fields appear as
    ``path.NAME.key``; an array of tables (``tuple[Section, ...]``) has its
    own row and its entries' keys as ``path[].key``.
    """
    rows = []
    hints = typing.get_type_hints(cls)
    for f in dataclasses.fields(cls):
        if not is_key(f):
            continue
        tp = hints[f.name]
        key = _join(path, f.name)
        inner = _unwrap_optional(tp)
        if dataclasses.is_dataclass(inner):
            rows.extend(describe(inner, key))
            continue
        if typing.get_origin(inner) is dict and dataclasses.is_dataclass(typing.get_args(inner)[1]):
            rows.extend(describe(typing.get_args(inner)[1], key + ".NAME"))
            continue
        default = "required" if f.default is dataclasses.MISSING else _fmt_default(f.default)
        rows.append({"key": key, "type": _type_name(tp), "default": default,
                     "units": f.metadata.get("units", ""),
                     "allowed": _allowed_text(f, tp),
                     "doc": f.metadata.get("doc", "")})
        entries = typing.get_args(inner) if typing.get_origin(inner) is tuple else ()
        if len(entries) == 2 and entries[1] is Ellipsis and dataclasses.is_dataclass(entries[0]):
            rows.extend(describe(entries[0], key + "[]"))
    return rows


def _unwrap_optional(tp):
    if typing.get_origin(tp) in (Union, types.UnionType):
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        if len(args) == 1:
            return args[0]
    return tp


def _fmt_default(value) -> str:
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, tuple):
        return "[" + ", ".join(_fmt_default(v) for v in value) + "]"
    return repr(value)
