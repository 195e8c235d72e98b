"""The client check of an exported law: CalculiX against this package's macro solve, same blocks, same law.

A cell scene's law is exported twice, for ccx
(:mod:`ngcontact.export.calculix`) and as JSON
(:mod:`ngcontact.export.json_law`).  The two blocks of
:mod:`ngcontact.export.calculix_model` are pressed by ``press`` and sheared
by ``shear`` (top displacements [m], base clamped), once by ccx with the
exported ``*SURFACE INTERACTION`` and once by this package as a macro scene
of shape ``block`` whose interface reads the JSON file back
(``interface.law = "file"``, ``law_file_form = "tabulated"``: the same
table, with the stick slope as its tangential stiffness and no friction of
its own).  The two agree where the ccx interface sticks everywhere
(``|tau| < mu0 p``): ccx's stick branch is then the linear ``lambda = k_t0``.

Compared: the reaction force on the block's top per metre (both components),
the mean contact pressure (``|R_y| / L``), the pressure at the interface's
centre and its largest value, the shear at the centre.
"""
from __future__ import annotations

import os
import time

import numpy as np

from ngcontact.drivers import run_macro
from ngcontact.export.calculix_model import Blocks, run
from ngcontact.export.export_law import export
from ngcontact.scene import loader

MACRO = """kind = "macro"
title = "Two blocks with the exported law (CalculiX comparison)"
[materials.solid]
E = {E!r}
nu = {nu!r}
[bodies]
rough = "solid"
counter = "solid"
[geometry]
shape = "block"
setting = "plane_strain"
[geometry.dimensions]
length = {length!r}
h_block = {h_block!r}
h_base = {h_base!r}
[interface]
law = "file"
law_file = "law/interface_law.json"
law_file_form = "tabulated"
[[supports]]
boundary = "bottom"
[[supports]]
boundary = "top"
displacement = [{shear!r}, {minus_press!r}]
[discretization]
order = {order}
maxh = {maxh!r}
[solver]
rtol = 1e-10
"""


def compare(cell: str, workdir: str, blocks: Blocks, *, length_unit: float, mu: float, p_max: float,
            table_tol: float = 1e-4, maxh: float | None = None, order: int = 2) -> dict:
    """Export, solve both ways and return ``{"rows": [(quantity, unit, ngcontact, ccx, rel. diff)], ...}``.

    Also ``seconds`` (``ngcontact``, ``ccx``), ``ccx`` (its results), ``law``,
    ``stick`` (the largest ``|tau| / (mu0 p)`` of ccx's contact nodes) and
    ``profile`` (this package's interface samples ``x``, ``pressure``, ``shear``).
    """
    law_dir = os.path.join(workdir, "law")
    opts = {"length_unit": length_unit, "p_max": p_max, "tolerance": table_tol, "mu": mu}
    path, law = export(cell, "json", law_dir, **opts)
    ccx_law, _ = export(cell, "calculix", law_dir, **opts)
    scene_path = os.path.join(workdir, "blocks.toml")
    b = blocks
    with open(scene_path, "w", encoding="utf-8") as fh:
        fh.write(MACRO.format(E=b.E, nu=b.nu, length=b.length, h_block=b.h_block, h_base=b.h_base, shear=b.shear,
                              minus_press=-b.press, order=order, maxh=maxh or b.length / b.nx * 2))
    t0 = time.perf_counter()
    scene = loader.load(scene_path)
    geo = run_macro.build_geometry(scene)
    problem, _ = run_macro.problem_of(scene, geo)
    sol = run_macro.solve_scene(scene, problem)
    from ngcontact.macro import macro_measures as MM
    force = MM.resultant(sol)
    prof = MM.interface_profile(sol, scene.output.points_per_element)
    ours_s = time.perf_counter() - t0
    with open(ccx_law, encoding="utf-8") as fh:
        cx = run(b, fh.read(), os.path.join(workdir, "ccx"))
    x, p, tau = (np.asarray(prof[k], float) for k in ("x", "pressure", "shear"))
    order_x = np.argsort(x)
    at = lambda v, where: float(np.interp(where, x[order_x], v[order_x]))  # noqa: E731
    mid, i_mid = 0.5 * b.length, b.nx // 2
    ours = {"R_x": force["x"], "R_y": force["y"], "mean": abs(force["y"]) / b.length,
            "p_mid": at(p, mid), "p_max": float(p.max()), "tau_mid": abs(at(tau, mid))}
    theirs = {"R_x": cx["rf_x"], "R_y": cx["rf_y"], "mean": abs(cx["rf_y"]) / b.length,
              "p_mid": float(cx["pressure"][i_mid]), "p_max": float(cx["pressure"].max()),
              "tau_mid": abs(float(cx["shear"][i_mid]))}
    names = {"R_x": ("reaction on the top, x", "N/m"), "R_y": ("reaction on the top, y", "N/m"),
             "mean": ("mean contact pressure", "Pa"), "p_mid": ("contact pressure at x = L/2", "Pa"),
             "p_max": ("largest contact pressure", "Pa"), "tau_mid": ("|shear| at x = L/2", "Pa")}
    rows = [(names[k][0], names[k][1], ours[k], theirs[k], abs(ours[k] - theirs[k]) / abs(theirs[k]))
            for k in ours]
    closed = cx["pressure"] > 0
    stick = float(np.max(np.abs(cx["shear"][closed]) / (mu * cx["pressure"][closed]))) if mu > 0 else 0.0
    return {"rows": rows, "seconds": {"ngcontact": ours_s, "ccx": cx["seconds"]}, "ccx": cx, "law": law,
            "stick": stick, "json": path, "ccx_law": ccx_law, "ndof": sol.ndof,
            "profile": {"x": x, "pressure": p, "shear": tau}}
