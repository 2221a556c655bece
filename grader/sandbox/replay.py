"""Replay logged episodes in the parent's own, unpatched gymnasium envs: the trusted trajectory.

A student can monkeypatch dynamics, wrappers or time limits in the child, or forge the log itself;
none of that reaches this process. Checks judge `Replay`, never the `EpisodeLog`.
Rewards are compared exactly (the same code on the same seed and actions gives the same floats;
NaN equals NaN), terminated/truncated flags exactly.

The child records every episode of a recording call; the parent replays each one in its own, unpatched
gymnasium and judges the replay, never the log:

- The recorder (`grader/sandbox/child/recorder.py`, child side) replaces `gymnasium.make` (every name it
  is bound to), `numpy.random.default_rng` and `gymnasium.utils.seeding.np_random`, so unseeded
  randomness comes from the call's seed streams; it sits outermost on each env, sees the gymnasium-API
  `reset`/`step` (the compat `gym` shim wraps it in turn), reseeds every reset from the grader's stream
  and logs the actions and what the student saw.
- The child's games (`grader/sandbox/child/envs.py`): an env `gymnasium.make` returns whose game is exactly
  gymnasium's `TaxiEnv` or `BlackjackEnv` is swapped in place (`envs.cheaper`, called by the recorder's
  `make`) to a subclass of the same name that does the same step with fewer numpy calls: Taxi skips
  `categorical_sample`'s arrays when there is one transition (it still draws the one number gymnasium
  draws) and caches each state's action mask; Blackjack draws `deck[integers(0, 13)]`, which is what
  `choice(deck)` draws. Each call returns what gymnasium's returns, type for type, and leaves the env's
  state and generator as gymnasium's would (`tests/grader/sandbox/test_envs.py`, step by step against
  gymnasium's classes, rainy and fickle Taxi and refused actions included); what the shortcuts do not
  cover goes to gymnasium's own code. The parent never uses these classes: it replays in gymnasium's.
- `grader/sandbox/replay.py`: `replay_episode(log: EpisodeLog) -> Replay` in the parent's own,
  unpatched gymnasium env (ids resolved with `grader.compat.resolve_env_id`). `Replay` carries the
  trusted `observations` (reset observation first), `rewards`, `terminated`, `truncated`, `length`
  (steps until the first terminated/truncated), `steps_after_done`, and `mismatch: str | None` describing
  the first disagreement with the student's log. Checks judge the replayed trajectory, never the log.
  Also `finished` (the episode reached terminated/truncated), `env_spec` (the replayed env's gymnasium
  `EnvSpec`, e.g. `max_episode_steps`, for checks that restrict ids/arguments), `matches`, `total_reward`.
  `replay_episodes(logs)` gives the same results, batching CartPole, Taxi and Blackjack episodes
  (`grader/sandbox/batched/`: `REPLAYERS`, bit-identical to gymnasium's scalar env; use it for many logs:
  CartPole and Taxi advance all episodes in lockstep over arrays, `replayer.lockstep`; Blackjack plays
  gymnasium's rules on plain lists; every batch's seeds are hashed at once, `draws.seeded_draws`, the
  streams of `np_random(seed)` without building a Generator; a batch is used only when the scalar env
  replays its longest, first and last episodes identically, and a batch of three or fewer is not played);
  `replay_past_time_limit(log)` replays an episode that went on after gym.make's time limit cut it (classic
  `gym.make(id).env`, a loop on `terminated` only: the second lab's FrozenLake) in the same env without the
  limit, its truncation flags checked to be the limit's (`time_limit_of(log)`);
  `verify_reset_seeds(logs_of_one_call, call_seed) -> str | None` checks the logged reset seeds against
  the stream `grader.sandbox.child.seeding` prescribes (`derive_call_seed(seed, call_index)`,
  `reset_seeds(call_seed, n)`: pure functions). Every reset, seeded by the student or not, takes the next
  seed of the stream; a student's seed is only logged (`student_seed`, plain non-negative ints) and
  reported as a `seed_replaced` compat event.
"""

from __future__ import annotations

import dataclasses
import math
import threading
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache
from typing import Any

import gymnasium
import numpy as np
from gymnasium.envs.registration import EnvSpec

from grader.compat import register_envs
from grader.sandbox.batched import REPLAYERS, BatchedEpisode, BatchedReplayer
from grader.sandbox.child.frames import paused_gc
from grader.sandbox.child.seeding import reset_seeds
from grader.sandbox.episode_log import EpisodeLog, environment_key

MAX_CACHED_ENVS = 16
MAX_BATCH_CELLS = 2_000_000
"""Largest steps x episodes of one batch (memory: CartPole keeps 48 bytes per cell)."""
WITNESSES = 3
"""Episodes of each batch replayed again by the scalar env (the longest, the first, the last); a batch of
no more episodes is not played at all (CartPole's 100 calls of one episode each)."""
_FORBIDDEN_KWARGS = frozenset({"render_mode", "disable_env_checker"})


@dataclass(frozen=True)
class Replay:
    """An episode replayed in the trusted env.

    Attributes:
        observations: the reset observation, then one per replayed step.
        rewards: the real rewards, one per replayed step (the replay stops at the real end).
        terminated: the real flags, one per replayed step.
        truncated: likewise.
        length: replayed steps: up to and including the first terminated/truncated, or every
            logged step if the episode did not end (or until the real env refused an action).
        finished: whether the episode reached terminated or truncated.
        steps_after_done: steps the student took after the episode ended.
        mismatch: the first disagreement with the student's log, or None.
        env_spec: the spec of the env replayed (id, kwargs, `max_episode_steps`), for callers that
            decide which envs and arguments a problem allows; None if it could not be made.
    """

    observations: list[Any]
    rewards: list[float]
    terminated: list[bool]
    truncated: list[bool]
    length: int
    finished: bool
    steps_after_done: int
    mismatch: str | None
    env_spec: EnvSpec | None

    @property
    def matches(self) -> bool:
        """True when the student's log agrees with the real env at every step."""
        return self.mismatch is None

    @property
    def total_reward(self) -> float:
        """Sum of the real rewards up to the end of the episode (steps after done excluded)."""
        return math.fsum(self.rewards[: self.length])


def replay_episode(log: EpisodeLog) -> Replay:
    """Replay `log` in a fresh reset of the real env and compare it step by step with what the student saw.

    The replay stops at the real end of the episode (first terminated/truncated): what the student
    did after it does not count and is only counted in `steps_after_done`. Callers that restrict env
    ids or arguments (e.g. `max_episode_steps`) check `log.env_id`/`log.env_kwargs` before replaying:
    an env without a time limit is replayed for as many steps as the log holds.

    Never raises for a bad log: an env that cannot be made, a reset that fails or an action the real
    env refuses ends the replay there with a `mismatch` saying so.
    """
    env, error = _cached_env(log.env_id, log.env_kwargs)
    if env is None:
        return _unplayable(f"{_env_name(log)} cannot be made: {error}", None)
    try:
        observation, _ = env.reset(seed=log.reset_seed, options=log.reset_options)
    except Exception as failure:
        return _unplayable(f"{_env_name(log)} refused reset(seed={log.reset_seed}): {failure}", env.spec)
    return _play(env, log, observation)


def replay_episodes(logs: Sequence[EpisodeLog]) -> list[Replay]:
    """Replay every log (see `replay_episode`); same results, much faster for many episodes.

    Episodes of envs with a batched replayer (`grader.sandbox.batched`: CartPole, Taxi, Blackjack) are
    replayed together; the longest, first and last of each batch are replayed again by the scalar env
    and the batch is used only if they agree exactly. Episodes that disagree with the log are replayed
    one by one, so mismatch messages always come from the scalar env.
    """
    with paused_gc():
        return _replay_all(logs)


def _replay_all(logs: Sequence[EpisodeLog]) -> list[Replay]:
    replays: list[Replay | None] = [None] * len(logs)
    groups: dict[tuple[int, str], list[int]] = {}
    for position, log in enumerate(logs):
        for number, replayer in enumerate(REPLAYERS):
            if replayer.is_batchable(log):
                groups.setdefault((number, log.environment), []).append(position)
                break
    for (number, _), positions in groups.items():
        first = logs[positions[0]]
        env, _ = _cached_env(first.env_id, first.env_kwargs)
        spec = None if env is None else env.spec
        for chunk in _chunks(sorted(positions, key=lambda position: logs[position].steps), logs):
            if len(chunk) <= WITNESSES:  # every episode would be replayed by the scalar env as a witness
                continue
            batch = _batch_or_none(REPLAYERS[number], [logs[position] for position in chunk])
            if batch is None:
                continue
            for position, played in zip(chunk, batch, strict=True):
                replays[position] = _from_batch(logs[position], played, spec)
    return [
        replay if replay is not None else replay_episode(log)
        for replay, log in zip(replays, logs, strict=True)
    ]


def time_limit_of(log: EpisodeLog) -> int | None:
    """The step limit of the env an episode was played in (`gym.make`'s `TimeLimit`), or None for none."""
    limit = log.env_kwargs.get("max_episode_steps")
    if limit is None:
        register_envs()
        spec = gymnasium.registry.get(log.env_id)
        limit = None if spec is None else spec.max_episode_steps
    return limit if type(limit) is int and limit > 0 else None


def replay_past_time_limit(log: EpisodeLog) -> Replay:
    """Replay an episode that went on after its env's time limit cut it, until the env itself ends it.

    Classic `gym.make(id).env` (the env inside `TimeLimit`, served by `grader.compat`) and a loop that stops
    on `terminated` only step on after the limit's `truncated`; the second lab counts such episodes to their
    end. The log is replayed in the same env without the limit (`max_episode_steps=-1`); its truncation
    flags must be the limit's: False before step `limit`, True from it on (as `TimeLimit` reports them, and
    as the env without a limit never does). An episode the limit did not cut replays as `replay_episode`.
    """
    limit = time_limit_of(log)
    if limit is None or log.steps < limit:
        return replay_episode(log)
    expected = [flag if number < limit else not flag for number, flag in enumerate(log.truncated, start=1)]
    unlimited = dataclasses.replace(
        log, env_kwargs={**log.env_kwargs, "max_episode_steps": -1}, truncated=expected
    )
    return replay_episode(unlimited)


def not_replayed(reason: str) -> Replay:
    """The `Replay` of a log the grader refused to replay (its env is not the problem's game, ...)."""
    return _unplayable(f"not replayed: {reason}", None)


def verify_reset_seeds(logs: Sequence[EpisodeLog], call_seed: int) -> str | None:
    """Check that the logs of one call (in reset order) used the seeds the grader's stream prescribes.

    Every reset takes the next seed of the call's reset stream (a student's own seed is replaced).
    Returns a description of the first deviation, or None.
    """
    for number, (log, expected) in enumerate(zip(logs, reset_seeds(call_seed, len(logs)), strict=True)):
        if log.reset_seed != expected:
            return (
                f"episode {number + 1} was reset with seed {log.reset_seed}, but the grader's seed stream gives {expected}: "  # noqa: E501
                "the episode log was altered"
            )
    return None


def _play(env: gymnasium.Env[Any, Any], log: EpisodeLog, observation: Any) -> Replay:
    observations = [_own(observation)]
    rewards: list[float] = []
    terminated_flags: list[bool] = []
    truncated_flags: list[bool] = []
    mismatch: str | None = None
    step = env.step
    for index, action in enumerate(log.actions):
        try:
            observation, reward, terminated, truncated, _ = step(_as_action(action))
        except Exception as failure:
            mismatch = mismatch or (
                f"step {index + 1} of the episode in {_env_name(log)}: "
                f"the real environment refused the action {action!r}: {failure}"
            )
            break
        reward, terminated, truncated = float(reward), bool(terminated), bool(truncated)
        observations.append(_own(observation))
        rewards.append(reward)
        terminated_flags.append(terminated)
        truncated_flags.append(truncated)
        if mismatch is None and not _same_step(log, index, reward, terminated, truncated):
            mismatch = _describe_mismatch(log, index, reward, terminated, truncated)
        if terminated or truncated:
            break
    return _replay(log, observations, rewards, terminated_flags, truncated_flags, mismatch, env.spec)


def _replay(
    log: EpisodeLog,
    observations: list[Any],
    rewards: list[float],
    terminated: list[bool],
    truncated: list[bool],
    mismatch: str | None,
    spec: EnvSpec | None,
) -> Replay:
    length = len(rewards)
    finished = length > 0 and (terminated[-1] or truncated[-1])
    after_done = log.steps - length if finished else 0
    return Replay(observations, rewards, terminated, truncated, length, finished, after_done, mismatch, spec)


def _chunks(positions: list[int], logs: Sequence[EpisodeLog]) -> list[list[int]]:
    """Split positions (sorted by episode length) so that steps x episodes stays within `MAX_BATCH_CELLS`."""
    chunks: list[list[int]] = [[]]
    for position in positions:
        if chunks[-1] and logs[position].steps * (len(chunks[-1]) + 1) > MAX_BATCH_CELLS:
            chunks.append([])
        chunks[-1].append(position)
    return chunks


def _batch_or_none(replayer: BatchedReplayer, group: Sequence[EpisodeLog]) -> list[BatchedEpisode] | None:
    """The batch's episodes, or None if the batch cannot run or the scalar env disagrees with it.

    The episode the batch played longest, the first and the last are replayed again by the scalar
    env; they must agree exactly, or the whole batch is discarded (its episodes are then replayed
    one by one).
    """
    try:
        batch = replayer.replay(group)
    except Exception:  # an env this replayer does not model (e.g. re-registered): use the scalar env
        return None
    longest = max(range(len(batch)), key=lambda position: len(batch[position].rewards))
    witnesses = sorted({longest, 0, len(batch) - 1})
    if all(_same_trajectory(replay_episode(group[index]), batch[index]) for index in witnesses):
        return batch
    return None


def _same_trajectory(scalar: Replay, played: BatchedEpisode) -> bool:
    same_observations = len(scalar.observations) == len(played.observations) and all(
        np.array_equal(real, batched)
        for real, batched in zip(scalar.observations, played.observations, strict=True)
    )
    same_steps = (scalar.rewards, scalar.terminated, scalar.truncated) == (
        played.rewards,
        played.terminated,
        played.truncated,
    )
    return same_observations and same_steps


def _from_batch(log: EpisodeLog, played: BatchedEpisode, spec: EnvSpec | None) -> Replay | None:
    """The replay of a batched episode, or None when it disagrees with the log (the scalar env explains)."""
    length = len(played.rewards)
    if (played.rewards, played.terminated, played.truncated) != (
        log.rewards[:length],
        log.terminated[:length],
        log.truncated[:length],
    ):
        return None
    return _replay(log, played.observations, played.rewards, played.terminated, played.truncated, None, spec)


def _same_step(log: EpisodeLog, index: int, reward: float, terminated: bool, truncated: bool) -> bool:
    seen = log.rewards[index]
    same_reward = seen == reward or (math.isnan(seen) and math.isnan(reward))
    return same_reward and log.terminated[index] == terminated and log.truncated[index] == truncated


def _describe_mismatch(log: EpisodeLog, index: int, reward: float, terminated: bool, truncated: bool) -> str:
    return (
        f"step {index + 1} of the episode in {_env_name(log)} (reset seed {log.reset_seed}): "
        f"your code saw reward={log.rewards[index]!r}, terminated={log.terminated[index]}, truncated={log.truncated[index]}, but the real environment gives reward={reward!r}, terminated={terminated}, truncated={truncated} for the same actions. "  # noqa: E501
        "The environment your code played was modified (its dynamics, its time limit or the log); "
        "play the environment gym.make returns, unmodified"
    )


def _unplayable(message: str, spec: EnvSpec | None) -> Replay:
    return Replay([], [], [], [], 0, False, 0, message, spec)


def _env_name(log: EpisodeLog) -> str:
    arguments = "".join(f", {key}={value!r}" for key, value in log.env_kwargs.items())
    return f"{log.requested_id} (gymnasium.make({log.env_id!r}{arguments}))"


def _as_action(action: Any) -> Any:
    return np.asarray(action) if type(action) is list else action


def _own(observation: Any) -> Any:
    return observation.copy() if type(observation) is np.ndarray else observation


_local = threading.local()


def _cached_env(env_id: str, env_kwargs: dict[str, Any]) -> tuple[gymnasium.Env[Any, Any] | None, str]:
    """One env per (id, kwargs) per thread; the env checker is skipped (these envs are gymnasium's own)."""
    cache: dict[str, gymnasium.Env[Any, Any]] = getattr(_local, "envs", None) or {}
    _local.envs = cache
    key = environment_key(env_id, env_kwargs)
    env = cache.get(key)
    if env is not None:
        return env, ""
    register_envs()
    if env_id not in gymnasium.registry:
        return None, f"{env_id!r} is not a registered gymnasium id"
    if _FORBIDDEN_KWARGS.intersection(env_kwargs):
        return None, f"the arguments {sorted(_FORBIDDEN_KWARGS.intersection(env_kwargs))} are not replayable"
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            env = gymnasium.make(env_id, disable_env_checker=True, **env_kwargs)
    except Exception as failure:
        return None, f"{type(failure).__name__}: {failure}"
    if len(cache) >= MAX_CACHED_ENVS:
        cache.pop(next(iter(cache))).close()
    cache[key] = env
    return env, ""


def policy_rollout_steps(log: EpisodeLog, policy: Callable[[Any], int], limit: int) -> int:
    """Steps a (reference) policy plays from a logged episode's start: its reset seed in the grader's env.

    The env is built from the log's id and arguments, which the integrity rules accepted before any
    start is valued; at most ``limit`` steps are played.
    """
    env = _rollout_env(log.env_id, tuple(sorted(log.env_kwargs.items())))
    observation, _ = env.reset(seed=log.reset_seed)
    for step in range(1, limit + 1):
        observation, _, terminated, truncated, _ = env.step(policy(observation))
        if terminated or truncated:
            return step
    return limit


@cache
def _rollout_env(env_id: str, env_kwargs: tuple[tuple[str, Any], ...]) -> gymnasium.Env[Any, Any]:
    return gymnasium.make(env_id, **dict(env_kwargs))
