"""The import graph of ARCHITECTURE.md holds: each layer imports only what its arrow allows.

    api  ->  grader  ->  reference (oracles only)
                   \\->  grader.compat        (stdlib, numpy, gymnasium)
                   \\->  grader.sandbox.child (stdlib, numpy, gymnasium, grader.compat)

Read from the source with `ast`: every `import`, also inside functions and under `if TYPE_CHECKING:`.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
THIRD_PARTY_OF_THE_CHILD = ("numpy", "gymnasium")


def imported_modules(path: Path) -> set[str]:
    """Every module a file imports by absolute name (relative imports resolved against its package)."""
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
    return modules


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
