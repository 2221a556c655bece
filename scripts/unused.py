"""List the module-level names (and methods) of `grader/` and `api/` that no code outside `tests/` uses.

A name (function, class or constant defined at module level, or a method of such a class) counts as used
when code outside `tests/` reads it: its own module past the definition, or any module of `grader/`,
`api/`, `reference/`, `bench/` or `scripts/`. Only reads count: `from x import name` and `__all__`
entries merely pass a name on, so a name that the package re-exports and only the tests read is listed.
Matching is by name (`stats.normal_cdf` and `normal_cdf` both read `normal_cdf`), so a name shared with
another module's live name is taken as used: the list can miss dead code, not flag live code by mistake.

Each listed name says where it is still read (the tests, or nowhere) and what may keep it alive
without a read: a decorator (routes, pytest hooks, validators register by decoration), a method of a
subclass (`ast.NodeVisitor.visit_*`, pytest and xdist protocols), a `pytest_`, `test_` or dunder name
(found by pytest or Python), a module of the student-facing shims (read by submissions), a mention in
`pyproject.toml` (entry points), a template or `ARCHITECTURE.md` (documented public API), or a reason
recorded in `KEPT`. Those need a person's judgement; the rest are dead.

Run: `python scripts/unused.py` (prints one line per name; exit status 0).
"""

from __future__ import annotations

import ast
import re
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFINING = ("grader", "api")
READING = ("grader", "api", "reference", "bench", "scripts")
TESTS = ("tests",)
DOCUMENTS = ("ARCHITECTURE.md", "pyproject.toml")
TEMPLATE_SUFFIXES = (".html", ".mako", ".js", ".ini", ".toml")
STUDENT_APIS = ("grader/compat/shim", "grader/compat/fallback")
"""Modules student code imports (`gym`, `gym_toytext`, `IPython`): their names are read by submissions."""
KEPT = {
    "add_serve_command": "entry point gymgrade.commands (pyproject.toml)",
    "add_worker_command": "entry point gymgrade.commands (pyproject.toml)",
    "executor_from_environment": "entry point gymgrade.executors (pyproject.toml)",
    "Grader": "the protocol the service types its grader against (documented seam of api/grader_adapter.py)",
    "data_uri": "read by grader/render/templates/report.html",
    "add_node": "pytest-xdist scheduler protocol",
    "add_node_collection": "pytest-xdist scheduler protocol",
    "mark_test_complete": "pytest-xdist scheduler protocol",
    "mark_test_pending": "pytest-xdist scheduler protocol",
    "remove_pending_tests_from_node": "pytest-xdist scheduler protocol",
    "remove_node": "pytest-xdist scheduler protocol",
    "schedule": "pytest-xdist scheduler protocol",
    "pass_probability": "the power of a configured test (tests/grader/lab/test_assignment.py pins it)",
    "revision": "read by alembic",
    "down_revision": "read by alembic",
    "branch_labels": "read by alembic",
    "depends_on": "read by alembic",
    "downgrade": "called by alembic",
    "lab_ids": "the lab ids grader.compat maps; tests/grader/compat/test_ids.py checks that each resolves",
}
"""Names listed on purpose, and why (a person's judgement recorded; printed with the name)."""


@dataclass(frozen=True)
class Definition:
    """A module-level name and how it is defined."""

    path: Path
    name: str
    kind: str
    decorated: bool


def _python_files(root: Path, folders: tuple[str, ...]) -> list[Path]:
    return sorted(path for folder in folders for path in (root / folder).rglob("*.py"))


def definitions(path: Path) -> list[Definition]:
    """The functions, classes (and their methods) and assigned names at the top of a module."""
    found = []
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            kind = "class" if isinstance(node, ast.ClassDef) else "function"
            found.append(Definition(path, node.name, kind, bool(node.decorator_list)))
        if isinstance(node, ast.ClassDef):
            found.extend(
                Definition(
                    path, method.name, f"method of {node.name}", bool(method.decorator_list or node.bases)
                )
                for method in node.body
                if isinstance(method, ast.FunctionDef | ast.AsyncFunctionDef)
            )
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            found.extend(
                Definition(path, target.id, "constant", False)
                for target in targets
                if isinstance(target, ast.Name) and target.id != "__all__"
            )
    return found


def reads(path: Path) -> Counter[str]:
    """How often each name is read in a module (names and attributes; imports and `__all__` excluded)."""
    counts: Counter[str] = Counter()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    exported = {
        id(node)
        for statement in tree.body
        if isinstance(statement, ast.Assign)
        and any(isinstance(target, ast.Name) and target.id == "__all__" for target in statement.targets)
        for node in ast.walk(statement.value)
    }
    for node in ast.walk(tree):
        if id(node) in exported:
            continue
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load):
            counts[node.id] += 1
        elif isinstance(node, ast.Attribute):
            counts[node.attr] += 1
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value.isidentifier():
            counts[node.value] += 1  # getattr(module, "name"), string annotations, registries by name
    return counts


def _texts(paths: list[Path]) -> str:
    return "\n".join(path.read_text(encoding="utf-8", errors="replace") for path in paths)


def unused(root: Path = ROOT) -> list[tuple[Definition, str, list[str]]]:
    """Every module-level name of `grader/` and `api/` read nowhere outside the tests.

    Returns:
        (definition, where it is still read: "tests" or "nowhere", what may keep it alive).
    """
    own_reads = {path: reads(path) for path in _python_files(root, READING)}
    test_reads: Counter[str] = sum((reads(path) for path in _python_files(root, TESTS)), Counter())
    documents = _texts([root / name for name in DOCUMENTS])
    templates = _texts(
        [
            path
            for folder in DEFINING
            for path in (root / folder).rglob("*")
            if path.suffix in TEMPLATE_SUFFIXES
        ]
    )
    listed = []
    for path in _python_files(root, DEFINING):
        for definition in definitions(path):
            name = definition.name
            if (
                any(counts[name] for other, counts in own_reads.items() if other != path)
                or own_reads[path][name]
            ):
                continue
            keepers = []
            if definition.decorated:
                keepers.append("decorated, or a method of a subclass (a framework may call it)")
            if name.startswith(("pytest_", "test_")) or re.fullmatch(r"__\w+__", name):
                keepers.append("pytest hook, pytest test or dunder")
            if re.search(rf"\b{re.escape(name)}\b", documents):
                keepers.append("named in ARCHITECTURE.md or pyproject.toml")
            if re.search(rf"\b{re.escape(name)}\b", templates):
                keepers.append("named in a template or data file")
            if definition.path.relative_to(root).as_posix().startswith(STUDENT_APIS):
                keepers.append("student-facing shim API")
            if name in KEPT:
                keepers.insert(0, f"kept: {KEPT[name]}")
            listed.append((definition, "tests" if test_reads[name] else "nowhere", keepers))
    return listed


def main() -> int:
    """Print one line per unused name: module, name, kind, where read, what may keep it."""
    for definition, where, keepers in unused():
        module = definition.path.relative_to(ROOT)
        keep = f"  [{'; '.join(keepers)}]" if keepers else ""
        print(f"{module}: {definition.name} ({definition.kind}) read by {where}{keep}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
