"""Trusted views of the episodes a call played, and the integrity diagnoses every check shares."""

from __future__ import annotations

import inspect
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache
from typing import TYPE_CHECKING, Any

import gymnasium
from gymnasium.envs.registration import load_env_creator

from grader.checks.base import CallRecord
from grader.sandbox.replay import verify_reset_seeds

if TYPE_CHECKING:
    from grader.sandbox.episodes import EpisodeLog
    from grader.sandbox.replay import Replay

# Constructor arguments that never change a game's rules.
_HARMLESS_KWARGS = frozenset({"render_mode"})


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


@dataclass(frozen=True)
class GameRules:
    """Which environment a problem must be played in.

    Attributes:
        lab_id: The id the lab uses (named in feedback).
        gymnasium_ids: Gymnasium ids that play exactly that game.
        required_kwargs: Effective constructor arguments (registered defaults merged with the student's)
            the game needs, e.g. Blackjack's ``sab=False``.
    """

    lab_id: str
    gymnasium_ids: tuple[str, ...]
    required_kwargs: Mapping[str, Any] = field(default_factory=dict)

    def problem_with(self, log: EpisodeLog) -> str | None:
        """Why an episode's environment is not the lab's game, or None when it is."""
        if log.env_id not in self.gymnasium_ids:
            return (
                f"the episodes must be played in {self.lab_id}, but you made {log.requested_id!r} "
                f"(gymnasium {log.env_id}), a different game: use gym.make({self.lab_id!r})"
            )
        effective = {**_default_kwargs(log.env_id), **dict(log.env_kwargs)}
        for name, value in self.required_kwargs.items():
            if effective.get(name) != value:
                return (
                    f"{self.lab_id} is played with {name}={value!r}, but your environment had "
                    f"{name}={effective.get(name)!r}, which changes the game: make it with "
                    f"gym.make({self.lab_id!r}) and no extra arguments"
                )
        extra = sorted(set(log.env_kwargs) - set(self.required_kwargs) - _HARMLESS_KWARGS)
        if extra:
            arguments = ", ".join(f"{name}={log.env_kwargs[name]!r}" for name in extra)
            return (
                f"you made {log.requested_id!r} with {arguments}, which changes the game (e.g. its time "
                "limit): "
                f"make it with gym.make({self.lab_id!r}) and no extra arguments"
            )
        return None


@cache
def _default_kwargs(env_id: str) -> dict[str, Any]:
    """The arguments an env gets when made without any: registered kwargs over constructor defaults."""
    spec = gymnasium.spec(env_id)
    creator = load_env_creator(spec.entry_point) if isinstance(spec.entry_point, str) else spec.entry_point
    parameters = inspect.signature(creator).parameters.values() if creator is not None else []
    defaults = {p.name: p.default for p in parameters if p.default is not inspect.Parameter.empty}
    return {**defaults, **spec.kwargs}


BLACKJACK = GameRules("Blackjack-v0", ("Blackjack-v1",), {"natural": False, "sab": False})
CARTPOLE = GameRules("CartPole-v0", ("CartPole-v0",))
MOUNTAIN_CAR = GameRules("MountainCar-v0", ("MountainCar-v0",))
TAXI = GameRules("Taxi-v3", ("Taxi-v4", "Taxi-v3"), {"is_rainy": False, "fickle_passenger": False})


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
