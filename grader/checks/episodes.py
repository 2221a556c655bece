"""Trusted views of the episodes a call played, and the integrity diagnoses every check shares."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from grader.checks.base import CallRecord
from grader.sandbox.replay import verify_reset_seeds

if TYPE_CHECKING:
    from grader.games import GameRules
    from grader.sandbox.episodes import EpisodeLog
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


def seed_problem(records: Sequence[CallRecord]) -> str | None:
    """Why some call's episodes did not start from the seeds the grader's stream prescribes, or None."""
    for record in records:
        deviation = verify_reset_seeds(record.outcome.episodes, record.outcome.seed)
        if deviation:
            return deviation
    return None


def integrity_problem(
    records: Sequence[CallRecord], episodes: Sequence[Episode], rules: GameRules
) -> str | None:
    """The first reason the episodes cannot be trusted or are not the lab's game, or None.

    Checks, in order: a reset seed differs from the grader's stream (an altered log); the replay
    disagrees with the student's log; the environment or its arguments
    differ from the lab's game; steps were taken after an episode ended; an episode was abandoned
    before it ended (reset in the middle of a game, or stopped early).
    """
    altered = seed_problem(records)
    if altered:
        return altered
    for episode in episodes:
        if episode.replay.mismatch:
            return (
                f"episode {_where(episode)} did not replay: {episode.replay.mismatch}. The grader replays "
                "every "
                f"episode in its own environment; results that the real game does not produce cannot count"
            )
    environments = {
        (e.log.env_id, e.log.requested_id, repr(sorted(e.log.env_kwargs.items()))): e for e in episodes
    }
    for episode in environments.values():
        problem = rules.problem_with(episode.log)
        if problem:
            return problem
    after_done = [episode for episode in episodes if episode.replay.steps_after_done > 0]
    if after_done:
        first = after_done[0]
        return (
            f"{len(after_done)} episode(s) kept stepping after the game was over (e.g. episode "
            f"{_where(first)} ended after {first.length} steps and you took {first.replay.steps_after_done} "
            "more). "
            f"Stop as soon as `done` (terminated or truncated) is True"
        )
    unfinished = [episode for episode in episodes if not episode.finished]
    if unfinished:
        first = unfinished[0]
        return (
            f"{len(unfinished)} game(s) were abandoned before they ended (e.g. episode {_where(first)} "
            "stopped "
            f"after {first.length} steps without terminating): you reset (or stopped) in the middle of a "
            "game. "
            f"Play each game until `done` is True and reset only between games"
        )
    return None


def repeated_seed_problem(episodes: Sequence[Episode], *, across_calls: bool) -> str | None:
    """A diagnosis when several episodes were reset with the same seed of the student's, or None.

    Episodes reset with the same seed are the same game, so their results are not independent runs.
    Within one call this is always wrong; across calls it is wrong for problems whose function plays one
    episode per call (the lab calls them 100 times to average independent runs).

    Args:
        episodes: The problem's played episodes.
        across_calls: Count repeats over all calls (True) or within each call only (False).
    """
    seeds = Counter(
        (0 if across_calls else episode.call_index, episode.log.student_seed)
        for episode in episodes
        if episode.log.student_seed is not None
    )
    repeated = [(key, count) for key, count in seeds.items() if count > 1]
    if not repeated:
        return None
    (_, seed), count = max(repeated, key=lambda item: item[1])
    return (
        f"{count} episodes were reset with the same seed ({seed}), so outside the grader they are the same "
        f"game played {count} times and their average says nothing: the runs are not independent. "
        f"Call reset() without a seed (or seed only the first reset)"
    )


def _where(episode: Episode) -> str:
    return f"{episode.position + 1} of call {episode.call_index + 1}"
