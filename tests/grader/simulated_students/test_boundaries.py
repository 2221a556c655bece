"""The grading path never depends on the test doubles, and the checks stay free of gymnasium and the child.

Read from the source with `ast` (every `import`, also inside functions and `if TYPE_CHECKING:`), so the
test holds for direct imports. Transitively `grader.lab.checks` still loads gymnasium: `checks/integrity.py`
replays episodes through `grader.sandbox.replay`, the trusted replay the verdicts rest on.
"""

import ast
from pathlib import Path

import pytest

GRADER = Path(__file__).resolve().parents[3] / "grader"


def _imported_modules(path: Path) -> set[str]:
    """Every module a file imports by absolute name (`from a.b import c` gives `a.b` and `a.b.c`)."""
    modules: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
        if isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                package = ".".join(path.relative_to(GRADER.parent).with_suffix("").parts[: -node.level])
                base = f"{package}.{node.module}" if node.module else package
            else:
                base = node.module or ""
            modules.add(base)
            modules.update(f"{base}.{alias.name}" for alias in node.names)
    return modules


def _within(module: str, package: str) -> bool:
    return module == package or module.startswith(f"{package}.")


def _importers(files: list[Path], forbidden: tuple[str, ...]) -> list[str]:
    return sorted(
        f"{path.relative_to(GRADER.parent)} imports {module}"
        for path in files
        for module in _imported_modules(path)
        if any(_within(module, package) for package in forbidden)
    )


def _sources(folder: Path) -> list[Path]:
    return sorted(folder.rglob("*.py"))


def test_the_scan_finds_the_imports_it_must_refuse() -> None:
    simulation = GRADER / "simulated_students" / "simulation.py"
    assert _importers([simulation], ("gymnasium",)) == [
        "grader/simulated_students/simulation.py imports gymnasium"
    ]
    assert "grader.sandbox.child.seeding.SeedStream" in _imported_modules(simulation)
    assert "grader.simulated_students.simulation" in _imported_modules(
        GRADER / "simulated_students" / "behaviours.py"
    )


def test_nothing_on_the_grading_path_imports_grader_testing() -> None:
    outside = [path for path in _sources(GRADER) if not path.is_relative_to(GRADER / "simulated_students")]
    assert outside, "found no grader sources: the path to grader/ is wrong"
    assert _importers(outside, ("grader.simulated_students",)) == []


@pytest.mark.parametrize("forbidden", ["gymnasium", "gym", "grader.sandbox.child"])
def test_the_checks_import_neither_gymnasium_nor_the_child_harness(forbidden: str) -> None:
    checks = _sources(GRADER / "lab" / "checks")
    assert len(checks) > 5, "found no check sources: the path to grader/lab/checks is wrong"
    assert _importers(checks, (forbidden,)) == []
