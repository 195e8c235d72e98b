"""A fully closed flat interface's normal stiffness is exact on every FE level but for round-off.

Under full contact the tangent problem of a flat interface (uniform penalty springs ``k_n`` between uniform
layers) has a solution linear through each layer, which every FE space holds: each level of the graded
refinement gives the interface stiffness ``k_n`` (the springs in series with nothing; the layers' compliance
is ``S_0``'s) to round-off, amplified by the difference ``S^-1 - S_0^-1`` of nearly equal compliances.
``scripts/fe_effectivity.py`` (``full_contact_roundoff``) therefore takes the levels' spread about the
reference as the oracle's resolution for such a load instead of reading an effectivity into round-off.
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import fe_effectivity  # noqa: E402

from ngcontact.cell.cell_solution import headline  # noqa: E402
from ngcontact.cell.fe.saturation import estimate_on_scene  # noqa: E402
from ngcontact.drivers.build import cell_loads, cell_solver  # noqa: E402
from ngcontact.scene.loader import load_with_contact  # noqa: E402


def test_every_level_of_a_full_contact_gives_k_n_and_the_script_takes_their_spread():
    scene = load_with_contact(os.path.join(fe_effectivity.ROOT, "geometries", "cells", "westergaard.toml"), None,
                              "fe", None)
    load = cell_loads(scene)[-1]                       # p/p* = 1.2: full contact
    refined = cell_solver(scene).refine_to(0.01, [load], required=False)
    levels = refined.per_load[0]["mesh_history"]
    k_n = float(scene.contact.k_n)
    assert len({(e["level"], e["order"]) for e in levels}) >= 3      # different meshes and orders
    assert all(e["contact_fraction"] > 1.0 - 1e-12 for e in levels)
    errors = [abs(e["headline"]["normal_stiffness"] / k_n - 1.0) for e in levels]
    assert max(errors) < 1e-7, errors                                # exact but for round-off
    got = headline(refined.solutions[0].results)
    roundoff = fe_effectivity.full_contact_roundoff(refined.per_load[0], got, "normal_stiffness", k_n, None)
    assert abs(roundoff - max(errors)) < 1e-15    # its measure: relative to the reference
    partial = [dict(levels[0], contact_fraction=0.9)] + levels[1:]
    assert fe_effectivity.full_contact_roundoff({"mesh_history": partial}, got, "normal_stiffness", k_n, None) == 0
    assert fe_effectivity.full_contact_roundoff(None, got, "normal_stiffness", k_n, None) == 0   # the answer alone


def test_the_scene_and_one_order_more_in_full_contact_each_give_k_n():
    """The default estimate's two sweeps (``next_order``) are exact but for round-off too."""
    scene = load_with_contact(os.path.join(fe_effectivity.ROOT, "geometries", "cells", "westergaard.toml"), None,
                              "fe", None)
    load = cell_loads(scene)[-1]
    refined = estimate_on_scene(cell_solver(scene), [load])
    got, more = headline(refined.solutions[0].results), refined.per_load[0]["next_order"]
    k_n = float(scene.contact.k_n)
    errors = [abs(h["normal_stiffness"] / k_n - 1.0) for h in (got, more)]
    assert max(errors) < 1e-7, errors
    roundoff = fe_effectivity.full_contact_roundoff(refined.per_load[0], got, "normal_stiffness", k_n, None)
    assert abs(roundoff - max(errors)) < 1e-15
