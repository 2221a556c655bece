"""The registry: ids, lookups, `--only` selection, acceptance modules, and a test-only problem end to end."""

from __future__ import annotations

from pathlib import Path

import pytest
from fake_problem import ECHO, ECHO_SOURCE, WITH_ECHO

from grader.errors import UnknownProblem
from grader.grading.execution import run_problem
from grader.lab.assignment import DEFAULT_CONFIG_PATH, load_config
from grader.lab.problems import PROBLEM_IDS, PROBLEMS
from grader.lab.registry import Problem, Registry
from grader.sandbox import IsolationPolicy

LAB_IDS = ", ".join(PROBLEM_IDS)


@pytest.mark.parametrize(
    ("ids", "found"),
    [
        (("echo", "echo"), "repeated ['echo'], invalid []"),
        (("echo", "two words"), "repeated [], invalid ['two words']"),
        ((), "repeated [], invalid [] in []"),
    ],
    ids=["repeated-id", "not-an-identifier", "empty"],
)
def test_a_malformed_registry_is_refused_at_import(ids: tuple[str, ...], found: str) -> None:
    with pytest.raises(ValueError, match="expected a non-empty registry of distinct identifiers") as raised:
        Registry(tuple(Problem(problem, "t", 1.0, ECHO.config, ECHO.check) for problem in ids))
    assert found in str(raised.value)


@pytest.mark.parametrize(
    ("names", "selected"),
    [(["taxi", "car"], ("car", "taxi")), ([" car ", "", "car"], ("car",))],
    ids=["registry-order", "blanks-and-repeats"],
)
def test_select_keeps_registry_order(names: list[str], selected: tuple[str, ...]) -> None:
    assert PROBLEMS.select(names) == selected


@pytest.mark.parametrize(
    ("names", "message"),
    [
        (["blackjak", "car"], f"unknown problem blackjak; expected ids among {LAB_IDS}"),
        (["", " "], f"unknown problem (none); expected ids among {LAB_IDS}"),
    ],
    ids=["misspelt", "none"],
)
def test_unknown_ids_name_what_was_found_and_what_is_expected(names: list[str], message: str) -> None:
    with pytest.raises(UnknownProblem) as raised:
        PROBLEMS.select(names)
    assert str(raised.value) == message
    with pytest.raises(UnknownProblem, match=f"expected ids among {LAB_IDS}, echo"):
        WITH_ECHO.problem("blackjak")


def test_acceptance_modules_are_named_for_their_problem() -> None:
    assert PROBLEMS.acceptance_problem("grader.grading.cases.test_car") == "car"
    assert WITH_ECHO.acceptance_problem("test_echo") == "echo"
    with pytest.raises(
        UnknownProblem, match="acceptance module test_echo grades no problem: expected test_<id>"
    ):
        PROBLEMS.acceptance_problem("grader.grading.cases.test_echo")


@pytest.mark.parametrize(
    ("source", "status", "score"),
    [(ECHO_SOURCE, "passed", 2.0), ("def echo(n):\n    return n + 1\n", "failed", 0.0)],
    ids=["echoes", "off-by-one"],
)
def test_a_problem_only_a_test_registry_declares_is_loaded_planned_and_judged(
    tmp_path: Path, source: str, status: str, score: float
) -> None:
    """No edit outside the registry entry: the loader, the typed lookup and run_problem follow it."""
    config_path = tmp_path / "assignment.toml"
    config_path.write_text(DEFAULT_CONFIG_PATH.read_text() + "\n[problems.echo]\nanswer = 7\n")
    submission = tmp_path / "opengym.py"
    submission.write_text(source)
    config = load_config(config_path, registry=WITH_ECHO)

    run = run_problem(
        submission, "echo", config=config, grading_seed=3, policy=IsolationPolicy.ALLOW_FALLBACK
    )

    result = run.result
    assert (result.id, result.title, result.status, result.score, result.max_score) == (
        "echo",
        "Problem E: echo",
        status,
        score,
        2.0,
    )
    assert result.feedback.startswith("echo(7) returned")
