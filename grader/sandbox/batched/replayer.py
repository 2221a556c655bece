"""What a batched replayer provides: many episodes of one env at once, bit-identical to the scalar env."""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol, TypeVar

import gymnasium
import numpy as np

from grader.sandbox.episode_log import EpisodeLog

MAX_HORIZON = 10_000
"""Longest time limit a batch accepts by default; episodes of envs without a time limit are replayed one
by one."""
_Env = TypeVar("_Env")
Arrays = tuple[np.ndarray, np.ndarray, np.ndarray]
Advance = Callable[[gymnasium.Env[Any, Any], _Env, Sequence[EpisodeLog], np.ndarray], Arrays]
"""Plays every log in lockstep: (the scalar env, its unwrapped core, the logs, the action matrix) to
(observations, rewards, terminated) as `finish` takes them."""


@dataclass(frozen=True)
class BatchedEpisode:
    """The real trajectory of one logged episode, up to its real end (or the end of the log).

    Attributes:
        observations: the reset observation, then one per replayed step.
        rewards: the real rewards, one per replayed step.
        terminated: the real flags, one per replayed step.
        truncated: likewise (the `TimeLimit` of the env spec or of `max_episode_steps`).
        finished: whether the last replayed step ended the episode.
    """

    observations: list[Any]
    rewards: list[float]
    terminated: list[bool]
    truncated: list[bool]
    finished: bool


class BatchedReplayer(Protocol):
    """One env family replayed many episodes at a time."""

    def is_batchable(self, log: EpisodeLog) -> bool:
        """Whether `replay` can replay `log` (plain env arguments, no reset options, valid actions)."""
        ...

    def replay(self, logs: Sequence[EpisodeLog]) -> list[BatchedEpisode]:
        """Replay batchable logs that share `env_id` and `env_kwargs`, in the given order."""
        ...


def plain_arguments(log: EpisodeLog, env_ids: frozenset[str], max_horizon: int = MAX_HORIZON) -> bool:
    """An episode of one of `env_ids`, no reset options, at most `max_episode_steps` given, a time limit
    of at most `max_horizon` steps (a lockstep batch is as long as its longest episode, never longer)."""
    if log.env_id not in env_ids or log.reset_options is not None or not log.actions:
        return False
    if set(log.env_kwargs) - {"max_episode_steps"}:
        return False
    limit = log.env_kwargs.get("max_episode_steps")
    if limit is not None and type(limit) is not int:
        return False
    return 0 < time_limit(log) <= max_horizon


def int_actions(actions: Sequence[Any], count: int) -> bool:
    """Whether every action is a plain int in `range(count)`."""
    return set(map(type, actions)) == {int} and min(actions) >= 0 and max(actions) < count


def time_limit(log: EpisodeLog) -> int:
    """The step at which `TimeLimit` truncates episodes of `log`'s env; 0 without a time limit."""
    limit = log.env_kwargs.get("max_episode_steps")
    if limit is None:
        limit = gymnasium.spec(log.env_id).max_episode_steps
    return 0 if limit is None or limit < 0 else int(limit)


def horizon(logs: Sequence[EpisodeLog]) -> int:
    """Lockstep steps needed: the longest log, but never past the time limit."""
    return min(max(log.steps for log in logs), time_limit(logs[0]))


def unlimited_env(env_id: str) -> gymnasium.Env[Any, Any]:
    """A fresh env of `env_id` without `TimeLimit` or env checker, used for its own `reset(seed)`."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return gymnasium.make(env_id, disable_env_checker=True, max_episode_steps=-1)


def lockstep(logs: Sequence[EpisodeLog], core: type[_Env], advance: Advance[_Env]) -> list[BatchedEpisode]:
    """The episodes of `logs` (sharing env id and arguments) played in lockstep by `advance`.

    `advance` gets the parent's own env of the logs' id (without time limit, for its `reset(seed)`), its
    unwrapped core, checked to be `core`, and the actions step-major (`action_matrix` up to `horizon`).

    Raises:
        TypeError: the registered env is not `core` (re-registered): the caller replays one by one.
    """
    scalar = unlimited_env(logs[0].env_id)
    try:
        env = scalar.unwrapped
        if type(env) is not core:
            raise TypeError(f"{logs[0].env_id} is not gymnasium's {core.__name__}")
        return finish(logs, *advance(scalar, env, logs, action_matrix(logs, horizon(logs))))
    finally:
        scalar.close()


def action_matrix(logs: Sequence[EpisodeLog], steps: int) -> np.ndarray:
    """Actions step-major, one column per log, padded with 0 after a log's end."""
    actions = np.zeros((steps, len(logs)), dtype=np.int64)
    for column, log in enumerate(logs):
        played = min(log.steps, steps)
        actions[:played, column] = log.actions[:played]
    return actions


def finish(
    logs: Sequence[EpisodeLog],
    observations: np.ndarray,
    rewards: np.ndarray,
    terminated: np.ndarray,
) -> list[BatchedEpisode]:
    """Cut lockstep arrays (step-major, one column per log) into `BatchedEpisode`s at each real end.

    Args:
        logs: the episodes, one column each (sharing env id and arguments).
        observations: shape (steps + 1, episodes, ...): the reset observation, then one per step.
        rewards: shape (steps, episodes).
        terminated: shape (steps, episodes), bool.
    """
    steps = terminated.shape[0]
    truncated_at = np.arange(1, steps + 1) >= time_limit(logs[0])
    done = terminated | truncated_at[:, None]
    truncated_flags = truncated_at.tolist()
    # One conversion per matrix, then list slices: per-episode numpy calls cost more than the episodes.
    observation_columns = _columns(observations)
    reward_columns = rewards.T.tolist()
    terminated_columns = terminated.T.tolist()
    ended: list[bool] = np.any(done, axis=0).tolist()
    first_end: list[int] = done.argmax(axis=0).tolist()
    episodes = []
    for column, log in enumerate(logs):
        played = min(log.steps, steps)
        finished = ended[column] and first_end[column] < played
        end = first_end[column] + 1 if finished else played
        episodes.append(
            BatchedEpisode(
                observations=observation_columns[column][: end + 1],
                rewards=reward_columns[column][:end],
                terminated=terminated_columns[column][:end],
                truncated=truncated_flags[:end],
                finished=finished,
            )
        )
    return episodes


def _columns(observations: np.ndarray) -> list[list[Any]]:
    """Per episode: Python scalars for scalar observations (Taxi's ints), else array rows (CartPole's)."""
    if observations.ndim == 2:
        return observations.T.tolist()  # type: ignore[no-any-return]
    return [list(observations[:, column]) for column in range(observations.shape[1])]
