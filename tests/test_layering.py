"""The import graph of ARCHITECTURE.md holds: each layer imports only what its arrow allows.

    api  ->  grader  ->  reference (oracles only)
                   \\->  grader.compat        (stdlib, numpy, gymnasium)
                   \\->  grader.sandbox.child (stdlib, numpy, gymnasium, grader.compat)

Inside grader/, the parts are stacked in `GRADER_LAYERS` (shown in ARCHITECTURE.md, "Layers inside
grader/"): a part imports its own layer or those below. Across grader, api and reference there is no import
circle at all.

Read from the source with `ast`: every `import`, also inside functions and under `if TYPE_CHECKING:`.
"""

from __future__ import annotations

import ast
import functools
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
THIRD_PARTY_OF_THE_CHILD = ("numpy", "gymnasium")
PACKAGES = ("grader", "api", "reference")
"""The project's packages: the import graph whose circles are counted."""
GRADER_LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("commands", ("__main__", "cli")),
    ("simulated students (calibration and tests only)", ("simulated_students",)),
    ("classes", ("classroom",)),
    ("one report's outputs", ("render",)),
    ("one grading", ("grading",)),
    ("the lab", ("lab",)),
    ("what came in, and plain data", ("submission", "report", "errors", "seeds")),
    ("untrusted execution", ("sandbox",)),
    ("the lab's dialects", ("compat",)),
    ("the parent's parser", ("parsing",)),
)
"""The entries of grader/ (its folders and its few plain-data modules), top layer first: a module imports
only its own layer or those below it (a module of the same layer too, as long as no circle forms)."""


@functools.cache
def imported_modules(path: Path) -> frozenset[str]:
    """Every module a file imports by absolute name (relative imports resolved against its package).

    Read once per file and run: every test here asks of the same files."""
    package_parts = path.relative_to(ROOT).with_suffix("").parts
    modules: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(package_parts[: -node.level] + ((node.module,) if node.module else ()))
            else:
                base = node.module or ""
            modules.add(base)
            modules.update(f"{base}.{alias.name}" for alias in node.names)
    return frozenset(modules)


def _within(module: str, package: str) -> bool:
    return module == package or module.startswith(f"{package}.")


def _sources(package: str) -> list[Path]:
    files = sorted((ROOT / package.replace(".", "/")).rglob("*.py"))
    assert files, f"found no sources of {package}: the path is wrong"
    return files


def _breaches(package: str, allowed: tuple[str, ...], *, stdlib: bool = True) -> list[str]:
    """Imports of `package`'s files that are neither its own, nor allowed, nor (when `stdlib`) stdlib."""
    breaches: list[str] = []
    for path in _sources(package):
        for module in sorted(imported_modules(path)):
            top = module.split(".")[0]
            if _within(module, package) or any(_within(module, other) for other in allowed):
                continue
            if stdlib and (top in sys.stdlib_module_names or top == "__future__"):
                continue
            breaches.append(f"{path.relative_to(ROOT)} imports {module}")
    return breaches


def test_the_scan_sees_relative_imports() -> None:
    assert "grader.compat.events" in imported_modules(ROOT / "grader/compat/dialect.py")
    assert "grader.compat.detection" in imported_modules(ROOT / "grader/compat/dialect.py")
    assert "grader.compat.errors" in imported_modules(ROOT / "grader/compat/envs/roulette.py")


@pytest.mark.parametrize(
    ("package", "forbidden"),
    [("grader", ("api",)), ("reference", ("grader", "api"))],
)
def test_no_layer_imports_the_one_above_it(package: str, forbidden: tuple[str, ...]) -> None:
    found = [
        f"{path.relative_to(ROOT)} imports {module}"
        for path in _sources(package)
        for module in sorted(imported_modules(path))
        if any(_within(module, other) for other in forbidden)
    ]
    assert found == []


def test_the_compat_layer_is_self_contained() -> None:
    assert _breaches("grader.compat", THIRD_PARTY_OF_THE_CHILD) == []


def test_the_child_harness_imports_only_what_the_sandbox_binds() -> None:
    assert _breaches("grader.sandbox.child", (*THIRD_PARTY_OF_THE_CHILD, "grader.compat")) == []


def test_the_grader_package_root_is_import_light() -> None:
    """`grader/__init__.py` is bound into the sandbox: it imports nothing beyond the standard library."""
    init = ROOT / "grader" / "__init__.py"
    assert [
        module for module in imported_modules(init) if module.split(".")[0] not in sys.stdlib_module_names
    ] == []


@functools.cache
def _module_files() -> dict[str, Path]:
    """Every module of the project's packages by dotted name (a package by its ``__init__.py``); listed once
    per run (read only)."""
    modules: dict[str, Path] = {}
    for package in PACKAGES:
        for path in _sources(package):
            parts = path.relative_to(ROOT).with_suffix("").parts
            modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return modules


def _resolved(name: str, modules: dict[str, Path]) -> str | None:
    """The project module an imported name refers to (``package.name`` when it is one, else its package)."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


def import_graph() -> dict[str, set[str]]:
    """Which project modules each project module imports (``from package import name`` counts as the
    module ``package.name`` when there is one, else as ``package``; a module's own packages are left out,
    as Python imports them whatever the module says)."""
    modules = _module_files()

    graph: dict[str, set[str]] = {module: set() for module in modules}
    for module, path in modules.items():
        for name in imported_modules(path):
            target = _resolved(name, modules)
            if target is not None and target != module and not module.startswith(f"{target}."):
                graph[module].add(target)
    return graph


def import_circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The graph's circles: its strongly connected components of more than one module, each sorted."""
    index: dict[str, int] = {}
    lowest: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles: list[list[str]] = []

    def visit(start: str) -> None:
        # Tarjan's algorithm with an explicit stack of iterators (the graph is deeper than the recursion limit
        # allows in the worst case).
        index[start] = lowest[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        pending: list[tuple[str, Iterator[str]]] = [(start, iter(sorted(graph[start])))]
        while pending:
            module, targets = pending[-1]
            target = next(targets, None)
            if target is not None:
                if target not in index:
                    index[target] = lowest[target] = len(index)
                    stack.append(target)
                    on_stack.add(target)
                    pending.append((target, iter(sorted(graph[target]))))
                elif target in on_stack:
                    lowest[module] = min(lowest[module], index[target])
                continue
            pending.pop()
            if pending:
                lowest[pending[-1][0]] = min(lowest[pending[-1][0]], lowest[module])
            if lowest[module] == index[module]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == module:
                        break
                if len(component) > 1:
                    circles.append(sorted(component))

    for module in sorted(graph):
        if module not in index:
            visit(module)
    return sorted(circles)


def test_the_circle_finder_sees_type_only_imports_and_circles() -> None:
    assert "grader.lab.assignment" in imported_modules(ROOT / "grader/render/text.py")  # under TYPE_CHECKING
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": {"e", "f"}, "f": set()}
    assert import_circles(graph) == [["a", "b", "c"]]


def test_there_is_no_import_circle() -> None:
    """Two modules that need each other move their shared contract down into a third."""
    circles = import_circles(import_graph())
    assert circles == [], "import circles (type-only imports included):\n" + "\n".join(
        f"  {len(circle)} modules: {', '.join(circle)}" for circle in circles
    )


def _grader_part(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if parts[0] == "grader" and len(parts) > 1 else None


def _layer_of() -> dict[str, int]:
    return {part: level for level, (_, parts) in enumerate(GRADER_LAYERS) for part in parts}


def test_every_part_of_grader_has_a_layer() -> None:
    parts = {part for module in _module_files() if (part := _grader_part(module)) is not None}
    unplaced = sorted(parts - set(_layer_of()))
    gone = sorted(set(_layer_of()) - parts)
    assert (unplaced, gone) == ([], []), (
        f"grader parts without a layer: {unplaced}; layers naming no part: {gone}. "
        "Place each new module or subpackage in GRADER_LAYERS (and ARCHITECTURE.md)"
    )


def test_no_part_of_grader_imports_a_layer_above_its_own() -> None:
    layer_of = _layer_of()
    modules = _module_files()
    upward = sorted(
        f"{modules[module].relative_to(ROOT)} ({GRADER_LAYERS[layer_of[part]][0]}) imports {target} "
        f"({GRADER_LAYERS[layer_of[target_part]][0]})"
        for module, targets in import_graph().items()
        if (part := _grader_part(module)) in layer_of
        for target in targets
        if (target_part := _grader_part(target)) in layer_of and layer_of[target_part] < layer_of[part]
    )
    assert upward == []


def layers_diagram() -> str:
    """The layers inside grader/ as ARCHITECTURE.md shows them, top first."""
    return "\n".join(f"{name}: {', '.join(parts)}" for name, parts in GRADER_LAYERS)


def test_architecture_shows_the_layers_held_here() -> None:
    architecture = (ROOT / "ARCHITECTURE.md").read_text(encoding="utf-8")
    assert f"```text\n{layers_diagram()}\n```" in architecture, (
        "ARCHITECTURE.md, section 'Layers inside grader/', must show exactly:\n" + layers_diagram()
    )


def _own_layer_graph() -> tuple[dict[str, int], dict[str, set[str]]]:
    """Each grader module's layer, and the grader modules each imports."""
    layer_of = _layer_of()
    modules = _module_files()

    graph = {  # as import_graph, but a module's import of its own package counts (`grader.cli.__main__`)
        module: {
            target
            for name in imported_modules(path)
            if (target := _resolved(name, modules)) is not None
            and target != module
            and _grader_part(target) in layer_of
        }
        for module, path in modules.items()
        if _grader_part(module) in layer_of
    }
    return {module: layer_of[_grader_part(module) or ""] for module in graph}, graph


def test_every_module_sits_in_the_lowest_layer_its_imports_allow_unless_its_layer_uses_it() -> None:
    """A module that imports grader modules sits as low as they allow, or is tied to the layer it sits in
    (it imports a module of that layer, or one imports it): `grader.render.figures` sits in the outputs
    because the HTML report draws with it. One that neither uses nor is used by its layer belongs lower,
    where its imports put it. A module that imports nothing of grader (`grader.grading.scheduling`,
    `grader.submission.notebook.cells`) has no such floor and sits with the concept it serves."""
    level, graph = _own_layer_graph()
    used_in_own_layer = {
        target for module, targets in graph.items() for target in targets if level[target] == level[module]
    }
    misplaced = []
    for module, targets in sorted(graph.items()):
        if not targets or _module_files()[module].name == "__init__.py":
            continue
        lowest_allowed = max(level[target] for target in targets)
        tied = module in used_in_own_layer or any(level[target] == level[module] for target in targets)
        if level[module] != lowest_allowed and not tied:
            misplaced.append(
                f"{module} sits in {GRADER_LAYERS[level[module]][0]!r}, but imports nothing of it and no module "  # noqa: E501
                f"of it imports it; its imports allow {GRADER_LAYERS[lowest_allowed][0]!r}"
            )
    assert misplaced == []


def test_nothing_on_the_grading_path_imports_the_simulated_students() -> None:
    _, graph = _own_layer_graph()
    importers = sorted(
        module
        for module, targets in graph.items()
        if _grader_part(module) != "simulated_students"
        and any(_grader_part(target) == "simulated_students" for target in targets)
    )
    assert importers == []


def test_grader_shows_one_entry_per_layer() -> None:
    entries = sorted(
        path.name.removesuffix(".py")
        for path in (ROOT / "grader").iterdir()
        if path.name != "__pycache__" and (path.suffix == ".py" or (path / "__init__.py").exists())
    )
    assert entries == sorted(["__init__", *_layer_of()])
