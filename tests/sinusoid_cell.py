"""The flat cell with Westergaard's sinusoidal gap as scene text, for tests that vary one section of it.

A flat interface between two layers of one material (E = 1, nu = 0.3), the gap ``2h sin^2(pi x)`` with
``h = 0.01``, one ``[load]`` and a ``[discretization]`` given whole.
"""


def sinusoid_cell(*, k_n: str = "1.0e3", enforcement: str = "exact", pressure: str = "0.005",
                  depth: str = "1.0", discretization: str = 'method = "spectral"\ngrid = 256') -> str:
    """The scene's TOML text; every argument is written as given (numbers as TOML text)."""
    return f"""\
kind = "cell"
[materials.solid]
E = 1.0
nu = 0.3
[bodies]
rough = "solid"
counter = "solid"
[geometry]
profile = "flat"
h_rough = {depth}
h_counter = {depth}
[contact]
k_n = {k_n}
enforcement = "{enforcement}"
gap = {{ kind = "sinusoid", h = 0.01 }}
[load]
pressure = [{pressure}]
[discretization]
{discretization}
"""
