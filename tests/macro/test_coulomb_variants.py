"""Coulomb friction on the flagship's natural variations: each converges and is admissible.

The femur / hip-stem scene with one line changed (load, interference,
line-to-line, clearance, order) and a block sheared while it sticks.  The
fixed point of Tresca passes cycled on several of these (a period-2 cycle
between "friction holds the stem with no pressure" and "the stem slides in
and the pressure peaks"); the coupled Newton with its width continuation
must solve them all.  Checks: equilibrium of every body to 1e-8 of the
largest force, and the friction law at every interface sample: |tau| <=
mu p, and |tau| = mu p wherever the point slips.
"""
import os
import re

import ngsolve as ng
import numpy as np
import pytest

from ngcontact.drivers import run_macro as RM
from ngcontact.macro import macro_measures as MM
from ngcontact.scene.loader import load

pytestmark = [pytest.mark.slow, pytest.mark.hard]

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FEMUR = os.path.join(ROOT, "geometries", "femur_stem.toml")

VARIANTS = {
    "top load 10 MPa": [(r"^pressure = 1e6", "pressure = 10e6")],
    "interference 5 um": [(r"-50e-6\]", "-5e-6]")],
    "interference 20 um": [(r"-50e-6\]", "-20e-6]")],
    "interference 100 um": [(r"-50e-6\]", "-100e-6]")],
    "line-to-line": [(r"^gap_table = .*$", "gap_table = [[0.05, 0.0], [0.18, 0.0]]")],
    "clearance 10 um": [(r"^gap_table = .*$", "gap_table = [[0.05, 10e-6], [0.18, 10e-6]]")],
    "order 2": [(r"^order = 3", "order = 2")],
    "huber width 1e-8": [(r"^huber_width = 1e-6", "huber_width = 1e-8")],
}

BLOCK = """
kind = "macro"
title = "Block sheared while it sticks"
[materials.steel]
E = 210e9
nu = 0.3
[bodies]
rough = "steel"
counter = "steel"
[geometry]
shape = "block"
setting = "plane_strain"
[geometry.dimensions]
length = 0.02
h_block = 0.005
h_base = 0.005
[interface]
law = "bundle"
weights = [1e13]
directions = [[1.0, 0.0]]
mu = {mu}
[[supports]]
boundary = "bottom"
[[loads]]
boundary = "top"
pressure = 10e6
traction = [2e6, 0.0]
[discretization]
order = 2
maxh = 0.0025
"""


def _solve(path):
    scene = load(path)
    geo = RM.build_geometry(scene)
    problem, _ = RM.problem_of(scene, geo)
    with ng.TaskManager():
        sol = RM.solve_scene(scene, problem)
    return scene, sol


def _admissible(scene, sol):
    eq = MM.equilibrium(sol)
    assert eq["error"] <= 1e-8, eq
    prof = MM.interface_profile(sol)
    mu = scene.interface.mu
    p, tau = np.asarray(prof["pressure"]), np.abs(np.asarray(prof["shear"]))
    bound = mu * np.maximum(p, 0.0)
    scale = max(float(bound.max()), 1.0)
    assert np.all(tau <= bound + 1e-8 * scale), float(np.max(tau - bound))
    slip = np.asarray(prof["status"]) == "slip"
    assert np.all(np.abs(tau[slip] - bound[slip]) <= 1e-8 * scale)
    return prof


@pytest.mark.parametrize("name", list(VARIANTS))
def test_femur_variant_converges_to_an_admissible_coulomb_state(name, tmp_path):
    text = open(FEMUR).read().replace('"cells/hip_hills.toml"',
                                      repr(os.path.join(ROOT, "geometries", "cells", "hip_hills.toml")).replace("'", '"'))
    for pattern, repl in VARIANTS[name]:
        text, n = re.subn(pattern, repl, text, flags=re.M)
        assert n >= 1, pattern
    path = tmp_path / "femur.toml"
    path.write_text(text)
    scene, sol = _solve(str(path))
    prof = _admissible(scene, sol)
    assert {"stick", "slip"} & set(prof["status"])


@pytest.mark.parametrize("mu", [0.3, 10.0])
def test_block_sheared_below_the_friction_limit_sticks(mu, tmp_path):
    path = tmp_path / "block.toml"
    path.write_text(BLOCK.format(mu=mu))
    scene, sol = _solve(str(path))
    prof = _admissible(scene, sol)
    assert set(prof["status"]) == {"stick"}
    R = MM.resultant(sol)
    assert abs(R["x"] - 2e6 * 0.02) <= 1e-8 * 2e6 * 0.02, R
