"""A cell or macro scene -> the :class:`~ngcontact.export.law_table.ExportedLaw` the exporters write.

* ``cell`` scene: its direction bundle (paper eqs. 31-33; computed once and
  cached by :mod:`ngcontact.coupling.cell_law`, no contact problem solved),
  lengths scaled by ``length_unit`` [m per cell unit]; macro gap 0; friction
  coefficient the paper's homogenized ``mu0 = |k_nt0| / k_n0`` (after eq. 34)
  unless one is given.
* ``macro`` scene: the normal law its interface uses (from its cell, its
  numbers or a law file), its uniform gap ``g0`` and its ``interface.mu``
  (when > 0).

The table's largest pressure ``p_max`` [Pa], unless given: the largest of
twice the pressure at which the last direction closes, ten times the largest
surface load of the scene (macro: ``loads``; cell: ``load.pressure``) and
twice ``k_n0 |g0|`` (an interference); a law without any of these (a linear
curve from zero and no loads) needs ``p_max`` given.

Every card written is admissible: the options are checked where they are
parsed (:func:`check_options`: finite numbers in their ranges), and the
law and its table before anything is rendered (:func:`check_law`: finite
numbers, a positive slope ``k_n0``, table rows that stay distinct as
written, overclosures strictly increasing); a violation is a
:class:`~ngcontact.errors.ModelError` naming the option to change.  The
cards name the scene by its file name and SHA-256 only, not by the
directories it lies in.
"""
from __future__ import annotations

import hashlib
import math
import os

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.export import law_table as lt
from ngcontact.scene import loader


#: ``--length-unit`` range [m per cell unit]: a picometre to a kilometre.  Outside it the cell's gaps in
#: metres merge below the law's resolution or overflow its pressures: a unit mistake, not a cell.
LENGTH_UNIT_RANGE = (1e-12, 1e3)


def check_options(*, length_unit: float = 1.0, p_max: float | None = None, tolerance: float = 1e-3,
                  mu: float | None = None) -> None:
    """Refuse a non-finite option or one outside its range, naming it, its value and what is allowed.

    Raises
    ------
    ModelError
        ``--length-unit`` not a finite number in :data:`LENGTH_UNIT_RANGE`,
        ``--max-pressure`` not a finite number > 0, ``--table-tol`` not in
        [0, 1), ``--mu`` not a finite number >= 0.
    """
    low, high = LENGTH_UNIT_RANGE
    if not (math.isfinite(length_unit) and low <= length_unit <= high):
        raise ModelError(f"--length-unit {length_unit!r}: metres per cell unit, must be a finite number in "
                         f"[{low:g}, {high:g}] (1e-6 for a cell drawn in micrometres)")
    if p_max is not None and not (math.isfinite(p_max) and p_max > 0):
        raise ModelError(f"--max-pressure {p_max!r}: the table's largest pressure [Pa], must be a finite number > 0")
    if not 0 <= tolerance < 1:
        raise ModelError(f"--table-tol {tolerance!r}: a fraction of the table's largest pressure, must lie in [0, 1)")
    if mu is not None and not (math.isfinite(mu) and mu >= 0):
        raise ModelError(f"--mu {mu!r}: the friction coefficient, must be a finite number >= 0")


def _sha256(path: str) -> str:
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def _normal_law(scene, path: str, length_unit: float):
    """``(normal law, macro gap, threshold, scene mu, gap table?, load scale, source)``."""
    from ngcontact.drivers.build import law_from_cell
    # the file name only: a card must not carry the user's directory layout; the hash identifies the scene
    source = {"scene": os.path.basename(path), "kind": scene.kind, "scene_sha256": _sha256(path)}
    if scene.kind == "cell":
        normal, info = law_from_cell(path, dim=scene.geometry.dim, length_unit=length_unit)
        loads = scene.load.pressure if scene.load is not None and scene.load.pressure else (0.0,)
        source.update(cell_sha256=info["key"], length_unit=length_unit, law="bundle")
        return normal, 0.0, 0.0, 0.0, False, max(abs(v) for v in loads), source
    if scene.kind != "macro":
        raise ModelError(f"kind = {scene.kind!r}: export takes a 'cell' scene or a 'macro' scene (its interface law)")
    from ngcontact.drivers.run_macro import interface_law_of
    spec = scene.interface
    law, info = interface_law_of(scene, 3 if scene.geometry.setting == "3d" else 2)
    if "key" in info:
        source.update(cell_sha256=info["key"], length_unit=spec.cell_length_unit)
    if "sha256" in info:
        source["law_file_sha256"] = info["sha256"]
    source["law"] = spec.law_file_form if spec.law == "file" else spec.law
    if spec.mu > 0:
        source["huber_width"] = spec.huber_width
    scale = max([0.0] + [abs(lo.pressure) for lo in scene.loads]
                + [float(np.linalg.norm(lo.traction)) for lo in scene.loads if lo.traction])
    return (law.normal, spec.gap if spec.gap_table is None else 0.0, spec.threshold, spec.mu,
            spec.gap_table is not None, scale, source)


def exported_law(path: str, *, length_unit: float = 1.0, p_max: float | None = None, tolerance: float = 1e-3,
                 mu: float | None = None) -> lt.ExportedLaw:
    """The law of the scene file ``path`` ready for the exporters (see the module docstring).

    Raises
    ------
    SceneError
        An invalid scene.
    ModelError
        A kind that has no interface law, ``p_max`` cannot be chosen, or an
        inadmissible option.
    """
    check_options(length_unit=length_unit, p_max=p_max, tolerance=tolerance, mu=mu)
    scene = loader.load(path)
    normal, g0, threshold, scene_mu, gap_table, scale, source = _normal_law(scene, path, length_unit)
    rows = normal.export_rows()
    kinks, slopes, K0, bundle = rows.kinks, rows.slopes, rows.K0, rows.bundle
    _check_curve(kinks, slopes, g0, scene.kind, length_unit)
    given = p_max
    default = _default_p_max(kinks, slopes, scale, g0)
    if p_max is None:
        p_max = default
        if not p_max > 0:
            raise ModelError("the law is linear from zero closure and the scene has no load to scale its table: "
                             "give the table's largest pressure (--max-pressure, Pa)")
    closure, pressure = lt.table(kinks, slopes, p_max=p_max, tolerance=tolerance)
    if mu is not None:
        mu0, mu_source = mu, "given"
    elif scene_mu > 0:
        mu0, mu_source = scene_mu, "the macro scene's interface.mu"
    elif K0 is not None:
        k_nt0 = float(np.linalg.norm(K0[0, 1:]))
        if k_nt0 > lt.ROUNDING * abs(K0[0, 0]):
            mu0, mu_source = k_nt0 / K0[0, 0], "|k_nt0| / k_n0 (paper, after eq. 34)"
        else:  # a symmetric cell: k_nt0 is rounding, and so would be mu0
            mu0, mu_source = 0.0, f"|k_nt0| / k_n0 (paper, after eq. 34), |k_nt0| <= {lt.ROUNDING:g} k_n0 taken as 0"
    else:
        mu0, mu_source = 0.0, "none (a tabulated law has no k_nt0)"
    notes = lt.not_carried(None if bundle is None else bundle["directions"], K0, threshold=threshold,
                           gap_table=gap_table, bilateral=rows.bilateral)
    if "huber_width" in source:
        notes += (f"the macro scene's friction regularization (Huber width w = {source['huber_width']:g} m: a "
                  "sticking point slips at most w) is not exported; the stick slope is the law's k_t0",)
    law = lt.ExportedLaw(kinks=np.asarray(kinks, float), slopes=np.asarray(slopes, float), closure=closure,
                         pressure=pressure, tolerance=tolerance, K0=K0, bundle=bundle, mu=mu0, mu_source=mu_source,
                         stick_slope=rows.stick_slope, gap=float(g0), source=source, notes=notes,
                         gap_force=None if K0 is None else np.asarray(rows.gap_force, float))
    check_law(law, given, default)
    return law


def _default_p_max(kinks, slopes, scale: float, g0: float) -> float:
    """The table's largest pressure unless given (module docstring); 0 when the law and scene give none."""
    p_full = float(lt.curve(kinks, slopes, [np.max(kinks)])[0])
    return max(2.0 * p_full, 10.0 * scale, 2.0 * float(np.sum(slopes)) * abs(g0))


def _check_curve(kinks, slopes, g0: float, kind: str, length_unit: float) -> None:
    """Refuse a normal curve no card can carry: non-finite kinks or slopes, no positive slope ``k_n0``, or
    pressures beyond the floating-point range at its last kink."""
    kinks, slopes = np.asarray(kinks, float), np.asarray(slopes, float)
    cause = (f"the cell's gaps times --length-unit {length_unit!r}" if kind == "cell"
             else "the macro scene's interface law")
    if kinks.size == 0 or not (np.all(np.isfinite(kinks)) and np.all(np.isfinite(slopes)) and math.isfinite(g0)):
        raise ModelError(f"the law's normal curve has no finite kinks and slopes ({cause}); nothing to export")
    k_n0 = float(np.sum(slopes))
    if not (math.isfinite(k_n0) and k_n0 > 0):
        raise ModelError(f"k_n0 = {k_n0:g} Pa/m: the law's stiffness once closed must be a finite number > 0 "
                         f"({cause}); a table without it transmits no pressure")
    p_full = float(lt.curve(kinks, slopes, [np.max(kinks)])[0])
    if not (math.isfinite(p_full) and math.isfinite(k_n0 * float(np.max(np.abs(kinks))))):
        raise ModelError(f"the law's pressures overflow (closures up to {np.max(np.abs(kinks)):.3g} m at "
                         f"k_n0 = {k_n0:.3g} Pa/m: {cause})")


def check_law(law: lt.ExportedLaw, given: float | None = None, default: float = 0.0) -> None:
    """Refuse a law whose card would not be admissible, naming the option to change.

    Every number an exporter writes is finite, and the table's rows as
    written (``pressure, overclosure`` with 13 significant digits,
    :func:`~ngcontact.export.law_table.number`) start at zero pressure, end
    above it, have strictly increasing overclosures and non-decreasing
    pressures (a tabulated law may have a plateau): two identical rows (a
    ``p_max`` below the closures' resolution) or a non-monotone overclosure
    (a macro gap that swamps the closures) are refused.

    ``given``: ``--max-pressure`` as given (``None``: the default, ``default``).
    """
    scalars = {"k_n0": law.k_n0, "the friction coefficient mu0": law.mu, "the stick slope k_t0": law.stick_slope,
               "the macro gap g0": law.gap, "the full-contact pressure": law.full_contact_pressure()}
    arrays = {"K0": law.K0, "the gap forces": law.gap_force, "the table": np.append(law.closure, law.pressure)}
    for name, value in list(scalars.items()) + list(arrays.items()):
        if value is not None and not np.all(np.isfinite(np.asarray(value, float))):
            if name == "the table" and given is not None:
                raise ModelError(f"--max-pressure {given!r}: the table's closures overflow; give a smaller one, "
                                 f"e.g. the default {default:.6g} Pa (omit --max-pressure)")
            raise ModelError(f"{name} of the law is not finite; no card can carry it")
    d = np.array([float(lt.number(c + law.gap)) for c in law.closure])
    p = np.array([float(lt.number(v)) for v in law.pressure])
    if len(d) >= 2 and p[0] == 0.0 and p[-1] > 0 and np.all(np.diff(d) > 0) and np.all(np.diff(p) >= 0):
        return
    span = f"overclosures {d[0]:.13g} .. {d[-1]:.13g} m, pressures 0 .. {law.p_max:.6g} Pa"
    if given is not None:
        hint = f"e.g. the default {default:.6g} Pa (omit --max-pressure)" if default > given else "a larger one"
        raise ModelError(f"--max-pressure {given!r}: too small for this law: its table's rows ({span}) are not "
                         f"distinct and increasing as written with 13 significant digits; give {hint}")
    raise ModelError(f"the table's rows ({span}) are not distinct and increasing as written with 13 significant "
                     f"digits (macro gap g0 = {law.gap:.6g} m): give a larger --max-pressure (Pa)")
