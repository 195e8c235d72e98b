"""The client check of an exported law: CalculiX against this package's macro solve, same blocks, same law.

A cell scene's law is exported twice, for ccx
(:mod:`ngcontact.export.calculix`) and as JSON
(:mod:`ngcontact.export.json_law`).  The two blocks of
:mod:`ngcontact.verification.calculix_model` are pressed by ``press`` and sheared
by ``shear`` (top displacements [m], base clamped), once by ccx with the
exported ``*SURFACE INTERACTION`` and once by this package as a macro scene
of shape ``block`` whose interface reads the JSON file back
(``interface.law = "file"``, ``law_file_form = "tabulated"``: the same
table, with the stick slope as its tangential stiffness and no friction of
its own).  The two agree where the ccx interface sticks everywhere
(``|tau| < mu0 p``): ccx's stick branch is then the linear ``lambda = k_t0``.

Compared (:mod:`ngcontact.verification.calculix_compare`): the reaction force on the block's top per metre
(both components), the mean contact pressure (``|R_y| / L``), the pressure at the interface's
centre and its largest value, the shear at the centre.

:func:`compare_press_fit` does the same for a plane-strain press fit of two
coaxial tubes: a macro scene takes the cell's law with an interference
``g0 < 0``, its law (with the gap) is exported, and ccx's hoop force,
displacements and contact pressure are compared with this package's solve
of the scene's geometry reading the JSON law back with the same gap.

This module is the scene-facing half of the check: it writes the scenes,
exports the law and solves the macro scene through the driver
(:mod:`ngcontact.drivers.run_macro`), which the verification room may not
import; the ccx models and the comparison are the harness in
``ngcontact/verification/``.
"""
from __future__ import annotations

import os
import time

from ngcontact.drivers import run_macro
from ngcontact.export.export_law import export
from ngcontact.scene import loader
from ngcontact.verification import calculix_compare as CC
from ngcontact.verification.calculix_model import Blocks, PressFit, run, run_press_fit

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
    ours, profile = CC.block_measures(sol, b, scene.output.points_per_element)
    ours_s = time.perf_counter() - t0
    with open(ccx_law, encoding="utf-8") as fh:
        cx = run(b, fh.read(), os.path.join(workdir, "ccx"))
    rows = CC.rows(CC.BLOCK_ROWS, ours, CC.block_ccx(cx, b))
    return {"rows": rows, "seconds": {"ngcontact": ours_s, "ccx": cx["seconds"]}, "ccx": cx, "law": law,
            "stick": CC.stick(cx, mu), "json": path, "ccx_law": ccx_law, "ndof": sol.ndof, "profile": profile}


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


def compare_press_fit(cell: str, workdir: str, fit: PressFit, *, length_unit: float, gap: float, p_max: float,
                      table_tol: float = 1e-4, maxh: float | None = None, order: int = 2) -> dict:
    """The press fit both ways: the law of a macro scene (the cell's, interference ``gap`` < 0) exported for ccx
    and as JSON; ccx on :class:`~ngcontact.verification.calculix_model.PressFit`, this package on the coaxial
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
    ours, profile = CC.press_fit_measures(sol, geo.mesh, fit, scene.output.points_per_element)
    ours_s = time.perf_counter() - t0
    with open(ccx_law, encoding="utf-8") as fh:
        cx = run_press_fit(fit, fh.read(), os.path.join(workdir, "ccx"))
    rows = CC.rows(CC.PRESS_FIT_ROWS, ours, CC.press_fit_ccx(cx, fit))
    return {"rows": rows, "seconds": {"ngcontact": ours_s, "ccx": cx["seconds"]}, "ccx": cx, "law": law,
            "ndof": sol.ndof, "profile": profile}
