"""Problem 5: `taxi()` / `taxi(q_table)` returns the mean total reward of random and Q-table episodes."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from itertools import chain
from typing import TYPE_CHECKING

import numpy as np
from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, judged_when_all_returned, paused_gc
from grader.lab.checks.integrity import (
    Episode,
    games_budget,
    noting_post_terminal_steps,
    played_episodes,
    played_games_problem,
    seed_problem,
)
from grader.lab.checks.truncation import ignored_truncation
from grader.lab.checks.values import as_number, describe, same_number
from grader.lab.settings import PlayedProblemConfig, Probability
from grader.lab.stats import goodness_of_fit, mean_tolerance
from grader.sandbox.limits import CallBudget
from grader.sandbox.outcome import Call, FunctionInfo
from reference.oracles import greedy_policy_return, optimal_q_table, optimal_return, random_policy_return

if TYPE_CHECKING:
    from grader.sandbox.outcome import PlainValue

ACTIONS = 6
EPISODE_STEPS = 250
"""Steps recorded per game: Taxi-v3 ends at 200; room for steps after the end to be diagnosed."""
TRAINING_EPISODES = 100_000
"""Episodes the lab's find_qvalues trains for, played inside a taxi() that trains its own table."""
TRAINING_STEPS = 4_000_000
"""Steps those training episodes may take (the lab's Q-learning took 1.59 million, measured: 2.5x room)."""
_POSITIONAL = frozenset({"POSITIONAL_ONLY", "POSITIONAL_OR_KEYWORD", "VAR_POSITIONAL"})


class TaxiConfig(PlayedProblemConfig):
    """The settings of `taxi()` or `taxi(q_table)`."""

    gamma: float = Field(
        gt=0.0,
        lt=1.0,
        description="Discount of the exact optimal Q-table passed when taxi takes a parameter.",
    )
    episodes_per_scenario: int = Field(
        ge=1, description="Episodes each scenario (random, Q-table) must play (the lab says 10000)."
    )
    mean_alpha: Probability = Field(
        description="False-fail probability of EACH two-sided z-test of a returned mean against its exact expectation (variance from the exact oracle)."  # noqa: E501
    )
    action_alpha: Probability = Field(
        description="False-fail probability of the chi-square test that the random scenario's actions are uniform over the 6 actions."  # noqa: E501
    )
    trained_slack: float = Field(
        ge=0.0,
        description="When taxi() trains its own table, its Q mean may fall this far below the optimal greedy return (on top of the z-test tolerance).",  # noqa: E501
    )


def takes_q_table(functions: Mapping[str, FunctionInfo]) -> bool:
    """Whether the submission's `taxi` takes a positional argument (the template's `taxi(q_table)`)."""
    info = functions.get("taxi")
    return info is not None and info.is_callable and any(p.kind in _POSITIONAL for p in info.parameters)


@dataclass(frozen=True)
class Scenarios:
    """The replayed episodes split into the random scenario and the Q-table scenario."""

    random: list[Episode]
    greedy: list[Episode]


def _mean(values: Sequence[float]) -> float:
    return math.fsum(values) / len(values) if values else math.nan


def split_scenarios(episodes: Sequence[Episode], random_mean: float, greedy_mean: float) -> Scenarios | None:
    """The random and Q-table episodes: the split (in play order, or alternating) with the returned means."""
    totals = [episode.replay.total_reward for episode in episodes]
    prefix = [0.0]
    for total in totals:
        prefix.append(prefix[-1] + total)
    count = len(totals)
    for first_is_random in (True, False):
        first_mean, second_mean = (
            (random_mean, greedy_mean) if first_is_random else (greedy_mean, random_mean)
        )
        for k in sorted(range(1, count), key=lambda k: abs(2 * k - count)):
            if same_number(first_mean, prefix[k] / k) and same_number(
                second_mean, (prefix[count] - prefix[k]) / (count - k)
            ):
                first, second = list(episodes[:k]), list(episodes[k:])
                return Scenarios(first, second) if first_is_random else Scenarios(second, first)
        evens, odds = list(episodes[0::2]), list(episodes[1::2])
        if (
            evens
            and odds
            and same_number(first_mean, _mean([e.replay.total_reward for e in evens]))
            and same_number(second_mean, _mean([e.replay.total_reward for e in odds]))
        ):
            return Scenarios(evens, odds) if first_is_random else Scenarios(odds, evens)
    return None


def _mismatch_cause(episodes: Sequence[Episode], random_mean: float, greedy_mean: float) -> str:
    half = len(episodes) // 2
    halves = (episodes[:half], episodes[half:])
    finals = [_mean([episode.final_reward for episode in part]) for part in halves]
    if any(same_number(returned, final) for returned in (random_mean, greedy_mean) for final in finals):
        return (
            "a returned mean equals the average of the episodes' LAST reward: "
            "add up every step's reward of an episode (total reward), not just the final one"
        )
    totals = [_mean([episode.replay.total_reward for episode in part]) for part in halves]
    return (
        f"the first and second half of your {len(episodes)} replayed episodes average {totals[0]:.3f} and {totals[1]:.3f} in total reward: "  # noqa: E501
        "return (mean total reward of the random episodes, mean total reward of the Q-table episodes)"
    )


@dataclass(frozen=True)
class TaxiCheck:
    """taxi: both scenarios backed by replay, each mean near its exact expectation, Q beats random."""

    def plan(self, settings: TaxiConfig, functions: Mapping[str, FunctionInfo], seed: int) -> list[Call]:
        """taxi(optimal Q-table) when taxi takes a parameter, else taxi()."""
        games = 2 * settings.episodes_per_scenario
        evaluation = games_budget(games, EPISODE_STEPS)
        if takes_q_table(functions):
            return [Call("taxi", (optimal_q_table(settings.gamma),), budget=evaluation)]
        budget = CallBudget(
            evaluation.max_episodes + 2 * TRAINING_EPISODES, evaluation.max_steps + TRAINING_STEPS
        )
        return [Call("taxi", budget=budget)]

    @noting_post_terminal_steps
    @paused_gc
    @judged_when_all_returned
    def judge(self, settings: TaxiConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge the returned means against the replayed scenarios and the exact expectations."""
        outcome = records[0].outcome
        value = outcome.value
        means = [as_number(item) for item in value] if isinstance(value, list) and len(value) == 2 else [None]
        if None in means:
            return _fail(
                f"taxi returned {describe(value)}; expected two numbers (random mean, Q-table mean)."
            )
        random_mean, greedy_mean = float(means[0]), float(means[1])  # type: ignore[arg-type]
        episodes = played_episodes(records)
        problem = played_games_problem(records, episodes, settings.game_rules(), across_calls=False)
        if problem:
            # An altered log is named as such; otherwise a loop that ignored `truncated` is named as that.
            diagnosis = None if seed_problem(records) else ignored_truncation(episodes)
            return _fail(f"taxi: {diagnosis or problem}.")
        measurements: dict[str, PlainValue] = {
            "returned_random_mean": random_mean,
            "returned_q_mean": greedy_mean,
            "episodes_replayed": len(episodes),
        }
        scenarios = split_scenarios(episodes, random_mean, greedy_mean)
        played = 2 * settings.episodes_per_scenario
        if scenarios is None and len(episodes) > played:
            # taxi() that trains its own table plays the training episodes first.
            scenarios = split_scenarios(episodes[-played:], random_mean, greedy_mean)
        if scenarios is None:
            # Steps after a time limit ended the episode count in the returned means, not in the replay.
            cause = ignored_truncation(episodes) or _mismatch_cause(episodes, random_mean, greedy_mean)
            return _fail(
                f"taxi returned ({random_mean:.6g}, {greedy_mean:.6g}), which no split of the replayed episodes supports; "  # noqa: E501
                f"{cause}.",
                measurements,
            )
        for name, scenario in (("random", scenarios.random), ("Q-table", scenarios.greedy)):
            if len(scenario) != settings.episodes_per_scenario:
                return _fail(
                    f"taxi must run each scenario {settings.episodes_per_scenario} times (the lab's number); "
                    f"the replay shows {len(scenario)} {name} episodes.",
                    measurements,
                )
        q_table = outcome.call.args[0] if outcome.call.args else None
        failure = _action_problem(scenarios, q_table, settings, measurements)
        if failure:
            return _fail(f"taxi: {failure}", measurements)
        return _judge_means(settings, random_mean, greedy_mean, q_table, measurements)


def _action_problem(
    scenarios: Scenarios, q_table: object, settings: TaxiConfig, measurements: dict[str, PlainValue]
) -> str | None:
    counts = _action_counts(scenarios.random)
    uniform = goodness_of_fit(counts, [1 / ACTIONS] * ACTIONS)
    measurements |= {"random_action_counts": counts, "random_action_p_value": uniform.p_value}
    if uniform.p_value < settings.action_alpha:
        shares = ", ".join(f"{count / sum(counts):.3f}" for count in counts)
        return (
            f"random actions are uniform over the 6 actions, but your random episodes chose them with shares {shares} (chi-square p = {uniform.p_value:.1e}). "  # noqa: E501
            "Use env.action_space.sample()."
        )
    chosen: dict[int, int] = {}
    # The table's greedy action of every state, computed once (np.argmax per row: the first largest value).
    best_actions = (
        np.argmax(q_table, axis=1).tolist() if isinstance(q_table, np.ndarray) and q_table.ndim == 2 else None
    )
    for episode in scenarios.greedy:
        for state, action in episode.decisions():
            state, action = int(state), int(action)
            if isinstance(q_table, np.ndarray):
                best = best_actions[state] if best_actions is not None else int(np.argmax(q_table[state]))
                if action != best:
                    return (
                        f"in a Q-table episode you chose action {action} in state {state}, but argmax(q_table[{state}]) is {best}: "  # noqa: E501
                        "act with np.argmax(q_table[state]) on the table you were given."
                    )
            elif chosen.setdefault(state, action) != action:
                return (
                    f"your Q-table episodes chose actions {chosen[state]} and {action} in the same state {state}: "  # noqa: E501
                    "acting greedily on one table always picks np.argmax(q_table[state])."
                )
    return None


def _action_counts(episodes: Sequence[Episode]) -> list[int]:
    """How often each action was taken, tallied by value first (the random episodes take 2 million)."""
    tally = Counter(chain.from_iterable(episode.actions for episode in episodes))
    counts = [0] * ACTIONS
    for action, count in tally.items():
        counts[int(action)] += count
    return counts


def _judge_means(
    settings: TaxiConfig,
    random_mean: float,
    greedy_mean: float,
    q_table: object,
    measurements: dict[str, PlainValue],
) -> Verdict:
    episodes = settings.episodes_per_scenario
    random_exact = random_policy_return()
    random_test = mean_tolerance(random_exact.mean, random_exact.variance, episodes, settings.mean_alpha)
    given = isinstance(q_table, np.ndarray)
    greedy_exact = greedy_policy_return(q_table) if given else optimal_return()  # type: ignore[arg-type]
    greedy_test = mean_tolerance(greedy_exact.mean, greedy_exact.variance, episodes, settings.mean_alpha)
    measurements |= {
        "q_table": f"the exact optimal table for gamma={settings.gamma}"
        if given
        else "trained by taxi() itself",
        "exact_random_mean": random_exact.mean,
        "random_tolerance": random_test.half_width,
        "exact_q_mean": greedy_exact.mean,
        "q_tolerance": greedy_test.half_width,
    }
    expected_random = f"random actions average {random_exact.mean:.2f} ± {random_test.half_width:.2f}"
    if not random_test.accepts(random_mean):
        return _fail(
            f"taxi: {expected_random} over {episodes} episodes; "
            f"yours averaged {random_mean:.2f} (replayed). "
            "The episodes are real, so this is a near-impossible chance or not the lab's game: regrade once.",
            measurements,
        )
    if given:
        expected_greedy = f"the optimal table averages {greedy_exact.mean:.3f} ± {greedy_test.half_width:.3f}"
        greedy_ok = greedy_test.accepts(greedy_mean)
    else:
        floor = greedy_exact.mean - greedy_test.half_width - settings.trained_slack
        expected_greedy = (
            f"a well-trained table averages at least {floor:.3f} (optimal {greedy_exact.mean:.3f})"
        )
        greedy_ok = greedy_mean >= floor
    if not greedy_ok or greedy_mean <= random_mean:
        return _fail(
            f"taxi: {expected_greedy} and beats random actions; "
            f"your Q-table episodes averaged {greedy_mean:.3f} (replayed). "
            "Train with find_qvalues as the lab does, then act with np.argmax(q_table[state]).",
            measurements,
        )
    return Verdict(
        "passed",
        1.0,
        f"taxi returned ({random_mean:.2f}, {greedy_mean:.3f}), both backed by {2 * episodes} replayed episodes: "  # noqa: E501
        f"{expected_random}, and {expected_greedy}.",
        measurements,
    )


def _fail(feedback: str, measurements: dict[str, PlainValue] | None = None) -> Verdict:
    return Verdict("failed", 0.0, feedback, measurements or {})
