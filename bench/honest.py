"""Each integrity rule's false-fail rate on honest patterns and its catch rate on the patterns it targets.

Every regrade runs a problem's planned calls in-process with a fresh seed
(`grader.simulated_students.simulation`: real gymnasium envs, episodes logged as the sandbox logs them,
replayed for real) and judges them with the real check, so every rule and every statistical test of the check
runs as in a grading. A regrade counts against a rule when the verdict is not the one an instructor would give
(honest: passed; targeted: failed, with the rule's own words in the feedback). The honest functions are the
in-process twins of the files in `submissions/honest/` (same loops, same resets, same post-terminal steps).

The selection rule reads only the starts a call dealt and which of them it played, so its false-fail
rate on the honest "double reset" (two resets, the second played) is also measured on its own, cheaply:
`--null-regrades` regrades deal each call's starts from the grader's reset stream (fresh call seeds),
play the second, and apply the rule's own code (`selection_tests`) to them, with the assignment's sizes.

    python bench/honest.py                 # 200 regrades of every pattern, 200 null regrades
    python bench/honest.py --regrades 20 --null-regrades 20   # a smoke run
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import gymnasium
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from grader.lab.assignment import load_config
from grader.lab.checks.base import ProblemId
from grader.lab.checks.starts import SELECTION_ALPHA, selection_tests
from grader.lab.problems import PROBLEMS
from grader.lab.settings import ProblemConfig
from grader.sandbox.child.seeding import reset_seeds
from grader.simulated_students.behaviours import (
    MISTAKES,
    car_policy,
    velocity_policy,
)
from grader.simulated_students.simulation import StudentFunction, function_infos, simulate_calls

SIZES: dict[ProblemId, dict[str, Any]] = {
    "random_blackjack": {"games": 2000},
    "blackjack": {"games_per_call": 1000, "thresholds": [12, 13]},
    "cartpole": {},
    "car": {},
}
"""Smaller than the assignment's Blackjack samples (2000 games, 1000 per n) so 200 regrades fit; cartpole
and car make the assignment's 100 calls."""


def _play(env: Any, policy: Callable[[Any], int], observation: Any) -> int:
    steps, done = 0, False
    while not done:
        observation, _, terminated, truncated, _ = env.step(policy(observation))
        steps, done = steps + 1, terminated or truncated
    return steps


def _double_reset(env_id: str, policy: Callable[[Any], int]) -> StudentFunction:
    def function(lab: Any) -> int:
        env = lab.make(env_id)
        env.reset()
        observation, _ = env.reset()
        return _play(env, policy, observation)

    return function


def _blackjack_double_reset(lab: Any, n: int) -> float:
    env = lab.make("Blackjack-v0")
    wins = 0
    for _ in range(n):
        env.reset()
        env.reset()
        done, reward = False, 0.0
        while not done:
            _, reward, terminated, truncated, _ = env.step(int(env.action_space.sample()))
            done = terminated or truncated
        wins += reward > 0
    return wins / n


def _scout(env_id: str, policy: Callable[[Any], int], keep: Callable[[Any], bool]) -> StudentFunction:
    def function(lab: Any) -> int:
        env = lab.make(env_id)
        observation, _ = env.reset()
        while not keep(observation):
            observation, _ = env.reset()
        return _play(env, policy, observation)

    return function


def _best_of_envs(env_id: str, policy: Callable[[Any], int], key: Callable[[Any], float]) -> StudentFunction:
    def function(lab: Any) -> int:
        envs = [lab.make(env_id) for _ in range(6)]
        starts = [env.reset()[0] for env in envs]
        best = min(range(6), key=lambda number: key(starts[number]))
        return _play(envs[best], policy, starts[best])

    return function


def _behaviour(name: str) -> StudentFunction:
    return next(mistake for mistake in MISTAKES if mistake.name == name).functions[
        next(iter(next(mistake for mistake in MISTAKES if mistake.name == name).functions))
    ]


@dataclass(frozen=True)
class Pattern:
    """One pattern a rule must judge right: honest (must pass) or targeted (must fail with `words`)."""

    rule: str
    name: str
    problem: ProblemId
    function: StudentFunction
    honest: bool
    words: str = ""


PATTERNS = [
    Pattern(
        "selection", "cartpole double reset", "cartpole", _double_reset("CartPole-v0", velocity_policy), True
    ),
    Pattern("selection", "car double reset", "car", _double_reset("MountainCar-v0", car_policy), True),
    Pattern("selection", "random_blackjack double reset", "random_blackjack", _blackjack_double_reset, True),
    Pattern(
        "selection", "cartpole reset after make", "cartpole", _behaviour("cartpole_reset_after_make"), True
    ),
    Pattern(
        "selection",
        "random_blackjack reset at loop end",
        "random_blackjack",
        _behaviour("random_blackjack_reset_at_loop_end"),
        True,
    ),
    Pattern(
        "selection",
        "car scouting (start left of -0.55, blind tape)",
        "car",
        _behaviour("car_scouting"),
        False,
        "not a fair sample",
    ),
    Pattern(
        "selection",
        "car scouting (start left of -0.5, velocity policy)",
        "car",
        _scout("MountainCar-v0", car_policy, lambda observation: observation[0] <= -0.5),
        False,
        "not a fair sample",
    ),
    Pattern(
        "selection",
        "car best of 6 envs",
        "car",
        _best_of_envs("MountainCar-v0", car_policy, lambda observation: observation[0]),
        False,
        "not a fair sample",
    ),
    Pattern(
        "selection",
        "cartpole scouting (|angle| < 0.01)",
        "cartpole",
        _scout("CartPole-v0", velocity_policy, lambda observation: abs(observation[2]) <= 0.01),
        False,
        "not a fair sample",
    ),
    Pattern(
        "selection",
        "cartpole best of 6 envs (smallest |angle|)",
        "cartpole",
        _best_of_envs("CartPole-v0", velocity_policy, lambda observation: abs(observation[2])),
        False,
        "not a fair sample",
    ),
    Pattern(
        "post-terminal", "cartpole 200-step loop", "cartpole", _behaviour("cartpole_step_after_done"), True
    ),
    Pattern(
        "post-terminal",
        "blackjack stick after bust",
        "blackjack",
        _behaviour("blackjack_sticks_after_bust"),
        True,
    ),
    Pattern(
        "post-terminal",
        "random_blackjack coin hits after bust",
        "random_blackjack",
        _behaviour("random_blackjack_coin_hits_after_bust"),
        True,
    ),
    Pattern(
        "post-terminal",
        "cartpole counts the steps after the end",
        "cartpole",
        _behaviour("cartpole_counts_steps_after_done"),
        False,
        "kept stepping after the game was over and counted those",
    ),
    Pattern(
        "post-terminal",
        "blackjack sticks first, threshold on the finished game",
        "blackjack",
        _behaviour("blackjack_sticks_first"),
        False,
        "draw while the sum is <=",
    ),
]


def _settings(problem: ProblemId) -> ProblemConfig:
    return load_config().problems[problem].model_copy(update=SIZES[problem])


def _sized(function: StudentFunction, settings: ProblemConfig) -> StudentFunction:
    games = getattr(settings, "games_per_call", None)
    if games is None or "games" not in function.__code__.co_varnames:
        return function
    return lambda lab, n: function(lab, n, games)  # type: ignore[call-arg]


def regrade(pattern: Pattern, seed: int) -> tuple[bool, float]:
    """(whether the verdict is the right one, the smallest selection-test p-value, 1.0 when none ran)."""
    settings = _settings(pattern.problem)
    functions = {pattern.problem: _sized(pattern.function, settings)}
    check = PROBLEMS.problem(pattern.problem).check
    calls = check.plan(settings, function_infos(functions), 0)
    records = simulate_calls(calls, functions, seed)
    verdict = check.judge(settings, records)
    tests = selection_tests(records)
    smallest = min((test.p_value for test in tests), default=1.0)
    if pattern.honest:
        return verdict.status == "passed", smallest
    return verdict.status == "failed" and pattern.words in verdict.feedback, smallest


NULL_SIZES: dict[str, tuple[str, dict[str, Any], int, int]] = {
    "cartpole": ("CartPole-v0", {}, 100, 1),
    "car": ("MountainCar-v0", {}, 100, 1),
    "random_blackjack": ("Blackjack-v1", {"natural": False, "sab": False}, 1, 2_000),
    "blackjack (sab)": ("Blackjack-v1", {}, 1, 2_000),
    "taxi": ("Taxi-v4", {}, 1, 2_000),
}
"""Game, arguments, calls and games per call: cartpole and car as graded (100 calls); Blackjack and Taxi
with 2,000 games instead of 10,000 to fit 200 regrades (Hoeffding's bound holds for any number of groups)."""


def null_regrade(env_id: str, env_kwargs: dict[str, Any], calls: int, games: int, seed: int) -> float:
    """The smallest selection p-value of one honest double-reset grading (every game: two resets, the second
    played), from the grader's reset stream of fresh call seeds; only the starts are dealt, not played."""
    env = gymnasium.make(env_id, **env_kwargs)
    records = []
    for call in range(calls):
        seeds = reset_seeds(int(np.random.SeedSequence((seed, call)).generate_state(1)[0]), 2 * games)
        logs, replays = [], []
        for number, reset_seed in enumerate(seeds):
            observation, _ = env.reset(seed=reset_seed)
            played = [0] if number % 2 else []
            logs.append(
                SimpleNamespace(actions=played, env_id=env_id, env_kwargs=env_kwargs, reset_seed=reset_seed)
            )
            replays.append(SimpleNamespace(observations=[observation]))
        records.append(SimpleNamespace(outcome=SimpleNamespace(episodes=logs), replays=replays))
    tests = selection_tests(records)  # type: ignore[arg-type]
    return min(test.p_value / test.threshold for test in tests)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--regrades", type=int, default=200, help="regrades of each honest pattern")
    parser.add_argument("--catch-regrades", type=int, default=50, help="regrades of each targeted pattern")
    parser.add_argument("--only", nargs="*", default=None, help="patterns whose name contains one of these")
    parser.add_argument("--null-regrades", type=int, default=200, help="null regrades of the selection rule")
    parser.add_argument("--first-seed", type=int, default=19_000_000)
    arguments = parser.parse_args()
    print("Selection rule alone on honest double resets (starts dealt, the second of each pair played):")
    print("| problem | calls x games | regrades | failed | smallest p / threshold | seconds |")
    print("|---|---|---|---|---|---|")
    for name, (env_id, env_kwargs, calls, games) in NULL_SIZES.items():
        chosen = not arguments.only or any(word in name for word in arguments.only)
        if not arguments.null_regrades or not chosen:
            continue
        started = time.perf_counter()
        ratios = [
            null_regrade(env_id, env_kwargs, calls, games, arguments.first_seed + number)
            for number in range(arguments.null_regrades)
        ]
        failed = sum(ratio <= 1.0 for ratio in ratios)
        print(
            f"| {name} | {calls} x {games} | {len(ratios)} | {failed} | {min(ratios):.3g} | {time.perf_counter() - started:.0f} |"  # noqa: E501
        )
        sys.stdout.flush()
    print()
    print(
        f"{arguments.regrades} regrades per honest pattern, {arguments.catch_regrades} per targeted one, "
        f"seeds {arguments.first_seed}..; selection alpha {SELECTION_ALPHA:g}"
    )
    print(
        "| rule | pattern | kind | right verdicts | wrong | rate (95% upper bound when 0) "
        "| smallest selection p | seconds |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for pattern in PATTERNS:
        if arguments.only and not any(word in pattern.name for word in arguments.only):
            continue
        started = time.perf_counter()
        count = arguments.regrades if pattern.honest else arguments.catch_regrades
        results = [regrade(pattern, arguments.first_seed + number) for number in range(count)]
        right = sum(ok for ok, _ in results)
        wrong = count - right
        smallest = min(p for _, p in results)
        kind = "honest: false-fail" if pattern.honest else "targeted: catch"
        rate = wrong / count if pattern.honest else right / count
        zero_bound = 1 - math.exp(math.log(0.05) / count)
        shown = f"{rate:.3f}" + (f" (< {zero_bound:.3f})" if pattern.honest and wrong == 0 else "")
        print(
            f"| {pattern.rule} | {pattern.name} | {kind} | {right} | {wrong} | {shown} | {smallest:.2g} | {time.perf_counter() - started:.0f} |"  # noqa: E501
        )
        sys.stdout.flush()


if __name__ == "__main__":
    main()
