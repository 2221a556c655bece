"""The toy-text games `gym_toytext` registers besides the lab's NChain and GuessingGame."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils import seeding
from scipy.stats import genpareto

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


def _wheel(seed: int) -> np.random.Generator:
    """The generator `reset(seed=seed)` gives the env, built independently with gymnasium's seeding."""
    generator, _ = seeding.np_random(seed)
    return generator


@pytest.mark.parametrize("bet", [0, 1, 2, 17, 36], ids=lambda bet: f"bet-{bet}")
def test_roulette_pays_every_spin_by_the_classic_rules(bet: int) -> None:
    """Each spin against the classic rules written out here: 0 pays 36 to 1 on a 37-spot wheel when the
    wheel shows 0; another bet pays 1 when the wheel shows a non-zero number of its parity; else -1."""
    env = RouletteEnv(spots=37)
    env.reset(seed=11)
    wheel = _wheel(11)
    rewards = []
    for _ in range(400):
        shown = int(wheel.integers(0, 37))
        if bet == 0:
            expected = 36.0 if shown == 0 else -1.0
        else:
            expected = 1.0 if shown != 0 and shown % 2 == bet % 2 else -1.0
        reward = env.step(bet)[1]
        rewards.append(reward)
        assert reward == expected
    assert set(rewards) == ({36.0, -1.0} if bet == 0 else {1.0, -1.0})  # both outcomes were seen


def test_kelly_coin_wins_with_the_edge_and_wealth_stops_at_the_cap() -> None:
    """A $1 bet each round from $240 of at most $250: the coin wins when a uniform draw is below the edge
    0.6 (gym's `flip`), the wealth moves by the bet and never passes the cap, where the game ends."""
    env = KellyCoinflipEnv(initial_wealth=240.0, edge=0.6, max_wealth=250.0)
    env.reset(seed=4)
    coin = _wheel(4)
    wealth, terminated, rounds = 240.0, False, 0
    while not terminated:
        won = coin.uniform() < 0.6
        wealth = min(250.0, wealth + (1.5 if won else -1.5))
        (observed, _), reward, terminated, _, _ = env.step(150)
        rounds += 1
        assert float(observed[0]) == pytest.approx(wealth)
    assert wealth == 250.0 and reward == 250.0 and rounds < 300  # ended at the cap, not on the rounds


def test_kelly_generalized_draws_edge_cap_and_rounds_from_their_priors() -> None:
    """At each reset the edge is the first draw of Beta(7, 3), the cap the generalized Pareto (shape 5,
    location 200) quantile of the next uniform, the rounds N(300, 25) rounded: scipy's laws, drawn from an
    independently built copy of the reset's generator."""
    env = KellyCoinflipGeneralizedEnv()
    for seed in (2, 9, 30):
        env.reset(seed=seed)
        draws = _wheel(seed)
        edge = draws.beta(7, 3)
        cap = round(float(genpareto.ppf(draws.uniform(), 5.0, loc=200.0)))
        rounds = round(float(draws.normal(300.0, 25.0)))
        assert (env.edge, env.max_wealth, env.max_rounds) == (pytest.approx(edge), cap, rounds)


def test_kelly_generalized_counts_wins_and_losses() -> None:
    """Wins and losses as the observation counts them: a round whose wealth did not fall is a win (a bet
    of nothing too: classic gym counted every round as a win), one whose wealth fell a loss."""
    env = KellyCoinflipGeneralizedEnv()
    env.reset(seed=6)
    draws = _wheel(6)
    edge = draws.beta(7, 3)
    draws.uniform(), draws.normal()  # the cap's and the rounds' draws
    wins = losses = 0
    for bet in [100, 0, 100, 0, 200, 0, 100, 100, 0, 100]:
        won = draws.uniform() < edge
        wins, losses = (wins + 1, losses) if won or bet == 0 else (wins, losses + 1)
        observation, _, terminated, _, _ = env.step(bet)
        assert observation[2:4] == (wins, losses)
        assert not terminated
    assert wins and losses
