"""Every name a script or an example imports from the package exists.

The scripts in ``scripts/`` and ``examples/`` run rarely (a benchmark is published once per change of its
figures), so a name the package renamed or removed would break them silently until the next publication:
``coulomb_newton_globalization.py`` imported ``fe_problem`` for months after it was gone.  The test reads
each file with :mod:`ast` (nothing of the script runs) and imports every ``ngcontact`` module it names, at
the top or inside a function, then looks up each imported name.
"""
from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FILES = sorted([*ROOT.glob("scripts/*.py"), *ROOT.glob("examples/*.py")])


def package_imports(path: Path) -> list[tuple[str, str | None, int]]:
    """``(module, name or None, line)`` of every import of ``ngcontact`` in ``path``."""
    out: list[tuple[str, str | None, int]] = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module \
                and node.module.split(".")[0] == "ngcontact":
            out += [(node.module, alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.Import):
            out += [(alias.name, None, node.lineno) for alias in node.names
                    if alias.name.split(".")[0] == "ngcontact"]
    return out


def test_the_scan_sees_a_missing_name(tmp_path):
    """The check below would fail on a script importing a name the package does not have."""
    script = tmp_path / "rotten.py"
    script.write_text("def f():\n    from ngcontact.drivers.cell_members import fe_problem\n")
    assert package_imports(script) == [("ngcontact.drivers.cell_members", "fe_problem", 2)]
    assert missing(script) == ["rotten.py:2: ngcontact.drivers.cell_members has no name 'fe_problem'"]


def missing(path: Path) -> list[str]:
    """The imports of ``path`` that do not resolve, one line each."""
    out = []
    for module, name, line in package_imports(path):
        try:
            mod = importlib.import_module(module)
        except ImportError as err:
            out.append(f"{path.name}:{line}: {module}: {err}")
            continue
        if name is not None and name != "*" and not hasattr(mod, name):
            try:                                   # a submodule imported by name
                importlib.import_module(f"{module}.{name}")
            except ImportError:
                out.append(f"{path.name}:{line}: {module} has no name {name!r}")
    return out


@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_every_package_name_a_script_imports_exists(path):
    assert missing(path) == []
