"""The problem stack has no import circle, counting every import (inside functions and type-only ones too).

From the bottom: problem_id <- games <- problem_config <- checks <- showcase, problem_plots <-
problem_registry <- problems, editions <- config (ARCHITECTURE.md, "Adding an edition or a lab"). The
whole-graph test of
tests/test_layering.py holds every package; this one names the problem stack's modules in its message.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STACK = ("grader.problem_id", "grader.games", "grader.problem_config", "grader.checks", "grader.showcase",
         "grader.problem_plots", "grader.problem_registry", "grader.problems", "grader.editions",
         "grader.config")  # fmt: skip


def _modules() -> dict[str, Path]:
    found = {}
    for path in (ROOT / "grader").rglob("*.py"):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def _graph(modules: dict[str, Path]) -> dict[str, set[str]]:
    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = {module: set() for module in modules}
    for module, path in modules.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                targets = [node.module, *(f"{node.module}.{alias.name}" for alias in node.names)]
            else:
                continue
            for target in targets:
                found = resolve(target)
                if found and found != module and not module.startswith(found + "."):
                    graph[module].add(found)
    return graph


def _reaches(graph: dict[str, set[str]], start: str, goal: str) -> bool:
    seen, todo = set(), [start]
    while todo:
        module = todo.pop()
        if module == goal:
            return True
        if module not in seen:
            seen.add(module)
            todo.extend(graph[module])
    return False


def test_no_module_of_the_problem_stack_is_in_an_import_circle() -> None:
    graph = _graph(_modules())
    stack = [module for module in graph if module.startswith(STACK)]
    assert len(stack) > 20, stack
    circles = sorted(
        f"{module} -> {target}"
        for module in stack
        for target in graph[module]
        if _reaches(graph, target, module)
    )
    assert circles == [], "these imports close a circle (move the shared name down a layer):\n" + "\n".join(
        circles
    )


def test_the_lowest_layer_imports_nothing_of_gymgrade() -> None:
    assert _graph(_modules())["grader.problem_id"] == set()
