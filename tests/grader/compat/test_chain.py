"""`gym.make`'s wrapper chain as served to student code (`grader.compat.chain`) and through the compat `gym`.

The served levels are checked over a stepper that counts what reaches it (a stand-in for the sandbox's
recorder): every level steps through it, a level below the time limit never sees the limit's truncation,
attributes are read (and, on the raw env, written) as each year's gym let student code read them.
"""

from __future__ import annotations

import copy
from typing import Any

import gymnasium
import pytest
from gymnasium.wrappers import TimeLimit

from grader.compat import events, make
from grader.compat.chain import (
    SERVED_CHAIN,
    ServedRaw,
    ServedWrapper,
    limit_reached,
    real_env,
    served_levels,
    time_limit_of,
)

LEFT, DOWN, RIGHT = 0, 1, 2
TO_THE_GOAL = (DOWN, DOWN, RIGHT, DOWN, RIGHT, RIGHT)
"""From the start of the deterministic 4x4 lake to its goal."""


class CountingStepper(gymnasium.Wrapper[Any, Any, Any, Any]):
    """The recorder's place in the chain: counts the resets and steps that reach it, and closes."""

    def __init__(self, env: gymnasium.Env[Any, Any]) -> None:
        super().__init__(env)
        self.resets = 0
        self.steps = 0
        self.closed = False

    def reset(self, *, seed: Any = None, options: dict[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
        self.resets += 1
        return self.env.reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        self.steps += 1
        return self.env.step(action)

    def close(self) -> None:
        self.closed = True
        self.env.close()


@pytest.fixture(autouse=True)
def _drained() -> None:
    events.drain()


def _lake() -> tuple[gymnasium.Env[Any, Any], CountingStepper]:
    made = gymnasium.make("FrozenLake-v1", is_slippery=False)
    return made, CountingStepper(made)


def _levels(top: gymnasium.Env[Any, Any], stepper: CountingStepper) -> list[gymnasium.Env[Any, Any]]:
    levels = [served_levels(top, stepper)]
    while isinstance(levels[-1], ServedWrapper):
        levels.append(levels[-1].env)
    return levels


def test_the_levels_mirror_gymnasium_s_chain_below_its_time_limit() -> None:
    made, stepper = _lake()
    levels = _levels(made, stepper)
    real = [made.env, made.env.env, made.env.env.env]
    assert [real_env(level) for level in levels] == real
    assert [type(real_env(level)).__name__ for level in levels] == [*SERVED_CHAIN[1:], "FrozenLakeEnv"]
    assert isinstance(levels[-1], ServedRaw)
    assert all(level.unwrapped is made.unwrapped for level in levels)  # gymnasium's raw env, as everywhere


@pytest.mark.parametrize("depth", [0, 1, 2], ids=["env.env", "env.env.env", "env.env.env.env (raw)"])
def test_every_level_steps_through_the_stepper_and_plays_past_the_time_limit(depth: int) -> None:
    made, stepper = _lake()
    level = _levels(made, stepper)[depth]
    assert level.reset(seed=0)[0] == 0
    flags = [level.step(LEFT)[2:4] for _ in range(120)]  # left at the start: against the wall
    assert flags == [(False, False)] * 120
    for action in TO_THE_GOAL:
        observation, reward, terminated, truncated, _ = level.step(action)
    assert (observation, reward, terminated, truncated) == (15, 1.0, True, False)
    assert (stepper.resets, stepper.steps) == (1, 126)
    assert limit_reached(time_limit_of(made))  # the real limit counted every step: only its cut is hidden


def test_the_top_keeps_its_time_limit() -> None:
    made, _ = _lake()
    made.reset(seed=0)
    assert [made.step(LEFT)[3] for _ in range(100)] == [False] * 99 + [True]


def test_attributes_are_forwarded_down_the_chain_and_reported() -> None:
    made, stepper = _lake()
    below = served_levels(made, stepper)  # gymnasium 0.29's gym.make(...).env: OrderEnforcing
    assert (len(below.P), below.nrow, len(below.env.env.P)) == (16, 4, 16)
    details = {event.env_id for event in events.drain()}
    assert details == {"FrozenLake-v1: env.P", "FrozenLake-v1: env.nrow"}
    with pytest.raises(AttributeError, match="private attribute '_elapsed_steps'"):
        _ = below._elapsed_steps


def test_the_raw_env_is_read_and_written_as_itself_and_has_no_env() -> None:
    made, stepper = _lake()
    raw = _levels(made, stepper)[-1]
    raw.reset(seed=0)
    raw.s = 14  # classic code sets the state on the raw env
    assert made.unwrapped.s == 14 and raw.step(RIGHT)[:3] == (15, 1.0, True)
    assert (raw.action_space, raw.observation_space) == (made.action_space, made.observation_space)
    assert raw.spec is made.unwrapped.spec and raw.np_random is made.unwrapped.np_random
    assert events.drain() == []  # the env's own attributes: nothing forwarded
    with pytest.raises(AttributeError):
        _ = raw.env


def test_closing_any_level_closes_through_the_stepper() -> None:
    made, stepper = _lake()
    _levels(made, stepper)[1].close()
    assert stepper.closed


def test_a_top_that_is_the_raw_env_is_served_as_the_raw_env() -> None:
    raw = gymnasium.make("FrozenLake-v1").unwrapped
    served = served_levels(raw, CountingStepper(gymnasium.make("FrozenLake-v1")))
    assert isinstance(served, ServedRaw) and served.served is raw


def test_the_time_limit_is_found_through_served_levels() -> None:
    made, stepper = _lake()
    assert isinstance(made, TimeLimit)
    assert time_limit_of(stepper) is made
    assert time_limit_of(served_levels(made, stepper)) is None  # below the limit there is none


@pytest.mark.parametrize(
    ("path", "idiom"),
    [
        (("env",), "2018-2022: gym.make(name).env"),
        (("env", "env"), "gym 0.22-0.23: the env under OrderEnforcing"),
        (("env", "env", "env"), "2023, gym 0.26: env.env.env"),
    ],
    ids=["env", "env.env", "env.env.env"],
)
def test_the_compat_gym_serves_each_year_s_levels(path: tuple[str, ...], idiom: str) -> None:
    level = make("FrozenLake-v1", is_slippery=False)
    for name in path:
        level = getattr(level, name)
    assert (len(level.P), level.nS, level.nA, level._max_episode_steps) == (16, 16, 4, None), idiom
    assert level.reset() == 0
    dones = [level.step(LEFT)[2] for _ in range(120)]
    assert not any(dones), idiom
    for action in TO_THE_GOAL:
        observation, reward, done, _ = level.step(action)
    assert (observation, reward, done) == (15, 1.0, True)


def test_the_compat_gym_s_raw_env_has_no_env() -> None:
    raw = make("FrozenLake-v1").env.env.env
    assert raw.level == len(SERVED_CHAIN)
    with pytest.raises(AttributeError, match="the FrozenLake-v1 environment has no attribute 'env'"):
        _ = raw.env


def test_a_copy_of_a_level_is_a_new_env_of_gymnasium_s_own_not_stepped_through_the_stepper() -> None:
    made, stepper = _lake()
    levels = _levels(made, stepper)
    made.reset(seed=0)
    copies = [copy.deepcopy(level) for level in levels]
    assert [type(duplicate) for duplicate in copies] == [type(real_env(level)) for level in levels]
    copies[-1].step(DOWN)
    assert stepper.steps == 0
