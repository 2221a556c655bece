"""Judge simulated students (real gymnasium episodes, replayed for real) with test-sized samples."""

import inspect
from functools import partial
from typing import Any

from grader.lab.assignment import load_config
from grader.lab.checks.base import CallRecord, ProblemId, Verdict
from grader.lab.problems import PROBLEMS
from grader.lab.settings import ProblemConfig
from grader.simulated_students.simulation import StudentFunction, function_infos, simulate_calls

# Samples smaller than the assignment's so the suite stays fast; every threshold is derived from them.
TEST_SIZES: dict[ProblemId, dict[str, Any]] = {
    "random_blackjack": {"games": 2000},
    "blackjack": {"games_per_call": 1000},
    "cartpole": {},
    "car": {},
    "taxi": {"episodes_per_scenario": 200},
    "find_qvalues": {},
}


def small_config(problem: ProblemId, **updates: Any) -> ProblemConfig:
    """The assignment's settings of a problem with test-sized samples."""
    settings = load_config().problems[problem]
    return settings.model_copy(update={**TEST_SIZES[problem], **updates})


def _sized(function: StudentFunction, settings: ProblemConfig) -> StudentFunction:
    parameters = inspect.signature(function).parameters
    if "games" in parameters and hasattr(settings, "games_per_call"):
        return partial(function, games=settings.games_per_call)
    if "episodes" in parameters and hasattr(settings, "episodes_per_scenario"):
        return partial(function, episodes=settings.episodes_per_scenario)
    return function


def simulate(
    problem: ProblemId,
    functions: dict[str, StudentFunction],
    seed: int,
    settings: ProblemConfig | None = None,
    *,
    replay: bool = True,
) -> list[CallRecord]:
    """Plan the problem's calls, run them on the simulated functions, replay every episode for real."""
    settings = settings or small_config(problem)
    sized = {name: _sized(function, settings) for name, function in functions.items()}
    calls = PROBLEMS.problem(problem).check.plan(settings, function_infos(sized))
    return simulate_calls(calls, sized, seed, replay=replay)


def grade(
    problem: ProblemId,
    functions: dict[str, StudentFunction],
    seed: int,
    settings: ProblemConfig | None = None,
) -> Verdict:
    """Simulate and judge one problem."""
    settings = settings or small_config(problem)
    return PROBLEMS.problem(problem).check.judge(settings, simulate(problem, functions, seed, settings))
