"""Edition rl1, problem 6: `taxi(q_table, q_table_decay)` plays greedy Taxi episodes with two given tables.

The grader passes two tables of its own whose greedy returns are known exactly and differ clearly: the
detour table (`reference.oracles.taxi.detour_q_table`, 5.757 per episode) as `q_table` and the optimal one
(7.930) as `q_table_decay`, both without ties, so any greedy rule plays the same policy and every episode
ends. The returned pair must be the replayed means of the two tables' episodes, every action the argmax of
its table's row, and each mean within its z-test tolerance of the exact expectation.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np
import numpy.typing as npt
from pydantic import Field

from grader.lab.checks.base import CallRecord, Verdict, judged_when_all_returned, paused_gc
from grader.lab.checks.integrity import Episode, games_budget, integrity_problem, played_episodes
from grader.lab.checks.taxi import EPISODE_STEPS, split_scenarios
from grader.lab.checks.values import as_number, describe
from grader.lab.settings import PlayedProblemConfig, Probability
from grader.lab.stats import mean_tolerance
from grader.sandbox.outcome import Call, FunctionInfo, PlainValue
from reference.oracles import greedy_policy_return, optimal_q_table
from reference.oracles.taxi import ACTIONS, detour_q_table


class TaxiTablesConfig(PlayedProblemConfig):
    """The settings of `taxi(q_table, q_table_decay)` (edition rl1)."""

    gamma: float = Field(default=0.6, gt=0.0, lt=1.0, description="Discount of the grader's two tables.")
    episodes_per_table: int = Field(
        default=1000, ge=1, description="Greedy episodes each table must play (the lab's 1 000)."
    )
    mean_alpha: Probability = Field(
        default=1e-6,
        description="False-fail probability of EACH two-sided z-test of a replayed mean against its exact expectation.",  # noqa: E501
    )


@cache
def grader_tables(gamma: float) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """(q_table, q_table_decay) the grader passes: the detour table and the optimal one, both tie-free."""
    return detour_q_table(gamma), optimal_q_table(gamma) - 1e-6 * np.arange(ACTIONS)


@dataclass(frozen=True)
class TaxiTablesCheck:
    """taxi(detour table, optimal table): both tables' episodes replayed, greedy, near their exact means."""

    def plan(
        self, settings: TaxiTablesConfig, functions: Mapping[str, FunctionInfo], seed: int
    ) -> list[Call]:
        """One recorded call with the grader's two tables."""
        tables = grader_tables(settings.gamma)
        budget = games_budget(2 * settings.episodes_per_table, EPISODE_STEPS)
        return [Call("taxi", tables, budget=budget)]

    @paused_gc
    @judged_when_all_returned
    def judge(self, settings: TaxiTablesConfig, records: Sequence[CallRecord]) -> Verdict:
        """Judge the returned pair against the replayed episodes and the exact expectations."""
        value = records[0].outcome.value
        means = (
            [as_number(item) for item in value]
            if isinstance(value, list | tuple) and len(value) == 2
            else [None]
        )
        if None in means:
            return _fail(
                f"taxi(q_table, q_table_decay) returned {describe(value)}; expected two numbers (mean total reward with q_table, with q_table_decay)."  # noqa: E501
            )
        first, second = float(means[0]), float(means[1])  # type: ignore[arg-type]
        episodes = played_episodes(records)
        problem = integrity_problem(records, episodes, settings.game_rules())
        if problem:
            return _fail(f"taxi: {problem}.")
        tables = grader_tables(settings.gamma)
        exact = [greedy_policy_return(table) for table in tables]
        tests = [
            mean_tolerance(moments.mean, moments.variance, settings.episodes_per_table, settings.mean_alpha)
            for moments in exact
        ]
        measurements: dict[str, PlainValue] = {
            "returned_q_table_mean": first,
            "returned_q_table_decay_mean": second,
            "exact_q_table_mean": exact[0].mean,
            "exact_q_table_decay_mean": exact[1].mean,
            "episodes_replayed": len(episodes),
        }
        expected = (
            f"greedy play averages {exact[0].mean:.3f} ± {tests[0].half_width:.3f} with the q_table the grader passed "  # noqa: E501
            f"and {exact[1].mean:.3f} ± {tests[1].half_width:.3f} with its q_table_decay over {settings.episodes_per_table} episodes each"  # noqa: E501
        )
        if len(episodes) < 2 * settings.episodes_per_table:
            few = "a single episode per table" if len(episodes) <= 2 else f"{len(episodes)} episodes in all"
            return _fail(
                f"taxi: your call played {few}; the lab asks for {settings.episodes_per_table} greedy episodes with each table, and the means of their total rewards. {expected}.",  # noqa: E501
                measurements,
            )
        scenarios = split_scenarios(episodes, first, second)
        if scenarios is None:
            return _fail(
                f"taxi returned ({first:.6g}, {second:.6g}), which no split of your {len(episodes)} replayed episodes into the two tables' episodes supports: return the mean TOTAL reward of each table's episodes, q_table's first. {expected}.",  # noqa: E501
                measurements,
            )
        played = (scenarios.random, scenarios.greedy)
        swapped = all(
            _not_greedy(scenario, table) is None for scenario, table in zip(played[::-1], tables, strict=True)
        )
        for name, table, scenario in zip(("q_table", "q_table_decay"), tables, played, strict=True):
            wrong = _not_greedy(scenario, table)
            if wrong is not None and not swapped:
                return _fail(f"taxi: {wrong.format(table=name)}", measurements)
        swapped = swapped or (tests[0].accepts(second) and tests[1].accepts(first))
        if swapped and not (tests[0].accepts(first) and tests[1].accepts(second)):
            return _fail(
                f"taxi returned ({first:.3f}, {second:.3f}): the means are swapped; {expected}. Return (mean with q_table, mean with q_table_decay) in that order.",  # noqa: E501
                measurements,
            )
        if not (tests[0].accepts(first) and tests[1].accepts(second)):
            return _fail(
                f"taxi: {expected}; your replayed episodes averaged {first:.3f} and {second:.3f}, beyond the tolerance (false-fail probability {settings.mean_alpha:g} each). Play each table's episodes from env.reset() without a seed.",  # noqa: E501
                measurements,
            )
        return Verdict(
            "passed",
            1.0,
            f"taxi: every action was greedy on its table and your means {first:.3f} and {second:.3f} match the replayed episodes; {expected}.",  # noqa: E501
            measurements,
        )


def _not_greedy(episodes: Sequence[Episode], table: npt.NDArray[np.float64]) -> str | None:
    """What the first non-greedy action was (the table's name left to fill in), or None."""
    chosen = steps = 0
    first: str | None = None
    for episode in episodes:
        for step in range(episode.length):
            state, action = int(episode.replay.observations[step]), episode.log.actions[step]
            best = int(np.argmax(table[state]))
            steps += 1
            if int(action) != best:
                chosen += 1
                where = f"in an episode with {{table}} you chose action {action} in state {state}, but argmax({{table}}[{state}]) is {best}"  # noqa: E501
                first = first or where
    if first is None:
        return None
    if chosen > steps // 4:
        return f"{chosen} of your {steps} actions with {{table}} were not its row's argmax, as in random play ({first}): act with np.argmax({{table}}[state])."  # noqa: E501
    return f"{first}: act with np.argmax({{table}}[state]) on the table you were given."


def _fail(feedback: str, measurements: dict[str, PlainValue] | None = None) -> Verdict:
    return Verdict("failed", 0.0, feedback, measurements or {})
