"""Shared judging of one-episode-per-call problems whose functions return the episode's length."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from grader.lab.checks.base import CallRecord, Verdict, outcome_verdict
from grader.lab.checks.integrity import (
    Episode,
    episodes_per_call,
    games_budget,
    played_episodes,
    played_games_problem,
)
from grader.lab.checks.values import as_number, describe, same_number, step_count_mismatch_cause
from grader.lab.games import Game, GameRules
from grader.sandbox.outcome import Call

if TYPE_CHECKING:
    from grader.sandbox.outcome import PlainValue

MAX_UNCOUNTED_STEPS = 3
"""Most steps before the counted loop that still read as the lab-era counting slip (one, in the lab)."""


def one_game_calls(function: str, calls: int, episode_steps: int) -> list[Call]:
    """`calls` calls of `function()`, each budgeted for one game of up to `episode_steps` recorded steps."""
    budget = games_budget(1, episode_steps)
    return [Call(function, budget=budget) for _ in range(calls)]


@dataclass(frozen=True)
class LengthRuns:
    """The replayed episodes of all calls, one per call, whose lengths the calls returned.

    Attributes:
        episodes: One episode per call, in call order.
        lengths: Their replayed lengths.
        game: The game they were played in.
        uncounted_steps: 0 when every call returned its episode's length; k > 0 when every call returned
            k steps fewer (steps taken before the counted loop, such as "one random step first").
    """

    episodes: list[Episode]
    lengths: list[int]
    game: Game
    uncounted_steps: int = 0

    @property
    def mean(self) -> float:
        """Mean episode length."""
        return sum(self.lengths) / len(self.lengths)

    def measurements(self) -> dict[str, PlainValue]:
        """Summary numbers for the report."""
        return {
            "calls": len(self.lengths),
            "mean_steps": self.mean,
            "min_steps": min(self.lengths),
            "max_steps": max(self.lengths),
            "lengths": list(self.lengths),
            "game": self.game.name,
            "uncounted_steps": self.uncounted_steps,
        }

    def passing_fraction(self, deduction: float) -> float:
        """The share of the points a passing verdict earns: all, less `deduction` on a counting slip."""
        return 1.0 - (deduction if self.uncounted_steps else 0.0)

    def counting_note(self, function: str, deduction: float) -> str:
        """The feedback sentence on a counting slip ("" when every count was right)."""
        if not self.uncounted_steps:
            return ""
        if self.uncounted_steps == 1:
            short, uncounted = (
                "one step",
                "the step taken before the counted loop (e.g. a random step after reset) was",
            )
        else:
            short = f"{self.uncounted_steps} steps"
            uncounted = f"the {short} taken before the counted loop were"
        cost = f" ({deduction:.0%} of the points deducted)" if deduction else ""
        return (
            f" Note: every count {function}() returned is {short} short of its replayed episode: "
            f"{uncounted} not counted. "
            f"The verdict follows the replayed episodes{cost}; count every env.step() call."
        )


def judge_lengths(function: str, rules: GameRules, records: Sequence[CallRecord]) -> Verdict | LengthRuns:
    """Check that every call played one real, complete episode and returned its length.

    A call returning its length minus k, for the same 1 <= k <= `MAX_UNCOUNTED_STEPS` in every call,
    is the lab-era "steps before the counted loop" slip: the runs are returned with `uncounted_steps = k`
    and judged by their replayed lengths. Any other difference fails.

    Args:
        function: The student function's name (for feedback).
        rules: The environments the episodes may be played in.
        records: One record per call.

    Returns:
        A failing verdict naming the first problem, or the runs to apply the problem's bar to.
    """
    early = outcome_verdict(records)
    if early is not None:
        return early
    episodes = played_episodes(records)
    problem = played_games_problem(records, episodes, rules, across_calls=True)
    if problem:
        return Verdict("failed", 0.0, f"{function}(): {problem}.", {})
    game = rules.played_game(episode.log for episode in episodes)
    if isinstance(game, str):
        return Verdict("failed", 0.0, f"{function}(): {game}.", {})
    chosen: list[Episode] = []
    shortfalls: list[float | None] = []
    for call_number, (record, call_episodes) in enumerate(
        zip(records, episodes_per_call(records, episodes), strict=True), 1
    ):
        if len(call_episodes) != 1:
            return Verdict(
                "failed",
                0.0,
                f"each call of {function}() must play exactly one episode and return its length; "
                f"call {call_number} played {len(call_episodes)}. Reset once per call and play until done.",
                {},
            )
        returned = as_number(record.outcome.value)
        episode = call_episodes[0]
        chosen.append(episode)
        shortfalls.append(None if returned is None else episode.length - returned)
    uncounted = _uncounted_steps(shortfalls, [episode.length for episode in chosen])
    if uncounted is not None:
        return LengthRuns(chosen, [episode.length for episode in chosen], game, uncounted)
    for call_number, (record, episode) in enumerate(zip(records, chosen, strict=True), 1):
        returned = as_number(record.outcome.value)
        if returned is None or not same_number(returned, float(episode.length)):
            after_done = episode.replay.steps_after_done
            if returned is None:
                cause = "expected a number"
            elif after_done and same_number(returned, float(episode.length + after_done)):
                cause = (
                    f"the loop kept stepping after the game was over and counted those {after_done} steps. "
                    "Stop as soon as `done` (terminated or truncated) is True"
                )
            else:
                cause = step_count_mismatch_cause(returned, episode.length, record.outcome.wall_time)
            return Verdict(
                "failed",
                0.0,
                f"call {call_number} of {function}() returned {describe(record.outcome.value)}, but the episode it played lasted {episode.length} steps (replayed); "  # noqa: E501
                f"{cause}.",
                {"returned": returned, "replayed_steps": episode.length},
            )
    return LengthRuns(chosen, [episode.length for episode in chosen], game)


def _uncounted_steps(shortfalls: list[float | None], lengths: list[int]) -> int | None:
    """k when every call returned its length minus the same k (0 <= k <= MAX_UNCOUNTED_STEPS), else None."""
    if not shortfalls or any(shortfall is None for shortfall in shortfalls):
        return None
    first = shortfalls[0]
    if first is None or not float(first).is_integer() or not 0 <= first <= MAX_UNCOUNTED_STEPS:
        return None
    if any(shortfall != first for shortfall in shortfalls) or any(length <= first for length in lengths):
        return None
    return int(first)
