"""Arrows point one way: every import inside the package obeys the layer table.

The table is the one of the repository's architecture: descriptions
(``scene``) and shapes (``geometry``) at the bottom, numerics (``fem``,
``laws``, ``solvers``) above them, ``parallel`` (batches of independent
solves on worker processes or a Dask cluster; no numerics, and the only
room that starts a pool) beside them, the three problems (``cell``,
``macro``, ``resolved``) that never know each other, ``coupling`` where
cell meets macro, ``verification`` above all numerics, ``drivers`` that
translate scenes into objects, ``export`` (a scene's law for other FE
codes) above them, and ``output``, ``runner``, ``cli`` (and ``python -m
ngcontact``) on top.  The test reads the source with :mod:`ast` (nothing is
imported), so a forbidden import inside a function counts as much as one at
the top of a module.
"""
from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "ngcontact"

NUMERICS = {"errors", "fem", "laws", "solvers"}
PROBLEMS = NUMERICS | {"geometry"}
#: room -> rooms it may import (its own room is always allowed)
ALLOWED: dict[str, set[str]] = {
    "errors": set(),
    # NGSolve's and Netgen's C++ output kept off the terminal, for the rooms that call them
    "quiet": set(),
    # validation at load time uses the values' own admissibility rules (an
    # SPD Voigt matrix, a PSD K0, the component names of a setting); the
    # objects the model solves with are built in drivers/build.py
    "scene": {"errors", "geometry", "fem.materials", "fem.elasticity", "laws.homogenized"},
    "geometry": {"errors", "quiet"},
    "fem": {"errors", "quiet"},
    "laws": {"errors"},
    "solvers": {"errors"},
    # batches of independent solves: pools of worker processes and Dask clusters, nothing numeric
    "parallel": {"errors"},
    "cell": PROBLEMS,
    "macro": PROBLEMS,
    "resolved": PROBLEMS,
    "coupling": PROBLEMS | {"cell", "macro", "parallel"},
    "verification": PROBLEMS | {"cell", "macro", "resolved", "coupling"},
    "output": {"errors"},
    "drivers": PROBLEMS | {"scene", "parallel", "cell", "macro", "resolved", "coupling", "verification", "output"},
    # the runner chooses where a run's batches go (parallel/executor.py) before a driver is imported
    "runner": {"errors", "drivers", "scene", "output", "parallel", "__init__"},
    # the exporters read a scene's law through the drivers and write through output's atomic writer; the ccx
    # check solves its macro scene through the drivers and hands the solution to its harness in verification
    "export": PROBLEMS | {"scene", "macro", "coupling", "verification", "drivers", "output", "__init__"},
    "cli": {"errors", "runner", "scene", "output", "export", "__init__"},
    "__init__": {"errors", "scene", "runner"},
    "__main__": {"cli"},
}


def _room(module: str) -> str:
    parts = module.split(".")[1:]  # drop "ngcontact"
    return parts[0] if parts else "__init__"


def _module_of(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__" and len(parts) > 1:
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path: Path):
    module = _module_of(path)
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:
                full = f"{target}.{alias.name}"
                # "from pkg import submodule" imports the submodule
                yield node.lineno, full if _is_module(full) else target


def _is_module(name: str) -> bool:
    rel = Path(*name.split(".")[1:]) if name.startswith("ngcontact.") else None
    return rel is not None and ((PACKAGE / rel).with_suffix(".py").exists() or (PACKAGE / rel).is_dir())


def _allowed(src: str, dst: str) -> bool:
    room, target_room = _room(src), _room(dst)
    if room == target_room:
        return True
    allowed = ALLOWED[room]
    sub = ".".join(dst.split(".")[1:3])
    return target_room in allowed or sub in allowed


def _violations() -> list[str]:
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        src = _module_of(path)
        for line, dst in _imports(path):
            if dst.split(".")[0] != "ngcontact":
                continue
            if dst == "ngcontact" and _room(src) != "__init__":
                dst = "ngcontact.__init__"  # e.g. `from ngcontact import __version__`
            if not _allowed(src, dst):
                out.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {src} -> {dst}")
    return out


def test_every_room_is_in_the_table():
    rooms = {_room(_module_of(p)) for p in PACKAGE.rglob("*.py")}
    assert rooms <= set(ALLOWED), f"rooms without a rule: {sorted(rooms - set(ALLOWED))}"


def test_imports_point_downstream():
    bad = _violations()
    assert not bad, "imports against the layer table:\n" + "\n".join(bad)


#: the libraries that start pools of workers, and the package's own pools
POOL_MODULES = ("multiprocessing", "concurrent.futures", "dask", "distributed")
POOL_NAMES = {"LocalPool", "DaskCluster", "ProcessPoolExecutor", "ThreadPoolExecutor", "Pool", "Client"}


def _pool_uses(source: str) -> set[str]:
    """Pool libraries a module imports and pool classes it names (``executor.LocalPool`` counts too)."""
    out = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith(POOL_MODULES)}
        elif isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").startswith(POOL_MODULES):
            out.add(node.module or "")
            out |= {a.name for a in node.names if a.name in POOL_NAMES}
        elif isinstance(node, ast.Name) and node.id in POOL_NAMES:
            out.add(node.id)
        elif isinstance(node, ast.Attribute) and node.attr in POOL_NAMES:
            out.add(node.attr)
    return out


def test_only_the_parallel_room_starts_a_pool():
    """Worker processes and clusters are started in ``parallel/`` alone; the rest asks it for an executor."""
    offenders = {str(p.relative_to(PACKAGE)): sorted(uses) for p in sorted(PACKAGE.rglob("*.py"))
                 if p.relative_to(PACKAGE).parts[0] != "parallel"
                 and (uses := _pool_uses(p.read_text(encoding="utf-8")))}
    assert not offenders, f"pools outside parallel/: {offenders}"


def test_the_pool_check_sees_a_pool():
    assert _pool_uses("from concurrent.futures import ProcessPoolExecutor\n") == {"concurrent.futures",
                                                                                   "ProcessPoolExecutor"}
    assert _pool_uses("import multiprocessing\n") == {"multiprocessing"}
    assert _pool_uses("ex = executor.LocalPool(2)\n") == {"LocalPool"}
    assert _pool_uses("from ngcontact.parallel import executor\nexecutor.make(2)\n") == set()


def test_the_check_sees_a_forbidden_import(tmp_path, monkeypatch):
    """Negative control: a cell module importing the macro problem is caught."""
    assert not _allowed("ngcontact.cell.cell_problem", "ngcontact.macro.macro_problem")
    assert not _allowed("ngcontact.macro.macro_problem", "ngcontact.cell.cell_problem")
    assert not _allowed("ngcontact.scene.loader", "ngcontact.drivers.build")
    assert _allowed("ngcontact.coupling.two_scale", "ngcontact.macro.macro_problem")


def test_no_import_cycles():
    graph: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        src = _module_of(path)
        graph.setdefault(src, set())
        for _, dst in _imports(path):
            if dst.startswith("ngcontact.") and dst != src:
                graph[src].add(dst if dst in graph or _is_module(dst) else dst.rsplit(".", 1)[0])
    state: dict[str, int] = {}
    cycles: list[list[str]] = []

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if nxt.endswith(".__init__"):
                continue
            if state.get(nxt) == 1:
                cycles.append(stack[stack.index(nxt):] + [nxt] if nxt in stack else [node, nxt])
            elif state.get(nxt) is None:
                visit(nxt, stack + [nxt])
        state[node] = 2

    for node in sorted(graph):
        if state.get(node) is None:
            visit(node, [node])
    assert not cycles, "import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles)


def test_no_two_modules_share_a_base_name():
    names: dict[str, list[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        if path.name != "__init__.py":
            names.setdefault(path.stem, []).append(str(path.relative_to(PACKAGE)))
    for pkg in (p for p in PACKAGE.rglob("*") if p.is_dir() and (p / "__init__.py").exists()):
        if pkg != PACKAGE:
            names.setdefault(pkg.name, []).append(str(pkg.relative_to(PACKAGE)) + "/")
    shared = {k: v for k, v in names.items() if len(v) > 1 and k != "__pycache__"}
    assert not shared, f"modules sharing a base name: {shared}"


def _raised_names(source: str) -> set[str]:
    """Names of the exception classes a module raises (``raise Name(...)``)."""
    out = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call) and isinstance(node.exc.func, ast.Name):
            out.add(node.exc.func.id)
    return out


def test_only_the_scene_layer_and_its_translator_raise_scene_errors():
    """Key paths of a scene belong to the scene layer and to the one scene -> objects translator
    (drivers/, which checks what needs a mesh, such as boundary labels); geometry and the numerics
    raise their own errors with argument names (GeometryError, ModelError), translated above them."""
    offenders = sorted(str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
                       if p.relative_to(PACKAGE).parts[0] not in ("scene", "drivers", "cli.py", "runner.py")
                       and "SceneError" in _raised_names(p.read_text(encoding="utf-8")))
    assert not offenders, f"raise SceneError below the scene layer: {offenders}"


def test_the_scene_error_check_sees_a_raise():
    assert _raised_names("def f():\n    raise SceneError('a', 1, 'b')\n") == {"SceneError"}
