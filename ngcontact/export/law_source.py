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
"""
from __future__ import annotations

import hashlib
import os

import numpy as np

from ngcontact.errors import ModelError
from ngcontact.export import law_table as lt
from ngcontact.scene import loader


def _sha256(path: str) -> str:
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def _normal_law(scene, path: str, length_unit: float):
    """``(normal law, macro gap, threshold, scene mu, gap table?, load scale, source)``."""
    from ngcontact.drivers.build import law_from_cell
    source = {"scene": os.path.abspath(path), "kind": scene.kind, "scene_sha256": _sha256(path)}
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
    if mu is not None and not mu >= 0:
        raise ModelError(f"--mu {mu!r}: must be >= 0")
    if not length_unit > 0:
        raise ModelError(f"--length-unit {length_unit!r}: metres per cell unit, must be > 0")
    if not 0 <= tolerance < 1:
        raise ModelError(f"--table-tol {tolerance!r}: a fraction of the table's largest pressure, in [0, 1)")
    if p_max is not None and not p_max > 0:
        raise ModelError(f"--max-pressure {p_max!r}: the table's largest pressure [Pa], must be > 0")
    scene = loader.load(path)
    normal, g0, threshold, scene_mu, gap_table, scale, source = _normal_law(scene, path, length_unit)
    rows = normal.export_rows()
    kinks, slopes, K0, bundle = rows.kinks, rows.slopes, rows.K0, rows.bundle
    if p_max is None:
        p_full = float(lt.curve(kinks, slopes, [np.max(kinks)])[0])
        p_max = max(2.0 * p_full, 10.0 * scale, 2.0 * float(np.sum(slopes)) * abs(g0))
        if not p_max > 0:
            raise ModelError("the law is linear from zero closure and the scene has no load to scale its table: "
                             "give the table's largest pressure (--max-pressure, Pa)")
    closure, pressure = lt.table(kinks, slopes, p_max=p_max, tolerance=tolerance)
    if mu is not None:
        mu0, mu_source = mu, "given"
    elif scene_mu > 0:
        mu0, mu_source = scene_mu, "the macro scene's interface.mu"
    elif K0 is not None:
        mu0, mu_source = float(np.linalg.norm(K0[0, 1:]) / K0[0, 0]), "|k_nt0| / k_n0 (paper, after eq. 34)"
    else:
        mu0, mu_source = 0.0, "none (a tabulated law has no k_nt0)"
    notes = lt.not_carried(None if bundle is None else bundle["directions"], K0, threshold=threshold,
                           gap_table=gap_table, bilateral=rows.bilateral)
    if "huber_width" in source:
        notes += (f"the macro scene's friction regularization (Huber width w = {source['huber_width']:g} m: a "
                  "sticking point slips at most w) is not exported; the stick slope is the law's k_t0",)
    return lt.ExportedLaw(kinks=np.asarray(kinks, float), slopes=np.asarray(slopes, float), closure=closure,
                          pressure=pressure, tolerance=tolerance, K0=K0, bundle=bundle, mu=mu0, mu_source=mu_source,
                          stick_slope=rows.stick_slope, gap=float(g0), source=source, notes=notes,
                          gap_force=None if K0 is None else np.asarray(rows.gap_force, float))
