"""Judge simulated students (real gymnasium episodes, replayed for real) with test-sized samples."""

import functools
import inspect
import random
from collections.abc import Sequence
from functools import partial
from typing import Any

import numpy as np

from grader.lab.assignment import load_config
from grader.lab.checks.base import CallRecord, ProblemId, Verdict
from grader.lab.problems import PROBLEMS
from grader.lab.settings import ProblemConfig
from grader.simulated_students.simulation import Lab, LabEnv, StudentFunction, function_infos, simulate_calls

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
    fast: bool = False,
) -> list[CallRecord]:
    """Plan the problem's calls, run them on the simulated functions, replay every episode for real
    (`replay`), or judge them as played (`fast`: Blackjack's cards from Python's generator)."""
    settings = settings or small_config(problem)
    sized = {name: _sized(function, settings) for name, function in functions.items()}
    calls = PROBLEMS.problem(problem).check.plan(settings, function_infos(sized), 0)
    return simulate_calls(calls, sized, seed, replay=replay and not fast, fast=fast)


LOW_CARDS = (1, 2, 3, 4, 5)


class _LowDeck:
    """Deals Blackjack's cards from ace to five only (stands in for gymnasium's generator, like `fast`)."""

    def __init__(self, seed: int) -> None:
        self._random = random.Random(seed)

    def choice(self, deck: Sequence[int]) -> int:
        return self._random.choice(LOW_CARDS)


def on_low_deck(function: StudentFunction) -> StudentFunction:
    """The student's function, its Blackjack games dealt from ace to five only: a game that is not the
    lab's, judged as played (`simulate(..., fast=True)`), so decisions, counts and the returned rate are
    right and only the win count is off. bench/verdict_power.py gives its exact win probabilities."""

    @functools.wraps(function)
    def played(lab: Lab, *args: Any, **kwargs: Any) -> Any:
        make = lab.make

        def low_deck_make(env_id: str, **env_kwargs: Any) -> LabEnv:
            env = make(env_id, **env_kwargs)
            env._env.unwrapped._np_random = _LowDeck(lab.call_seed)  # fast mode never reseeds it
            return env

        lab.make = low_deck_make  # type: ignore[method-assign]
        return function(lab, *args, **kwargs)

    return played


def grade(
    problem: ProblemId,
    functions: dict[str, StudentFunction],
    seed: int,
    settings: ProblemConfig | None = None,
    *,
    fast: bool = False,
) -> Verdict:
    """Simulate and judge one problem (`fast`: see `simulate`)."""
    settings = settings or small_config(problem)
    records = simulate(problem, functions, seed, settings, fast=fast)
    return PROBLEMS.problem(problem).check.judge(settings, records)


def deal_only_hard_starts(env: LabEnv, greedy: Any, at_most: float = 4.0) -> None:
    """Rig a simulated Taxi env so that its resets deal only the starts where greedy play on `greedy` (an
    action per state) returns at most `at_most`: a start law that is not the lab's, for episodes judged as
    played, so that only a test of the greedy mean can tell."""
    game = env._env.unwrapped  # the simulated gymnasium game; a student in the sandbox cannot reach it
    law = np.asarray(game.initial_state_distrib, dtype=float)
    for start in np.flatnonzero(law):
        game.s, total, done = int(start), 0.0, False
        while not done:
            _, reward, terminated, truncated, _ = game.step(int(greedy[game.s]))
            total, done = total + reward, terminated or truncated
        law[start] = float(total <= at_most)
    game.initial_state_distrib = law / law.sum()
