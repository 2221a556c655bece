"""Tests for grader.compat.adapter: the classic API over gymnasium, and what it tolerates."""

from __future__ import annotations

import copy
import warnings
from typing import Any

import gymnasium
import numpy as np
import pytest

from grader.compat import UnsupportedRenderModeError, events, make


@pytest.fixture(autouse=True)
def _empty_log() -> None:
    events.drain()


def _kinds() -> list[str]:
    return [
        event.kind for event in events.drain() if event.kind not in (events.RENAMED_ID, events.API_DETECTED)
    ]


def test_reset_returns_the_observation_only() -> None:
    assert make("NChain-v0").reset() == 0


def test_reset_with_return_info_returns_observation_and_info() -> None:
    observation, info = make("Taxi-v3").reset(seed=3, return_info=True)
    assert (observation, sorted(info)) == (
        gymnasium.make("Taxi-v4").reset(seed=3)[0],
        ["action_mask", "prob"],
    )


def test_step_returns_the_classic_four_tuple() -> None:
    env = make("NChain-v0")
    env.reset()
    observation, reward, done, info = env.step(0)
    assert (observation in (0, 1), reward in (0, 2), done, info) == (True, True, False, {})


def test_done_is_terminated_or_truncated_and_truncation_is_flagged_as_classic_timelimit_did() -> None:
    env = make("CartPole-v0")
    observation = env.reset(seed=1)
    # Pushing towards the side the pole falls to keeps it up past the 200-step limit of CartPole-v0.
    steps, done, info = 0, False, {}
    while not done:
        observation, _, done, info = env.step(int(3 * observation[2] + observation[3] > 0))
        steps += 1
    assert (steps, info) == (200, {"TimeLimit.truncated": True})


def test_termination_has_no_timelimit_flag() -> None:
    env = make("CartPole-v0")
    env.reset(seed=1)
    steps, done, info = 0, False, {}
    while not done:
        _, _, done, info = env.step(0)
        steps += 1
    assert steps < 200 and info == {}


def test_seed_then_reset_replays_the_gymnasium_episode_seeded_the_same_way() -> None:
    env = make("Taxi-v3")
    assert env.seed(42) == [42]
    assert env.reset() == gymnasium.make("Taxi-v4").reset(seed=42)[0]
    assert _kinds() == [events.LEGACY_SEED_CALL]


def _play(step: Any, first_observation: Any, actions: list[int]) -> list[Any]:
    trajectory = [first_observation]
    for action in actions:
        result = step(action)
        trajectory.append(result[:2])
        if result[2] or (len(result) == 5 and result[3]):
            break
    return trajectory


@pytest.mark.parametrize("seed", range(200))
def test_blackjack_v0_plays_the_sab_false_game_card_for_card(seed: int) -> None:
    actions = [int(bit) for bit in np.random.default_rng(seed).integers(0, 2, size=12)]
    classic = make("Blackjack-v0")
    target = gymnasium.make("Blackjack-v1", natural=False, sab=False)
    assert _play(classic.step, classic.reset(seed=seed), actions) == _play(
        target.step, target.reset(seed=seed)[0], actions
    )


def test_blackjack_v0_is_not_the_registered_sab_default() -> None:
    env = make("Blackjack-v0")
    assert (env.unwrapped.sab, env.unwrapped.natural) == (False, False)


def test_step_before_reset_resets_first_as_classic_blackjack_allowed() -> None:
    env = make("Blackjack-v0")
    observation, _, done, info = env.step(0)
    assert len(observation) == 3 and done and info == {}
    assert _kinds() == [events.STEP_BEFORE_RESET]


def test_step_before_reset_uses_the_seed_given_to_seed() -> None:
    classic = make("Blackjack-v0")
    classic.seed(7)
    target = gymnasium.make("Blackjack-v1", natural=False, sab=False)
    target.reset(seed=7)
    assert classic.step(0)[:2] == target.step(0)[:2]


def test_step_after_done_passes_through_quietly_and_is_recorded() -> None:
    env = make("CartPole-v0")
    env.reset(seed=0)
    done = False
    while not done:
        _, _, done, _ = env.step(0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        after = [env.step(0) for _ in range(3)]
    assert [str(warning.message) for warning in caught] == []
    assert [result[2] for result in after] == [True, True, True]
    assert _kinds() == [events.STEP_AFTER_DONE]


def test_step_after_done_detail_counts_each_step() -> None:
    env = make("Taxi-v3")
    env.reset(seed=0)
    done = False
    while not done:
        _, _, done, _ = env.step(0)
    env.step(0)
    env.step(0)
    after = [event for event in events.drain() if event.kind == events.STEP_AFTER_DONE]
    assert len(after) == 1 and after[0].detail.endswith("(2 times)")


def test_reset_ends_the_after_done_state() -> None:
    env = make("Blackjack-v0")
    env.reset(seed=0)
    env.step(0)
    env.reset(seed=1)
    env.step(0)
    assert _kinds() == []


@pytest.mark.parametrize(
    "action",
    [np.int64(1), np.int32(1), np.uint8(1), np.array(1)],
    ids=["int64", "int32", "uint8", "0-d array"],
)
def test_numpy_integer_actions_become_ints(action: Any) -> None:
    env = make("Taxi-v3")
    env.reset(seed=0)
    taken: list[Any] = []
    real_step = env.gymnasium_env.step

    def spy(step_action: Any) -> Any:
        taken.append(step_action)
        return real_step(step_action)

    env.gymnasium_env.step = spy  # type: ignore[method-assign]
    env.step(action)
    assert [type(value) for value in taken] == [int]
    assert _kinds() == [events.NUMPY_ACTION]


def test_box_actions_are_left_alone() -> None:
    env = make("MountainCarContinuous-v0")
    env.reset(seed=0)
    env.step(np.array([0.5], dtype=np.float32))
    assert _kinds() == []


def test_render_without_mode_draws_nothing_and_is_recorded_once(monkeypatch: pytest.MonkeyPatch) -> None:
    env = make("Acrobot-v1")
    env.reset(seed=0)
    monkeypatch.setattr(env.unwrapped, "render", lambda: pytest.fail("render() reached gymnasium"))
    assert [env.render() for _ in range(100)] == [None] * 100
    assert _kinds() == [events.RENDER_WITHOUT_MODE]


def test_render_before_reset_is_harmless_too() -> None:
    assert make("CartPole-v0").render() is None


@pytest.mark.parametrize(
    ("env_id", "shape"),
    [("CartPole-v0", (400, 600, 3)), ("Acrobot-v1", (500, 500, 3)), ("Taxi-v3", (456, 536, 3))],
    ids=["CartPole-v0", "Acrobot-v1", "Taxi-v3"],
)
def test_render_rgb_array_draws_a_frame_of_the_current_state(env_id: str, shape: tuple[int, ...]) -> None:
    env = make(env_id)
    env.reset(seed=0)
    frame = env.render(mode="rgb_array")
    assert (frame.shape, frame.dtype) == (shape, np.uint8)
    assert env.unwrapped.render_mode is None


def test_render_ansi_returns_text_for_text_envs() -> None:
    env = make("Taxi-v3")
    env.reset(seed=0)
    assert "+---------+" in env.render(mode="ansi")


def test_render_in_a_mode_the_env_lacks_fails_with_the_modes_it_has() -> None:
    env = make("NChain-v0")
    env.reset()
    with pytest.raises(UnsupportedRenderModeError) as raised:
        env.render(mode="rgb_array")
    assert (
        str(raised.value)
        == "NChain-v0 cannot render in mode 'rgb_array'; it supports no mode at all. Use one of those."
    )


def test_an_env_made_with_a_render_mode_renders_in_it() -> None:
    env = make("CartPole-v0", render_mode="rgb_array")
    env.reset(seed=0)
    assert env.render().shape == (400, 600, 3)
    assert _kinds() == []


def test_attributes_are_read_through_the_wrapper_stack() -> None:
    env = make("Taxi-v3")
    env.reset(seed=0)
    assert (len(env.P), env.s) == (500, env.unwrapped.s)


@pytest.mark.parametrize(
    ("env_id", "sizes"),
    [("FrozenLake-v0", (16, 4)), ("FrozenLake8x8-v0", (64, 4)), ("Taxi-v3", (500, 6))],
    ids=["FrozenLake-v0", "FrozenLake8x8-v0", "Taxi-v3"],
)
def test_classic_toy_text_sizes_are_served(env_id: str, sizes: tuple[int, int]) -> None:
    env = make(env_id)
    assert (env.nS, env.nA) == sizes
    assert len(env.P) == sizes[0]  # the 2018 lab: value_iteration(env.P, env.nS, env.nA)


def test_env_env_is_the_same_environment_without_its_time_limit() -> None:
    outer = make("FrozenLake-v0", is_slippery=False)
    inner = outer.env  # the 2018 lab: env = gym.make("FrozenLake-v0").env
    assert inner is outer.env and isinstance(inner, type(outer))
    assert (inner.nS, inner.nA, len(inner.P), inner._max_episode_steps) == (16, 4, 16, None)
    assert outer._max_episode_steps == 100
    assert inner.reset() == 0
    for _ in range(150):  # left from the start bumps into the wall forever
        observation, reward, done, _info = inner.step(0)
        assert (observation, reward, done) == (0, 0.0, False)
    raw = inner.env.env  # gym 0.26's chain: TimeLimit > OrderEnforcing > PassiveEnvChecker > the env
    assert (raw.nS, len(raw.P), raw._max_episode_steps) == (16, 16, None)
    with pytest.raises(AttributeError, match="has no attribute 'env'"):
        _ = raw.env


def test_the_outer_env_keeps_its_time_limit() -> None:
    outer = make("FrozenLake-v0", is_slippery=False)
    outer.reset()
    dones = [outer.step(0)[2] for _ in range(100)]
    assert dones == [False] * 99 + [True]


def test_sizes_of_a_continuous_space_are_missing_attributes() -> None:
    with pytest.raises(AttributeError) as raised:
        _ = make("CartPole-v0").nS
    assert str(raised.value) == "the CartPole-v0 environment has no attribute 'nS'"


def test_private_attributes_are_not_forwarded() -> None:
    with pytest.raises(AttributeError, match="private attribute '_secret'"):
        _ = make("Taxi-v3")._secret


def test_spaces_spec_and_random_generator_are_gymnasium_s() -> None:
    env = make("Taxi-v3")
    assert (env.action_space, env.observation_space) == (
        gymnasium.spaces.Discrete(6),
        gymnasium.spaces.Discrete(500),
    )
    assert env.spec is not None and env.spec.id == "Taxi-v4"
    assert isinstance(env.np_random, np.random.Generator)


def test_close_and_context_manager() -> None:
    with make("CartPole-v0") as env:
        env.reset(seed=0)
        env.render(mode="rgb_array")
    assert env.unwrapped.isopen is False


def test_a_missing_attribute_names_the_environment() -> None:
    with pytest.raises(AttributeError) as raised:
        _ = make("Taxi-v3").reward_range
    assert str(raised.value) == "the Taxi-v3 environment has no attribute 'reward_range'"


def test_a_copy_is_an_independent_environment_in_the_same_state() -> None:
    original = make("Taxi-v3")
    original.reset(seed=1)
    duplicate = copy.deepcopy(original)
    assert [duplicate.step(0)[:3] for _ in range(5)] == [original.step(0)[:3] for _ in range(5)]


def test_the_classic_step_limit_can_be_read_and_changed_on_the_env() -> None:
    env = make("MountainCar-v0")
    assert env._max_episode_steps == 200
    env._max_episode_steps = 5
    env.reset(seed=0)
    assert [env.step(1)[2] for _ in range(5)] == [False] * 4 + [True]


def test_an_env_without_a_step_limit_has_none_and_cannot_be_given_one() -> None:
    env = make("Blackjack-v0")
    assert env._max_episode_steps is None
    with pytest.raises(AttributeError, match=r"the Blackjack-v0 environment has no step limit to change"):
        env._max_episode_steps = 10


@pytest.mark.parametrize(
    ("mode", "detail_start"),
    [(None, "render() would open a window"), ("human", "render('human') would open a window")],
    ids=["no-mode", "human"],
)
def test_window_rendering_is_a_recorded_no_op(mode: str | None, detail_start: str) -> None:
    env = make("CartPole-v0")
    env.reset(seed=0)
    assert env.render(mode=mode) is None
    (event,) = [event for event in events.drain() if event.kind == events.RENDER_WITHOUT_MODE]
    assert event.detail.startswith(detail_start)
