"""The spectral start under exact contact (:func:`ngcontact.cell.spectral_start.start_multiplier_on_twin`): the
state on the exact twin's contact set and Uzawa's multiplier at the twin's pressure reach the rigid start's
fixed point in fewer Newton steps."""
from __future__ import annotations

import math
import tomllib

from ngcontact.cell.spectral_start import SpectralStart
from ngcontact.drivers.build import build_cell, cell_loads, cell_problem, spectral_cell
from ngcontact.scene.loader import from_dict

from test_bisinusoid_scene import SCENE
from test_contact_edge_mesh import H


def test_an_exact_cell_started_on_its_twin_reaches_the_rigid_start_s_answer_from_closer():
    """The quarter bisinusoid at ``p/p* = 0.05`` meshed at ``interface_maxh`` 0.04: from the rigid start and
    with the multiplier at the exact twin's pressure (256^2) the same contact fraction and closure to the
    Uzawa tolerance; from the twin the first Uzawa pass leaves a penetration at most a quarter of the rigid
    start's, and the solve takes no more Newton steps.  (On this small mesh the saving is one step in about
    fifteen, in the last pass, whose count a round-off at its stopping test may change: the steps are not
    asked to be fewer, the start's distance is.)"""
    scene = from_dict(tomllib.loads(SCENE.format(pressure=0.05 * math.pi * H)))
    load = cell_loads(scene)[0]
    cell = build_cell(scene, interface_maxh=0.04)
    rigid = cell_problem(scene, cell)
    assert rigid.start == "rigid"
    twin = spectral_cell(scene, grid=256, friction=False, tol=1e-8)
    assert twin.enforcement == "exact"
    started = cell_problem(scene, cell, predictor=SpectralStart(twin))
    assert started.start == "predictor"
    a, b = rigid.solve(load, first=True), started.solve(load, first=True)
    assert b.newton[0]["start"]["kind"] == "spectral multiplier"
    for name in ("contact_fraction", "mean_closure"):
        assert math.isclose(a.results[name], b.results[name], rel_tol=1e-6), name
    first = [s.newton[0]["uzawa_penetrations"][0] for s in (a, b)]
    assert first[1] <= 0.25 * first[0], first
    assert b.iterations <= a.iterations
