"""The toy-text games `gym_toytext` registers besides the lab's NChain and GuessingGame."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

from grader.compat.envs import (
    TOY_TEXT_IDS,
    HotterColderEnv,
    KellyCoinflipEnv,
    KellyCoinflipGeneralizedEnv,
    RouletteEnv,
    register_envs,
)
from grader.compat.errors import InvalidActionError


def test_every_gym_toytext_id_is_registered_with_its_time_limit() -> None:
    register_envs()
    limits = {env_id: gymnasium.spec(env_id).max_episode_steps for env_id in TOY_TEXT_IDS}
    assert limits == {
        "GuessingGame-v0": 200,
        "HotterColder-v0": 200,
        "KellyCoinflip-v0": None,
        "KellyCoinflipGeneralized-v0": None,
        "NChain-v0": 1000,
        "Roulette-v0": 100,
    }


def test_hotter_colder_rewards_closeness() -> None:
    env = HotterColderEnv()
    assert env.reset(seed=3)[0] == 0
    target = env.number
    observation, reward, terminated, truncated, info = env.step(np.array([target - 100.0], np.float32))
    assert (observation, terminated, truncated, info["guesses"]) == (1, False, False, 1)
    assert reward == pytest.approx(((target - 100 + 2000) / (target + 2000)) ** 2, rel=1e-6)
    with pytest.raises(InvalidActionError, match="HotterColder-v0 takes one guess in"):
        env.step(5000.0)


def test_roulette_walks_away_with_the_last_action_and_pays_parity() -> None:
    env = RouletteEnv(spots=37)
    env.reset(seed=1)
    rewards = {env.step(1)[1] for _ in range(200)}
    assert rewards == {1.0, -1.0}
    assert env.step(37)[1:3] == (0.0, True)


def test_kelly_bets_are_capped_at_the_wealth_and_the_game_ends_broke_or_capped() -> None:
    env = KellyCoinflipEnv()
    (wealth, rounds), _ = env.reset(seed=0)
    assert (float(wealth[0]), rounds) == (25.0, 300)
    terminated = False
    while not terminated:
        (wealth, rounds), reward, terminated, _, _ = env.step(env.action_space.n - 1)
    assert float(wealth[0]) in (0.0, 250.0) or rounds == 0
    assert reward == pytest.approx(float(wealth[0]))


def test_kelly_generalized_draws_its_hidden_parameters_at_each_reset() -> None:
    env = KellyCoinflipGeneralizedEnv()
    env.reset(seed=5)
    first = (env.edge, env.max_wealth, env.max_rounds)
    env.reset()
    assert (env.edge, env.max_wealth, env.max_rounds) != first
    assert 0 < env.edge < 1 and env.max_wealth >= 200 and env.max_rounds > 0
