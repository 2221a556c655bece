"""FrozenLake episodes replay exactly with their map and slipperiness, a forged log is refused, and an
episode that went on past its time limit replays to its end in the env without the limit."""

from __future__ import annotations

import dataclasses

import gymnasium
import pytest

from grader.sandbox.episode_log import EpisodeLog
from grader.sandbox.replay import replay_episode, replay_past_time_limit, time_limit_of


def _played(kwargs: dict, seed: int, actions_of, steps: int | None = None) -> EpisodeLog:  # type: ignore[no-untyped-def,type-arg]
    """An honest log: the episode played in gymnasium's own env (past its end when `steps` says so)."""
    env = gymnasium.make("FrozenLake-v1", **kwargs)
    state, _ = env.reset(seed=seed)
    actions: list[int] = []
    rewards: list[float] = []
    terminated: list[bool] = []
    truncated: list[bool] = []
    while steps is None or len(actions) < steps:
        action = actions_of(state)
        state, reward, done, cut, _ = env.step(action)
        actions.append(action)
        rewards.append(float(reward))
        terminated.append(bool(done))
        truncated.append(bool(cut))
        if steps is None and (done or cut):
            break
        if done:
            break
    return EpisodeLog(
        0, "FrozenLake-v1", "FrozenLake-v1", dict(kwargs), seed, None, actions, rewards, terminated, truncated
    )


@pytest.mark.parametrize(
    "kwargs",
    [
        {"map_name": "4x4", "is_slippery": True},
        {"map_name": "8x8", "is_slippery": True},
        {"map_name": "4x4", "is_slippery": False},
        {"map_name": "8x8", "is_slippery": False, "max_episode_steps": 2000},
    ],
    ids=["4x4", "8x8", "still4", "still8_limit"],
)
def test_an_honest_frozen_lake_episode_replays_exactly(kwargs: dict) -> None:  # type: ignore[type-arg]
    log = _played(kwargs, 11, lambda state: [1, 2][state % 2])
    replay = replay_episode(log)
    assert replay.mismatch is None
    assert replay.rewards == log.rewards and replay.finished


@pytest.mark.parametrize(
    ("forge", "words"),
    [
        (lambda log: dataclasses.replace(log, rewards=[*log.rewards[:-1], 1.0 - log.rewards[-1]]), "reward="),
        (lambda log: dataclasses.replace(log, env_kwargs={**log.env_kwargs, "is_slippery": False}), "step"),
        (lambda log: dataclasses.replace(log, reset_seed=log.reset_seed + 1), "step"),
    ],
    ids=["reward", "slipperiness", "seed"],
)
def test_a_forged_frozen_lake_log_is_refused(forge, words: str) -> None:  # type: ignore[no-untyped-def]
    log = _played({"map_name": "4x4", "is_slippery": True}, 5, lambda state: 1 if state % 4 < 2 else 2)
    forged = forge(log)
    replay = replay_episode(forged)
    assert replay.mismatch is not None and words in replay.mismatch


def test_an_episode_played_past_its_time_limit_replays_to_its_end() -> None:
    """Classic `gym.make(id).env` and a loop on `terminated` alone step on after the 100-step limit."""
    wall = {"map_name": "4x4", "is_slippery": True}
    # Up along the top row (slips left or right), down only in its last cell, over the hole: a long walk,
    # found by seed to outlast the limit and end in the hole.
    log = next(
        candidate
        for seed in range(500)
        if (candidate := _played(wall, seed, lambda state: 1 if state == 3 else 3, steps=1000)).steps > 100
        and candidate.terminated[-1]
    )
    assert time_limit_of(log) == 100
    cut = replay_episode(log)
    assert cut.truncated[-1] and cut.length == 100 and cut.steps_after_done == log.steps - 100
    whole = replay_past_time_limit(log)
    assert whole.mismatch is None and whole.length == log.steps and whole.terminated[-1]
    assert whole.rewards == log.rewards
    forged = dataclasses.replace(log, truncated=[False] * log.steps)  # a limit that never cut: not this env
    assert replay_past_time_limit(forged).mismatch is not None
