"""epsilon_decay (edition rl1): exact over the grid; each typical mistake fails and is named."""

from typing import Any

import pytest

from grader.lab.assignment import load_config
from grader.lab.checks.base import Verdict
from grader.lab.checks.epsilon_decay import GRID, EpsilonDecayConfig
from grader.lab.editions.rl1 import RL1
from grader.simulated_students import epsilon_decay as students
from grader.simulated_students.simulation import simulate_calls

PROBLEM = RL1.registry.problem("epsilon_decay")


def _settings(**updates: Any) -> EpsilonDecayConfig:
    settings = load_config(RL1.default_config).problems["epsilon_decay"]
    assert isinstance(settings, EpsilonDecayConfig)
    return settings.model_copy(update=updates)


def _judge(function: Any, **updates: Any) -> Verdict:
    settings = _settings(**updates)
    functions = {"epsilon_decay": function} if function is not None else {}
    calls = PROBLEM.check.plan(settings, {}, 0)
    return PROBLEM.check.judge(settings, simulate_calls(calls, functions, seed=0))


@pytest.mark.parametrize("function", students.HONEST.values(), ids=list(students.HONEST))
def test_an_honest_decay_passes_exactly(function: Any) -> None:
    verdict = _judge(function)
    assert (verdict.status, verdict.fraction) == ("passed", 1.0)
    assert verdict.feedback == f"epsilon_decay: every value is exact over {len(GRID)} argument sets."


def test_the_grid_covers_first_last_defaults_bounds_and_large_n() -> None:
    assert any(point.episode == 1 for point in GRID)
    assert any(point.episode == point.n for point in GRID)
    assert any(point.start is None for point in GRID)
    assert any(point.start not in (None, 1.0) and point.end not in (None, 1e-6) for point in GRID)
    assert max(point.n for point in GRID) >= 1_000_000
    assert min(point.n for point in GRID) >= 2  # the N - 1 mistake returns numbers, not ZeroDivisionError


@pytest.mark.parametrize(("name", "mistake"), students.MISTAKES.items(), ids=list(students.MISTAKES))
def test_each_mistake_fails_and_is_named(name: str, mistake: tuple[Any, str]) -> None:
    function, words = mistake
    verdict = _judge(function)
    assert verdict.status == "failed", name
    assert verdict.fraction == 0.0
    assert words in verdict.feedback


def test_the_message_says_what_was_expected_and_found() -> None:
    verdict = _judge(students.zero_based)
    assert verdict.feedback.startswith(
        "epsilon_decay(1, 100) returned 0.99; expected epsilon_start - (episode - 1) * delta with "
        "delta = (1.0 - 1e-06) / 100 = 1.0"
    )
    assert "Likely cause: your values are those of 0-based episodes" in verdict.feedback


def test_the_exponential_decay_is_graded_only_when_enabled() -> None:
    assert len(PROBLEM.check.plan(_settings(), {}, 0)) == len(GRID)
    enabled = _settings(grade_exp=True)
    calls = PROBLEM.check.plan(enabled, {}, 0)
    assert len(calls) == 2 * len(GRID)
    assert all(call.kwargs == {"decay_type": "exp"} for call in calls[len(GRID) :])
    assert _judge(students.honest, grade_exp=True).status == "passed"


def test_a_wrong_exponential_decay_costs_its_share() -> None:
    verdict = _judge(students.exp_off_by_one, grade_exp=True, exp_share=0.25)
    assert (verdict.status, verdict.fraction) == ("failed", 0.75)
    assert "decay_type='exp'" in verdict.feedback


def test_no_decay_type_parameter_fails_the_exponential_part_only() -> None:
    verdict = _judge(students.honest_rewritten, grade_exp=True)
    assert (verdict.status, verdict.fraction) == ("failed", 0.5)
    assert "decay_type" in verdict.feedback


def test_a_stub_is_missing_and_an_absent_function_too() -> None:
    def stub(_lab: Any, episode: int, N: int, epsilon_start: float = 1.0, epsilon_end: float = 1e-6) -> float:
        raise NotImplementedError("Problem 5 incomplete")

    assert _judge(stub).status == "missing"
    assert _judge(None).status == "missing"


@pytest.mark.parametrize("value", [True, "0.5", None, [0.5], float("inf")], ids=repr)
def test_a_value_that_is_no_number_fails(value: object) -> None:
    verdict = _judge(lambda _lab, *args: value)
    assert verdict.status == "failed"
    assert "returned no finite number" in verdict.feedback
    assert verdict.feedback.endswith("argument sets wrong). Return a float.")
