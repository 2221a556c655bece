"""The lab's registry is the only list of its problems: sources, acceptance modules and titles follow it."""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

from grader.lab.assignment import load_config
from grader.lab.editions import EDITIONS
from grader.lab.problems import PROBLEM_IDS, PROBLEMS

ROOT = Path(__file__).resolve().parents[3]
REGISTRY = ROOT / "grader" / "lab" / "problems.py"
ACCEPTANCE = ROOT / "grader" / "grading" / "cases"


def _listed_ids(node: ast.AST) -> set[str]:
    """The problem ids a literal tuple, list, set or dict (keys) spells out, or a string names."""
    if isinstance(node, ast.Dict):
        items: list[ast.expr | None] = list(node.keys)
    elif isinstance(node, ast.Tuple | ast.List | ast.Set):
        items = list(node.elts)
    elif isinstance(node, ast.Constant) and isinstance(node.value, str):
        return set(PROBLEM_IDS) & set(re.findall(r"\w+", node.value))
    else:
        return set()
    return {item.value for item in items if isinstance(item, ast.Constant) and item.value in PROBLEM_IDS}


def _sources() -> list[Path]:
    return sorted(path for package in ("grader", "api") for path in (ROOT / package).rglob("*.py"))


@pytest.mark.slow
def test_no_source_lists_every_problem_but_the_registry() -> None:
    """A list of all the ids anywhere else (a tuple, a dict's keys, a Literal, a description) would drift."""
    lists = [
        f"{path.relative_to(ROOT)}:{node.lineno}"
        for path in _sources()
        if path != REGISTRY
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
        if _listed_ids(node) == set(PROBLEM_IDS)
    ]
    assert lists == []


_QUOTED = ", ".join(repr(problem) for problem in PROBLEM_IDS)


@pytest.mark.parametrize(
    "source",
    [
        f"IDS = ({_QUOTED})",
        f"SIZES = {{{', '.join(f'{problem!r}: 1' for problem in PROBLEM_IDS)}}}",
        f"ProblemId = Literal[{_QUOTED}]",
        f"DESCRIPTION = 'Problem id: {', '.join(PROBLEM_IDS)}.'",
    ],
    ids=["tuple", "dict", "literal", "description"],
)
def test_the_scan_finds_every_spelling_of_the_list(source: str) -> None:
    assert any(_listed_ids(node) == set(PROBLEM_IDS) for node in ast.walk(ast.parse(source)))


def test_one_acceptance_module_per_problem_and_no_other() -> None:
    modules = {path.stem for path in ACCEPTANCE.glob("test_*.py")}
    assert modules == {
        problem.acceptance_module for edition in EDITIONS.values() for problem in edition.registry
    }


EVERY_PROBLEM = list(
    {problem.id: problem for edition in EDITIONS.values() for problem in edition.registry}.values()
)


@pytest.mark.parametrize("problem", EVERY_PROBLEM, ids=lambda problem: problem.id)
def test_each_acceptance_module_grades_its_own_problem(problem: object) -> None:
    module = importlib.import_module(f"grader.grading.cases.{problem.acceptance_module}")  # type: ignore[attr-defined]
    assert problem.id == module.PROBLEM  # type: ignore[attr-defined]
    assert callable(getattr(module, f"test_{problem.id}"))  # type: ignore[attr-defined]


def test_reports_take_titles_and_points_from_the_registry() -> None:
    config = load_config()
    assert {problem.id: (problem.title, problem.points) for problem in PROBLEMS} == {
        problem: (settings.title, settings.points) for problem, settings in config.problems.items()
    }
