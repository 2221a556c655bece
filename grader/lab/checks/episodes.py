"""Trusted views of the episodes a call played: the student's actions with the grader's own replay."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from grader.lab.checks.base import CallRecord

if TYPE_CHECKING:
    from grader.sandbox.episode_log import EpisodeLog
    from grader.sandbox.replay import Replay


@dataclass(slots=True)
class Episode:
    """One played episode: the student's actions with the outcome the grader's own replay produced.

    Attributes:
        call_index: Index of the call (in planned order) that played it.
        position: Index of the episode among the call's played episodes.
        log: The student's log (untrusted: only actions, ids and seeds are read from it).
        replay: The grader's replay of those actions.
    """

    call_index: int
    position: int
    log: EpisodeLog
    replay: Replay

    @property
    def length(self) -> int:
        """Steps until the episode ended (or all steps, when it never ended)."""
        return int(self.replay.length)

    @property
    def finished(self) -> bool:
        """Whether the episode reached a terminal state or its time limit."""
        last = self.length - 1
        return last >= 0 and bool(self.replay.terminated[last] or self.replay.truncated[last])

    @property
    def reached_terminal(self) -> bool:
        """Whether the episode ended in a terminal state (not by the time limit)."""
        last = self.length - 1
        return last >= 0 and bool(self.replay.terminated[last])

    @property
    def actions(self) -> list[Any]:
        """The actions taken before the episode ended."""
        return list(self.log.actions[: self.length])

    @property
    def rewards(self) -> list[float]:
        """The replayed rewards of the steps before the episode ended."""
        return [float(reward) for reward in self.replay.rewards[: self.length]]

    @property
    def total_reward(self) -> float:
        """Sum of the replayed rewards."""
        return float(self.replay.total_reward)

    @property
    def final_reward(self) -> float:
        """The replayed reward of the last step (0 for an empty episode)."""
        rewards = self.rewards
        return rewards[-1] if rewards else 0.0

    def decisions(self) -> list[tuple[Any, Any]]:
        """(observation seen, action taken) for every step before the episode ended."""
        length = self.replay.length
        return list(zip(self.replay.observations[:length], self.log.actions[:length], strict=True))


def played_episodes(records: Sequence[CallRecord]) -> list[Episode]:
    """Every episode of the records in which at least one action was taken, in play order."""
    episodes = []
    for call_index, record in enumerate(records):
        played = [
            (log, replay)
            for log, replay in zip(record.outcome.episodes, record.replays, strict=True)
            if len(log.actions) > 0
        ]
        episodes += [
            Episode(call_index, position, log, replay) for position, (log, replay) in enumerate(played)
        ]
    return episodes


def episodes_per_call(records: Sequence[CallRecord], episodes: Sequence[Episode]) -> list[list[Episode]]:
    """The played episodes (from `played_episodes(records)`) grouped by call."""
    grouped: list[list[Episode]] = [[] for _ in records]
    for episode in episodes:
        grouped[episode.call_index].append(episode)
    return grouped


def all_resets(records: Sequence[CallRecord]) -> list[Episode]:
    """Every reset of the records, played or not, in reset order (``position``: index among the call's)."""
    return [
        Episode(call_index, position, log, replay)
        for call_index, record in enumerate(records)
        for position, (log, replay) in enumerate(zip(record.outcome.episodes, record.replays, strict=True))
    ]
