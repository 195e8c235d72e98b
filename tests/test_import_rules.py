"""Arrows point one way: every import inside the package obeys the layer table.

The table is the one of the repository's architecture: descriptions
(``scene``) and shapes (``geometry``) at the bottom, numerics (``fem``,
``laws``, ``solvers``) above them, ``parallel`` (batches of independent
solves on worker processes or a Dask cluster; no numerics, and the only
room that starts a pool) beside them, the three problems (``cell``,
``macro``, ``resolved``) that never know each other, ``coupling`` where
cell meets macro, ``verification`` above all numerics, ``drivers`` that
translate scenes into objects, ``distributed`` (a macro scene over MPI
ranks: the macro driver's pieces around a distributed mesh; the runner
and the command line ask it for the ranks), ``export`` (a scene's law for other FE
codes) above them, and ``output``, ``runner``, ``cli`` (and ``python -m
ngcontact``) on top.  ``_version`` is a leaf that the package face
(``ngcontact/__init__.py``) and the rooms that stamp reports and files
import, so that nothing inside the package imports the face; the face
itself reaches below the runner only for the two names of the library API
that a caller's own NGSolve script uses (the law of a cell scene, its
interface energy on the caller's mesh).  The test
reads the source with :mod:`ast` (nothing is imported), so a forbidden
import inside a function counts as much as one at the top of a module; on
the same imports, module by module, the import graph has no cycle at all
(no strongly connected component of two or more modules, the face
included).
"""
from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "ngcontact"

NUMERICS = {"errors", "fem", "laws", "solvers"}
PROBLEMS = NUMERICS | {"geometry"}
#: room -> rooms it may import (its own room is always allowed)
ALLOWED: dict[str, set[str]] = {
    # the package's version, a leaf: the face, the runner, the command line and the exporters stamp with it
    "_version": set(),
    "errors": set(),
    # NGSolve's and Netgen's C++ output kept off the terminal, for the rooms that call them
    "quiet": set(),
    # validation at load time uses the values' own admissibility rules (an
    # SPD Voigt matrix, a PSD K0, the component names of a setting) and the
    # friction laws' registry (their names and parameter keys); the objects
    # the model solves with are built in drivers/build.py
    "scene": {"errors", "geometry", "fem.materials", "fem.elasticity", "laws.homogenized", "laws.friction"},
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
    # a macro scene on a mesh distributed over MPI ranks: the macro driver's pieces around a distributed solve
    "distributed": PROBLEMS | {"macro", "drivers", "output"},
    # the runner chooses where a run's batches go (parallel/executor.py) before a driver is imported, and
    # whether a macro scene runs distributed over MPI ranks
    "runner": {"_version", "errors", "drivers", "scene", "output", "parallel", "distributed"},
    # the exporters read a scene's law through the drivers and write through output's atomic writer; the ccx
    # check solves its macro scene through the drivers and hands the solution to its harness in verification
    "export": PROBLEMS | {"_version", "scene", "macro", "coupling", "verification", "drivers", "output"},
    "cli": {"_version", "errors", "runner", "scene", "output", "export", "distributed"},
    # the package face: nothing inside the package imports it (its version is in _version); the law of a cell
    # and its energy on a mesh of the caller's are imported on first use
    "__init__": {"_version", "errors", "scene", "runner", "drivers.cell_scene_law", "macro.interface_form"},
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
                dst = "ngcontact.__init__"  # `from ngcontact import x`: the package face
            if not _allowed(src, dst):
                out.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {src} -> {dst}")
    return out


def test_every_room_is_in_the_table():
    rooms = {_room(_module_of(p)) for p in PACKAGE.rglob("*.py")}
    assert rooms <= set(ALLOWED), f"rooms without a rule: {sorted(rooms - set(ALLOWED))}"


def test_imports_point_downstream():
    bad = _violations()
    assert not bad, "imports against the layer table:\n" + "\n".join(bad)


#: inside ``cell``: the methods behind the cell protocol never know each other, and the protocol's own modules
#: (the load, the solution, the protocol, eq. 34's coefficients) know neither; only the spectral start of an FE
#: solve, a predictor passed in by the builder, joins the two
#: a method is a sub-package of ``cell`` (``cell/fe/``, ``cell/spectral/``, any third one): it may import itself
#: and the shared modules; the spectral start may import the two methods it joins
JOINS: dict[str, set[str]] = {"cell.spectral_start": {"cell.fe", "cell.spectral", "cell.shared"}}


def _methods() -> set[str]:
    return {f"cell.{p.name}" for p in (PACKAGE / "cell").iterdir() if (p / "__init__.py").exists()}


def _cell_part(module: str) -> str | None:
    parts = module.split(".")
    if len(parts) < 3 or parts[1] != "cell":
        return None
    if "cell." + parts[2] in _methods() or "cell." + parts[2] in JOINS:
        return "cell." + parts[2]
    return "cell.shared"


def _may_import(part: str) -> set[str]:
    return JOINS.get(part, {part, "cell.shared"})


def test_the_cell_methods_do_not_know_each_other():
    bad = []
    for path in sorted((PACKAGE / "cell").rglob("*.py")):
        src = _module_of(path)
        part = _cell_part(src)
        for line, dst in _imports(path):
            target = _cell_part(dst)
            if part is not None and target is not None and target not in _may_import(part):
                bad.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {src} -> {dst}")
    assert not bad, "imports across the cell's methods:\n" + "\n".join(bad)
    assert _cell_part("ngcontact.cell.fe.cell_problem") == "cell.fe"
    assert {"cell.fe", "cell.spectral"} <= _methods()
    assert "cell.spectral" not in _may_import("cell.fe")      # negative control of the rule itself
    assert _may_import("cell.shared") == {"cell.shared"}


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
    assert not _allowed("ngcontact.cell.fe.cell_problem", "ngcontact.macro.macro_problem")
    assert not _allowed("ngcontact.macro.macro_problem", "ngcontact.cell.fe.cell_problem")
    assert not _allowed("ngcontact.scene.loader", "ngcontact.drivers.build")
    assert _allowed("ngcontact.coupling.two_scale", "ngcontact.macro.macro_problem")


def _import_graph() -> dict[str, set[str]]:
    """Module -> the package's modules it imports, the package face ``ngcontact`` included (``from ngcontact
    import x`` imports the face, ``from ngcontact.a import b`` the module ``ngcontact.a.b`` or the package
    ``ngcontact.a``).  Imports inside functions count; a package's ``__init__`` run before its modules does not
    (it is no import written in the source)."""
    graph: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        src = _module_of(path)
        deps = graph.setdefault(src, set())
        for _, dst in _imports(path):
            if dst != "ngcontact" and not dst.startswith("ngcontact."):
                continue
            while dst != "ngcontact" and not _is_module(dst):   # a name inside a module: that module
                dst = dst.rsplit(".", 1)[0]
            if dst != src:
                deps.add(dst)
    return graph


def _strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of ``graph`` (Tarjan): a component of more than one module is a cycle."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            components.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return components


def test_no_import_cycles():
    """No module reaches itself through the package's imports, the package face included."""
    cycles = [c for c in _strongly_connected(_import_graph()) if len(c) > 1]
    assert not cycles, "modules that import one another (strongly connected):\n" + "\n".join(
        " <-> ".join(c) for c in cycles)


def test_the_cycle_check_sees_a_cycle_through_the_package_face():
    """Negative control: the runner importing the version from the face the face imports the runner from."""
    graph = {"ngcontact": {"ngcontact.runner", "ngcontact.errors"}, "ngcontact.runner": {"ngcontact"},
             "ngcontact.errors": set(), "ngcontact.a": {"ngcontact.b"}, "ngcontact.b": {"ngcontact.c"},
             "ngcontact.c": {"ngcontact.a", "ngcontact.errors"}}
    cycles = [c for c in _strongly_connected(graph) if len(c) > 1]
    assert sorted(cycles) == [["ngcontact", "ngcontact.runner"], ["ngcontact.a", "ngcontact.b", "ngcontact.c"]]


def test_the_version_is_a_leaf_that_the_face_and_the_runner_import():
    graph = _import_graph()
    assert ALLOWED["_version"] == set() and graph["ngcontact._version"] == set()
    assert "ngcontact._version" in graph["ngcontact"] and "ngcontact._version" in graph["ngcontact.runner"]
    assert not any("ngcontact" in deps for deps in graph.values()), "a module imports the package face"


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
    (drivers/, which checks what needs a mesh, such as boundary labels; distributed/, the macro driver's
    pieces under MPI, which refuses what does not run distributed); geometry and the numerics
    raise their own errors with argument names (GeometryError, ModelError), translated above them."""
    offenders = sorted(str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
                       if p.relative_to(PACKAGE).parts[0] not in ("scene", "drivers", "distributed", "cli.py", "runner.py")
                       and "SceneError" in _raised_names(p.read_text(encoding="utf-8")))
    assert not offenders, f"raise SceneError below the scene layer: {offenders}"


def test_the_scene_error_check_sees_a_raise():
    assert _raised_names("def f():\n    raise SceneError('a', 1, 'b')\n") == {"SceneError"}
