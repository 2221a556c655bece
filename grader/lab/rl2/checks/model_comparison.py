"""The 2024 edition's `model_comparison(episodes=1000)` -> (avg_Q_reward, avg_val_iter_reward, statement).

The grader calls it once with `episodes` (100 by default). It trains a Q-table through the course's helper
`model_free_RL.run_qlearn` (provided by the grader, `grader/compat/model_free.py`; its 70 000 training
episodes are the helper's own, not recorded; about 80 s: `call_seconds` allows for more), saved as
`q_table.npy` in the grading's own working directory, plays `episodes` episodes greedily on it
(`run_simulation_table`) and `episodes` with value iteration's policy on slippery 8x8 FrozenLake.

Judged, exactly: the played episodes (recorded, replayed, the first lab's integrity rules) are 2 x episodes
on the slippery 8x8 lake; the first `episodes` are the Q-table's, and `avg_Q_reward` must be their replayed
mean; the next are value iteration's: every action greedy on the exact optimal values (ties allowed, one
action per state) and `avg_val_iter_reward` their replayed mean. Each mean is read either way the lab's
gyms allow (up to gym.make's time limit, or each episode to its end past it). The statement is free text:
a non-empty str, never graded on its content. The Q-table's quality is not judged (training is the helper's
and a short run learns a poor table; the lab asks for the comparison, not a score).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, judged_when_all_returned, paused_gc
from grader.lab.checks.integrity import Episode, games_budget, integrity_problem, played_episodes
from grader.lab.checks.values import as_number, describe
from grader.lab.games import FROZEN_LAKE_8X8
from grader.lab.rl2.checks.frozen_lake import LAKE_STEPS, whole_mean
from grader.lab.settings import PlayedProblemConfig
from grader.sandbox.outcome import Call, FunctionInfo, PlainValue
from reference.oracles.mdp import judge_policy, optimal_solution, q_values
from reference.oracles.mdps import frozen_lake as lake_mdp

FUNCTION = "model_comparison"


class ModelComparisonConfig(PlayedProblemConfig):
    """The settings of `model_comparison(episodes)` (edition v2024)."""

    episodes: int = Field(
        default=100,
        ge=10,
        le=10_000,
        description="episodes passed: each policy plays that many; both means are checked exactly against their replayed episodes.",  # noqa: E501
    )


@dataclass(frozen=True)
class ModelComparisonCheck:
    """model_comparison: both means the replayed ones, value iteration's play greedy on the exact values."""

    def plan(
        self, settings: ModelComparisonConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """One call; the budget covers 2 x episodes games (the helper's training is not recorded)."""
        budget = games_budget(2 * settings.episodes, LAKE_STEPS * 10)
        return [Call(FUNCTION, (settings.episodes,), budget=budget)]

    @paused_gc
    @judged_when_all_returned
    def judge(self, settings: ModelComparisonConfig, records: Sequence[CallRecord]) -> Verdict:
        """The returned triple against the replayed episodes."""
        value = records[0].outcome.value
        call = f"model_comparison({settings.episodes})"
        if not isinstance(value, list | tuple) or len(value) != 3:
            return _fail(
                f"{call} returned {describe(value)}; expected (avg_Q_reward, avg_val_iter_reward, statement)."
            )
        q_mean, vi_mean, statement = as_number(value[0]), as_number(value[1]), value[2]
        if q_mean is None or vi_mean is None:
            return _fail(f"{call} returned {describe(value)}; the two average rewards must be numbers.")
        if not isinstance(statement, str) or not statement.strip():
            return _fail(
                f"{call}: the statement is {describe(statement)}; return a sentence or two (a non-empty str) comparing the two methods. Its content is not graded."  # noqa: E501
            )
        episodes = played_episodes(records)
        problem = integrity_problem(records, episodes, settings.game_rules())
        if problem:
            return _fail(f"{call}: {problem}.")
        wrong = next((e for e in episodes if FROZEN_LAKE_8X8.mismatch(e.log) is not None), None)
        if wrong is not None:
            return _fail(
                f"{call}: an episode was played in {wrong.log.requested_id!r} with {wrong.log.env_kwargs}; the comparison is on the slippery 8x8 lake (gym.make('FrozenLake-v1', map_name='8x8', is_slippery=True))."  # noqa: E501
            )
        n = settings.episodes
        if len(episodes) != 2 * n:
            return _fail(
                f"{call}: you played {len(episodes)} episodes; episodes={n} asks for {n} with the Q-table (run_simulation_table), then {n} with value iteration's policy."  # noqa: E501
            )
        measurements: dict[str, PlainValue] = {}
        groups = (episodes[:n], episodes[n:])
        named = (("avg_Q_reward", groups[0], q_mean), ("avg_val_iter_reward", groups[1], vi_mean))
        for name, group, mean in named:
            reading = _reading(group, mean)
            measurements[f"{name}_replayed"] = math.fsum(e.total_reward for e in group) / n
            if reading is None:
                return _fail(
                    f"{call}: you returned {mean:.6g} as {name}, but the {n} episodes played for it average {measurements[f'{name}_replayed']:.6g} (replayed). "  # noqa: E501
                    "Return the mean of the returns of exactly the episodes played with that policy, the Q-table's first.",  # noqa: E501
                    measurements,
                )
            measurements[f"{name}_reading"] = reading
        off = _not_optimal(groups[1])
        if off:
            return _fail(f"{call}: {off}", measurements)
        return Verdict(
            "passed",
            1.0,
            f"model_comparison: {n} episodes with the Q-table and {n} with value iteration's policy (every action optimal), both means the replayed ones ({q_mean:.3f} and {vi_mean:.3f}); the statement is not graded.",  # noqa: E501
            measurements,
        )


def _reading(episodes: Sequence[Episode], mean: float) -> str | None:
    cut = math.fsum(episode.total_reward for episode in episodes) / len(episodes)
    whole = whole_mean(episodes)
    for reading, value in (("up to the time limit", cut), ("to the end, past the time limit", whole)):
        if value is not None and abs(mean - value) <= 1e-9 * max(1.0, abs(value)):
            return reading
    return None


def _not_optimal(episodes: Sequence[Episode]) -> str | None:
    """Why value iteration's episodes were not played with one optimal policy, or None.

    Every action must be greedy on the exact optimal values, one per state, and the policy they make (the
    states no episode visited given optimal actions) must be optimal by its exact value: at discount 1 a
    greedy tie may circle forever (always left in the start state).
    """
    mdp = lake_mdp("8x8", slippery=True)
    look_ahead = q_values(mdp, optimal_solution(mdp, 1.0).values, 1.0)
    best = look_ahead.max(axis=1)
    chosen: dict[int, int] = {}
    for episode in episodes:
        for state, action in episode.decisions():
            state, action = int(state), int(action)
            if chosen.setdefault(state, action) != action:
                return f"value iteration's episodes took actions {chosen[state]} and {action} in state {state}: play one policy (one action per state)."  # noqa: E501
            if look_ahead[state, action] < best[state] - 1e-9 * (1 + abs(best[state])):
                return f"value iteration's episodes took action {action} in state {state}, which is not optimal there (its look-ahead on the exact optimal values is {look_ahead[state, action]:.6g}, the best {best[state]:.6g}): play the greedy policy of value iteration's values."  # noqa: E501
    completed = optimal_solution(mdp, 1.0).policy.copy()
    for state, action in chosen.items():
        completed[state] = action
    judged = judge_policy(mdp, completed, 1.0)
    if not judged.optimal:
        return (
            f"value iteration's episodes played actions that tie with the best on the optimal values but never reach the goal from some states (the start's value under them is {judged.values[0]:.4g}, the optimum {judged.optimal_values[0]:.4g}; the unvisited states given optimal actions): "  # noqa: E501
            "at discount 1 a greedy tie can walk in circles; play the policy value iteration's values give with the lab's first argmax."  # noqa: E501
        )
    return None


def _fail(feedback: str, measurements: dict[str, PlainValue] | None = None) -> Verdict:
    return Verdict("failed", 0.0, feedback, measurements or {})
