"""The scene text of a small 3D press fit (a quarter of two coaxial tubes, a linear law with an interference),
shared by the 3D report tests and the MPI tests."""
from __future__ import annotations


def press_fit_3d(*, maxh: float = 0.004, title: str = "3D press fit of two tubes, a quarter", solver: str = "") -> str:
    """The scene's text with mesh size ``maxh``, ``title`` and the lines of an optional ``[solver]`` section."""
    text = f"""\
kind = "macro"
title = "{title}"

[materials.steel]
E = 210e9
nu = 0.3

[materials.bone]
E = 17e9
nu = 0.3

[bodies]
rough = "steel"
counter = "bone"

[geometry]
shape = "coaxial"
setting = "3d"

[geometry.dimensions]
a = 0.004
b = 0.008
c = 0.014
height = 0.01

[interface]
law = "linear"
kn = 1e13
kt = 1e12
gap = -2e-6

[[supports]]
boundary = "bottom"

[[supports]]
boundary = "sym_x"
components = ["x"]

[[supports]]
boundary = "sym_y"
components = ["y"]

[[loads]]
boundary = "top"
pressure = 5e6

[discretization]
order = 2
maxh = {maxh}
"""
    return text + (f"\n[solver]\n{solver}" if solver else "")
