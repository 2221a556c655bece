"""Tests for grader.compat.envs.guessing_game: the classic GuessingGame-v0 rules."""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
import pytest

from grader.compat import GuessingGameEnv, InvalidActionError, register_envs


def _game(number: float) -> GuessingGameEnv:
    env = GuessingGameEnv()
    env.reset(seed=0)
    env.number = number
    return env


def test_reset_observes_no_guess_yet() -> None:
    assert GuessingGameEnv().reset(seed=0) == (0, {})


@pytest.mark.parametrize(
    ("guess", "observation", "reward", "terminated"),
    [
        (-500.0, 1, 0, False),
        (490.0, 1, 0, False),
        (490.5, 1, 1, True),
        (500.0, 2, 1, True),
        (509.5, 3, 1, True),
        (510.0, 3, 0, False),
        (9000.0, 3, 0, False),
    ],
    ids=["far-below", "edge-below", "inside-below", "equal", "inside-above", "edge-above", "far-above"],
)
def test_observation_is_the_side_of_the_target_and_reward_needs_strictly_within_10(
    guess: float, observation: int, reward: int, terminated: bool
) -> None:
    assert _game(500.0).step(guess)[:3] == (observation, reward, terminated)


def test_info_has_guesses_then_number_as_the_lab_prints() -> None:
    env = _game(524.50509074)
    env.step(0.0)
    assert list(env.step(0.0)[4].items()) == [("guesses", 2), ("number", 524.50509074)]


def test_the_200th_miss_ends_the_episode_as_truncated() -> None:
    env = _game(500.0)
    results = [env.step(0.0) for _ in range(200)]
    assert [index for index, result in enumerate(results) if result[3]] == [199]
    assert not any(result[2] for result in results)


@pytest.mark.parametrize(
    "action",
    [500, 500.0, [500.0], np.array([500.0]), np.array([500.0], dtype=np.float32), np.float32(500.0)],
    ids=["int", "float", "list", "array-float64", "array-float32", "numpy-scalar"],
)
def test_a_guess_can_be_a_number_a_list_or_an_array(action: Any) -> None:
    assert _game(500.0).step(action)[:3] == (2, 1, True)


@pytest.mark.parametrize(
    "action",
    [10000.5, -20000, [1.0, 2.0], np.array([]), float("nan"), "500", None],
    ids=["above-bounds", "below-bounds", "two-guesses", "empty", "nan", "string", "none"],
)
def test_invalid_guesses_are_refused_with_what_is_expected(action: Any) -> None:
    with pytest.raises(InvalidActionError, match=r"GuessingGame-v0 expects one guess in \[-10000, 10000\]"):
        _game(0.0).step(action)


def test_spaces_are_the_classic_ones() -> None:
    env = GuessingGameEnv()
    assert env.action_space == gymnasium.spaces.Box(-10000.0, 10000.0, (1,), np.float32)
    assert env.observation_space == gymnasium.spaces.Discrete(4)


def test_targets_are_drawn_from_minus_1000_to_1000() -> None:
    env = GuessingGameEnv()
    numbers = []
    for seed in range(2000):
        env.reset(seed=seed)
        numbers.append(env.number)
    # Uniform on [-1000, 1000): each half holds 1000 +- 200 of 2000 draws except with probability < 1e-15.
    assert min(numbers) >= -1000 and max(numbers) < 1000
    assert 800 < sum(number < 0 for number in numbers) < 1200


def test_bisection_as_the_lab_suggests_always_wins_within_the_limit() -> None:
    register_envs()
    env = gymnasium.make("GuessingGame-v0")
    for seed in range(100):
        env.reset(seed=seed)
        low, high, reward, guesses = -10000.0, 10000.0, 0, 0
        while not reward:
            guess = (low + high) / 2
            observation, reward, _, truncated, info = env.step(guess)
            assert not truncated
            low, high = (guess, high) if observation == 1 else (low, guess)
            guesses = info["guesses"]
        assert guesses <= 11
