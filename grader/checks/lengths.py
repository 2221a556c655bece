"""Shared judging of one-episode-per-call problems whose functions return the episode's length."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from grader.checks.base import CallRecord, Verdict, outcome_verdict
from grader.checks.episodes import (
    Episode,
    GameRules,
    all_resets,
    episodes_per_call,
    integrity_problem,
    played_episodes,
    repeated_seed_problem,
)
from grader.checks.values import as_number, describe, same_number, step_count_mismatch_cause

if TYPE_CHECKING:
    from grader.sandbox.outcome import PlainValue


@dataclass(frozen=True)
class LengthRuns:
    """The replayed episodes of all calls, one per call, whose lengths the calls returned.

    Attributes:
        episodes: One episode per call, in call order.
        lengths: Their replayed lengths.
    """

    episodes: list[Episode]
    lengths: list[int]

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
        }


def judge_lengths(function: str, rules: GameRules, records: Sequence[CallRecord]) -> Verdict | LengthRuns:
    """Check that every call played one real, complete episode and returned its length.

    Args:
        function: The student function's name (for feedback).
        rules: The environment the episodes must be played in.
        records: One record per call.

    Returns:
        A failing verdict naming the first problem, or the runs to apply the problem's bar to.
    """
    early = outcome_verdict(records)
    if early is not None:
        return early
    episodes = played_episodes(records)
    problem = integrity_problem(records, episodes, rules) or repeated_seed_problem(
        all_resets(records), across_calls=True
    )
    if problem:
        return Verdict("failed", 0.0, f"{function}(): {problem}.", {})
    chosen: list[Episode] = []
    for call_number, (record, call_episodes) in enumerate(
        zip(records, episodes_per_call(records, episodes), strict=True), 1
    ):
        if len(call_episodes) != 1:
            return Verdict(
                "failed",
                0.0,
                f"each call of {function}() must play exactly one episode and return its length; call "
                f"{call_number} played {len(call_episodes)}. Reset once per call and play until done.",
                {},
            )
        returned = as_number(record.outcome.value)
        episode = call_episodes[0]
        if returned is None or not same_number(returned, float(episode.length)):
            cause = (
                "expected a number"
                if returned is None
                else step_count_mismatch_cause(returned, episode.length, record.outcome.wall_time)
            )
            return Verdict(
                "failed",
                0.0,
                f"call {call_number} of {function}() returned {describe(record.outcome.value)}, but the "
                "episode it "
                f"played lasted {episode.length} steps (replayed); {cause}.",
                {"returned": returned, "replayed_steps": episode.length},
            )
        chosen.append(episode)
    return LengthRuns(chosen, [episode.length for episode in chosen])
