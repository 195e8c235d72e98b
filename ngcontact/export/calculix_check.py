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

:func:`compare_press_fit` does the same for a plane-strain press fit of two
coaxial tubes: a macro scene takes the cell's law with an interference
``g0 < 0``, its law (with the gap) is exported, and ccx's hoop force,
displacements and contact pressure are compared with this package's solve
of the scene's geometry reading the JSON law back with the same gap.
"""
from __future__ import annotations

import os
import time

import numpy as np

from ngcontact.drivers import run_macro
from ngcontact.export.calculix_model import Blocks, PressFit, run, run_press_fit
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


PRESS_FIT = """kind = "macro"
title = "Coaxial press fit through a cell's law (CalculiX comparison)"
[materials.solid]
E = {E!r}
nu = {nu!r}
[bodies]
rough = "solid"
counter = "solid"
[geometry]
shape = "coaxial"
setting = "plane_strain"
[geometry.dimensions]
a = {a!r}
b = {b!r}
c = {c!r}
[interface]
{law}
gap = {gap!r}
[[supports]]
boundary = "sym_x"
components = ["x"]
[[supports]]
boundary = "sym_y"
components = ["y"]
[discretization]
order = {order}
maxh = {maxh!r}
[solver]
rtol = 1e-10
"""


def _mean(t: np.ndarray, v: np.ndarray) -> float:
    """Trapezoidal mean of the samples ``v`` over ``t`` (numpy >= 1.24 has no ``trapezoid``)."""
    return float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(t)) / (t[-1] - t[0]))


def compare_press_fit(cell: str, workdir: str, fit: PressFit, *, length_unit: float, gap: float, p_max: float,
                      table_tol: float = 1e-4, maxh: float | None = None, order: int = 2) -> dict:
    """The press fit both ways: the law of a macro scene (the cell's, interference ``gap`` < 0) exported for ccx
    and as JSON; ccx on :class:`~ngcontact.export.calculix_model.PressFit`, this package on the coaxial
    plane-strain macro geometry reading the JSON back (``law_file_form = "tabulated"``, the same gap).

    Compared: the hoop force of the outer tube on its cut ``x = 0`` [N/m], the radial displacements of the
    mantle and the bore at 45 degrees [m], the contact pressure at 45 degrees and its mean over the arc [Pa].
    Returns ``rows``, ``seconds``, ``ccx`` and ``profile`` (``theta``, ``pressure``) like :func:`compare`.
    """
    os.makedirs(workdir, exist_ok=True)
    source = os.path.join(workdir, "press_fit_from_cell.toml")
    fmt = dict(E=fit.E, nu=fit.nu, a=fit.a, b=fit.b, c=fit.c, gap=gap, order=order,
               maxh=maxh or (fit.c - fit.a) / (fit.n_inner + fit.n_outer) * 2)
    with open(source, "w", encoding="utf-8") as fh:
        fh.write(PRESS_FIT.format(law=f"cell = {os.path.abspath(cell)!r}\ncell_length_unit = {length_unit!r}"
                                  .replace("'", '"'), **fmt))
    law_dir = os.path.join(workdir, "law")
    opts = {"p_max": p_max, "tolerance": table_tol}
    _, law = export(source, "json", law_dir, **opts)
    ccx_law, _ = export(source, "calculix", law_dir, **opts)
    scene_path = os.path.join(workdir, "press_fit.toml")
    with open(scene_path, "w", encoding="utf-8") as fh:
        fh.write(PRESS_FIT.format(law='law = "file"\nlaw_file = "law/interface_law.json"\n'
                                      'law_file_form = "tabulated"', **fmt))
    t0 = time.perf_counter()
    scene = loader.load(scene_path)
    geo = run_macro.build_geometry(scene)
    problem, _ = run_macro.problem_of(scene, geo)
    sol = run_macro.solve_scene(scene, problem)
    from ngcontact.macro import macro_measures as MM
    hoop = MM.equilibrium(sol)["bodies"]["outer"]["x"]["supports"]
    prof = MM.interface_profile(sol, scene.output.points_per_element)
    diag = np.array([1.0, 1.0]) / np.sqrt(2.0)
    u = {key: float(np.asarray(gf(geo.mesh(*(r * diag)))).ravel() @ diag)
         for key, gf, r in (("mantle", sol.u_counter, fit.c), ("bore", sol.u_rough, fit.a))}
    ours_s = time.perf_counter() - t0
    with open(ccx_law, encoding="utf-8") as fh:
        cx = run_press_fit(fit, fh.read(), os.path.join(workdir, "ccx"))
    theta = np.arctan2(np.asarray(prof["y"], float), np.asarray(prof["x"], float))
    p = np.asarray(prof["pressure"], float)
    o = np.argsort(theta)
    ours = {"hoop": abs(hoop), "u_mantle": u["mantle"], "u_bore": u["bore"],
            "p_45": float(np.interp(np.pi / 4, theta[o], p[o])),
            "p_mean": _mean(theta[o], p[o])}
    pc = cx["pressure"]
    theirs = {"hoop": abs(cx["hoop"]), "u_mantle": cx["u_mantle"], "u_bore": cx["u_bore"],
              "p_45": float(pc[fit.n_theta // 2]), "p_mean": _mean(cx["theta"], pc)}
    names = {"hoop": ("hoop force of the outer tube", "N/m"), "u_mantle": ("radial displacement, mantle", "m"),
             "u_bore": ("radial displacement, bore", "m"), "p_45": ("contact pressure at 45 degrees", "Pa"),
             "p_mean": ("mean contact pressure", "Pa")}
    rows = [(names[k][0], names[k][1], ours[k], theirs[k], abs(ours[k] - theirs[k]) / abs(theirs[k]))
            for k in ours]
    return {"rows": rows, "seconds": {"ngcontact": ours_s, "ccx": cx["seconds"]}, "ccx": cx, "law": law,
            "ndof": sol.ndof, "profile": {"theta": theta[o], "pressure": p[o]}}
