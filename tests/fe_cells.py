"""The shipped small-slope cells that ``discretization.method = "auto"`` gives the spectral cell, as FE cells.

``geometries/cells/stem_grooves.toml`` and ``tabulated_gap.toml`` set no key only the FE cell reads, so the
spectral cell solves them.  Tests of the FE cell solve them with the FE discretization (and Newton limit)
they shipped with: :data:`FE` (``[discretization]`` keys, ``method = "fe"`` among them) and :data:`SOLVER`.
"""
import os
import tomllib

from ngcontact.scene.loader import from_dict

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CELLS = os.path.join(ROOT, "geometries", "cells")
#: the ``[discretization]`` of each cell's FE version
FE = {"stem_grooves": {"method": "fe", "order": 2, "maxh": 25e-6, "interface_maxh": 1e-6},
      "tabulated_gap": {"method": "fe", "order": 2, "maxh": 0.2, "interface_maxh": 0.02}}
#: the ``[solver]`` keys of each cell's FE version beside the shipped ones
SOLVER = {"stem_grooves": {"max_iter": 60}, "tabulated_gap": {}}


def shipped(name: str) -> str:
    """The path of the shipped cell scene ``name``."""
    return os.path.join(CELLS, f"{name}.toml")


def fe_table(name: str) -> dict:
    """The parsed scene ``name`` with its FE ``[discretization]`` and ``[solver]`` keys, its data files named by
    absolute paths (the table may be validated or written anywhere)."""
    with open(shipped(name), "rb") as fh:
        data = tomllib.load(fh)
    data["discretization"] = {**data.get("discretization", {}), **FE[name]}
    data["solver"] = {**data.get("solver", {}), **SOLVER[name]}
    gap = data["contact"].get("gap", {})
    if "file" in gap:
        gap["file"] = os.path.join(CELLS, gap["file"])
    return data


def fe_scene(name: str):
    """The validated FE version of the shipped cell ``name``."""
    return from_dict(fe_table(name), base_dir=CELLS)


def fe_text(name: str) -> str:
    """The FE version of the shipped cell ``name`` as TOML text (:func:`fe_table`)."""
    return toml(fe_table(name))


def toml(data: dict, path: str = "") -> str:
    """A scene table as TOML text: scalar keys first, then each sub-table as its own section."""
    plain = {k: v for k, v in data.items() if not isinstance(v, dict)}
    lines = [f"[{path}]"] if path and plain else []
    lines += [f"{k} = {value(v)}" for k, v in plain.items()]
    for k, v in data.items():
        if isinstance(v, dict):
            lines.append(toml(v, f"{path}.{k}" if path else k))
    return "\n".join(lines) + "\n"


def value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(value(x) for x in v) + "]"
    return repr(v)
