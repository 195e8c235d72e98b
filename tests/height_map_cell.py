"""The shipped height-map cell (``geometries/cells/height_map.toml``) as the FE cell with the penalty, for tests
of the FE cell on a map: the shipped scene's text with its ``[contact]`` and ``[discretization]`` replaced by
``k_n = 1e3`` and order 2 on interface elements of ``interface_maxh``, and the map's path made absolute."""
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHIPPED = os.path.join(ROOT, "geometries", "cells", "height_map.toml")


def fe_height_map(interface_maxh: float = 0.12) -> str:
    """The scene's TOML text (module docstring)."""
    text = open(SHIPPED, encoding="utf-8").read()
    head, contact = text.split("[contact]\n", 1)
    load = contact[contact.index("[load]"):contact.index("[discretization]")]
    head = head.replace('file = "data/height_map_example.npy"',
                        f'file = "{os.path.join(ROOT, "geometries", "cells", "data", "height_map_example.npy")}"')
    return (f"{head}[contact]\nk_n = 1.0e3\n\n{load}[discretization]\norder = 2\nmaxh = 0.4\n"
            f"interface_maxh = {interface_maxh}\n")
