"""The interface-law file written by ``ngcontact export --format json``, read back by a macro scene.

``interface.law = "file"`` with ``interface.law_file = "law.json"`` takes the
normal law from such a file; ``interface.law_file_form`` picks which of its
forms: ``bundle`` (the direction bundle of paper eqs. 31-33, exact),
``tabulated`` (the pressure-closure table with the stick slope as the
tangential stiffness) or ``linear`` (``K0`` and the gap forces of eq. 34).
Friction stays the macro scene's own (``interface.mu``, ``threshold``).

The file is one JSON object (SI units: m, Pa, Pa/m; local frame ``(n0, t0[,
t1])``, compression positive)::

    {"format": "ngcontact-interface-law", "format_version": 1,
     "source": {...}, "units": {...},
     "coefficients": {"K0": [[...]], "gap_force": [...]} | null,
     "bundle": {"weights": [...], "directions": [[...]], "gaps": [...]} | null,
     "table": {"closure": [...], "pressure": [...], "tolerance": t},
     "friction": {"mu": mu0, "stick_slope": k_t0}, "gap": g0, "not_carried": [...]}

This module only reads and validates it (at load time, like every file a
scene names); :mod:`ngcontact.export.json_law` writes it and
:mod:`ngcontact.drivers.build` turns it into a law.  The table is checked
row by row as a monotone law's, every form the file holds as the package's
law, and the form the scene uses by its stiffness (:func:`stiffness`)
against the bodies as a law the scene states is
(:func:`ngcontact.scene.magnitudes.check_file_law`); each fault names the
file, the row or key, its value and what is allowed.
"""
from __future__ import annotations

import json
import math

from ngcontact.errors import SceneError
from ngcontact.laws import homogenized as il
from ngcontact.scene.sections import check_input_file

FORMAT = "ngcontact-interface-law"
FORMAT_VERSION = 1
FORMS = ("bundle", "tabulated", "linear")
#: Largest law file read (bytes).
MAX_BYTES = 64 * 2 ** 20


def _numbers(value, key: str, depth: int):
    """``value`` as nested tuples of finite floats of the given depth (1: list, 2: list of lists)."""
    if depth == 0:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise SceneError(key, value, "a finite number")
        return float(value)
    if not isinstance(value, list) or not value:
        raise SceneError(key, value if not isinstance(value, list) else "[]", "a non-empty list")
    return tuple(_numbers(v, f"{key}[{i}]", depth - 1) for i, v in enumerate(value))


def read(path: str, key: str = "interface.law_file") -> dict:
    """The validated contents of a law file: ``bundle``, ``table``, ``coefficients``, ``stick_slope``.

    Raises
    ------
    SceneError
        Under ``key`` (or ``key: field``) for a missing, unreadable, foreign
        or malformed file, or numbers the laws refuse.
    """
    check_input_file(key, path, "JSON law file", max_bytes=MAX_BYTES,
                     missing="no such law file (write one with `ngcontact export SCENE --format json`)")
    try:
        with open(path, encoding="utf-8-sig") as fh:   # a byte-order mark is skipped, as in scene files
            data = json.load(fh)
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise SceneError(key, path, f"a readable JSON law file ({type(exc).__name__}: {exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise SceneError(key, path, f"a JSON object with \"format\": \"{FORMAT}\" (written by ngcontact export)")
    if data.get("format_version") != FORMAT_VERSION:
        raise SceneError(f"{key}: format_version", data.get("format_version"), f"{FORMAT_VERSION}")
    out: dict = {"bundle": None, "coefficients": None}
    tab = data.get("table")
    if not isinstance(tab, dict):
        raise SceneError(f"{key}: table", tab, "an object with closure and pressure lists")
    out["table"] = {"closure": _numbers(tab.get("closure"), f"{key}: table.closure", 1),
                    "pressure": _numbers(tab.get("pressure"), f"{key}: table.pressure", 1)}
    _check_rows(out["table"], key, path)
    fr = data.get("friction")
    if not isinstance(fr, dict):
        raise SceneError(f"{key}: friction", fr, "an object with mu and stick_slope")
    out["stick_slope"] = _numbers(fr.get("stick_slope"), f"{key}: friction.stick_slope", 0)
    out["mu"] = _numbers(fr.get("mu"), f"{key}: friction.mu", 0)
    if data.get("bundle") is not None:
        b = data["bundle"]
        if not isinstance(b, dict):
            raise SceneError(f"{key}: bundle", b, "an object with weights, directions and gaps")
        out["bundle"] = {"weights": _numbers(b.get("weights"), f"{key}: bundle.weights", 1),
                         "directions": _numbers(b.get("directions"), f"{key}: bundle.directions", 2),
                         "gaps": _numbers(b.get("gaps"), f"{key}: bundle.gaps", 1)}
        for i, w in enumerate(out["bundle"]["weights"]):
            if not w > 0:
                raise SceneError(f"{key}: bundle.weights[{i}]", w, f"in the law file {path}: each direction's weight "
                                 "(a stiffness, Pa/m) must be > 0")
    if data.get("coefficients") is not None:
        co = data["coefficients"]
        if not isinstance(co, dict):
            raise SceneError(f"{key}: coefficients", co, "an object with K0 and gap_force")
        out["coefficients"] = {"K0": _numbers(co.get("K0"), f"{key}: coefficients.K0", 2),
                               "gap_force": _numbers(co.get("gap_force"), f"{key}: coefficients.gap_force", 1)}
    for form in FORMS:  # every form the file holds must be a law the package accepts
        if _has(out, form):
            try:
                normal_law_of(out, form)
            except ValueError as exc:
                raise SceneError(f"{key}: {form}", path, str(exc)) from None
    return out


def _check_rows(table: dict, key: str, path: str) -> None:
    """The pressure-closure table of a law file is a monotone law's, row by row (the rule of
    :class:`ngcontact.laws.tabulated_law.TabulatedLaw`, each fault named by its row): as many pressures as
    closures, at least two rows, the closures strictly increasing, the pressures non-decreasing from 0 and
    not all 0."""
    c, p = table["closure"], table["pressure"]
    where = f"in the law file {path}"
    if len(p) != len(c) or len(c) < 2:
        raise SceneError(f"{key}: table.pressure", f"{len(p)} rows", f"{where}: one pressure per closure "
                         f"({len(c)} closures), at least two rows")
    if p[0] != 0.0:
        raise SceneError(f"{key}: table.pressure[0]", p[0], f"{where}: must be 0 (contact starts at the first "
                         "closure)")
    for i in range(1, len(c)):
        if not c[i] > c[i - 1]:
            raise SceneError(f"{key}: table.closure[{i}]", c[i], f"{where}: the closures must increase strictly "
                             f"(row {i - 1} has {c[i - 1]!r})")
        if p[i] < p[i - 1]:
            raise SceneError(f"{key}: table.pressure[{i}]", p[i], f"{where}: the pressures must not decrease, a "
                             f"monotone law with a convex energy (row {i - 1} has {p[i - 1]!r})")
    if not any(p):
        raise SceneError(f"{key}: table.pressure", list(p), f"{where}: the table carries no pressure; a law needs "
                         "a positive pressure in some row")


def stiffness(contents: dict, form: str) -> tuple[str, str, float, object]:
    """``(field, symbol, k, value)``: the largest normal stiffness ``k`` of the file's law of ``form``, taken as
    an explicit law's is (:func:`ngcontact.scene.magnitudes.interface_stiffness`): the steepest slope
    ``dp/dc`` of the pressure-closure table (``field``: the row it ends at, ``value`` that row's pressure; a
    slope beyond double precision is ``inf``), the summed bundle weights, ``K0``'s normal entry."""
    if form == "bundle":
        w = contents["bundle"]["weights"]
        return "bundle.weights", "sum(weights)", float(math.fsum(w)), list(w)
    if form == "linear":
        kn = contents["coefficients"]["K0"][0][0]
        return "coefficients.K0[0][0]", "K0_nn", kn, kn
    c, p = contents["table"]["closure"], contents["table"]["pressure"]
    slopes = [(p[i] - p[i - 1]) / (c[i] - c[i - 1]) if math.isfinite(p[i] - p[i - 1]) else math.inf
              for i in range(1, len(c))]
    i = max(range(len(slopes)), key=lambda j: slopes[j]) + 1
    return f"table.pressure[{i}]", f"dp/dc (rows {i - 1}-{i})", slopes[i - 1], p[i]


def _has(contents: dict, form: str) -> bool:
    return {"bundle": contents["bundle"] is not None, "tabulated": True,
            "linear": contents["coefficients"] is not None}[form]


def normal_law_of(contents: dict, form: str) -> il.NormalLaw:
    """The normal law of form ``form`` from :func:`read`'s contents (``ValueError`` if the file lacks it)."""
    if not _has(contents, form):
        raise ValueError(f"the law file holds no {form} law (it has: "
                         + ", ".join(f for f in FORMS if _has(contents, f)) + ")")
    if form == "bundle":
        b = contents["bundle"]
        return il.BundleLaw(weights=b["weights"], directions=b["directions"], gaps=b["gaps"])
    if form == "tabulated":
        t = contents["table"]
        return il.TabulatedLaw(closure=t["closure"], pressure=t["pressure"], kt=contents["stick_slope"])
    K0, gf = contents["coefficients"]["K0"], contents["coefficients"]["gap_force"]
    if len(K0) != 2 or any(len(r) != 2 for r in K0) or len(gf) != 2:
        raise ValueError("a linear law from a file needs a 2 x 2 K0 and two gap forces (2D or axisymmetric)")
    return il.LinearLaw(kn=K0[0][0], kt=K0[1][1], knt=K0[0][1], gap_force=(gf[0], gf[1]))
