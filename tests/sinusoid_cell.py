"""The flat cell with Westergaard's sinusoidal gap as scene text, for tests that vary one section of it.

A flat interface between two layers of one material (E = 1, nu = 0.3), the gap ``2h sin^2(pi x)`` with
``h = 0.01`` (waves along ``x`` of the 3D cell, ``profile = "flat3d"``), one ``[load]`` and a
``[discretization]`` given whole.
"""


def sinusoid_cell(*, k_n: str = "1.0e3", enforcement: str = "exact", pressure: str = "0.005",
                  depth: str = "1.0", discretization: str = 'method = "spectral"\ngrid = 256',
                  profile: str = "flat", friction: str | None = None) -> str:
    """The scene's TOML text; every argument is written as given (numbers as TOML text); ``friction``: the key
    ``contact.friction`` where given."""
    friction_line = "" if friction is None else f'friction = "{friction}"\n'
    return f"""\
kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "{profile}"
h_rough = {depth}
h_counter = {depth}
[contact]
k_n = {k_n}
enforcement = "{enforcement}"
{friction_line}gap = {{ kind = "sinusoid", h = 0.01 }}
[load]
pressure = [{pressure}]
[discretization]
{discretization}
"""
